// Bouncing ball (paper eq. `HDSball`): one flight phase, impact at y = 0, anchor at the apex (dy = 0).
#include "hybridcont/models.h"
#include "models/ball_flight.h"

namespace hybridcont {

HybridModel MakeBouncingBall() {
  auto b = internal::BallBuilder("bouncing-ball", "ball bouncing elastically on the ground (paper §4.1)");
  Vector typical(2);
  typical << 0.5, 0.3;
  b.AddPhase<internal::BallFlight>("flight", {"y", "dy"}, typical);
  b.SetAnchor<internal::BallApex>();
  b.Symmetry("time-reversal", {Vector(Eigen::Vector2d(1, -1))}, true);
  return b.Build();
}

}  // namespace hybridcont
