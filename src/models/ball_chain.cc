// A scalable test model: a ball that bounces m times per period, written with m identical flight phases
// (phase i ends at the i-th impact). Its multiple-shooting Jacobian is block-cyclic with m + 1 blocks; it
// measures how the cost of a Newton step grows with the number of phases (issue 6).
#include <cmath>
#include <stdexcept>

#include "hybridcont/models.h"
#include "hybridcont/shooting_layout.h"
#include "models/ball_flight.h"

namespace hybridcont {

HybridModel MakeBallChain(int num_phases) {
  if (num_phases < 1) throw std::invalid_argument("ball-chain: number of phases must be >= 1");
  auto b = internal::BallBuilder("ball-chain", "ball bouncing m times per period, one phase per bounce");
  Vector typical(2);
  typical << 0.5, 0.3;
  for (int i = 0; i < num_phases; ++i) b.AddPhase<internal::BallFlight>("flight-" + std::to_string(i + 1), {"y", "dy"}, typical);
  b.SetAnchor<internal::BallApex>();
  b.Symmetry("time-reversal", std::vector<Vector>(num_phases, Vector(Eigen::Vector2d(1, -1))), true);
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
