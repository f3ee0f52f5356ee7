// Monodromy and Floquet multipliers: the ball's closed-form monodromy, the freedom of phase and the
// left eigenvector dH (Thm 2.1) on computed orbits, agreement with the state-based Phi(t^A, x0), the
// deflation on synthetic matrices, and the stability change of SLIP hopping in place at its SB point.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <functional>
#include <random>

#include <Eigen/LU>
#include <Eigen/QR>

#include "hybridcont/floquet.h"
#include "hybridcont/models.h"
#include "hybridcont/statebased_shooting.h"
#include "known_orbits.h"

namespace hybridcont {
namespace {

TEST(Floquet, BallMonodromyIsTheClosedForm) {
  // From the apex (H, 0), g = 1, v = sqrt(2H): Phi_1 = [[1, v], [0, 1]], S = [[-1, 0], [2/v, -1]],
  // Phi_2 = Phi_1, so Phi_T = [[1, 0], [2/v, 1]]: a Jordan block at 1 (the period grows with H).
  const HybridModel ball = MakeBouncingBall();
  TimeBasedShooting tb(ball, IntegratorOptions{});
  for (double H : {0.2, 1.0, 3.0}) {
    const FloquetResult fl = ComputeFloquet(tb, BallOrbit(tb.layout(), H));
    ASSERT_TRUE(fl.ok()) << fl.message;
    const double v = std::sqrt(2.0 * H);
    Matrix expected(2, 2);
    expected << 1, 0, 2 / v, 1;
    EXPECT_LT((fl.monodromy - expected).norm(), 1e-12) << "H = " << H << "\n" << fl.monodromy;
    ASSERT_EQ(fl.saltations.size(), 1u);
    Matrix S(2, 2);
    S << -1, 0, 2 / v, -1;
    EXPECT_LT((fl.saltations[0] - S).norm(), 1e-12);
    EXPECT_EQ(fl.num_unit, 2);
    EXPECT_TRUE(fl.normal);
    EXPECT_TRUE(fl.stable);
    EXPECT_TRUE(fl.nontrivial.empty());
    EXPECT_EQ(fl.bp_test, 1.0);
    EXPECT_EQ(fl.pd_test, 4.0);
    EXPECT_LT(fl.flow_residual, 1e-12);
    EXPECT_LT(fl.first_integral_residual, 1e-12);
    ASSERT_EQ(fl.multipliers.size(), 2u);
    EXPECT_NEAR(std::abs(fl.multipliers[0] - 1.0), 0.0, 1e-6);  // Jordan pair: ~sqrt(round-off)
  }
}

TEST(Floquet, FreedomOfPhaseAndLeftEigenvectorOnSlipOrbits) {
  const HybridModel slip = MakeSlip();
  TimeBasedShooting tb(slip, IntegratorOptions{});
  for (double H : {1.05, 1.1, 1.3, 1.4, 1.8, 2.5}) {
    const FloquetResult fl = ComputeFloquet(tb, SlipHoppingInPlace(slip, tb.layout(), H));
    ASSERT_TRUE(fl.ok()) << fl.message;
    // Phi_T f(x0) = f(x0) and dH(x0) Phi_T = dH(x0), to the integration accuracy
    EXPECT_LT(fl.flow_residual, 1e-8) << "H = " << H;
    EXPECT_LT(fl.first_integral_residual, 1e-8) << "H = " << H;
    ASSERT_EQ(fl.multipliers.size(), 4u);
    // the computed trivial pair (from the full eigen-decomposition) is within ~sqrt(1e-10) of 1
    EXPECT_LT(std::abs(fl.multipliers[0] - 1.0), 1e-4) << "H = " << H;
    EXPECT_LT(std::abs(fl.multipliers[1] - 1.0), 1e-4) << "H = " << H;
    ASSERT_EQ(fl.nontrivial.size(), 2u);
    // the full spectrum is {1, 1} ∪ nontrivial: product of all = det(Phi_T)
    const std::complex<double> prod = fl.nontrivial[0] * fl.nontrivial[1];
    EXPECT_NEAR(prod.real(), fl.monodromy.determinant(), 1e-7) << "H = " << H;
  }
}

TEST(Floquet, TimeBasedMonodromyEqualsTheStateBasedFundamentalMatrix) {
  // Two independent computations of Phi_T: segment Phi's (rkf78, fixed durations) with saltations, and the
  // event-driven chain of the Poincaré map (dopri5, located events).
  const HybridModel slip = MakeSlip();
  TimeBasedShooting tb(slip, IntegratorOptions{});
  StateBasedShooting sb(slip, PoincareOptions{});
  for (double H : {1.1, 1.4, 2.0}) {
    const Vector u = SlipHoppingInPlace(slip, tb.layout(), H);
    const FloquetResult fl = ComputeFloquet(tb, u);
    ASSERT_TRUE(fl.ok());
    Vector r;
    Matrix dr;
    ASSERT_TRUE(sb.Evaluate(sb.FromTimeBased(u), &r, &dr).ok);
    const Matrix& Phi = sb.last_map().Phi;
    EXPECT_LT((Phi - fl.monodromy).norm() / fl.monodromy.norm(), 1e-8) << "H = " << H;
    // and the multipliers from it agree
    Vector f0, Hv;
    Matrix dH;
    slip.phase(0).UnfoldedVectorField(u.segment(tb.layout().state_offset(0), 4), Vector::Zero(1), &f0, nullptr,
                                      nullptr);
    slip.phase(0).FirstIntegrals(u.segment(tb.layout().state_offset(0), 4), &Hv, &dH, nullptr);
    const FloquetResult fs = AnalyzeMonodromy(Phi, f0, dH.row(0));
    ASSERT_TRUE(fs.ok());
    for (int i = 0; i < 2; ++i) EXPECT_LT(std::abs(fs.nontrivial[i] - fl.nontrivial[i]), 1e-7) << "H = " << H;
  }
}

// Phi = Q blockdiag([[1, c], [0, 1]], A) Q^T with f = Q e1, dH = e2^T Q^T: the trivial Jordan pair and A.
FloquetResult Synthetic(const Matrix& A, std::uint32_t seed) {
  const int n = 2 + static_cast<int>(A.rows());
  Matrix P = Matrix::Zero(n, n);
  P(0, 0) = P(1, 1) = 1.0;
  P(0, 1) = 0.7;
  P.bottomRightCorner(n - 2, n - 2) = A;
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal;
  const Matrix G = Matrix::NullaryExpr(n, n, [&]() { return normal(rng); });
  const Matrix Q = Eigen::HouseholderQR<Matrix>(G).householderQ();
  const Vector f = Q.col(0);
  const RowVector dH = Q.col(1).transpose();
  return AnalyzeMonodromy(Q * P * Q.transpose(), f, dH);
}

TEST(Floquet, DeflationRecoversTheNontrivialMultipliersExactly) {
  // saddle: (2, 1/2)
  Matrix A(2, 2);
  A << 2.0, 0.3, 0.0, 0.5;
  FloquetResult fl = Synthetic(A, 7);
  ASSERT_TRUE(fl.ok());
  EXPECT_NEAR(fl.nontrivial[0].real(), 2.0, 1e-13);
  EXPECT_NEAR(fl.nontrivial[1].real(), 0.5, 1e-13);
  EXPECT_NEAR(fl.bp_test, (2.0 - 1.0) * (0.5 - 1.0), 1e-13);
  EXPECT_NEAR(fl.pd_test, 4.0 * 3.0 * 1.5, 1e-12);
  EXPECT_FALSE(fl.stable);
  EXPECT_TRUE(fl.normal);
  EXPECT_NEAR(fl.max_modulus, 2.0, 1e-13);
  // rotation by theta: on the unit circle, bp = |e^{i theta} - 1|^2 > 0
  const double theta = 0.9;
  A << std::cos(theta), -std::sin(theta), std::sin(theta), std::cos(theta);
  fl = Synthetic(A, 8);
  EXPECT_TRUE(fl.stable);
  EXPECT_NEAR(fl.nontrivial[0].imag(), std::sin(theta), 1e-13);  // + first
  EXPECT_NEAR(fl.bp_test, 2.0 - 2.0 * std::cos(theta), 1e-13);
  EXPECT_NEAR(fl.pd_test, 4.0 * (2.0 + 2.0 * std::cos(theta)), 1e-12);
  // a flip pair (-1.5, -1/1.5): pd changes sign across -1
  A << -1.5, 0.0, 0.0, -1.0 / 1.5;
  fl = Synthetic(A, 9);
  EXPECT_LT(fl.pd_test, 0.0);
  EXPECT_FALSE(fl.stable);
  // a third unit multiplier: not normal
  A << 1.0, 0.0, 0.0, 0.4;
  fl = Synthetic(A, 10);
  EXPECT_EQ(fl.num_unit, 3);
  EXPECT_FALSE(fl.normal);
}

TEST(Floquet, ZeroDurationTransitionAndEquilibriaAreStatuses) {
  const HybridModel slip = MakeSlip();
  TimeBasedShooting tb(slip, IntegratorOptions{});
  const FloquetResult fl = ComputeFloquet(tb, BuiltinStartPoint(slip));
  EXPECT_EQ(fl.status, FloquetStatus::kSaltationUndefined);
  EXPECT_NE(fl.message.find("segment 1"), std::string::npos) << fl.message;
  const HybridModel ball = MakeBouncingBall();
  TimeBasedShooting tb_ball(ball, IntegratorOptions{});
  EXPECT_FALSE(ComputeFloquet(tb_ball, BuiltinStartPoint(ball)).ok());  // u0 = 0: the equilibrium
}


TEST(Floquet, SlipHoppingInPlaceChangesStabilityAtTheSbPointsOfTheContinuation) {
  // The nontrivial pair is the leg-angle (alpha) mode; hopping in place at k = 40, w2 = 5.
  // Measured (rtol 1e-10): H = 1.1: mu = 1.70796, -0.350128 (unstable); H = 1.4: mu = 0.645354, -0.543768
  // (stable: the swing leg is a driven oscillator, the reduced map is not area-preserving, so the
  // transverse mode can contract).
  const HybridModel slip = MakeSlip();
  TimeBasedShooting tb(slip, IntegratorOptions{});
  auto floquet = [&](double H) { return ComputeFloquet(tb, SlipHoppingInPlace(slip, tb.layout(), H)); };
  const FloquetResult low = floquet(1.1), mid = floquet(1.4), high = floquet(1.8);
  ASSERT_TRUE(low.ok() && mid.ok() && high.ok());
  EXPECT_FALSE(low.stable);
  EXPECT_NEAR(low.max_modulus, 1.70796, 1e-5);
  EXPECT_TRUE(mid.stable);
  EXPECT_NEAR(mid.nontrivial[0].real(), 0.645354, 1e-5);
  EXPECT_NEAR(mid.nontrivial[1].real(), -0.543768, 1e-5);
  EXPECT_FALSE(high.stable);
  for (const FloquetResult* f : {&low, &mid, &high}) EXPECT_TRUE(f->normal);
  EXPECT_LT(low.bp_test, 0.0);
  EXPECT_GT(mid.bp_test, 0.0);
  EXPECT_LT(high.bp_test, 0.0);

  // The +1 crossings, located by bisection on the closed-form orbits, against the SB points the
  // continuation found at H = 1.24674011004 and H = 1.61443: they agree to ~1e-12 (measured
  // 1.246740110039 at rtol 1e-10, 1.246740110027 at rtol 1e-12) and 1.614433284724.
  auto bp = [&](double H) { return floquet(H).bp_test; };
  const double bp1 = Bisect(bp, 1.1, 1.4);
  const double bp2 = Bisect(bp, 1.4, 1.8);
  EXPECT_NEAR(bp1, 1.24674011004, 1e-10);
  EXPECT_NEAR(bp2, 1.61443, 1e-5);
  // At the same H a second multiplier passes through -1 (pd changes sign at 1.246740110061, within 1e-10
  // of bp1), and returns inside the unit circle at H = 1.2828093238: the orbits are linearly stable on
  // (1.28281, 1.61443), not on the whole interval between the SB points.
  auto pd = [&](double H) { return floquet(H).pd_test; };
  EXPECT_NEAR(Bisect(pd, 1.2, 1.25), bp1, 1e-9);
  const double pd2 = Bisect(pd, 1.25, 1.3);
  EXPECT_NEAR(pd2, 1.2828093238, 1e-8);
  EXPECT_FALSE(floquet(pd2 - 1e-4).stable);
  EXPECT_TRUE(floquet(pd2 + 1e-4).stable);
  EXPECT_TRUE(floquet(bp2 - 1e-4).stable);
  EXPECT_FALSE(floquet(bp2 + 1e-4).stable);
}

}  // namespace
}  // namespace hybridcont
