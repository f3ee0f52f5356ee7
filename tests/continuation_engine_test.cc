// Corrector, stepper, stops and located special points on algebraic curves with exact answers.
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "continuation_test_problems.h"
#include "hybridcont/continuation.h"
#include "hybridcont/corrector.h"

namespace hybridcont {
namespace {

using testing::Circle;
using testing::FailsAbove;
using testing::ParabolaAndLine;
using testing::Pitchfork;
using testing::Transcritical;

const double kGoldenRatioConjugate = (std::sqrt(5.0) - 1.0) / 2.0;  // SB of ParabolaAndLine: x = λ

TEST(CorrectorTest, PseudoArclengthStaysOnTheHyperplane) {
  Circle circle;
  Corrector corrector(&circle);
  Vector u;
  const CorrectorResult result = corrector.CorrectPseudoArclength(Eigen::Vector2d(1.1, 0.2), Eigen::Vector2d(0, 1), &u);
  ASSERT_EQ(result.status, CorrectorStatus::kConverged) << result.BriefReport();
  EXPECT_NEAR(u(1), 0.2, 1e-15);                      // τᵀ(u − u_pred) = 0 with τ = e_y
  EXPECT_NEAR(u(0), std::sqrt(1 - 0.04), 1e-14);
  EXPECT_GT(result.contraction, 0);
  EXPECT_LT(result.contraction, 0.1);                 // quadratic convergence from a close predictor
}

// Deuflhard's estimate after a full Newton step: from a predictor 1e-4 off the circle, e₁ = e₀²/(2x) ≈ 5e-9
// and θ₁|Δ₁| ≈ 3e-13 is below the step tolerance, so u₁ + Δ₁ (error e₁²/(2x) ≈ 1e-17) is returned after two
// evaluations; plain Newton needs two more (u₂ still has |Δ₂| = 1e-17 > 0 to confirm, then u₃).
TEST(CorrectorTest, AcceptsTheNewtonStepOnItsErrorEstimate) {
  Circle circle;
  const double x = std::sqrt(0.96);
  Vector u;
  Corrector corrector(&circle);
  CorrectorResult result = corrector.CorrectPseudoArclength(Eigen::Vector2d(x + 1e-4, 0.2), Eigen::Vector2d(0, 1), &u);
  ASSERT_TRUE(result.converged()) << result.BriefReport();
  EXPECT_EQ(result.evaluations, 2);
  EXPECT_EQ(result.iterations, 2);
  EXPECT_NEAR(u(0), x, 2e-16);
  EXPECT_EQ(u(1), 0.2);
  // jacobian() is the one at u₁ = u − Δ₁: dr = 2u₁ᵀ, |Δ₁| ≈ 5e-9.
  EXPECT_NEAR(corrector.jacobian()(0, 0), 2 * x, 2e-8);
  EXPECT_GT(std::abs(corrector.jacobian()(0, 0) - 2 * x), 1e-9);

  CorrectorOptions plain;
  plain.accept_on_error_estimate = false;
  Corrector newton(&circle, plain);
  Vector v;
  result = newton.CorrectPseudoArclength(Eigen::Vector2d(x + 1e-4, 0.2), Eigen::Vector2d(0, 1), &v);
  ASSERT_TRUE(result.converged()) << result.BriefReport();
  EXPECT_EQ(result.evaluations, 4);
  EXPECT_NEAR(v(0), x, 2e-16);

  // |Δ₁| above max_jacobian_distance·(1 + ||u||): the step is taken, and u₂ evaluated.
  CorrectorOptions near_jacobian;
  near_jacobian.max_jacobian_distance = 1e-9;
  Corrector strict(&circle, near_jacobian);
  result = strict.CorrectPseudoArclength(Eigen::Vector2d(x + 1e-4, 0.2), Eigen::Vector2d(0, 1), &v);
  ASSERT_TRUE(result.converged()) << result.BriefReport();
  EXPECT_EQ(result.evaluations, 3);
  EXPECT_NEAR(v(0), x, 2e-16);
}

// A predictor on the curve to the rounding level costs one evaluation when dr there is exact (the root
// finders' trial points): (0.6, 0.8) is on the unit circle to within one rounding error.
TEST(CorrectorTest, AcceptsAPredictorOnTheCurveAfterOneExactEvaluation) {
  Circle circle;
  CorrectorOptions exact;
  exact.accept_on_error_estimate = false;  // as for SB trial points: plain Newton otherwise
  exact.predictor_jacobian_tolerance = 0;
  Corrector corrector(&circle, exact);
  Vector u;
  CorrectorResult result = corrector.CorrectPseudoArclength(Eigen::Vector2d(0.6, 0.8), Eigen::Vector2d(-0.8, 0.6), &u);
  ASSERT_TRUE(result.converged()) << result.BriefReport();
  EXPECT_EQ(result.evaluations, 1);
  EXPECT_EQ(result.iterations, 1);
  EXPECT_NEAR(u(0), 0.6, 1e-16);
  EXPECT_NEAR(u(1), 0.8, 1e-16);
  EXPECT_NEAR(corrector.jacobian()(0, 0), 1.2, 1e-15);

  // dr at the predictor loosened by predictor_jacobian_tolerance (the problem's own is 0 here): the point
  // is evaluated once more.
  exact.predictor_jacobian_tolerance = 1e-2;
  Corrector loosened(&circle, exact);
  result = loosened.CorrectPseudoArclength(Eigen::Vector2d(0.6, 0.8), Eigen::Vector2d(-0.8, 0.6), &u);
  ASSERT_TRUE(result.converged()) << result.BriefReport();
  EXPECT_EQ(result.evaluations, 2);

  // 1e-12 off the curve: the first step (~1e-12) is above kOnCurveStep·(1 + ||u||) = 2e-13, so Newton goes on.
  exact.predictor_jacobian_tolerance = 0;
  Corrector off(&circle, exact);
  result = off.CorrectPseudoArclength(Eigen::Vector2d(0.6 * (1 + 1e-12), 0.8 * (1 + 1e-12)), Eigen::Vector2d(-0.8, 0.6), &u);
  ASSERT_TRUE(result.converged()) << result.BriefReport();
  EXPECT_EQ(result.evaluations, 2);
  EXPECT_NEAR(u.norm(), 1.0, 1e-15);
}

// r = x + 1e5x² + 1e7x³ (λ free, pinned by the border): Newton from x₀ = −5e-3 lands exactly on the root
// (r(x) = x r'(x) there), so from 3e-8 beside it the first step lands 6e-8 from the root by chance:
// θ₁ = 1.2e-5 and θ₁|Δ₁| = 7e-13 promise convergence, yet u₁ + Δ₁ is 3.6e-10 off (the contraction is a
// lower bound of the curvature, ω = 2e5 here). max_jacobian_distance = 1e-8 refuses that step.
class CurvedScalar : public ZeroProblem {
 public:
  int num_equations() const override { return 1; }
  std::vector<std::string> unknown_names() const override { return {"x", "lambda"}; }
  EvaluationStatus Evaluate(const Vector& u, Vector* r, Matrix* dr) override {
    const double x = u(0);
    if (r) *r = Vector::Constant(1, x + 1e5 * x * x + 1e7 * x * x * x);
    if (dr) *dr = Eigen::RowVector2d(1 + 2e5 * x + 3e7 * x * x, 0);
    return {};
  }
  void set_jacobian_tolerance(double tolerance) override { tolerance_ = tolerance; }
  double jacobian_tolerance() const override { return tolerance_; }
  double tolerance_ = 0;
};

TEST(CorrectorTest, AcceptedNewtonStepIsBoundedWhereTheContractionMisleads) {
  CurvedScalar problem;
  Corrector corrector(&problem);
  Vector u;
  const CorrectorResult result = corrector.CorrectFixedComponent(Eigen::Vector2d(-5e-3 + 3e-8, 0), 1, 0.0, &u);
  ASSERT_TRUE(result.converged()) << result.BriefReport();
  // Within the step tolerance, as promised (here 1.3e-14: the step of 3.7e-10 from u₂ was accepted).
  EXPECT_LT(std::abs(u(0)), CorrectorOptions().step_tolerance) << result.BriefReport();
  EXPECT_EQ(u(1), 0.0);
  // The counterexample itself: allowed a step of 6e-8, the estimate accepts a point 3.6e-10 off.
  CorrectorOptions loose;
  loose.max_jacobian_distance = 1e-6;
  Corrector trusting(&problem, loose);
  ASSERT_TRUE(trusting.CorrectFixedComponent(Eigen::Vector2d(-5e-3 + 3e-8, 0), 1, 0.0, &u).converged());
  EXPECT_GT(std::abs(u(0)), 3e-10);
}

// The predictor's evaluation runs with predictor_jacobian_tolerance, the others with the problem's own,
// which is restored afterwards — also when an evaluation throws.
class RecordsJacobianTolerance : public CurvedScalar {
 public:
  EvaluationStatus Evaluate(const Vector& u, Vector* r, Matrix* dr) override {
    seen.push_back(tolerance_);
    if (static_cast<int>(seen.size()) - 1 == throw_at) throw std::runtime_error("model failure");
    return CurvedScalar::Evaluate(u, r, dr);
  }
  std::vector<double> seen;
  int throw_at = -1;
};

TEST(CorrectorTest, PredictorJacobianToleranceIsScopedToThePredictor) {
  RecordsJacobianTolerance problem;
  problem.set_jacobian_tolerance(1e-4);  // the user's own
  Corrector corrector(&problem);
  Vector u;
  ASSERT_TRUE(corrector.CorrectFixedComponent(Eigen::Vector2d(1e-3, 0), 1, 0.0, &u).converged());
  ASSERT_GE(problem.seen.size(), 2u);
  EXPECT_EQ(problem.seen[0], 1e-2);
  for (size_t i = 1; i < problem.seen.size(); ++i) EXPECT_EQ(problem.seen[i], 1e-4);
  EXPECT_EQ(problem.jacobian_tolerance(), 1e-4);
  problem.seen.clear();
  problem.throw_at = 0;
  EXPECT_THROW(corrector.CorrectFixedComponent(Eigen::Vector2d(1e-3, 0), 1, 0.0, &u), std::runtime_error);
  EXPECT_EQ(problem.jacobian_tolerance(), 1e-4);
}

TEST(CorrectorTest, MoorePenroseFindsTheNearestPoint) {
  Circle circle;
  Corrector corrector(&circle);
  Vector u;
  const Eigen::Vector2d predictor(1.2, 0.9);
  const CorrectorResult result = corrector.CorrectMoorePenrose(predictor, Eigen::Vector2d(-0.6, 0.8), &u);
  ASSERT_TRUE(result.converged()) << result.BriefReport();
  const Vector nearest = predictor.normalized();      // argmin over the circle (eq. corrector)
  // Newton-like Moore–Penrose iterates converge to a point within O(||u_pred − S||²) of the nearest one.
  EXPECT_NEAR(u.norm(), 1.0, 1e-14);
  EXPECT_LT((u - nearest).norm(), 0.02);
}

TEST(CorrectorTest, FixedComponentAndStatuses) {
  Circle circle;
  Corrector corrector(&circle);
  Vector u;
  CorrectorResult result = corrector.CorrectFixedComponent(Eigen::Vector2d(0.5, 0.9), 0, 0.6, &u);
  ASSERT_TRUE(result.converged());
  EXPECT_EQ(u(0), 0.6);
  EXPECT_NEAR(u(1), 0.8, 1e-15);
  // x = 2 does not meet the circle: Newton cannot converge; a status, never an exception.
  result = corrector.CorrectFixedComponent(Eigen::Vector2d(2, 0.5), 0, 2.0, &u);
  EXPECT_FALSE(result.converged());
  // The bordered matrix at the origin (dr = 0) is singular.
  result = corrector.CorrectPseudoArclength(Eigen::Vector2d(0, 0), Eigen::Vector2d(1, 0), &u);
  EXPECT_EQ(result.status, CorrectorStatus::kSingular);
  FailsAbove failing(&circle, 0, 0.0);
  Corrector failing_corrector(&failing);
  result = failing_corrector.CorrectPseudoArclength(Eigen::Vector2d(1, 0), Eigen::Vector2d(0, 1), &u);
  EXPECT_EQ(result.status, CorrectorStatus::kEvaluationFailed);
  EXPECT_EQ(result.message, "component above its limit");
  EXPECT_THROW(corrector.CorrectPseudoArclength(Vector::Zero(3), Vector::Zero(3), &u), std::invalid_argument);
}

// On the unit circle the tangent predictor's residual is exactly h², so with evaluations failing above
// |r| = 0.01 the corrector fails for every h > 0.1, while the angle criterion alone (α̃ = 0.15) asks for
// h = 0.15 after each success. Without a memory of the failed step every second step was rejected
// (h = 0.15 fails, 0.075 succeeds, 0.15 is proposed again); with it, about one step in four.
TEST(ContinuationTest, StepControlRemembersWhereTheCorrectorFailed) {
  Circle circle;
  testing::FailsFarFromCurve failing(&circle, 0.01);
  ContinuationOptions options;
  options.predictor = PredictorType::kTangent;
  options.turning_point_components = {};
  const Branch branch = TraceBranch(&failing, Eigen::Vector2d(1, 0), options);
  ASSERT_EQ(branch.termination, TerminationReason::kClosedLoop) << branch.FullReport();
  for (const ContinuationPoint& point : branch.points) EXPECT_NEAR(point.u.norm(), 1.0, 1e-14);
  for (size_t i = 1; i < branch.points.size(); ++i) EXPECT_LE(branch.points[i].step, 0.1);
  // Measured: 87 points with 21 rejected steps; without the memory 127 points with 63.
  EXPECT_LE(branch.rejected_steps, static_cast<int>(branch.points.size()) / 4) << branch.BriefReport();
  EXPECT_LT(branch.points.size(), 100u) << branch.BriefReport();
}

// The memory is local: failures only in the upper half (y > 0, steps above 0.01 fail) must not hold the
// steps down in the lower half, where the angle criterion alone sets h ≈ 0.15. Released by 1.1 per point
// only, the cap would take ~30 points to grow from 0.0075 to 0.15; it is forgotten after 4 failed steps.
TEST(ContinuationTest, StepMemoryIsForgottenFurtherAlongTheBranch) {
  Circle circle;
  testing::FailsFarFromCurve failing(&circle, 1e-4, 1, 0.0);
  ContinuationOptions options;
  options.predictor = PredictorType::kTangent;
  options.turning_point_components = {};
  const Branch branch = TraceBranch(&failing, Eigen::Vector2d(1, 0), options);
  ASSERT_EQ(branch.termination, TerminationReason::kClosedLoop) << branch.FullReport();
  const auto lower_points = [](const Branch& b) {
    int lower = 0;
    for (const ContinuationPoint& point : b.points) lower += point.u(1) < 0 ? 1 : 0;
    return lower;
  };
  const Branch free_branch = TraceBranch(&circle, Eigen::Vector2d(1, 0), options);
  // Measured: 29 against 21 without failures (43 if the memory were only released by 1.1 per point).
  EXPECT_LE(lower_points(branch), lower_points(free_branch) + 10) << branch.BriefReport();
}

TEST(ContinuationOptionsTest, ValidateNamesFieldValueAndConstraint) {
  ContinuationOptions options;
  EXPECT_EQ(options.Validate(), "");
  options.min_step = 1.0;
  EXPECT_EQ(options.Validate(), "ContinuationOptions::min_step = 1 must be <= max_step = 0.25");
  options = ContinuationOptions();
  options.direction = 0;
  EXPECT_EQ(options.Validate(), "ContinuationOptions::direction = 0 must be +1 or -1");
  options = ContinuationOptions();
  options.targets = {{"H", 2.0}};
  EXPECT_EQ(options.ValidateFor({"x", "y"}), "ContinuationOptions::targets: \"H\" is not an unknown of the problem");
  Circle circle;
  EXPECT_THROW(ContinuationStepper(&circle, options), std::invalid_argument);
}

TEST(ContinuationTest, CircleTurningPointsAndClosedLoop) {
  Circle circle;
  ContinuationOptions options;
  options.turning_point_components = {"y"};
  const Branch branch = TraceBranch(&circle, Eigen::Vector2d(1, 0), options);
  ASSERT_EQ(branch.termination, TerminationReason::kClosedLoop) << branch.FullReport();
  EXPECT_EQ(branch.points.back().u, branch.points.front().u);  // closes exactly
  EXPECT_NEAR(branch.points.back().arclength, 2 * M_PI, 0.01);  // chords of one turn, not two
  ASSERT_EQ(branch.special_points.size(), 2u);
  // det([dr; τᵀ]) > 0 at (1, 0) with dr = (2, 0): τ = (0, 1), counter-clockwise: (0, 1) first.
  const double expected_y[] = {1.0, -1.0};
  for (int i = 0; i < 2; ++i) {
    const SpecialPoint& point = branch.special_points[i];
    EXPECT_EQ(point.type, SpecialPointType::kTurningPoint);
    EXPECT_EQ(point.status, LocationStatus::kLocated);
    EXPECT_EQ(point.component, "y");
    EXPECT_NEAR(point.u(0), 0.0, 1e-11);
    EXPECT_NEAR(point.u(1), expected_y[i], 1e-15);  // an extremum: error quadratic in the bracket
    EXPECT_LE(point.precision(), options.location_tolerance);
    EXPECT_LE(point.interval_width(0), 1e-11);
  }
  EXPECT_GT(branch.special_points[1].arclength, branch.special_points[0].arclength);
}

TEST(ContinuationTest, PitchforkSimpleBifurcationLocated) {
  Pitchfork pitchfork;
  ContinuationOptions options;
  options.bounds = {{"lambda", -2, 1}};
  const Branch branch = TraceBranch(&pitchfork, Eigen::Vector2d(0, -1), options);
  EXPECT_EQ(branch.termination, TerminationReason::kBoundReached);
  EXPECT_EQ(branch.points.back().u(1), 1.0);  // stopped exactly on the bound
  ASSERT_EQ(branch.special_points.size(), 1u);
  const SpecialPoint& sb = branch.special_points[0];
  EXPECT_EQ(sb.type, SpecialPointType::kSimpleBifurcation);
  EXPECT_EQ(sb.status, LocationStatus::kLocated);
  EXPECT_NEAR(sb.u(0), 0.0, 1e-15);
  EXPECT_NEAR(sb.u(1), 0.0, 1e-10);
  EXPECT_LE(sb.precision(), 1e-11);
  EXPECT_LE(sb.interval_width(1), 1e-11);
  // The tangent keeps its orientation through the SB point (τ·τ_old > 0) while det([dr; τᵀ]) flips.
  for (size_t i = 1; i < branch.points.size(); ++i) {
    EXPECT_GT(branch.points[i].tangent.dot(branch.points[i - 1].tangent), 0.0);
    EXPECT_EQ(std::signbit(branch.points[i].sb_test), branch.points[i].u(1) > 0);  // det = −λ·(·)
  }
}

TEST(ContinuationTest, TranscriticalSimpleBifurcationLocated) {
  Transcritical transcritical;
  ContinuationOptions options;
  options.bounds = {{"lambda", -1, 1}};
  // Along the line x = λ from (−0.7, −0.7): it meets x = 0 at the origin.
  const Branch branch = TraceBranch(&transcritical, Eigen::Vector2d(-0.7, -0.7), options);
  ASSERT_EQ(branch.special_points.size(), 1u) << branch.FullReport();
  const SpecialPoint& sb = branch.special_points[0];
  EXPECT_EQ(sb.status, LocationStatus::kLocated);
  EXPECT_NEAR(sb.u(0), 0.0, 1e-10);
  EXPECT_NEAR(sb.u(1), 0.0, 1e-10);
  for (const ContinuationPoint& point : branch.points) EXPECT_NEAR(point.u(0), point.u(1), 1e-14);
}

TEST(ContinuationTest, FoldFollowedBySimpleBifurcation) {
  // Parabola λ = 1 − x² from x = −0.5 towards x > 0: fold in λ at (0, 1), then the SB point with the line
  // x = λ at x = λ = (√5 − 1)/2.
  ParabolaAndLine curve;
  ContinuationOptions options;
  options.turning_point_components = {"lambda"};
  options.bounds = {{"x", -0.5, 1.0}};
  ContinuationStepper stepper(&curve, options);
  StepStatus status = stepper.Start(Eigen::Vector2d(-0.5, 0.75), Eigen::Vector2d(1, 1));  // towards x > 0
  while (status == StepStatus::kContinuing) status = stepper.Step();
  const Branch& branch = stepper.branch();
  ASSERT_EQ(branch.special_points.size(), 2u) << branch.FullReport(curve.unknown_names());
  const SpecialPoint& fold = branch.special_points[0];
  const SpecialPoint& sb = branch.special_points[1];
  EXPECT_EQ(fold.type, SpecialPointType::kTurningPoint);
  EXPECT_EQ(fold.status, LocationStatus::kLocated);
  EXPECT_NEAR(fold.u(0), 0.0, 1e-11);
  EXPECT_NEAR(fold.u(1), 1.0, 1e-15);
  EXPECT_EQ(sb.type, SpecialPointType::kSimpleBifurcation);
  EXPECT_EQ(sb.status, LocationStatus::kLocated);
  EXPECT_NEAR(sb.u(0), kGoldenRatioConjugate, 1e-10);
  EXPECT_NEAR(sb.u(1), kGoldenRatioConjugate, 1e-10);
  EXPECT_EQ(branch.termination, TerminationReason::kBoundReached);
  EXPECT_EQ(branch.points.back().u(0), 1.0);
  EXPECT_NEAR(branch.points.back().u(1), 0.0, 1e-14);
}

TEST(ContinuationTest, TargetReachedExactly) {
  Pitchfork pitchfork;
  ContinuationOptions options;
  options.targets = {{"lambda", 2.0}};
  const Branch branch = TraceBranch(&pitchfork, Eigen::Vector2d(1, 1), options);  // on λ = x²
  ASSERT_EQ(branch.termination, TerminationReason::kTargetReached) << branch.message;
  const Vector& u = branch.points.back().u;
  EXPECT_NEAR(u(1), 2.0, 1e-12);
  EXPECT_NEAR(u(0), std::sqrt(2.0), 1e-12);
}

TEST(ContinuationTest, SumBoundAndUserPredicate) {
  Pitchfork pitchfork;
  ContinuationOptions options;
  options.sum_bounds = {{{"x", "lambda"}, -10, 3.0}};  // x + x² <= 3
  Branch branch = TraceBranch(&pitchfork, Eigen::Vector2d(1, 1), options);
  ASSERT_EQ(branch.termination, TerminationReason::kBoundReached);
  const double x_star = (-1 + std::sqrt(13.0)) / 2;
  EXPECT_NEAR(branch.points.back().u(0), x_star, 1e-12);
  EXPECT_NEAR(branch.points.back().u.sum(), 3.0, 1e-12);

  options = ContinuationOptions();
  options.stop_predicate = [](const Vector& u) { return u(1) > 1.5; };
  branch = TraceBranch(&pitchfork, Eigen::Vector2d(1, 1), options);
  ASSERT_EQ(branch.termination, TerminationReason::kUserStop);
  EXPECT_GT(branch.points.back().u(1), 1.5);
  EXPECT_LE(branch.points[branch.points.size() - 2].u(1), 1.5);
}

// The caller's abandon hook sees the branch so far after every accepted point: its reason ends the branch there,
// as the message of kAbandoned, with the points kept.
TEST(ContinuationTest, AnAbandonedBranchEndsWhereItsCallerSaysWhy) {
  Pitchfork pitchfork;
  ContinuationOptions options;
  int calls = 0;
  options.abandon = [&calls](const Branch& b) -> std::string {
    ++calls;
    return b.points.size() == 7 ? "seven points are enough" : "";
  };
  const Branch branch = TraceBranch(&pitchfork, Eigen::Vector2d(1, 1), options);
  EXPECT_EQ(branch.termination, TerminationReason::kAbandoned);
  EXPECT_EQ(branch.message, "seven points are enough");
  EXPECT_EQ(branch.points.size(), 7u);
  EXPECT_EQ(calls, 6);  // once per accepted point after the start
  EXPECT_EQ(ToString(TerminationReason::kAbandoned), "abandoned");
}

TEST(ContinuationTest, MaxPointsAndStepTooSmallKeepTheBranch) {
  Pitchfork pitchfork;
  ContinuationOptions options;
  options.max_points = 5;
  Branch branch = TraceBranch(&pitchfork, Eigen::Vector2d(0, -1), options);
  EXPECT_EQ(branch.termination, TerminationReason::kMaxPoints);
  EXPECT_EQ(branch.points.size(), 5u);

  FailsAbove failing(&pitchfork, 1, 0.5);  // evaluations fail for λ > 0.5
  options = ContinuationOptions();
  options.detect_bifurcations = false;
  branch = TraceBranch(&failing, Eigen::Vector2d(0, -1), options);
  ASSERT_EQ(branch.termination, TerminationReason::kStepTooSmall) << branch.message;
  EXPECT_GT(branch.points.size(), 5u);
  EXPECT_LE(branch.points.back().u(1), 0.5);
  EXPECT_GT(branch.points.back().u(1), 0.5 - 2 * options.min_step);  // halved down to min_step
  EXPECT_GT(branch.rejected_steps, 10);
  EXPECT_NE(branch.message.find("component above its limit"), std::string::npos);
}

TEST(ContinuationTest, SecantPredictorAndMoorePenroseTraceTheSameCurve) {
  Circle circle;
  for (const CorrectorType corrector : {CorrectorType::kPseudoArclength, CorrectorType::kMoorePenrose}) {
    ContinuationOptions options;
    options.predictor = PredictorType::kSecant;
    options.corrector_type = corrector;
    options.turning_point_components = {"x"};
    const Branch branch = TraceBranch(&circle, Eigen::Vector2d(0, 1), options);
    ASSERT_EQ(branch.termination, TerminationReason::kClosedLoop) << ToString(corrector);
    for (const ContinuationPoint& point : branch.points) EXPECT_NEAR(point.u.norm(), 1.0, 1e-12);
    ASSERT_EQ(branch.special_points.size(), 2u);
    EXPECT_NEAR(std::abs(branch.special_points[0].u(0)), 1.0, 1e-15);
    EXPECT_NEAR(branch.special_points[0].u(1), 0.0, 1e-11);
  }
}

TEST(ContinuationTest, StepperPointByPointEqualsDriver) {
  ParabolaAndLine curve;
  ContinuationOptions options;
  options.turning_point_components = {"lambda"};
  options.bounds = {{"x", -0.5, 1.0}};
  int progress_calls = 0;
  options.progress = [&progress_calls](const ProgressInfo& info) {
    EXPECT_EQ(info.point_index, progress_calls);
    ++progress_calls;
  };
  const Branch driven = TraceBranch(&curve, Eigen::Vector2d(-0.5, 0.75), options);
  const int driver_calls = progress_calls;
  progress_calls = 0;
  ContinuationStepper stepper(&curve, options);
  ASSERT_EQ(stepper.Start(Eigen::Vector2d(-0.5, 0.75)), StepStatus::kContinuing);
  size_t steps = 0;
  while (stepper.Step() == StepStatus::kContinuing) {
    ++steps;
    ASSERT_EQ(stepper.branch().points.size(), steps + 1);  // one point per Step()
  }
  const Branch& stepped = stepper.branch();
  EXPECT_EQ(driver_calls, progress_calls);
  ASSERT_EQ(stepped.points.size(), driven.points.size());
  for (size_t i = 0; i < driven.points.size(); ++i) {
    EXPECT_EQ(stepped.points[i].u, driven.points[i].u);
    EXPECT_EQ(stepped.points[i].tangent, driven.points[i].tangent);
  }
  ASSERT_EQ(stepped.special_points.size(), driven.special_points.size());
  for (size_t i = 0; i < driven.special_points.size(); ++i) {
    EXPECT_EQ(stepped.special_points[i].u, driven.special_points[i].u);
  }
  EXPECT_EQ(stepped.termination, driven.termination);
}

// x(λ − x) = 0 (transcritical) with a deterministic "integrator noise": |δr| ~ 1e-12, |δdr| ~ 1e-10,
// a different value at every u, as a shooting map at rtol 1e-10 has.
class NoisyTranscritical : public ZeroProblem {
 public:
  int num_equations() const override { return 1; }
  std::vector<std::string> unknown_names() const override { return {"x", "lambda"}; }
  EvaluationStatus Evaluate(const Vector& u, Vector* r, Matrix* dr) override {
    const double x = u(0), l = u(1);
    if (r) *r = Vector::Constant(1, x * (l - x) + 1e-12 * Noise(u, 1));
    if (dr) {
      dr->resize(1, 2);
      *dr << l - 2 * x + 1e-10 * Noise(u, 2), x + 1e-10 * Noise(u, 3);
    }
    return {};
  }

