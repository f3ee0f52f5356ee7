#include "scenario.h"

#include <cmath>
#include <stdexcept>

#include "hybridcont/models.h"
#include "hybridcont/shooting_layout.h"

namespace hybridcont::app {

namespace {
std::vector<std::string> Durations(const HybridModel& model) {
  std::vector<std::string> t;
  for (int i = 0; i <= model.num_phases(); ++i) t.push_back("t" + std::to_string(i + 1));
  return t;
}
}  // namespace

Scenario DefaultScenario(const HybridModel& model) {
  Scenario s;
  s.start = BuiltinStartPoint(model);
  const ShootingLayout layout(model);
  s.describe = [](const Vector&) { return std::string("periodic orbit"); };
  // |xi| <= 1 ends the at-rest xi-branches through the equilibria (they exist for every xi).
  s.bounds.push_back({"xi", -1.0, 1.0});
  const std::string& name = model.name();
  if (name == "bouncing-ball") {
    s.bounds.push_back({"H", -1.0, 1.0});
    s.keyframes = {"H", 0.5};
  } else if (name == "rocking-block") {
    const double H_max = model.parameter("m") * model.parameter("g") * model.parameter("l0") *
                         (1.0 - std::cos(model.parameter("beta")));
    s.bounds.push_back({"H", -1.0, H_max});
    // T grows without bound towards the homoclinic orbit at H_max: stop cleanly at |T| = 20, where
    // H_max - H ~ 1e-9. Beyond T ~ 30 the monodromy grows like e^{lambda T} and Newton's linear systems lose
    // all accuracy (measured: steps collapse to 1e-6 near T = 33), so nothing is gained by going on.
    s.sum_bounds.push_back({Durations(model), -20.0, 20.0});
    s.keyframes = {"H", 0.5 * H_max};
    // H <= H_max ~ 0.045 and alpha <= beta: scaled to O(1) so that the branch is resolved in H too.
    s.unknown_scales.push_back({"H", H_max});
    for (int i = 1; i <= 2; ++i) {
      s.unknown_scales.push_back({"x" + std::to_string(i) + "_alpha", model.parameter("beta")});
      s.unknown_scales.push_back({"x" + std::to_string(i) + "_dalpha", std::sqrt(H_max / model.parameter("m")) /
                                                                          model.parameter("l0")});
    }
    s.max_step = 0.5;
  } else if (name == "bouncing-rod") {
    s.bounds.push_back({"H", -1.0, 0.6});
    s.sum_bounds.push_back({Durations(model), -10.0, 10.0});
    s.start_conditions.push_back({{{"t2", 1.0}, {"t1", -1.0}, {"t3", -1.0}}, "t2 = t1 + t3"});
    s.keyframes = {"T", 0.8};
    s.describe = [layout](const Vector& u) {
      const double asymmetry = u(layout.time_index(1)) - u(layout.time_index(0)) - u(layout.time_index(2));
      return std::string(std::abs(asymmetry) < 1e-6 ? "symmetric orbit (t2 = t1 + t3)"
                                                    : asymmetry > 0 ? "non-symmetric orbit (t2 > t1 + t3)"
                                                                    : "non-symmetric orbit (t2 < t1 + t3)");
    };
    // dalpha = sqrt(2H)/r ~ 100 would dominate every norm of u; r * dalpha is O(1) (an energy-like
    // velocity), and durations are O(0.1).
    for (int i = 1; i <= model.num_phases() + 1; ++i) {
      s.unknown_scales.push_back({"x" + std::to_string(i) + "_dalpha", model.parameter("l0") / model.parameter("r")});
    }
  } else if (name == "slip") {
    s.bounds.push_back({"H", 0.0, 2.0});
    s.sum_bounds.push_back({Durations(model), -20.0, 20.0});
    s.keyframes = {"H", 1.8};
    // Steps stay at 0.1. Larger steps cost fewer evaluations (0.2: 1661 instead of 1916) and, since the
    // Floquet pass finds crossing pairs inside one step (FindHiddenRootPair), keep the PD points of
    // hopping in place. But the cluster of nearly tangent crossings near H = 1.6116 (four images of one
    // branch) is resolved differently from one step to the next above 0.135 (measured for max_step in
    // 0.14–0.23: 23 or 31 half-branches, 17 to 23 SB points), while 0.09–0.135 all give the same 23
    // half-branches and 21 SB points, all located.
    s.describe = [layout](const Vector& u) {
      const double dx = u(layout.state_offset(1) + 2);  // x2_dx: forward speed in flight
      return std::string(std::abs(dx) < 1e-6 ? "hopping in place" : dx > 0 ? "forward hopping" : "backward hopping");
    };
  } else {
    throw std::invalid_argument("model '" + name + "' has no default run scenario");
  }
  return s;
}

}  // namespace hybridcont::app
