// Locating sign changes of a test function between branch points (used for Floquet BP/PD points).
#include <gtest/gtest.h>

#include <cmath>

#include "continuation_test_problems.h"
#include "hybridcont/corrector.h"
#include "hybridcont/test_function_root.h"

namespace hybridcont {
namespace {

TEST(TestFunctionRoot, LocatesALevelOfANonlinearFunctionOnTheCircle) {
  testing::Circle circle;
  // two points of the unit circle; the test function x*y - 0.3 changes sign between them
  const double a = 0.2, b = 0.6;
  const Vector u_a = (Vector(2) << std::cos(a), std::sin(a)).finished();
  const Vector u_b = (Vector(2) << std::cos(b), std::sin(b)).finished();
  const auto test = [](const Vector& u) { return u(0) * u(1) - 0.3; };
  const TestFunctionRoot root = LocateTestFunctionRoot(&circle, u_a, u_b, test, TestFunctionRootOptions{});
  ASSERT_TRUE(root.located) << root.message;
  // exact: sin(2 theta) = 0.6 on the circle
  const double theta = 0.5 * std::asin(0.6);
  EXPECT_NEAR(root.u(0), std::cos(theta), 1e-11);
  EXPECT_NEAR(root.u(1), std::sin(theta), 1e-11);
  EXPECT_LT(root.precision, 1e-10);
  EXPECT_LT(root.iterations, 30);
}

TEST(TestFunctionRoot, NoSignChangeIsReportedNotLocated) {
  testing::Circle circle;
  const Vector u_a = (Vector(2) << 1.0, 0.0).finished();
  const Vector u_b = (Vector(2) << 0.0, 1.0).finished();
  const TestFunctionRoot root =
      LocateTestFunctionRoot(&circle, u_a, u_b, [](const Vector&) { return 1.0; }, TestFunctionRootOptions{});
  EXPECT_FALSE(root.located);
  EXPECT_NE(root.message.find("no sign change"), std::string::npos);
}

// Two roots inside one step: g = (y − sin 0.5)² − 0.02² is positive at the samples θ = 0.2, 0.45, 0.75
// of the unit circle (arclength θ) and negative for |y − sin 0.5| < 0.02, between θ = 0.45 and 0.75. The
// parabola through the samples dips to −2e-3 near θ = 0.52, the probe there is negative, and the two
// roots are located on both sides of it.
TEST(TestFunctionRoot, FindsTwoRootsBetweenSamplesOfOneSign) {
  testing::Circle circle;
  const auto at = [](double theta) { return Vector((Vector(2) << std::cos(theta), std::sin(theta)).finished()); };
  const double center = std::sin(0.5), width = 0.02;
  const auto test = [&](const Vector& u) { return (u(1) - center) * (u(1) - center) - width * width; };
  const std::array<double, 3> s = {0.2, 0.45, 0.75};
  const Vector u0 = at(s[0]), u1 = at(s[1]), u2 = at(s[2]);
  const std::array<double, 3> g = {test(u0), test(u1), test(u2)};
  ASSERT_GT(g[0], 0);
  ASSERT_GT(g[1], 0);
  ASSERT_GT(g[2], 0);
  const std::optional<double> dip = ParabolaDipThroughZero(s, g);
  ASSERT_TRUE(dip.has_value());
  EXPECT_GT(*dip, s[1]);
  EXPECT_LT(*dip, s[2]);

  const HiddenRootPair pair = FindHiddenRootPair(&circle, {&u0, &u1, &u2}, s, g, test);
  ASSERT_TRUE(pair.found);
  EXPECT_EQ(pair.segment, 1);
  EXPECT_LT(pair.value, 0);
  EXPECT_NEAR(pair.u.norm(), 1.0, 1e-12);  // on the curve
  const TestFunctionRoot low = LocateTestFunctionRoot(&circle, u1, pair.u, test, TestFunctionRootOptions{});
  const TestFunctionRoot high = LocateTestFunctionRoot(&circle, pair.u, u2, test, TestFunctionRootOptions{});
  ASSERT_TRUE(low.located) << low.message;
  ASSERT_TRUE(high.located) << high.message;
  EXPECT_NEAR(low.u(1), center - width, 1e-11);
  EXPECT_NEAR(high.u(1), center + width, 1e-11);
}

// A minimum that stays above zero is not a pair: the parabola's extremum has the samples' sign (offset
// 5e-3), or it dips (offset 1e-3: the function is not a parabola in θ) and the probe refutes it.
TEST(TestFunctionRoot, AMinimumAboveZeroIsNoPair) {
  testing::Circle circle;
  const auto at = [](double theta) { return Vector((Vector(2) << std::cos(theta), std::sin(theta)).finished()); };
  const double center = std::sin(0.5);
  const std::array<double, 3> s = {0.2, 0.45, 0.75};
  const Vector u0 = at(s[0]), u1 = at(s[1]), u2 = at(s[2]);
  for (const double offset : {5e-3, 1e-3}) {
    const auto test = [&](const Vector& u) { return (u(1) - center) * (u(1) - center) + offset; };
    const std::array<double, 3> g = {test(u0), test(u1), test(u2)};
    EXPECT_EQ(ParabolaDipThroughZero(s, g).has_value(), offset < 2e-3) << offset;
    EXPECT_FALSE(FindHiddenRootPair(&circle, {&u0, &u1, &u2}, s, g, test).found) << offset;
  }
  // Not a local minimum of |g| (monotone samples): never probed.
  EXPECT_FALSE(ParabolaDipThroughZero({0.0, 1.0, 2.0}, {3.0, 2.0, 1.0}).has_value());
  // Samples of both signs: an ordinary sign change, not a hidden pair.
  EXPECT_FALSE(ParabolaDipThroughZero({0.0, 1.0, 2.0}, {1.0, -0.1, 1.0}).has_value());
}

// Two curves 0.03 apart, y = x² and y = x² + 0.03; the test (x − 0.3)⁴ + 1e-3 − (y − x²) is positive all
// along the first and negative on the second near x = 0.3. Samples on the first at x = −0.5, 0.1, 0.5
// predict a dip at x = 0.3; the chord point there lies 0.04 above the first curve, 0.01 from the second,
// where Newton went. The probe must stay on the sampled branch: no pair.
TEST(TestFunctionRoot, AProbeOnANeighbouringBranchConfirmsNoPair) {
  class TwoParabolas : public ZeroProblem {
   public:
    int num_equations() const override { return 1; }
    std::vector<std::string> unknown_names() const override { return {"x", "y"}; }
    EvaluationStatus Evaluate(const Vector& u, Vector* r, Matrix* dr) override {
      const double a = u(1) - u(0) * u(0), b = a - 0.03;
      if (r) *r = Vector::Constant(1, a * b);
      if (dr) {
        dr->resize(1, 2);
        *dr << -2 * u(0) * (a + b), a + b;
      }
      return {};
    }
  } curves;
  const auto test = [](const Vector& u) {
    return std::pow(u(0) - 0.3, 4) + 1e-3 - (u(1) - u(0) * u(0));
  };
  const auto at = [](double x) { return Vector((Vector(2) << x, x * x).finished()); };
  const std::array<double, 3> s = {-0.5, 0.1, 0.5};
  const Vector u0 = at(s[0]), u1 = at(s[1]), u2 = at(s[2]);
  const std::array<double, 3> g = {test(u0), test(u1), test(u2)};
  ASSERT_TRUE(ParabolaDipThroughZero(s, g).has_value());
  const HiddenRootPair pair = FindHiddenRootPair(&curves, {&u0, &u1, &u2}, s, g, test);
  EXPECT_FALSE(pair.found) << "probe (" << pair.u.transpose() << "), test " << pair.value;
}

// With refined_test, the integration error widens the precision: on the perturbed circle the root of
// y (a test that does not depend on the problem) lies 0.33ε from the exact (1, 0), because the computed
// curve does; the bracket alone says 1e-12.
TEST(TestFunctionRoot, IntegrationErrorWidensThePrecision) {
  const double epsilon = 1e-7;
  testing::PerturbedCircle curve(epsilon);
  const auto y = [](const Vector& u) { return u(1); };
  const Eigen::Vector2d u_a(std::cos(0.3), -std::sin(0.3)), u_b(std::cos(0.3), std::sin(0.3));
  // the branch points, on the perturbed curve
  Vector a, b;
  Corrector corrector(&curve);
  ASSERT_TRUE(corrector.CorrectPseudoArclength(u_a, Eigen::Vector2d(1, 0), &a).converged());
  ASSERT_TRUE(corrector.CorrectPseudoArclength(u_b, Eigen::Vector2d(1, 0), &b).converged());
  const TestFunctionRoot bare = LocateTestFunctionRoot(&curve, a, b, y, TestFunctionRootOptions{});
  ASSERT_TRUE(bare.located) << bare.message;
  const double error = (bare.u - Eigen::Vector2d(1, 0)).norm();
  EXPECT_NEAR(error, 0.5 * std::abs(std::sin(7.0)) * epsilon, 1e-2 * epsilon);
  EXPECT_LT(bare.precision, 1e-11);

  TestFunctionRootOptions options;
  options.refined_test = [](ZeroProblem&, const Vector& u) { return u(1); };
  const TestFunctionRoot root = LocateTestFunctionRoot(&curve, a, b, y, options);
  EXPECT_EQ(root.u, bare.u);
  EXPECT_NE(root.message.find("integration error"), std::string::npos) << root.message;
  EXPECT_GE(0.5 * root.precision, error);
  EXPECT_LE(0.5 * root.precision, 3 * error) << root.message;
}

}  // namespace
}  // namespace hybridcont
