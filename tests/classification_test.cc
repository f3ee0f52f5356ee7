// Physical classification of time-based solutions (paper Table `stateVStime`).
#include <gtest/gtest.h>

#include "hybridcont/classification.h"
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
