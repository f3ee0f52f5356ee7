// Zeros of test functions found by the continuation (test_function.h) on the unit circle, where every
// zero is known in closed form: simple zeros, two zeros inside one step (a sign change hidden between
// samples), and a zero the function touches without changing sign (a double zero), against a near miss
// that must not be reported.
#include <cmath>
#include <memory>
#include <vector>

#include <gtest/gtest.h>

#include "continuation_test_problems.h"
#include "hybridcont/continuation.h"
#include "hybridcont/test_function.h"

namespace hybridcont {
namespace {

// g(x, y) = (1 + x²/2)·((y − c)^power − offset): the factor keeps g from being a function of y alone.
class HeightMonitor : public TestFunctions {
 public:
  HeightMonitor(double c, int power, double offset) : c_(c), power_(power), offset_(offset) {}
  std::vector<SpecialPointType> types() const override { return {SpecialPointType::kUserTestFunction}; }
  void Evaluate(const Vector& u, bool, Vector* values) override {
    const double x = u(0), y = u(1);
    *values = Vector::Constant(1, (1 + 0.5 * x * x) * (std::pow(y - c_, power_) - offset_));
  }
  std::unique_ptr<TestFunctions> Clone() const override { return std::make_unique<HeightMonitor>(*this); }

 private:
  double c_;
  int power_;
  double offset_;
};

std::vector<SpecialPoint> MonitorPoints(double c, int power, double offset) {
  testing::Circle circle;
  ContinuationOptions options;
  options.max_step = 0.25;
  options.initial_step = 0.25;
  options.test_functions = std::make_shared<HeightMonitor>(c, power, offset);
  const Branch branch = TraceBranch(&circle, (Vector(2) << 1.0, 0.0).finished(), options);
  EXPECT_EQ(branch.termination, TerminationReason::kClosedLoop) << branch.BriefReport();
  std::vector<SpecialPoint> points;
  for (const SpecialPoint& p : branch.special_points) {
    if (p.type == SpecialPointType::kUserTestFunction) points.push_back(p);
  }
  return points;
}

TEST(TestFunctions, SimpleZerosAreLocated) {
  const std::vector<SpecialPoint> points = MonitorPoints(0.3, 1, 0.0);
  ASSERT_EQ(points.size(), 2u);
  for (const SpecialPoint& p : points) {
    EXPECT_EQ(p.status, LocationStatus::kLocated) << p.BriefReport();
    EXPECT_NEAR(p.u(1), 0.3, 1e-11) << p.BriefReport();
    EXPECT_NEAR(std::abs(p.u(0)), std::sqrt(1 - 0.09), 1e-11) << p.BriefReport();
  }
}

// (y − c)² − 1e-8 has its two zeros y = c ± 1e-4 inside one step of 0.25, of one sign at the samples.
TEST(TestFunctions, TwoZerosInsideOneStepAreBothLocated) {
  const std::vector<SpecialPoint> points = MonitorPoints(0.3, 2, 1e-8);
  ASSERT_EQ(points.size(), 4u);  // two pairs: one where the circle passes y = 0.3 upwards, one downwards
  int above = 0, below = 0;
  for (const SpecialPoint& p : points) {
    EXPECT_EQ(p.status, LocationStatus::kLocated) << p.BriefReport();
    const double dy = p.u(1) - 0.3;
    EXPECT_NEAR(std::abs(dy), 1e-4, 1e-11) << p.BriefReport();
    (dy > 0 ? above : below)++;
  }
  EXPECT_EQ(above, 2);
  EXPECT_EQ(below, 2);
}

// (y − c)² touches zero at y = c: one located point per passage, flagged as a touching zero.
TEST(TestFunctions, TouchingZeroIsLocatedAsOne) {
  const std::vector<SpecialPoint> points = MonitorPoints(0.3, 2, 0.0);
  ASSERT_EQ(points.size(), 2u);
  for (const SpecialPoint& p : points) {
    EXPECT_EQ(p.status, LocationStatus::kLocated) << p.BriefReport();
    EXPECT_NE(p.message.find("touching zero"), std::string::npos) << p.BriefReport();
    EXPECT_NEAR(p.u(1), 0.3, 1e-9) << p.BriefReport();
    EXPECT_LT(p.precision(), 1e-8) << p.BriefReport();
    EXPECT_LE(p.u(1) - 0.3, p.interval_width(1)) << p.BriefReport();  // the interval holds the zero
  }
  // The same at the fourth power: a flatter bowl, still one point per passage.
  const std::vector<SpecialPoint> flat = MonitorPoints(0.3, 4, 0.0);
  ASSERT_EQ(flat.size(), 2u);
  for (const SpecialPoint& p : flat) EXPECT_NEAR(p.u(1), 0.3, 1e-4) << p.BriefReport();
}

// (y − c)² + 1e-6 comes within 1e-6 of zero (a miss distance 1e-3 in y): no zero.
TEST(TestFunctions, NearMissIsNotAZero) {
  EXPECT_TRUE(MonitorPoints(0.3, 2, -1e-6).empty());
}

}  // namespace
}  // namespace hybridcont
