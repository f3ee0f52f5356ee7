// Known orbits are zeros of the time-based shooting map; perturbed ones are not.
#include <gtest/gtest.h>

#include <cmath>

#include <Eigen/LU>

#include "hybridcont/corrector.h"
#include "hybridcont/models.h"
#include "hybridcont/timebased_shooting.h"
#include "known_orbits.h"

namespace hybridcont {
namespace {

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
  for (const std::string name : {"bouncing-ball", "rocking-block", "bouncing-rod", "slip"}) {
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

// set_jacobian_tolerance (the corrector's predictor evaluations): with ξ = 1e-4 the ξ·∇²H term of df~/dx
// changes dr by ~1e-4 relative; a tolerance of 1e-2 leaves it out, r is untouched, and a relaxed dr is
// never served to a later exact request (nor an exact one recomputed for a relaxed request).
TEST(TimeBasedShooting, JacobianToleranceLeavesOutOnlyTheHessianTermAndKeepsTheCacheHonest) {
  const HybridModel slip = MakeSlip();
  TimeBasedShooting shooting(slip, IntegratorOptions{});
  Vector u = SlipHoppingInPlace(slip, shooting.layout(), 1.5);
  u(shooting.layout().xi_index()) = 1e-4;
  Vector r_exact, r_relaxed, r;
  Matrix dr_exact, dr_relaxed, dr;
  ASSERT_TRUE(shooting.Evaluate(u, &r_exact, &dr_exact).ok);
  TimeBasedShooting relaxed(slip, IntegratorOptions{});
  relaxed.set_jacobian_tolerance(1e-2);
  ASSERT_TRUE(relaxed.Evaluate(u, &r_relaxed, &dr_relaxed).ok);
  for (int i = 0; i < shooting.layout().num_segments(); ++i) EXPECT_TRUE(relaxed.segment_flow(i).jacobian_relaxed);
  // r: the same integration (the term enters the sensitivities only; error control sees them, so r agrees
  // to the integration tolerance, not bitwise).
  EXPECT_LT((r_relaxed - r_exact).lpNorm<Eigen::Infinity>(), 1e-9);
  const double difference = (dr_relaxed - dr_exact).lpNorm<Eigen::Infinity>() / dr_exact.lpNorm<Eigen::Infinity>();
  EXPECT_GT(difference, 1e-7);   // the term was left out ...
  EXPECT_LT(difference, 1e-2);   // ... and it is below the tolerance
  // An exact request at the same u integrates again and gets the exact dr; a relaxed request is then
  // served from that exact evaluation.
  relaxed.set_jacobian_tolerance(0.0);
  ASSERT_TRUE(relaxed.Evaluate(u, &r, &dr).ok);
  EXPECT_EQ(relaxed.num_evaluations(), 2);
  EXPECT_EQ(dr, dr_exact);
  relaxed.set_jacobian_tolerance(1e-2);
  ASSERT_TRUE(relaxed.Evaluate(u, &r, &dr).ok);
  EXPECT_EQ(relaxed.num_evaluations(), 2);
  EXPECT_EQ(dr, dr_exact);
  // On the orbit itself (ξ = 0) there is no term to leave out: the relaxed evaluation is exact and
  // cached as such.
  u(shooting.layout().xi_index()) = 0.0;
  ASSERT_TRUE(relaxed.Evaluate(u, &r, &dr).ok);
  EXPECT_FALSE(relaxed.segment_flow(0).jacobian_relaxed);
  relaxed.set_jacobian_tolerance(0.0);
  ASSERT_TRUE(relaxed.Evaluate(u, &r, &dr).ok);
  EXPECT_EQ(relaxed.num_evaluations(), 3);
}

// The corrector leaves the term out at the predictor only: from a predictor 1e-3 off hopping in place
// (ξ = 1e-4 among the errors) it reaches the same point, with the same number of steps, as with every
// Jacobian exact.
TEST(TimeBasedShooting, PredictorJacobianToleranceDoesNotChangeTheCorrectedPoint) {
  const HybridModel slip = MakeSlip();
  TimeBasedShooting shooting(slip, IntegratorOptions{});
  const Vector solution = SlipHoppingInPlace(slip, shooting.layout(), 1.5);
  Vector predictor = solution + 1e-3 * Vector::LinSpaced(solution.size(), -1.0, 1.0);
  predictor(shooting.layout().xi_index()) = 1e-4;
  const Vector border = Vector::Unit(solution.size(), shooting.layout().H_index());
  CorrectorOptions exact_options;
  exact_options.predictor_jacobian_tolerance = 0.0;
  Vector u_exact, u_relaxed;
  const CorrectorResult exact = Corrector(&shooting, exact_options).CorrectPseudoArclength(predictor, border, &u_exact);
  const CorrectorResult relaxed = Corrector(&shooting).CorrectPseudoArclength(predictor, border, &u_relaxed);
  ASSERT_TRUE(exact.converged()) << exact.BriefReport();
  ASSERT_TRUE(relaxed.converged()) << relaxed.BriefReport();
  EXPECT_EQ(relaxed.iterations, exact.iterations);
  EXPECT_LT((u_relaxed - u_exact).lpNorm<Eigen::Infinity>(), 1e-11);
  EXPECT_LT(std::abs(u_relaxed(shooting.layout().xi_index())), 1e-12);
}

}  // namespace
}  // namespace hybridcont
