// The precision of located special points includes the integration error (special_point.h, "Integration
// error"): checked on a curve with a known discretization error, and on the SLIP against an exploration
// at 10x tighter integration tolerances.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "bifurcation/branch_registry.h"
#include "continuation/bordered_solver.h"
#include "continuation/branch_geometry.h"
#include "continuation_test_problems.h"
#include "hybridcont/continuation.h"
#include "hybridcont/corrector.h"
#include "hybridcont/exploration.h"
#include "hybridcont/models.h"
#include "study_fixture.h"
#include "study/engine/scenario.h"

namespace hybridcont {
namespace {

using testing::PerturbedCircle;

Branch TraceToTheTurningPoint(ZeroProblem* curve, bool check_integration_error) {
  ContinuationOptions options;
  options.turning_point_components = {"x"};
  options.bounds = {{"y", -2, 0.5}};
  options.check_integration_error = check_integration_error;
  ContinuationStepper stepper(curve, options);
  StepStatus status = stepper.Start(Eigen::Vector2d(0, -1), Eigen::Vector2d(1, 0));
  while (status == StepStatus::kContinuing) status = stepper.Step();
  return stepper.TakeBranch();
}

TEST(SpecialPointPrecision, CoversTheDiscretizationErrorOfATurningPoint) {
  const double epsilon = 1e-7;
  PerturbedCircle curve(epsilon);
  const Eigen::Vector2d exact(1, 0);

  const Branch bare = TraceToTheTurningPoint(&curve, false);
  ASSERT_EQ(bare.special_points.size(), 1u) << bare.FullReport();
  const SpecialPoint& located = bare.special_points[0];
  ASSERT_EQ(located.type, SpecialPointType::kTurningPoint);
  // The root of the computed test function, 1.18ε from the exact turning point: the bracket alone
  // (location_tolerance) does not hold the exact point.
  const double error = (located.u - exact).norm();
  EXPECT_NEAR(error, std::hypot(0.5 * std::sin(7.0), 1.5 * std::cos(7.0)) * epsilon, 1e-2 * epsilon);
  EXPECT_LT(located.precision(), 1e-10);

  const Branch checked = TraceToTheTurningPoint(&curve, true);
  ASSERT_EQ(checked.special_points.size(), 1u) << checked.FullReport();
  const SpecialPoint& tp = checked.special_points[0];
  EXPECT_EQ(tp.u, located.u);  // the same location, now with its error
  EXPECT_NE(tp.message.find("integration error"), std::string::npos) << tp.BriefReport();
  // The interval holds the exact point, componentwise, and is not vacuous: its half-width is within 3x
  // the true error (the estimate is doubled, and the errors along and off the branch are added).
  for (int i = 0; i < 2; ++i) {
    EXPECT_LE(std::abs(tp.u(i) - exact(i)), 0.5 * tp.interval_width(i)) << i << ": " << tp.BriefReport();
  }
  EXPECT_GE(0.5 * tp.precision(), error);
  EXPECT_LE(0.5 * tp.precision(), 3 * error) << tp.BriefReport();
}

// A turning point where the test function is much flatter than across the step: x = −(a y² + y⁴) with
// a = 1e-4 has its turning point in x at (0, 0), and with the perturbation ε·sin(7x + 3y) (ε scaled by
// Refined) it moves to y ≈ 1.5ε/a, far more than on the circle. τ_x changes ~50x faster across a step of
// 0.1 than at the root: an error estimate with the step's secant slope alone said 30x too little;
// RootLocation::slope takes the flatter final bracket's.
class PerturbedQuartic : public ZeroProblem {
 public:
  explicit PerturbedQuartic(double epsilon) : epsilon_(epsilon) {}
  int num_equations() const override { return 1; }
  std::vector<std::string> unknown_names() const override { return {"x", "y"}; }
  EvaluationStatus Evaluate(const Vector& u, Vector* r, Matrix* dr) override {
    const double x = u(0), y = u(1), phase = 7 * x + 3 * y;
    if (r) *r = Vector::Constant(1, x + kA * y * y + y * y * y * y + epsilon_ * std::sin(phase));
    if (dr) {
      dr->resize(1, 2);
      *dr << 1 + 7 * epsilon_ * std::cos(phase), 2 * kA * y + 4 * y * y * y + 3 * epsilon_ * std::cos(phase);
    }
    return {};
  }
  std::unique_ptr<ZeroProblem> Refined(double factor) const override {
    return std::make_unique<PerturbedQuartic>(epsilon_ * factor);
  }
  static constexpr double kA = 1e-4;

