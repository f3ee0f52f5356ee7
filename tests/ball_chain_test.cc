// The scalable ball-chain model: closed-form orbits are zeros, Newton on large multiple-shooting systems
// (sparse bordered LU above BorderedSolver::kSparseThreshold unknowns) converges back to them, and its
// many segments integrated on several threads give the serial map.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <stdexcept>

#include "hybridcont/corrector.h"
#include "hybridcont/models.h"
#include "hybridcont/timebased_shooting.h"

namespace hybridcont {
namespace {

TEST(BallChain, ClosedFormOrbitIsAZeroWithPeriod2mSqrt2H) {
  for (int m : {1, 3, 20}) {
    const HybridModel chain = MakeBallChain(m);
    TimeBasedShooting shooting(chain, IntegratorOptions{});
    const Vector u = BallChainOrbit(chain, 0.5);
    EXPECT_NEAR(shooting.layout().Period(u), 2.0 * m * std::sqrt(2.0 * 0.5), 1e-14);
    Vector r;
    ASSERT_TRUE(shooting.Evaluate(u, &r, nullptr).ok);
    EXPECT_LT(r.lpNorm<Eigen::Infinity>(), 1e-12) << "m = " << m;
    EXPECT_EQ(shooting.num_equations(), 3 * m + 2 + 2);  // sum n_i + m + 2 with n_i = 2
  }
}

TEST(BallChain, NewtonOnALargeSparseSystemReturnsToTheOrbit) {
  // m = 80: N + 1 = 245 unknowns, above the sparse threshold of the bordered solver.
  const int m = 80;
  const HybridModel chain = MakeBallChain(m);
  TimeBasedShooting shooting(chain, IntegratorOptions{});
  const Vector exact = BallChainOrbit(chain, 0.5);
  ASSERT_GE(shooting.num_unknowns(), 150);
  // perturb every duration and state, keep H fixed by correcting with the H component fixed
  Vector guess = exact;
  for (int i = 0; i < guess.size() - 2; ++i) guess(i) += 1e-3 * std::sin(1.0 + i);
  Corrector corrector(&shooting);
  Vector u;
  const CorrectorResult result =
      corrector.CorrectFixedComponent(guess, shooting.layout().H_index(), 0.5, &u);
  ASSERT_TRUE(result.converged()) << result.message;
  EXPECT_LE(result.iterations, 6);
  // The family is one-dimensional and H fixes it up to the phase along the orbit, which the anchor
  // fixes: the corrected point is the closed-form orbit.
  EXPECT_LT((u - exact).lpNorm<Eigen::Infinity>(), 1e-9);
}

// The sparse channel: from 150 unknowns on, the shooting map assembles dr as triplets, with the same
// entries as the dense assembly (which stays the reference), and the corrector's Newton steps on the
// sparse path give the same iterates as on a dense map.
TEST(BallChain, SparseJacobianEqualsTheDenseOne) {
  const HybridModel chain = MakeBallChain(60);
  TimeBasedShooting shooting(chain, IntegratorOptions{});
  ASSERT_TRUE(shooting.prefers_sparse_jacobian());
  Vector u = BallChainOrbit(chain, 0.5);
  for (int i = 0; i < u.size(); ++i) u(i) += 1e-3 * std::cos(2.0 + i);  // xi != 0 too
  Vector r_dense, r_sparse;
  Matrix dense;
  SparseMatrix sparse;
  ASSERT_TRUE(shooting.Evaluate(u, &r_dense, &dense).ok);
  ASSERT_TRUE(shooting.EvaluateSparse(u, &r_sparse, &sparse).ok);
  EXPECT_EQ(r_dense, r_sparse);
  EXPECT_EQ(Matrix(sparse), dense);
  // O(N) nonzeros: per segment a (n+1) x (n + 2 + k) block and -I, plus the first-integral row
  EXPECT_LT(sparse.nonZeros(), 20 * shooting.num_unknowns());
}

// A ZeroProblem that hides the sparse channel: the corrector then runs the dense path on the same map.
class DenseOnly : public ZeroProblem {
 public:
  explicit DenseOnly(ZeroProblem* problem) : problem_(problem) {}
  int num_equations() const override { return problem_->num_equations(); }
  std::vector<std::string> unknown_names() const override { return problem_->unknown_names(); }
  EvaluationStatus Evaluate(const Vector& u, Vector* r, Matrix* dr) override { return problem_->Evaluate(u, r, dr); }