 private:
  // In [−1, 1], changing completely when u changes by ~1e-15.
  static double Noise(const Vector& u, int salt) {
    const double phase = std::sin(1e15 * u(0) + 7.3e14 * u(1) + salt);
    return phase;
  }
};

// Next to an SB point the bordered matrix is singular for every border, so Newton corrections of the
// residual noise (1e-12 / distance) leave the bracket: located to the noise level, the bracket honest.
// The λ axis of a transcritical map from λ = −0.5 to the bound λ = 1.
Branch TraceTheAxis(ZeroProblem* curve, const ContinuationOptions& options) {
  ContinuationStepper stepper(curve, options);
  StepStatus status = stepper.Start(Eigen::Vector2d(0, -0.5), Eigen::Vector2d(0, 1));
  while (status == StepStatus::kContinuing) status = stepper.Step();
  return stepper.TakeBranch();
}

TEST(ContinuationTest, SimpleBifurcationOfANoisyMapLocatedToTheNoiseLevel) {
  NoisyTranscritical curve;
  ContinuationOptions options;
  options.bounds = {{"lambda", -1, 1}};
  const Branch branch = TraceTheAxis(&curve, options);
  ASSERT_EQ(branch.termination, TerminationReason::kBoundReached) << branch.FullReport();
  ASSERT_EQ(branch.special_points.size(), 1u) << branch.FullReport();
  const SpecialPoint& sb = branch.special_points[0];
  EXPECT_EQ(sb.status, LocationStatus::kLocated) << sb.BriefReport();
  EXPECT_NE(sb.message.find("located to the noise level"), std::string::npos) << sb.BriefReport();
  // Honest precision: the exact SB (0, 0) lies in the bracket, which is far wider than location_tolerance
  // (the noise allows ~1e-6) and far narrower than the step it was found in (1.3e-4 against 0.25: the
  // bracket widened by kNoiseMargin = 4 of its widths on each side).
  EXPECT_GT(sb.precision(), options.location_tolerance);
  EXPECT_LT(sb.precision(), 1e-2 * branch.points[sb.index + 1].step) << sb.BriefReport();
  // The exact SB (0, 0) within the precision, in every component (the estimate may be a trial point that
  // Newton took to the crossing line x = λ: still within the bracket width of the SB).
  EXPECT_LE(sb.u.lpNorm<Eigen::Infinity>(), sb.precision()) << sb.BriefReport();
  // The SB tangent is the branch's (λ axis), not a mixture of the two kernel directions.
  EXPECT_NEAR(std::abs(sb.tangent(1)), 1.0, 1e-12);
}

// The same map failing where Newton's corrections of the noise jump off the branch (|x| > 1e-10), as a
// shooting map may when a jump makes a duration or state leave its domain: a trial point whose first
// evaluation succeeded at the noise level and whose later one failed is noise-limited too.
TEST(ContinuationTest, SimpleBifurcationLocatedToTheNoiseLevelWhenTheJumpFailsToEvaluate) {
  class FailingOffTheAxis : public NoisyTranscritical {
   public:
    EvaluationStatus Evaluate(const Vector& u, Vector* r, Matrix* dr) override {
      if (std::abs(u(0)) > 1e-10) return EvaluationStatus::Failure("x = " + std::to_string(u(0)) + " outside |x| <= 1e-10");
      return NoisyTranscritical::Evaluate(u, r, dr);
    }
  } curve;
  ContinuationOptions options;
  options.bounds = {{"lambda", -1, 1}};
  const Branch branch = TraceTheAxis(&curve, options);
  ASSERT_EQ(branch.special_points.size(), 1u) << branch.FullReport();
  const SpecialPoint& sb = branch.special_points[0];
  EXPECT_EQ(sb.status, LocationStatus::kLocated) << sb.BriefReport();
  EXPECT_NE(sb.message.find("located to the noise level"), std::string::npos) << sb.BriefReport();
  EXPECT_LE(sb.u.lpNorm<Eigen::Infinity>(), sb.precision()) << sb.BriefReport();
}

// Curve x = 0, y = λ² whose bordered matrix has a singular value δ in the x direction and a residual
// quadratic in the predictor's error e = y − λ²: r₂ = δx + e². Newton's first step overshoots by e²/δ
// along x and the second one takes it back exactly: |Δ₁| ≈ |Δ₀| although Newton converges in three steps.
// The step contraction then pins h where e²/δ ~ e (the bouncing rod next to its non-symmetric family);
// the residual contraction does not.
class OvershootingCurve : public ZeroProblem {
 public:
  int num_equations() const override { return 2; }
  std::vector<std::string> unknown_names() const override { return {"x", "y", "lambda"}; }
  EvaluationStatus Evaluate(const Vector& u, Vector* r, Matrix* dr) override {
    const double x = u(0), y = u(1), l = u(2), e = y - l * l;
    if (r) {
      r->resize(2);
      *r << e, kDelta * x + e * e;
    }
    if (dr) {
      dr->resize(2, 3);
      *dr << 0, 1, -2 * l, kDelta, 2 * e, -4 * e * l;
    }
    return {};
  }
  static constexpr double kDelta = 1e-5;
};

TEST(ContinuationTest, StepControlIsNotPinnedByAnOvershootingFirstNewtonStep) {
  OvershootingCurve curve;
  ContinuationOptions options;
  options.bounds = {{"lambda", -1, 1}};
  options.max_points = 400;
  ContinuationStepper stepper(&curve, options);
  StepStatus status = stepper.Start(Eigen::Vector3d(0, 0.81, -0.9), Eigen::Vector3d(0, 0, 1));
  while (status == StepStatus::kContinuing) status = stepper.Step();
  const Branch& branch = stepper.branch();
  ASSERT_EQ(branch.termination, TerminationReason::kBoundReached) << branch.FullReport();
  EXPECT_EQ(branch.points.back().u(2), 1.0) << branch.message << " " << (branch.points.back().u(2) - 1.0);
  for (const ContinuationPoint& point : branch.points) {
    // x is resolved to residual_tolerance / δ only (r₂ = δx at e = 0).
    EXPECT_LE(std::abs(point.u(0)), options.corrector.residual_tolerance / OvershootingCurve::kDelta);
    EXPECT_NEAR(point.u(1), point.u(2) * point.u(2), 1e-12);
  }
  // Arclength of y = λ² over [−0.9, 1] is 2.8; the step contraction alone (h ~ 5e-3) did not reach λ = 1
  // within the 400 points.
  EXPECT_LT(branch.points.size(), 150u) << branch.FullReport();
}

TEST(ContinuationTest, SingularStartIsReportedNotThrown) {
  Pitchfork pitchfork;
  const Branch branch = TraceBranch(&pitchfork, Eigen::Vector2d(0, 0), ContinuationOptions());
  EXPECT_EQ(branch.termination, TerminationReason::kStartFailed);
  EXPECT_EQ(branch.points.size(), 0u);
}

}  // namespace
}  // namespace hybridcont
