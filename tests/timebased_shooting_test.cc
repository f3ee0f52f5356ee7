// Known orbits are zeros of the time-based shooting map; perturbed ones are not (issue 2).
#include <gtest/gtest.h>

#include <cmath>

#include <Eigen/LU>

#include "hybridcont/models.h"
#include "hybridcont/timebased_shooting.h"

namespace hybridcont {
namespace {

// The analytic bouncing-ball orbit at level H (m = g = 1): apex height H, fall and rise times sqrt(2H).
Vector BallOrbit(const ShootingLayout& layout, double H) {
  Vector u = Vector::Zero(layout.num_unknowns());
  const double t = std::sqrt(2.0 * H);
  u(layout.time_index(0)) = t;                 // t1: apex -> impact
  u(layout.state_offset(0)) = H;               // x1 = [H, 0]
  u(layout.time_index(1)) = t;                 // t2: impact -> apex
  u(layout.state_offset(1) + 1) = std::sqrt(2.0 * H);  // x2 = [0, +v]
  u(layout.H_index()) = H;
  return u;
}

TEST(TimeBasedShooting, LayoutFollowsThePaper) {
  const HybridModel slip = MakeSlip();
  const ShootingLayout layout(slip);
  // N = sum n_i + m + 2 = (4 + 5 + 4) + 2 + 2 = 17
  EXPECT_EQ(layout.num_equations(), 17);
  const std::vector<std::string> expected = {"t3", "x3_alpha", "x3_l", "x3_dalpha", "x3_dl", "t2", "x2_y",
                                             "x2_alpha", "x2_dx", "x2_dy", "x2_dalpha", "t1", "x1_alpha",
                                             "x1_l", "x1_dalpha", "x1_dl", "xi", "H"};
  EXPECT_EQ(layout.unknown_names(), expected);
  EXPECT_EQ(ShootingLayout(MakeBouncingBall()).num_equations(), 7);  // paper: N = 7 for the block/ball
  // The rod: N = 3*4 + 2 + 2 = 16; the paper quotes 17, the length of its u (= N + 1).
  EXPECT_EQ(ShootingLayout(MakeBouncingRod()).num_unknowns(), 17);
}

TEST(TimeBasedShooting, AnalyticBallOrbitIsAZeroWithPeriodSqrt8H) {
  const HybridModel ball = MakeBouncingBall();
  TimeBasedShooting shooting(ball, IntegratorOptions{});
  for (double H : {0.05, 0.5, 1.0}) {
    const Vector u = BallOrbit(shooting.layout(), H);
    EXPECT_NEAR(shooting.layout().Period(u), std::sqrt(8.0 * H), 1e-15);
    Vector r;
    ASSERT_TRUE(shooting.Evaluate(u, &r, nullptr).ok);
    EXPECT_LT(r.lpNorm<Eigen::Infinity>(), 1e-12) << "H = " << H;
    Vector perturbed = u;
    perturbed(shooting.layout().time_index(0)) += 1e-3;
    shooting.Evaluate(perturbed, &r, nullptr);
    EXPECT_GT(r.lpNorm<Eigen::Infinity>(), 5e-4);
  }
}

// SLIP hopping in place (alpha = 0): harmonic stance about l_eq = l0 - mg/k from the nadir l_min,
// ballistic flight. H = m g l_min + k (l_min - l0)^2 / 2 fixes l_min.
Vector SlipHoppingInPlace(const HybridModel& slip, const ShootingLayout& layout, double H) {
  const double m = slip.parameter("m"), g = slip.parameter("g"), k = slip.parameter("k"), l0 = slip.parameter("l0");
  // k/2 (l - l0)^2 + m g l - H = 0, smaller root
  const double a = 0.5 * k, b = m * g - k * l0, c = 0.5 * k * l0 * l0 - H;
  const double l_min = (-b - std::sqrt(b * b - 4 * a * c)) / (2 * a);
  const double w = std::sqrt(k / m);
  const double amplitude = (l0 - m * g / k) - l_min;
  const double t_stance = std::acos(-(m * g / k) / amplitude) / w;
  const double dl_takeoff = amplitude * w * std::sin(w * t_stance);
  Vector u = Vector::Zero(layout.num_unknowns());
  u(layout.time_index(0)) = t_stance;
  u(layout.state_offset(0) + 1) = l_min;
  u(layout.time_index(1)) = 2.0 * dl_takeoff / g;
  u(layout.state_offset(1) + 0) = l0;          // y
  u(layout.state_offset(1) + 3) = dl_takeoff;  // dy
  u(layout.time_index(2)) = t_stance;
  u(layout.state_offset(2) + 1) = l0;
  u(layout.state_offset(2) + 3) = -dl_takeoff;
  u(layout.H_index()) = H;
  return u;
}

TEST(TimeBasedShooting, SlipHoppingInPlaceIsAZero) {
  const HybridModel slip = MakeSlip();
  TimeBasedShooting shooting(slip, IntegratorOptions{});
  for (double H : {1.2, 1.5, 1.9}) {
    const Vector u = SlipHoppingInPlace(slip, shooting.layout(), H);
    Vector r;
    Matrix dr;
    ASSERT_TRUE(shooting.Evaluate(u, &r, &dr).ok);
    EXPECT_LT(r.lpNorm<Eigen::Infinity>(), 1e-9) << "H = " << H << " r = " << r.transpose();
    // A normal orbit: dr has full rank N at a regular point.
    Eigen::FullPivLU<Matrix> lu(dr);
    EXPECT_EQ(lu.rank(), shooting.num_equations());
    Vector perturbed = u;
    perturbed(shooting.layout().state_offset(0) + 0) += 1e-3;  // tilt the leg
    shooting.Evaluate(perturbed, &r, nullptr);
    EXPECT_GT(r.lpNorm<Eigen::Infinity>(), 1e-4);
  }
}

TEST(TimeBasedShooting, PaperStartPointsAreSingularZeros) {
  for (const std::string& name : BuiltinModelNames()) {
    const HybridModel model = MakeBuiltinModel(name);
    TimeBasedShooting shooting(model, IntegratorOptions{});
    const Vector u0 = BuiltinStartPoint(model);
    Vector r;
    Matrix dr;
    ASSERT_TRUE(shooting.Evaluate(u0, &r, &dr).ok) << name;
    EXPECT_LT(r.lpNorm<Eigen::Infinity>(), 1e-10) << name;
    // Singular: rank deficient (a bifurcation point), as the paper states.
    EXPECT_LT(Eigen::FullPivLU<Matrix>(dr).setThreshold(1e-10).rank(), shooting.num_equations()) << name;
  }
}

TEST(TimeBasedShooting, OneIntegrationPerPhasePerPoint) {
  const HybridModel slip = MakeSlip();
  TimeBasedShooting shooting(slip, IntegratorOptions{});
  const Vector u = SlipHoppingInPlace(slip, shooting.layout(), 1.5);
  Vector r;
  Matrix dr;
  shooting.Evaluate(u, &r, &dr);
  const long work = shooting.counters().rhs_evaluations;
  shooting.Evaluate(u, &r, nullptr);
  shooting.Evaluate(u, nullptr, &dr);
  EXPECT_EQ(shooting.counters().rhs_evaluations, work);  // served from the cache
  EXPECT_EQ(shooting.num_evaluations(), 1);
}

}  // namespace
}  // namespace hybridcont
