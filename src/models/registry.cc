#include <cmath>
#include <functional>
#include <stdexcept>

#include "hybridcont/models.h"
#include "hybridcont/shooting_layout.h"

namespace hybridcont {
namespace {

struct Entry {
  const char* name;
  HybridModel (*make)();
};

const std::vector<Entry>& Registry() {
  static const std::vector<Entry> entries = {
      {"bouncing-ball", &MakeBouncingBall},
      {"rocking-block", &MakeRockingBlock},
      {"bouncing-rod", &MakeBouncingRod},
      {"slip", &MakeSlip},
      {"ball-chain", [] { return MakeBallChain(10); }},
  };
  return entries;
}

}  // namespace

std::vector<std::string> BuiltinModelNames() {
  std::vector<std::string> names;
  for (const Entry& e : Registry()) names.push_back(e.name);
  return names;
}

HybridModel MakeBuiltinModel(const std::string& name) {
  std::string known;
  for (const Entry& e : Registry()) {
    if (name == e.name) return e.make();
    known += (known.empty() ? "" : ", ") + std::string(e.name);
  }
  throw std::invalid_argument("unknown model '" + name + "' (built-in models: " + known + ")");
}

Vector BuiltinStartPoint(const HybridModel& model) {
  const ShootingLayout layout(model);
  Vector u = Vector::Zero(layout.num_unknowns());
  if (model.name() == "slip") {
    // Vertical harmonic oscillation with zero flight time (paper §4.4): t1 = t3 = T0/2, t2 = 0,
    // x̄_1 at nadir l = l0 - 2mg/k, x̄_3 at l = l0 with zero velocity, H = m g l0.
    const double m = model.parameter("m"), g = model.parameter("g"), k = model.parameter("k"),
                 l0 = model.parameter("l0");
    const double half_period = M_PI * std::sqrt(m / k);
    u(layout.time_index(0)) = half_period;
    u(layout.time_index(1)) = 0.0;
    u(layout.time_index(2)) = half_period;
    u(layout.state_offset(0) + 1) = l0 - 2.0 * m * g / k;  // x1_l
    u(layout.state_offset(1) + 0) = l0;                    // x2_y
    u(layout.state_offset(2) + 1) = l0;                    // x3_l
    u(layout.H_index()) = m * g * l0;
  }
  if (model.name() == "ball-chain") return BallChainOrbit(model, 0.5);  // a regular point
  return u;  // equilibria at H = 0 for the ball, the block and the rod
}

}  // namespace hybridcont