 private:
  double epsilon_;
};

TEST(SpecialPointPrecision, CoversATurningPointWhereTheTestIsFlat) {
  const double epsilon = 1e-9;
  PerturbedQuartic curve(epsilon);
  ContinuationOptions options;
  options.turning_point_components = {"x"};
  options.bounds = {{"y", -1, 0.5}};
  options.max_step = 0.1;
  ContinuationStepper stepper(&curve, options);
  const double y0 = -0.5;
  StepStatus status = stepper.Start(Eigen::Vector2d(-(PerturbedQuartic::kA * y0 * y0 + std::pow(y0, 4)), y0),
                                    Eigen::Vector2d(0.5, 1).normalized());
  while (status == StepStatus::kContinuing) status = stepper.Step();
  const Branch branch = stepper.TakeBranch();
  ASSERT_EQ(branch.special_points.size(), 1u) << branch.FullReport();
  const SpecialPoint& tp = branch.special_points[0];
  ASSERT_EQ(tp.type, SpecialPointType::kTurningPoint);
  const Eigen::Vector2d exact(0, 0);
  const double error = (tp.u - exact).norm();
  EXPECT_GT(error, 1e3 * epsilon);  // the flat test amplifies ε ~1e4-fold
  for (int i = 0; i < 2; ++i) {
    EXPECT_LE(std::abs(tp.u(i) - exact(i)), 0.5 * tp.interval_width(i)) << i << ": " << tp.BriefReport();
  }
  EXPECT_GE(0.5 * tp.precision(), error) << tp.BriefReport();
  EXPECT_LE(0.5 * tp.precision(), 10 * error) << tp.BriefReport();
}

// A root finder trial exactly on the root ends the location with a one-point bracket: its test value is
// that 0 (it was the old bracket end's, −1 here, and the integration error then took it for a change of
// the test function) and the slope comes from the bracket just before (the case of the
// line y = x from (0, 0) to (2, 2) and the test x − 1, whose first secant trial is exactly x = 1).
TEST(SpecialPointPrecision, ATrialExactlyOnTheRootReportsATestOfZero) {
  struct Line : ZeroProblem {
    int num_equations() const override { return 1; }
    std::vector<std::string> unknown_names() const override { return {"x", "y"}; }
    EvaluationStatus Evaluate(const Vector& u, Vector* r, Matrix* dr) override {
      if (r) *r = Vector::Constant(1, u(1) - u(0));
      if (dr) *dr = Eigen::RowVector2d(-1, 1);
      return {};
    }
  } line;
  ContinuationPoint a, b;
  a.u = Eigen::Vector2d(0, 0);
  b.u = Eigen::Vector2d(2, 2);
  a.tangent = b.tangent = Eigen::Vector2d(1, 1).normalized();
  b.arclength = (b.u - a.u).norm();
  Corrector corrector(&line);
  internal::BorderedSolver solver;
  internal::Segment segment(&corrector, &solver, &line, a, b, false);
  const auto test = [](const internal::Segment::Probe& p) { return p.u(0) - 1; };
  const internal::RootLocation root = internal::LocateRoot(&segment, test, 1e-11, 60);
  ASSERT_TRUE(root.located) << root.message;
  EXPECT_DOUBLE_EQ(root.estimate.u(0), 1.0);
  EXPECT_EQ(root.test, 0.0);
  // d(x − 1)/dσ along the unit tangent: 1/√2
  EXPECT_NEAR(root.slope, 1 / std::sqrt(2.0), 1e-12);
}

// A problem exact to rounding has no refined copy: the precision stays the bracket's.
TEST(SpecialPointPrecision, ExactProblemsKeepTheBracket) {
  struct Exact : PerturbedCircle {
    Exact() : PerturbedCircle(0.0) {}
    std::unique_ptr<ZeroProblem> Refined(double) const override { return nullptr; }
  } exact;
  const Branch branch = TraceToTheTurningPoint(&exact, true);
  ASSERT_EQ(branch.special_points.size(), 1u) << branch.FullReport();
  EXPECT_LE(branch.special_points[0].precision(), ContinuationOptions().location_tolerance);
  EXPECT_TRUE(branch.special_points[0].message.empty()) << branch.special_points[0].BriefReport();
}

BifurcationDiagram ExploreSlip(double tolerance_factor) {
  return *StudyOf(MakeSlip(), WithTolerance(IntegratorOptions().rtol * tolerance_factor)).diagram;
}

// The independent check: the SLIP explored again at 10x tighter tolerances. Every special point of the
// default run lies within the two runs' precisions of its counterpart (the exact point is within each
// run's half-width of it), also those whose bracket is 2.5e-12 but which move by up to ~1e-6 with the
// tolerances (the turning point at the loop's reflection midpoint). Points located to the noise level
// carry an estimate, not a bound (special_point.h): they move with the noise of the path (a parent SB
// point located a little differently starts the whole branch elsewhere), measured up to 2.9x their
// intervals; asserted within 3x.
TEST(SpecialPointPrecision, SlipSpecialPointsMoveWithinTheirPrecisionWhenTheTolerancesShrink) {
  const BifurcationDiagram coarse = ExploreSlip(1.0);
  const BifurcationDiagram fine = ExploreSlip(0.1);
  ASSERT_EQ(coarse.branches.size(), fine.branches.size());
  int compared = 0, widened = 0, noise_limited = 0, at_sb = 0;
  for (const SpecialPoint& p : coarse.special_points) {
    if (p.duplicate_of >= 0 || p.type == SpecialPointType::kSingularStart) continue;
    const SpecialPoint* match = nullptr;
    for (const SpecialPoint& q : fine.special_points) {
      if (q.type != p.type || q.duplicate_of >= 0) continue;
      if (match == nullptr || (q.u - p.u).norm() < (match->u - p.u).norm()) match = &q;
    }
    ASSERT_NE(match, nullptr) << p.BriefReport(coarse.unknown_names);
    const bool estimate = p.message.find("noise level") != std::string::npos ||
                          match->message.find("noise level") != std::string::npos;
    const double half_widths = 0.5 * (p.interval_width.norm() + match->interval_width.norm());
    const double allowed = (estimate ? 3.0 : 1.0) * half_widths + 1e-12 * (1 + p.u.norm());
    EXPECT_LE((p.u - match->u).norm(), allowed) << p.BriefReport(coarse.unknown_names) << "\n"
                                                 << match->BriefReport(fine.unknown_names);
    ++compared;
    if (estimate) ++noise_limited;
    // A turning point at an SB point takes that point's interval, not its own meaningless estimate (the
    // reflection midpoint of the loop: 3.8e-6; on the SLIP with w2 = 12 the estimate claimed 2 and more).
    if (p.message.find("at the simple bifurcation point") != std::string::npos) {
      ++at_sb;
      EXPECT_LT(p.precision(), 1e-5) << p.BriefReport(coarse.unknown_names);
    }
    if (p.message.find("integration error") != std::string::npos) ++widened;
  }
  EXPECT_GE(compared, 40);
  EXPECT_LE(noise_limited, 12);
  EXPECT_GE(at_sb, 2);  // the loop's reflection midpoint and where branch 18 passes the zero-duration family
  // Most points: the integration error (1e-11..5e-10) exceeds the 2.5e-12 bracket.
  EXPECT_GE(widened, compared / 2);
}

// Two crossing branches locate their common SB point each to its own precision: the two locations are one
// point when every component differs by at most their interval widths plus same_point_tolerance·(1 + ||u||)
// (here 1e-6 · (1 + √5) = 3.24e-6), and two points are distinct when they differ by more.
TEST(SpecialPointPrecision, OneSbPointLocatedFromTwoBranchesIsOnePointWithinTheirPrecisions) {
  const auto sb = [](double x, double width) {
    SpecialPoint p;
    p.type = SpecialPointType::kSimpleBifurcation;
    p.status = LocationStatus::kLocated;
    p.u = Eigen::Vector2d(x, 2);
    p.interval_width = Eigen::Vector2d::Constant(width);
    return p;
  };
  const ExplorationOptions options;
  ASSERT_EQ(options.same_point_tolerance, 1e-6);
  internal::BranchRegistry registry(options);
  SpecialPoint first = sb(1, 2e-6), second = sb(1 + 7e-6, 2e-6), third = sb(1 + 7.5e-6, 0);
  EXPECT_TRUE(registry.Register(&first, 1));
  EXPECT_FALSE(registry.Register(&second, 2));  // 7e-6 <= 3.24e-6 + 2e-6 + 2e-6
  EXPECT_EQ(second.duplicate_of, first.id);
  EXPECT_TRUE(registry.Register(&third, 2));    // 7.5e-6 > 3.24e-6 + 2e-6 + 0
  // Without widths only the tolerance counts: 5e-6 apart are two points.
  internal::BranchRegistry exact(options);
  SpecialPoint a = sb(1, 0), b = sb(1 + 5e-6, 0), c = sb(1 + 3e-6, 0);
  EXPECT_TRUE(exact.Register(&a, 1));
  EXPECT_TRUE(exact.Register(&b, 1));
  EXPECT_FALSE(exact.Register(&c, 1));
}

}  // namespace
}  // namespace hybridcont
