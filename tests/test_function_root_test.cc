// Locating sign changes of a test function between branch points (used for Floquet BP/PD points).
#include <gtest/gtest.h>

#include <cmath>

#include "continuation_test_problems.h"
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

}  // namespace
}  // namespace hybridcont
