// Branch switching (Lyapunov–Schmidt), singular starts and automatic exploration on algebraic curves.
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "continuation_test_problems.h"
#include "hybridcont/branch_switching.h"
#include "hybridcont/exploration.h"

namespace hybridcont {
namespace {

using testing::Circle;
using testing::ParabolaAndLine;
using testing::Pitchfork;
using testing::ThreeAxes;
using testing::Transcritical;

// Every point of a branch satisfies `on_curve`; the branch is one of the known curves. The first point
// of a branch leaving an SB point is that located point, exact only to its location precision (asserted
// separately, ~1e-11), so it is skipped here.
template <typename Predicate>
bool AllOn(const Branch& branch, Predicate on_curve) {
  for (size_t i = branch.parent_special_point >= 0 ? 1 : 0; i < branch.points.size(); ++i) {
    if (!on_curve(branch.points[i].u)) return false;
  }
  return true;
}

// Number of branches whose points all lie on the curve and on the side `side` (a predicate on u).
template <typename Curve, typename Side>
int CountBranches(const BifurcationDiagram& diagram, Curve curve, Side side) {
  int count = 0;
  for (const Branch& branch : diagram.branches) {
    if (branch.points.size() >= 2 && AllOn(branch, curve) && side(branch.points.back().u)) ++count;
  }
  return count;
}

TEST(BranchSwitchingTest, PitchforkSingularStartDirections) {
  Pitchfork pitchfork;
  const BranchDirections analysis = AnalyzeSingularPoint(&pitchfork, Eigen::Vector2d(0, 0), StartOptions());
  ASSERT_EQ(analysis.status, BranchSwitchStatus::kOk) << analysis.BriefReport();
  EXPECT_EQ(analysis.kernel_dimension, 2);
  EXPECT_EQ(analysis.cokernel_dimension, 1);
  ASSERT_EQ(analysis.directions.size(), 2u);
  // Q = −2αβ: the parabola's tangent (1, 0) and the trivial branch (0, 1), in either order.
  std::vector<Vector> expected = {Eigen::Vector2d(1, 0), Eigen::Vector2d(0, 1)};
  for (const Vector& e : expected) {
    const bool found = (analysis.directions[0] - e).norm() < 1e-8 || (analysis.directions[1] - e).norm() < 1e-8;
    EXPECT_TRUE(found) << e.transpose();
  }
}

TEST(BranchSwitchingTest, ThreeDimensionalKernelWithLinearConditions) {
  ThreeAxes axes;
  const Eigen::Vector3d origin(0, 0, 0);
  StartOptions options;
  BranchDirections analysis = AnalyzeSingularPoint(&axes, origin, options);
  EXPECT_EQ(analysis.kernel_dimension, 3);
  EXPECT_EQ(analysis.cokernel_dimension, 2);
  EXPECT_EQ(analysis.status, BranchSwitchStatus::kUnderdetermined);

  // The symmetry x = y (coefficients on named components) leaves the plane {x = y}: only the λ-axis.
  options.conditions = {{{{"x", 1.0}, {"y", -1.0}}}};
  analysis = AnalyzeSingularPoint(&axes, origin, options);
  ASSERT_EQ(analysis.status, BranchSwitchStatus::kOk) << analysis.BriefReport();
  ASSERT_EQ(analysis.directions.size(), 1u);
  EXPECT_LT((analysis.directions[0] - Eigen::Vector3d(0, 0, 1)).norm(), 1e-8);

  // λ = 0 leaves the plane {λ = 0}: the x- and y-axes.
  options.conditions = {{{{"lambda", 1.0}}}};
  const std::vector<Vector> lines = BranchDirectionsAt(axes, origin, options);
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_NEAR(std::abs(lines[0](0)) + std::abs(lines[1](0)), 1.0, 1e-8);
  EXPECT_NEAR(std::abs(lines[0](1)) + std::abs(lines[1](1)), 1.0, 1e-8);
  EXPECT_NEAR(std::abs(lines[0](2)) + std::abs(lines[1](2)), 0.0, 1e-12);

  // Two conditions leave one direction: selected by the conditions alone.
  options.conditions = {{{{"lambda", 1.0}}}, {{{"y", 1.0}}}};
  const std::vector<Vector> x_axis = BranchDirectionsAt(axes, origin, options);
  ASSERT_EQ(x_axis.size(), 1u);
  EXPECT_LT((x_axis[0] - Eigen::Vector3d(1, 0, 0)).norm(), 1e-12);
}

TEST(BranchSwitchingTest, TransverseRootAtLocatedSimpleBifurcation) {
  ParabolaAndLine curve;
  ContinuationOptions options;
  options.bounds = {{"x", -0.5, 1.0}};
  ContinuationStepper stepper(&curve, options);
  StepStatus status = stepper.Start(Eigen::Vector2d(-0.5, 0.75), Eigen::Vector2d(1, 1));
  while (status == StepStatus::kContinuing) status = stepper.Step();
  ASSERT_EQ(stepper.branch().special_points.size(), 1u);
  const SpecialPoint& sb = stepper.branch().special_points[0];
  const BranchSwitch result = SwitchDirectionAt(&curve, sb, BranchSwitchOptions());
  ASSERT_EQ(result.status, BranchSwitchStatus::kOk) << result.BriefReport();
  // Incoming: parabola tangent ∥ (1, −2x*); transverse: the line x = λ, ∥ (1, 1).
  const double x_star = (std::sqrt(5.0) - 1) / 2;
  const Vector line = Eigen::Vector2d(1, 1).normalized();
  const Vector parabola = Eigen::Vector2d(1, -2 * x_star).normalized();
  EXPECT_NEAR(std::abs(result.direction.dot(line)), 1.0, 1e-12);
  EXPECT_NEAR(std::abs(result.incoming_direction.dot(parabola)), 1.0, 1e-12);
  EXPECT_LT(result.incoming_root_angle, 1e-4);  // incoming tangent at the last point before the SB
  const std::vector<Branch> branches = TraceSwitchedBranches(&curve, sb, result, options);
  ASSERT_EQ(branches.size(), 2u);
  for (const Branch& branch : branches) {
    EXPECT_TRUE(AllOn(branch, [](const Vector& u) { return std::abs(u(0) - u(1)) < 1e-12; }));
    EXPECT_GT(branch.points.size(), 2u);
  }
}

TEST(ExplorationTest, PitchforkFromTrivialBranch) {
  Pitchfork pitchfork;
  ExplorationOptions options;
  options.continuation.bounds = {{"lambda", -1, 1}};
  const BifurcationDiagram diagram = Explore(&pitchfork, Eigen::Vector2d(0, -0.5), options);
  ASSERT_EQ(diagram.status, ExplorationStatus::kCompleted) << diagram.FullReport();
  ASSERT_EQ(diagram.branches.size(), 4u) << diagram.FullReport();
  auto trivial = [](const Vector& u) { return u(0) == 0; };
  auto parabola = [](const Vector& u) { return std::abs(u(1) - u(0) * u(0)) < 1e-12; };
  EXPECT_EQ(CountBranches(diagram, trivial, [](const Vector& u) { return u(1) == 1; }), 1);
  EXPECT_EQ(CountBranches(diagram, trivial, [](const Vector& u) { return u(1) == -1; }), 1);
  EXPECT_EQ(CountBranches(diagram, parabola, [](const Vector& u) { return u(0) > 0.99; }), 1);
  EXPECT_EQ(CountBranches(diagram, parabola, [](const Vector& u) { return u(0) < -0.99; }), 1);
  ASSERT_EQ(diagram.special_points.size(), 1u);
  const SpecialPoint& sb = diagram.special_points[0];
  EXPECT_EQ(sb.type, SpecialPointType::kSimpleBifurcation);
  EXPECT_EQ(sb.status, LocationStatus::kLocated);
  EXPECT_LE(sb.u.lpNorm<Eigen::Infinity>(), 1e-10);
  for (const Branch& branch : diagram.branches) {
    if (branch.parent_special_point == sb.id) {
      EXPECT_EQ(branch.depth, 1);
      EXPECT_EQ(branch.termination, TerminationReason::kBoundReached);
    }
  }
}

TEST(ExplorationTest, TranscriticalFromTrivialBranch) {
  Transcritical transcritical;
  ExplorationOptions options;
  options.continuation.bounds = {{"lambda", -1, 1}};
  const BifurcationDiagram diagram = Explore(&transcritical, Eigen::Vector2d(0, 0.4), options);
  ASSERT_EQ(diagram.branches.size(), 4u) << diagram.FullReport();
  auto trivial = [](const Vector& u) { return u(0) == 0; };
  auto line = [](const Vector& u) { return std::abs(u(0) - u(1)) < 1e-12; };
  EXPECT_EQ(CountBranches(diagram, trivial, [](const Vector& u) { return u(1) == 1; }), 1);
  EXPECT_EQ(CountBranches(diagram, trivial, [](const Vector& u) { return u(1) == -1; }), 1);
  EXPECT_EQ(CountBranches(diagram, line, [](const Vector& u) { return u(1) == 1; }), 1);
  EXPECT_EQ(CountBranches(diagram, line, [](const Vector& u) { return u(1) == -1; }), 1);
  ASSERT_EQ(diagram.special_points.size(), 1u);
  EXPECT_EQ(diagram.special_points[0].status, LocationStatus::kLocated);
  EXPECT_LE(diagram.special_points[0].u.lpNorm<Eigen::Infinity>(), 1e-10);
}

TEST(ExplorationTest, CircleIsOneClosedBranch) {
  Circle circle;
  ExplorationOptions options;
  options.continuation.turning_point_components = {"y"};
  const BifurcationDiagram diagram = Explore(&circle, Eigen::Vector2d(0.6, 0.8), options);
  ASSERT_EQ(diagram.branches.size(), 1u) << diagram.FullReport();  // not traced backwards again
  EXPECT_EQ(diagram.branches[0].termination, TerminationReason::kClosedLoop);
  ASSERT_EQ(diagram.special_points.size(), 2u);
  for (const SpecialPoint& point : diagram.special_points) {
    EXPECT_NEAR(point.u(0), 0.0, 1e-11);
    EXPECT_NEAR(std::abs(point.u(1)), 1.0, 1e-15);
  }
}

TEST(ExplorationTest, PitchforkFromSingularStart) {
  Pitchfork pitchfork;
  ExplorationOptions options;
  options.continuation.bounds = {{"lambda", -1, 1}};
  const BifurcationDiagram diagram = Explore(&pitchfork, Eigen::Vector2d(0, 0), options);
  EXPECT_EQ(diagram.start.kernel_dimension, 2);
  ASSERT_EQ(diagram.branches.size(), 4u) << diagram.FullReport();
  ASSERT_GE(diagram.special_points.size(), 1u);
  EXPECT_EQ(diagram.special_points[0].type, SpecialPointType::kSingularStart);
  for (const Branch& branch : diagram.branches) {
    EXPECT_EQ(branch.parent_special_point, 0);
    EXPECT_TRUE(branch.termination == TerminationReason::kBoundReached) << branch.BriefReport();
    EXPECT_TRUE(AllOn(branch, [](const Vector& u) { return u(0) == 0 || std::abs(u(1) - u(0) * u(0)) < 1e-12; }));
  }
  // No SB point re-found at the start: every branch leaves it on its first (skipped) interval.
  for (const SpecialPoint& point : diagram.special_points) {
    EXPECT_NE(point.type, SpecialPointType::kSimpleBifurcation) << point.BriefReport();
  }
}

TEST(ExplorationTest, ParabolaAndLineTwoSimpleBifurcationsNoBranchTwice) {
  ParabolaAndLine curve;
  ExplorationOptions options;
  options.continuation.bounds = {{"x", -2.5, 2.5}, {"lambda", -3, 3}};
  options.continuation.turning_point_components = {"lambda"};
  const BifurcationDiagram diagram = Explore(&curve, Eigen::Vector2d(-0.5, 0.75), options);
  ASSERT_EQ(diagram.status, ExplorationStatus::kCompleted);
  int sb_count = 0, fold_count = 0;
  for (const SpecialPoint& point : diagram.special_points) {
    if (point.type == SpecialPointType::kSimpleBifurcation) {
      ++sb_count;
      EXPECT_EQ(point.status, LocationStatus::kLocated);
      const double exact = point.u(0) > 0 ? (std::sqrt(5.0) - 1) / 2 : -(std::sqrt(5.0) + 1) / 2;
      EXPECT_NEAR(point.u(0), exact, 1e-10);
      EXPECT_NEAR(point.u(1), exact, 1e-10);
    } else if (point.type == SpecialPointType::kTurningPoint) {
      ++fold_count;
      EXPECT_NEAR(point.u(0), 0.0, 1e-11);
      EXPECT_NEAR(point.u(1), 1.0, 1e-15);
    }
  }
  EXPECT_EQ(sb_count, 2) << diagram.FullReport();
  EXPECT_EQ(fold_count, 1) << diagram.FullReport();
  // The parabola (start, two halves) and the line: three pieces between the two SB points, two outside.
  auto on_parabola = [](const Vector& u) { return std::abs(u(0) * u(0) + u(1) - 1) < 1e-12; };
  auto on_line = [](const Vector& u) { return std::abs(u(0) - u(1)) < 1e-12; };
  int parabola = 0, line = 0, known = 0;
  for (const Branch& branch : diagram.branches) {
    if (branch.termination == TerminationReason::kKnownBranch) {
      ++known;
      continue;
    }
    if (AllOn(branch, on_parabola)) ++parabola;
    else if (AllOn(branch, on_line)) ++line;
    else ADD_FAILURE() << branch.FullReport();
  }
  EXPECT_EQ(parabola, 2) << diagram.FullReport();  // both halves from the regular start
  // The line: from the first SB both ways (one of them reaches the other SB and goes on); at the second
  // SB both line rays are already known, so nothing is traced again.
  EXPECT_EQ(line, 2) << diagram.FullReport();
  EXPECT_EQ(known, 0) << diagram.FullReport();
}

// x(ελ − x) = 0: the lines x = 0 and x = ελ, crossing at the origin at the small angle atan ε.
class ShallowCrossing : public ZeroProblem {
 public:
  explicit ShallowCrossing(double epsilon) : epsilon_(epsilon) {}
  int num_equations() const override { return 1; }
  std::vector<std::string> unknown_names() const override { return {"x", "lambda"}; }
  EvaluationStatus Evaluate(const Vector& u, Vector* r, Matrix* dr) override {
    const double x = u(0), l = u(1);
    if (r) *r = Vector::Constant(1, x * (epsilon_ * l - x));
    if (dr) {
      dr->resize(1, 2);
      *dr << epsilon_ * l - 2 * x, epsilon_ * x;
    }
    return {};
  }

