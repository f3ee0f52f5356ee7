// Bouncing ball (paper eq. `HDSball`): one flight phase, impact at y = 0, anchor at the apex (dy = 0).
#include "hybridcont/model_builder.h"
#include "hybridcont/models.h"
#include "models/ball_flight.h"

namespace hybridcont {

HybridModel MakeBouncingBall() {
  ModelBuilder<internal::BallParameters<double>> b("bouncing-ball", "ball bouncing elastically on the ground (paper §4.1)");
  b.Parameter("m", [](auto& p) -> auto& { return p.m; }, "mass", ParameterRange::Positive())
      .Parameter("g", [](auto& p) -> auto& { return p.g; }, "gravity", ParameterRange::Positive());
  Vector typical(2);
  typical << 0.5, 0.3;
  b.AddPhase<internal::BallFlight>("flight", {"y", "dy"}, typical);
  b.SetAnchor<internal::BallApex>();
  b.Symmetry("time-reversal", {Vector(Eigen::Vector2d(1, -1))}, true);

  ModelSetup setup;
  setup.title = "bouncing ball";
  // The start u0 = 0: the ball at rest on the ground, an equilibrium with zero durations (paper §4.1).
  setup.start.kind = StartSpec::Kind::kSingular;
  // |xi| <= 1 ends the at-rest xi-branches through the equilibria (they exist for every xi).
  setup.run.bounds = {{"xi", "-1", "1"}, {"H", "-1", "1"}};
  setup.run.keyframe_component = "H";
  setup.run.keyframe_value = "0.5";
  // y is the height of the ball's lowest point (the impact is at y = 0): drawn as a disc of radius 0.1 resting
  // on it (the model is a point mass; the disc is small against the bounces it shows).
  setup.drawing.mass_radius = 0.1;
  DrawingSpec::PhaseDrawing flight;
  flight.phase = "flight";
  flight.points = {{"ball", "X", "y + 0.1"}};
  flight.masses = {"ball"};
  setup.drawing.phases = {flight};
  b.Setup(std::move(setup));
  return b.Build();
}

}  // namespace hybridcont
