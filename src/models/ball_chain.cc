// A scalable test model: a ball that bounces m times per period, written with m identical flight phases
// (phase i ends at the i-th impact). Its multiple-shooting Jacobian is block-cyclic with m + 1 blocks; it
// measures how the cost of a Newton step grows with the number of phases.
#include <cmath>
#include <stdexcept>
#include <string>

#include "hybridcont/model_builder.h"
#include "hybridcont/models.h"
#include "hybridcont/shooting_layout.h"
#include "models/ball_flight.h"

namespace hybridcont {
namespace {

// The set-up depends on the number of phases (one start value per segment), so it is written here rather
// than as a fixed table. The run follows the orbit family from its closed-form orbit at H = 0.5 (a regular
// point, the formulas of BallChainOrbit as expressions) both ways to the bounds of the bouncing ball.
ModelSetup BallChainSetup(int num_phases) {
  ModelSetup setup;
  setup.title = "ball chain";
  // An exact orbit (r = 0 by construction), not a guess; unlike the paper's starts it is a regular point.
  setup.start.kind = StartSpec::Kind::kSingular;
  const std::string height = "(0.5/(m*g))", fall_time = "(sqrt(2*g*" + height + ")/g)";
  for (int i = 0; i <= num_phases; ++i) {
    const bool first = i == 0, last = i == num_phases;
    const std::string segment = std::to_string(i + 1);
    setup.start.values.push_back({"t" + segment, (first || last) ? fall_time : "2*" + fall_time});
    if (first) setup.start.values.push_back({"x1_y", height});  // at the apex, dy = 0
    else setup.start.values.push_back({"x" + segment + "_dy", "sqrt(2*g*" + height + ")"});  // after an impact, y = 0
  }
  setup.start.values.push_back({"H", "0.5"});
  // |xi| <= 1 ends the at-rest xi-branches through the equilibria (they exist for every xi).
  setup.run.bounds = {{"xi", "-1", "1"}, {"H", "-1", "1"}};
  setup.run.keyframe_component = "H";
  setup.run.keyframe_value = "0.5";
  // As the bouncing ball: y is the height of the ball's lowest point, a disc of radius 0.5 resting on it.
  setup.drawing.mass_radius = 0.5;
  for (int i = 0; i < num_phases; ++i) {
    DrawingSpec::PhaseDrawing flight;
    flight.phase = "flight-" + std::to_string(i + 1);
    flight.points = {{"ball", "X", "y + 0.5"}};
    flight.masses = {"ball"};
    setup.drawing.phases.push_back(flight);
  }
  return setup;
}

}  // namespace

HybridModel MakeBallChain(int num_phases) {
  if (num_phases < 1) throw std::invalid_argument("ball-chain: number of phases must be >= 1");
  ModelBuilder<internal::BallParameters<double>> b("ball-chain", "ball bouncing m times per period, one phase per bounce");
  b.Parameter("m", [](auto& p) -> auto& { return p.m; }, "mass", ParameterRange::Positive())
      .Parameter("g", [](auto& p) -> auto& { return p.g; }, "gravity", ParameterRange::Positive());
  Vector typical(2);
  typical << 0.5, 0.3;
  for (int i = 0; i < num_phases; ++i) b.AddPhase<internal::BallFlight>("flight-" + std::to_string(i + 1), {"y", "dy"}, typical);
  b.SetAnchor<internal::BallApex>();
  b.Symmetry("time-reversal", std::vector<Vector>(num_phases, Vector(Eigen::Vector2d(1, -1))), true);
  b.Setup(BallChainSetup(num_phases));
  return b.Build();
}

Vector BallChainOrbit(const HybridModel& chain, double H) {
  const ShootingLayout layout(chain);
  const double g = chain.parameter("g"), mass = chain.parameter("m");
  const double height = H / (mass * g), v = std::sqrt(2.0 * g * height), t_fall = v / g;
  Vector u = Vector::Zero(layout.num_unknowns());
  for (int i = 0; i < layout.num_segments(); ++i) {
    const bool first = i == 0, last = i == layout.num_segments() - 1;
    u(layout.time_index(i)) = (first || last) ? t_fall : 2.0 * t_fall;
    u(layout.state_offset(i)) = first ? height : 0.0;
    u(layout.state_offset(i) + 1) = first ? 0.0 : v;
  }
  u(layout.H_index()) = H;
  return u;
}

}  // namespace hybridcont