 private:
  double epsilon_;
};

// Branches that meet at a small angle are still two branches: the new line x = ελ lies within the old
// known-branch tolerances (chord sag, 8° for "same ray" and "parallel tangent") of x = 0 near the SB.
TEST(ExplorationTest, BranchesCrossingAtASmallAngleAreBothTraced) {
  for (const double epsilon : {0.1, 0.02, 0.005}) {
    ShallowCrossing curve(epsilon);
    ExplorationOptions options;
    options.continuation.bounds = {{"lambda", -1, 1}};
    const BifurcationDiagram diagram = Explore(&curve, Eigen::Vector2d(0, -0.5), options);
    ASSERT_EQ(diagram.status, ExplorationStatus::kCompleted) << diagram.FullReport();
    ASSERT_EQ(diagram.special_points.size(), 1u) << diagram.FullReport();
    EXPECT_EQ(diagram.special_points[0].status, LocationStatus::kLocated);
    EXPECT_LE(diagram.special_points[0].u.lpNorm<Eigen::Infinity>(), 1e-10);
    ASSERT_EQ(diagram.branches.size(), 4u) << "epsilon = " << epsilon << "\n" << diagram.FullReport();
    auto trivial = [](const Vector& u) { return u(0) == 0; };
    auto line = [epsilon](const Vector& u) { return std::abs(u(0) - epsilon * u(1)) < 1e-13; };
    EXPECT_EQ(CountBranches(diagram, trivial, [](const Vector& u) { return u(1) == 1; }), 1);
    EXPECT_EQ(CountBranches(diagram, trivial, [](const Vector& u) { return u(1) == -1; }), 1);
    EXPECT_EQ(CountBranches(diagram, line, [](const Vector& u) { return u(1) == 1; }), 1) << diagram.FullReport();
    EXPECT_EQ(CountBranches(diagram, line, [](const Vector& u) { return u(1) == -1; }), 1) << diagram.FullReport();
    for (const Branch& branch : diagram.branches) {
      EXPECT_EQ(branch.termination, TerminationReason::kBoundReached) << branch.FullReport();
    }
  }
}

// The λ-axis of ThreeAxes is a curve of singular points (dr = [[0, 0, 0], [λ, −λ, 0]]: kernel of
// dimension 2 for every λ), like the bouncing rod's at-rest ξ-line: both half-branches end at once with
// kStartFailed and the kernel dimension, without rejected steps.
TEST(ExplorationTest, CurveOfSingularPointsIsRefusedAtOnce) {
  ThreeAxes axes;
  ExplorationOptions options;
  options.continuation.bounds = {{"lambda", -1, 1}};
  options.start_conditions = {{{{"x", 1.0}, {"y", -1.0}}}};
  const BifurcationDiagram diagram = Explore(&axes, Eigen::Vector3d(0, 0, 0), options);
  ASSERT_EQ(diagram.branches.size(), 2u) << diagram.FullReport();
  for (const Branch& branch : diagram.branches) {
    EXPECT_EQ(branch.termination, TerminationReason::kStartFailed) << branch.FullReport();
    EXPECT_EQ(branch.rejected_steps, 0);
    EXPECT_EQ(branch.points.size(), 1u);
    EXPECT_NE(branch.message.find("dr has a kernel of dimension 2 along this direction: not a simple curve"),
              std::string::npos)
        << branch.message;
  }
  EXPECT_EQ(diagram.status, ExplorationStatus::kStartFailed);
}

TEST(ExplorationTest, ValidateAndReports) {
  ExplorationOptions options;
  EXPECT_EQ(options.Validate(), "");
  options.max_branches = 0;
  EXPECT_EQ(options.Validate(), "ExplorationOptions::max_branches = 0 must be >= 1");
  Pitchfork pitchfork;
  EXPECT_THROW(Explore(&pitchfork, Eigen::Vector2d(0, -0.5), options), std::invalid_argument);
  options = ExplorationOptions();
  options.continuation.bounds = {{"lambda", -1, 1}};
  const BifurcationDiagram diagram = Explore(&pitchfork, Eigen::Vector2d(0, -0.5), options);
  EXPECT_EQ(diagram.BriefReport(), "Exploration completed: 4 branches, 1 SB points (1 located), 0 turning points");
  EXPECT_NE(diagram.FullReport().find("Branch switches:"), std::string::npos);
}

}  // namespace
}  // namespace hybridcont