 private:
  ZeroProblem* problem_;
};

TEST(BallChain, SparseAndDenseCorrectorPathsAgree) {
  const HybridModel chain = MakeBallChain(60);
  TimeBasedShooting shooting(chain, IntegratorOptions{});
  DenseOnly dense(&shooting);
  Vector guess = BallChainOrbit(chain, 0.5);
  for (int i = 0; i < guess.size() - 2; ++i) guess(i) += 1e-3 * std::sin(1.0 + i);
  Vector u_sparse, u_dense;
  Corrector sparse_corrector(&shooting), dense_corrector(&dense);
  const CorrectorResult a = sparse_corrector.CorrectFixedComponent(guess, shooting.layout().H_index(), 0.5, &u_sparse);
  const CorrectorResult b = dense_corrector.CorrectFixedComponent(guess, shooting.layout().H_index(), 0.5, &u_dense);
  ASSERT_TRUE(a.converged()) << a.message;
  ASSERT_TRUE(b.converged()) << b.message;
  EXPECT_EQ(a.iterations, b.iterations);
  EXPECT_LT((u_sparse - u_dense).lpNorm<Eigen::Infinity>(), 1e-13);
  // dr at iterates equal to rounding (the two LUs order their pivots differently)
  EXPECT_LT((sparse_corrector.jacobian() - dense_corrector.jacobian()).norm(), 1e-12 * dense_corrector.jacobian().norm());
}

// The segments integrated on two threads give r, dr and the work counters of the serial loop, bitwise;
// a clone (one thread) gives them too, and AddWorkOf sums its counters into the original's.
TEST(BallChain, SegmentsOnTwoThreadsGiveTheSerialMapBitwise) {
  const int m = 200;
  const HybridModel chain = MakeBallChain(m);
  ASSERT_GE(m + 1, 2 * TimeBasedShooting::kMinSegmentsPerThread);  // large enough for the threads
  Vector u = BallChainOrbit(chain, 0.5);
  for (int i = 0; i < u.size() - 2; ++i) u(i) += 1e-3 * std::sin(1.0 + i);
  TimeBasedShooting serial(chain, IntegratorOptions{});
  serial.set_threads(1);
  TimeBasedShooting threaded(chain, IntegratorOptions{});
  threaded.set_threads(2);
  EXPECT_EQ(threaded.threads(), 2);
  Vector r1, r2, r_only;
  Matrix dr1, dr2;
  ASSERT_TRUE(serial.Evaluate(u, &r1, &dr1).ok);
  ASSERT_TRUE(threaded.Evaluate(u, &r2, &dr2).ok);
  EXPECT_TRUE(r1 == r2);
  EXPECT_TRUE(dr1 == dr2);
  u(0) += 1e-9;  // r alone: the integration without sensitivities
  ASSERT_TRUE(serial.Evaluate(u, &r1, nullptr).ok);
  ASSERT_TRUE(threaded.Evaluate(u, &r2, nullptr).ok);
  EXPECT_TRUE(r1 == r2);
  for (int k = 1; k <= 20; ++k) {  // many loops of the team: each result complete and in its place
    u(1) += 1e-7;
    ASSERT_TRUE(serial.Evaluate(u, &r1, nullptr).ok);
    ASSERT_TRUE(threaded.Evaluate(u, &r2, nullptr).ok);
    ASSERT_TRUE(r1 == r2) << "evaluation " << k;
  }
  EXPECT_EQ(serial.counters().rhs_evaluations, threaded.counters().rhs_evaluations);
  EXPECT_EQ(serial.counters().steps, threaded.counters().steps);
  EXPECT_EQ(serial.num_evaluations(), threaded.num_evaluations());

  EXPECT_EQ(threaded.jacobian_tolerance(), TimeBasedShooting::kXiHessianTolerance);  // the default
  threaded.set_jacobian_tolerance(0.0);  // exact: a clone must evaluate as the original does
  const std::unique_ptr<ZeroProblem> clone = threaded.Clone();
  ASSERT_NE(clone, nullptr);
  const auto& clone_map = dynamic_cast<const TimeBasedShooting&>(*clone);
  EXPECT_EQ(clone_map.threads(), 1);
  EXPECT_EQ(clone->jacobian_tolerance(), 0.0);
  ASSERT_TRUE(clone->Evaluate(u, &r_only, nullptr).ok);
  EXPECT_TRUE(r_only == r1);
  const long before = threaded.counters().rhs_evaluations;
  EXPECT_GT(clone_map.counters().rhs_evaluations, 0);
  threaded.AddWorkOf(*clone);
  EXPECT_EQ(threaded.counters().rhs_evaluations, before + clone_map.counters().rhs_evaluations);
  EXPECT_EQ(threaded.num_evaluations(), 23);

  EXPECT_THROW(threaded.set_threads(0), std::invalid_argument);
}

}  // namespace
}  // namespace hybridcont
