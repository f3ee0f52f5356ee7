// Physical classification of time-based solutions (paper Table `stateVStime`).
#include <gtest/gtest.h>

#include "hybridcont/classification.h"
#include "hybridcont/expression_model.h"
#include "hybridcont/model_file.h"
#include "hybridcont/models.h"
#include "known_orbits.h"

namespace hybridcont {
namespace {

Classification Classify(const HybridModel& model, const Vector& u) {
  const OrbitTrace trace(model, u, IntegratorOptions{});
  return ClassifyOrbit(model, u, trace, ClassificationOptions{});
}

TEST(Classification, AnalyticOrbitsArePhysical) {
  const HybridModel ball = MakeBouncingBall();
  const Classification c = Classify(ball, BallOrbit(ShootingLayout(ball), 0.5));
  EXPECT_TRUE(c.physical) << ToString(c.reason) << " " << c.detail;
  const HybridModel slip = MakeSlip();
  const Classification s = Classify(slip, SlipHoppingInPlace(slip, ShootingLayout(slip), 1.5));
  EXPECT_TRUE(s.physical) << ToString(s.reason) << " " << s.detail;
}

TEST(Classification, ReversedTimeBallIsNotPhysical) {
  // The paper's dashed branch T = -sqrt(8H): the same states traversed backward in time.
  const HybridModel ball = MakeBouncingBall();
  const ShootingLayout layout(ball);
  Vector u = BallOrbit(layout, 0.5);
  u(layout.time_index(0)) *= -1;
  u(layout.time_index(1)) *= -1;
  u(layout.state_offset(1) + 1) *= -1;  // x2 = [0, -v]: backward from the impact
  const Classification c = Classify(ball, u);
  EXPECT_FALSE(c.physical);
  EXPECT_EQ(c.reason, OrbitClass::kReversedTime);
}

TEST(Classification, SlipStartHasAZeroDurationFlight) {
  const HybridModel slip = MakeSlip();
  const Classification c = Classify(slip, BuiltinStartPoint(slip));
  EXPECT_EQ(c.reason, OrbitClass::kZeroDuration);
  EXPECT_NE(c.detail.find("t2"), std::string::npos) << c.detail;
}

TEST(Classification, BallAtRestWithXiIsAtRest) {
  const HybridModel ball = MakeBouncingBall();
  Vector u = Vector::Zero(ShootingLayout(ball).num_unknowns());
  u(ShootingLayout(ball).xi_index()) = 0.4;
  EXPECT_EQ(Classify(ball, u).reason, OrbitClass::kAtRest);
}

TEST(Classification, EarlierAnchorCrossingIsFoundOnTheDenseOutput) {
  // Return segment twice as long as the rise: the apex (anchor) was passed half-way.
  const HybridModel ball = MakeBouncingBall();
  const ShootingLayout layout(ball);
  Vector u = BallOrbit(layout, 0.5);
  u(layout.time_index(1)) *= 2.0;
  const Classification c = Classify(ball, u);
  EXPECT_EQ(c.reason, OrbitClass::kMissedAnchor) << c.detail;
  // The crossing is found at the apex time sqrt(2H) = 1 within one sub-step of the interpolant.
  EXPECT_NE(c.detail.find("t = 1"), std::string::npos) << c.detail;
}

TEST(Classification, EventReachedUpwardIsWrongDirection) {
  // Ball falling from the apex for zero... instead: start on the ground moving up, "event" at t = 0+:
  // segment 1 from [0, v] backward? Use an impact reached from below: x1 = [-H, v] rises to y = 0 with
  // dy > 0 at t1 = (v - sqrt(v^2 - 2H)).
  const HybridModel ball = MakeBouncingBall();
  const ShootingLayout layout(ball);
  Vector u = BallOrbit(layout, 0.5);
  const double v = 2.0, H = 0.5;
  u(layout.state_offset(0)) = -H;
  u(layout.state_offset(0) + 1) = v;
  u(layout.time_index(0)) = v - std::sqrt(v * v - 2 * H);
  const Classification c = Classify(ball, u);
  EXPECT_EQ(c.reason, OrbitClass::kWrongDirection) << c.detail;
}

}  // namespace
}  // namespace hybridcont

namespace hybridcont {
namespace {

TEST(Classification, PhaseStartingBeyondItsGuardIsNotPhysical) {
  // Segment 1 starts 0.1 below the ground moving up (a penetration), rises through y = 0 and comes back
  // down through it at t1 = 1 + sqrt(0.8): the end crossing is downward and there is no earlier downward
  // crossing, but the trajectory was beyond its guard: the replay of such an orbit never finds the event.
  const HybridModel ball = MakeBouncingBall();
  const ShootingLayout layout(ball);
  Vector u = BallOrbit(layout, 0.5);
  u(layout.state_offset(0)) = -0.1;
  u(layout.state_offset(0) + 1) = 1.0;
  u(layout.time_index(0)) = 1.0 + std::sqrt(0.8);
  const Classification c = Classify(ball, u);
  EXPECT_EQ(c.reason, OrbitClass::kMissedEvent) << c.detail;
  EXPECT_NE(c.detail.find("t = 0 "), std::string::npos) << c.detail;
}

}  // namespace
}  // namespace hybridcont

namespace hybridcont {
namespace {

// The return segment runs in phase 1 up to the section; phase 1's own event crossed there from above is a
// missed event too. A ball with a clock s: its section is s = 1/2 (half-way through a flight that starts at
// each bounce with s = 0). Segment 2 starts 0.05 above the floor falling at speed 1, so it passes through the
// floor at t = sqrt(1.1) - 1 = 0.0488 before its section at t = 1/2; every segment's end is a transversal crossing.
TEST(Classification, PhaseOnesEventCrossedBeforeTheSectionIsAMissedEvent) {
  const char* text = R"toml(
hybridcont = 1
name = "clocked-ball"
conservative = false

[parameters]
g = 1.0

[[phases]]
name = "flight"
states = ["s", "y", "v"]
typical = [0.5, 0.5, -1]
ode = { s = "1", y = "v", v = "-g" }
event = "y"
anchor = "0.5 - s"
reset = { s = "0", y = "y", v = "-v" }

[start]
kind = "guess"
values = { t1 = 1, t2 = 0.5, x1_s = 0.5, x1_y = 0.5, x1_v = 0 }

[run]
parameter = "g"
)toml";
  const HybridModel model = BuildExpressionModel(ParseModelText(text, "clocked-ball.toml"));
  const ShootingLayout layout(model);
  Vector u = Vector::Zero(layout.num_unknowns());
  u(layout.time_index(0)) = 1.0;  // from the section (y = 1/2, at rest) to the floor
  u.segment(layout.state_offset(0), 3) << 0.5, 0.5, 0.0;
  u(layout.time_index(1)) = 0.5;  // from s = 0 to the section
  u.segment(layout.state_offset(1), 3) << 0.0, 0.05, -1.0;
  const Classification c = Classify(model, u);
  EXPECT_EQ(c.reason, OrbitClass::kMissedEvent) << c.detail;
  EXPECT_NE(c.detail.find("before the section) at t = 0.04"), std::string::npos) << c.detail;
  // Rising from the floor instead, the same segment is admissible.
  u.segment(layout.state_offset(1), 3) << 0.0, 0.0, 1.0;
  const Classification rising = Classify(model, u);
  EXPECT_TRUE(rising.physical) << ToString(rising.reason) << " " << rising.detail;
}

}  // namespace
}  // namespace hybridcont
