// Exploration with symmetries (exploration.h, "Symmetries"): half-branches that are images of traced
// ones are mapped, and the diagram is the one traced without symmetries.
#include <algorithm>
#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "continuation_test_problems.h"
#include "hybridcont/exploration.h"
#include "hybridcont/models.h"
#include "hybridcont/timebased_shooting.h"
#include "study/engine/model_exploration.h"

namespace hybridcont {
namespace {

// Counts evaluations.
template <class Problem>
class Counting : public Problem {
 public:
  EvaluationStatus Evaluate(const Vector& u, Vector* r, Matrix* dr) override {
    ++evaluations;
    return Problem::Evaluate(u, r, dr);
  }
  int evaluations = 0;
};

// x (λ − 1 − m x)(λ + 1 + m x) = 0 with the symmetry λ -> −λ: the lines x = 0 and λ = ±(1 + m x), which
// cross x = 0 at (0, ±1) at the angle atan(1/m) (5.7° for m = 10).
class NarrowCrossing : public ZeroProblem {
 public:
  explicit NarrowCrossing(double m = 10) : m_(m) {}
  int num_equations() const override { return 1; }
  std::vector<std::string> unknown_names() const override { return {"x", "lambda"}; }
  EvaluationStatus Evaluate(const Vector& u, Vector* r, Matrix* dr) override {
    const double x = u(0), l = u(1), a = l - 1 - m_ * x, b = l + 1 + m_ * x;
    if (r) *r = Vector::Constant(1, x * a * b);
    if (dr) {
      dr->resize(1, 2);
      *dr << a * b + x * (-m_ * b + a * m_), x * (a + b);
    }
    return {};
  }
  std::vector<Symmetry> symmetries() const override { return {{"lambda-flip", Eigen::Vector2d(1, -1)}}; }
  std::unique_ptr<ZeroProblem> Clone() const override { return std::make_unique<NarrowCrossing>(*this); }

 private:
  double m_;
};

// x (λ² − 1 − x) = 0 with a false declaration (x, λ) -> (−x, −λ), true on the line x = 0 only: the
// switching directions at (0, 1), mapped from (0, −1), would point off the parabola.
class PartlySymmetric : public ZeroProblem {
 public:
  int num_equations() const override { return 1; }
  std::vector<std::string> unknown_names() const override { return {"x", "lambda"}; }
  EvaluationStatus Evaluate(const Vector& u, Vector* r, Matrix* dr) override {
    const double x = u(0), l = u(1), p = l * l - 1 - x;
    if (r) *r = Vector::Constant(1, x * p);
    if (dr) {
      dr->resize(1, 2);
      *dr << p - x, 2 * x * l;
    }
    return {};
  }
  std::vector<Symmetry> symmetries() const override { return {{"both-flip", Eigen::Vector2d(-1, -1)}}; }
  std::unique_ptr<ZeroProblem> Clone() const override { return std::make_unique<PartlySymmetric>(*this); }
};

// x ((λ − 3)² + x² − 1)((λ + 3)² + x² − 1) = 0 with λ -> −λ: the line x = 0 and two circles, mirror
// images, each a closed loop from its SB points (the last point of a closed loop is its
// singular start, which the image check must not take for a failed mapping).
class TwoCircles : public ZeroProblem {
 public:
  int num_equations() const override { return 1; }
  std::vector<std::string> unknown_names() const override { return {"x", "lambda"}; }
  EvaluationStatus Evaluate(const Vector& u, Vector* r, Matrix* dr) override {
    const double x = u(0), l = u(1);
    const double a = (l - 3) * (l - 3) + x * x - 1, b = (l + 3) * (l + 3) + x * x - 1;
    if (r) *r = Vector::Constant(1, x * a * b);
    if (dr) {
      dr->resize(1, 2);
      *dr << a * b + x * (2 * x * b + a * 2 * x), x * (2 * (l - 3) * b + a * 2 * (l + 3));
    }
    return {};
  }
  std::vector<Symmetry> symmetries() const override { return {{"lambda-flip", Eigen::Vector2d(1, -1)}}; }
};

// The diagram from u0 with the problem's symmetries and without (every half-branch traced).
struct TwoRuns {
  BifurcationDiagram mapped, traced;
};
TwoRuns ExploreWithAndWithout(ZeroProblem* problem, const Vector& u0, ExplorationOptions options) {
  TwoRuns runs;
  options.use_symmetries = true;
  runs.mapped = Explore(problem, u0, options);
  options.use_symmetries = false;
  runs.traced = Explore(problem, u0, options);
  return runs;
}

int Images(const BifurcationDiagram& d) {
  int images = 0;
  for (const Branch& b : d.branches) images += b.image_of >= 0;
  return images;
}

// Same branches (count, terminations, ends) and special points as a diagram traced without symmetries.
// `unreliable`: special points whose location is known not to be reproducible (compared by type only).
void ExpectSameDiagram(const BifurcationDiagram& traced, const BifurcationDiagram& mapped, double tolerance,
                       const std::function<bool(const SpecialPoint&)>& unreliable = {}) {
  ASSERT_EQ(traced.branches.size(), mapped.branches.size()) << traced.FullReport() << mapped.FullReport();
  for (size_t i = 0; i < traced.branches.size(); ++i) {
    const Branch& a = traced.branches[i];
    const Branch& b = mapped.branches[i];
    EXPECT_EQ(a.termination, b.termination) << "branch " << i;
    EXPECT_EQ(a.parent_special_point, b.parent_special_point) << "branch " << i;
    // A loop completed by reflection has points of its own past its midpoint: the same curve, ending
    // at the same point (checked), sampled otherwise.
    if (a.reflected_from < 0 && b.reflected_from < 0) ASSERT_EQ(a.points.size(), b.points.size()) << "branch " << i;
    EXPECT_LE((a.points.back().u - b.points.back().u).lpNorm<Eigen::Infinity>(), tolerance) << "branch " << i;
  }
  ASSERT_EQ(traced.special_points.size(), mapped.special_points.size());
  for (size_t k = 0; k < traced.special_points.size(); ++k) {
    const SpecialPoint& a = traced.special_points[k];
    const SpecialPoint& b = mapped.special_points[k];
    EXPECT_EQ(a.type, b.type) << "special point " << k;
    if (unreliable && unreliable(a)) continue;
    EXPECT_EQ(a.status, b.status) << "special point " << k;
    // within `tolerance` or the points' own precision (componentwise width of their final brackets)
    const auto width = [](const SpecialPoint& p) {
      return p.interval_width.size() ? p.interval_width.lpNorm<Eigen::Infinity>() : 0.0;
    };
    EXPECT_LE((a.u - b.u).lpNorm<Eigen::Infinity>(), std::max(tolerance, width(a) + width(b))) << "special point " << k;
  }
}

TEST(ExplorationSymmetry, PitchforkMirrorHalfIsMappedNotTraced) {
  ExplorationOptions options;
  options.continuation.bounds = {{"lambda", -1, 1}};
  for (const Vector& u0 : {Vector(Eigen::Vector2d(0, -0.5)), Vector(Eigen::Vector2d(0, 0))}) {
    SCOPED_TRACE(u0.transpose());
    Counting<testing::Pitchfork> plain;
    Counting<testing::SymmetricPitchfork> symmetric;
    const BifurcationDiagram traced = Explore(&plain, u0, options);
    const BifurcationDiagram mapped = Explore(&symmetric, u0, options);
    ASSERT_EQ(mapped.branches.size(), 4u) << mapped.FullReport();
    // One image: one half of the parabola, the other under x -> −x, point by point.
    ASSERT_EQ(Images(mapped), 1) << mapped.FullReport();
    for (const Branch& b : mapped.branches) {
      if (b.image_of < 0) continue;
      const Branch& source = mapped.branches[b.image_of];
      EXPECT_EQ(b.symmetry, "x-flip");
      EXPECT_EQ(b.newton_iterations, 0);
      EXPECT_EQ(b.termination, TerminationReason::kBoundReached);
      ASSERT_EQ(b.points.size(), source.points.size());
      for (size_t i = 0; i < b.points.size(); ++i) {
        EXPECT_EQ(b.points[i].u, Vector(Eigen::Vector2d(-source.points[i].u(0), source.points[i].u(1))));
        EXPECT_EQ(b.points[i].tangent(1), source.points[i].tangent(1));
        // on λ = x² (the first point is the SB point, located to ~1e-11)
        if (i > 0) EXPECT_NEAR(b.points[i].u(1), b.points[i].u(0) * b.points[i].u(0), 1e-12);
      }
      EXPECT_GT(std::abs(b.points.back().u(0)), 0.99);
    }
    ExpectSameDiagram(traced, mapped, 1e-10);
    EXPECT_TRUE(mapped.warnings.empty());
    // The image costs one evaluation (its check) instead of a trace.
    EXPECT_LT(symmetric.evaluations, plain.evaluations - 10) << plain.evaluations << " " << symmetric.evaluations;
  }
}

TEST(ExplorationSymmetry, NotUsedWhenAStopIsNotSymmetric) {
  ExplorationOptions options;
  options.continuation.bounds = {{"lambda", -1, 1}, {"x", -1, 0.5}};  // x -> −x moves the bound on x
  testing::SymmetricPitchfork symmetric;
  const BifurcationDiagram d = Explore(&symmetric, Eigen::Vector2d(0, -0.5), options);
  ASSERT_EQ(d.branches.size(), 4u) << d.FullReport();
  EXPECT_EQ(Images(d), 0);
  options.use_symmetries = false;
  options.continuation.bounds = {{"lambda", -1, 1}};
  EXPECT_EQ(Images(Explore(&symmetric, Eigen::Vector2d(0, -0.5), options)), 0);
}

TEST(ExplorationSymmetry, AFalseDeclarationIsCaughtAndTheBranchTraced) {
  ExplorationOptions options;
  options.continuation.bounds = {{"lambda", -1, 1}};
  testing::Pitchfork plain;
  testing::FalselySymmetricPitchfork falsely;
  const BifurcationDiagram traced = Explore(&plain, Eigen::Vector2d(0, -0.5), options);
  const BifurcationDiagram d = Explore(&falsely, Eigen::Vector2d(0, -0.5), options);
  EXPECT_EQ(Images(d), 0) << d.FullReport();
  ASSERT_EQ(d.warnings.size(), 1u) << d.FullReport();
  EXPECT_NE(d.warnings[0].find("symmetry 'both-flip' does not map branch"), std::string::npos) << d.warnings[0];
  ExpectSameDiagram(traced, d, 0.0);
}

// A branch crossing the image of another at a small angle is traced, not taken for that image (from
// (1, 1 + m) the half-branches along λ = −1 − m x at (0, −1) are 5.7° off the images of those along
// x = 0 at (0, 1); none is an image). From (0, 0.5) the line λ = −1 − m x is the image of λ = 1 + m x.
TEST(ExplorationSymmetry, BranchesCrossingAtSmallAnglesAreNotImages) {
  for (const double m : {10.0, 6.0}) {
    SCOPED_TRACE(m);
    ExplorationOptions options;
    options.continuation.bounds = {{"lambda", -40, 40}, {"x", -0.05, 3}};
    options.threads = 1;
    NarrowCrossing problem(m);
    const TwoRuns runs = ExploreWithAndWithout(&problem, Eigen::Vector2d(1, 1 + m), options);
    const BifurcationDiagram& mapped = runs.mapped;
    const BifurcationDiagram& traced = runs.traced;
    ExpectSameDiagram(traced, mapped, 1e-9);
    EXPECT_EQ(Images(mapped), 0) << mapped.FullReport();
  }
  for (const double m : {10.0, 6.0}) {
    SCOPED_TRACE(m);
    ExplorationOptions options;
    options.continuation.bounds = {{"lambda", -40, 40}, {"x", -10, 10}};
    options.threads = 1;
    NarrowCrossing problem(m);
    const TwoRuns runs = ExploreWithAndWithout(&problem, Eigen::Vector2d(0, 0.5), options);
    const BifurcationDiagram& mapped = runs.mapped;
    const BifurcationDiagram& traced = runs.traced;
    ExpectSameDiagram(traced, mapped, 1e-9);
    EXPECT_GE(Images(mapped), 2) << mapped.FullReport();
    // Images end on the mapped bound: the image of a branch that reached λ = 40 reaches λ = −40.
    int messages = 0;
    for (const Branch& b : mapped.branches) {
      if (b.image_of < 0 || b.termination != TerminationReason::kBoundReached) continue;
      const Branch& source = mapped.branches[b.image_of];
      EXPECT_EQ(b.points.back().u(1), -source.points.back().u(1));
      if (std::abs(b.points.back().u(1)) == 40) {
        EXPECT_EQ(b.message, b.points.back().u(1) > 0 ? "reached lambda <= 40" : "reached lambda >= -40")
            << source.message;
        ++messages;
      }
    }
    EXPECT_GE(messages, 1) << mapped.FullReport();
  }
}

TEST(ExplorationSymmetry, AClosedLoopIsMappedOntoItsImage) {
  ExplorationOptions options;
  options.continuation.bounds = {{"lambda", -5, 5}, {"x", -2, 2}};
  TwoCircles problem;
  const BifurcationDiagram mapped = Explore(&problem, Eigen::Vector2d(0, 0.5), options);
  EXPECT_TRUE(mapped.warnings.empty()) << mapped.FullReport();
  int loops = 0, mapped_loops = 0;
  for (const Branch& b : mapped.branches) {
    if (b.termination != TerminationReason::kClosedLoop) continue;
    ++loops;
    if (b.image_of >= 0) ++mapped_loops;
  }
  EXPECT_EQ(loops, 2) << mapped.FullReport();
  EXPECT_EQ(mapped_loops, 1) << mapped.FullReport();
  options.use_symmetries = false;
  ExpectSameDiagram(Explore(&problem, Eigen::Vector2d(0, 0.5), options), mapped, 1e-9);
}

TEST(ExplorationSymmetry, ASelfSymmetricLoopIsCompletedByReflection) {
  ExplorationOptions options;
  options.continuation.bounds = {{"x", -2, 2}};
  testing::CircleOnAxis problem;
  const TwoRuns runs = ExploreWithAndWithout(&problem, Eigen::Vector2d(0.3, 0), options);
  const BifurcationDiagram& reflected = runs.mapped;
  const BifurcationDiagram& traced = runs.traced;
  ExpectSameDiagram(traced, reflected, 1e-9);
  const Branch* loop = nullptr;
  for (const Branch& b : reflected.branches) {
    if (b.reflected_from >= 0) loop = &b;
  }
  ASSERT_NE(loop, nullptr) << reflected.FullReport();
  EXPECT_EQ(loop->termination, TerminationReason::kClosedLoop);
  const int j = loop->reflected_from - 1;
  EXPECT_EQ(static_cast<int>(loop->points.size()), 2 * j + 2);
  for (const ContinuationPoint& p : loop->points) EXPECT_NEAR(p.u.squaredNorm(), 1.0, 1e-10);
  // Its midpoint, the SB point (−1, 0), is its only special point (the start, (1, 0), is not searched).
  ASSERT_EQ(loop->special_points.size(), 1u) << loop->FullReport();
  const SpecialPoint& mid = loop->special_points[0];
  EXPECT_EQ(mid.type, SpecialPointType::kSimpleBifurcation);
  EXPECT_LE((mid.u - Eigen::Vector2d(-1, 0)).norm(), 1e-10);
  EXPECT_EQ(mid.index, j);
  for (int i = 1; i <= j; ++i) {
    const ContinuationPoint& a = loop->points[i];
    const ContinuationPoint& b = loop->points[2 * j + 1 - i];
    EXPECT_EQ(b.u, Vector(Eigen::Vector2d(a.u(0), -a.u(1))));
    EXPECT_EQ(b.arclength, 2 * mid.arclength - a.arclength);
    EXPECT_EQ(b.tangent, Vector(Eigen::Vector2d(-a.tangent(0), a.tangent(1))));  // −g(τ)
    // the SB test changes sign across the midpoint
    EXPECT_LT(a.sb_test * b.sb_test, 0) << i;
  }
}

// The special points at the midpoint (the SB point and the turning point in x, τ_x(M) = 0) are kept
// once whatever the steps: over 400 maximal steps (two of them once dropped or doubled the
// turning point, among them 0.02 + 0.2 · 922/3000), the reflected diagram has the traced one's special points.
TEST(ExplorationSymmetry, TheMidpointsSpecialPointsDoNotDependOnTheSteps) {
  std::vector<double> steps = {0.02 + 0.2 * 922 / 3000.0, 0.09985, 0.050697032478347948};
  for (int i = 0; i < 400; ++i) steps.push_back(0.02 + 0.2 * i / 400.0);
  for (const double h : steps) {
    SCOPED_TRACE(h);
    ExplorationOptions options;
    options.continuation.bounds = {{"x", -2, 2}};
    options.continuation.turning_point_components = {"x", "lambda"};
    options.continuation.max_step = h;
    options.continuation.initial_step = std::min(h, 0.05);
    testing::CircleOnAxis problem;
    const TwoRuns runs = ExploreWithAndWithout(&problem, Eigen::Vector2d(0.3, 0), options);
    const BifurcationDiagram& reflected = runs.mapped;
    const BifurcationDiagram& traced = runs.traced;
    ASSERT_EQ(reflected.BriefReport(), traced.BriefReport());
    ASSERT_EQ(reflected.special_points.size(), traced.special_points.size());
    for (size_t k = 0; k < traced.special_points.size(); ++k) {
      EXPECT_EQ(reflected.special_points[k].type, traced.special_points[k].type) << k;
      EXPECT_LE((reflected.special_points[k].u - traced.special_points[k].u).norm(), 1e-4) << k;
    }
  }
}

// A declaration that holds on one branch only: switching directions are computed, never mapped, and the
// diagram is the traced one, on any number of threads.
TEST(ExplorationSymmetry, ADeclarationTrueOnOneBranchOnlyChangesNothing) {
  ExplorationOptions options;
  options.continuation.bounds = {{"lambda", -1.5, 1.5}, {"x", -2, 2}};
  options.threads = 1;
  PartlySymmetric problem;
  const BifurcationDiagram mapped = Explore(&problem, Eigen::Vector2d(0, 0.5), options);
  for (const int threads : {2, 3}) {
    options.threads = threads;
    const BifurcationDiagram concurrent = Explore(&problem, Eigen::Vector2d(0, 0.5), options);
    EXPECT_EQ(concurrent.FullReport(), mapped.FullReport());
  }
  options.use_symmetries = false;
  options.threads = 1;
  const BifurcationDiagram traced = Explore(&problem, Eigen::Vector2d(0, 0.5), options);
  ASSERT_EQ(traced.branches.size(), mapped.branches.size()) << traced.FullReport() << mapped.FullReport();
  for (const Branch& b : mapped.branches) EXPECT_NE(b.termination, TerminationReason::kStepTooSmall);
}

// The time-based map of every built-in model is equivariant under its declared symmetries to the last
// bit (the integrator's arithmetic is symmetric under sign changes): |r(S u)| = |r(u)|.
TEST(ExplorationSymmetry, TimeBasedMapsAreExactlyEquivariant) {
  for (const std::string& name : BuiltinModelNames()) {
    SCOPED_TRACE(name);
    const HybridModel model = MakeBuiltinModel(name);
    TimeBasedShooting shooting(model, IntegratorOptions{});
    const std::vector<Symmetry> group = shooting.symmetries();
    EXPECT_EQ(group.size(), name == "slip" ? 3u : 1u);
    std::srand(7);
    const Vector u = BuiltinStartPoint(model) + 0.05 * Vector::Random(shooting.num_unknowns());
    Vector r, r_image;
    ASSERT_TRUE(shooting.Evaluate(u, &r, nullptr).ok);
    ASSERT_GT(r.norm(), 1e-3);
    for (const Symmetry& g : group) {
      ASSERT_TRUE(shooting.Evaluate(g.Apply(u), &r_image, nullptr).ok);
      EXPECT_EQ(r_image.cwiseAbs(), r.cwiseAbs()) << g.name;
    }
  }
}

// A built-in model's default scenario on one thread, with or without symmetries.
struct ScenarioRun {
  BifurcationDiagram diagram;
  long evaluations = 0;
};
ScenarioRun RunScenario(const std::string& name, bool use_symmetries, int max_branches = 0) {
  const HybridModel model = MakeBuiltinModel(name);
  const study::Scenario scenario = study::DefaultScenario(model);
  ExplorationOptions options = study::ScenarioExplorationOptions(scenario);
  options.use_symmetries = use_symmetries;
  options.threads = 1;
  if (max_branches > 0) options.max_branches = max_branches;
  study::ModelExploration exploration(model, scenario, IntegratorOptions{}, options);
  ScenarioRun run;
  run.diagram = exploration.Run();
  run.evaluations = exploration.num_evaluations();
  return run;
}

// The SLIP's complete diagram: with symmetries the same branches (in the same order: switching
// directions have a canonical sign), SB and turning points as traced without, at about 55% of the map
// evaluations; the closed loop (branch 8) is traced to its midpoint and completed by reflection.
//
// Except two: the loop's turning points where all durations pass through 0 together (T ≈ 0, H̄ ≈ 1.5714)
// are not reproducible — any perturbation of dr at the 1e-8 level moves them by up to 1e-2 (bench/README,
// "found on the way"), and the traced loop's pair is not mirror-symmetric to that level. The reflected
// loop's pair is, exactly; that is asserted instead.
TEST(ExplorationSymmetry, SlipDiagramIsTheTracedOneAtLessWork) {
  const ScenarioRun traced = RunScenario("slip", false);
  const ScenarioRun mapped = RunScenario("slip", true);
  EXPECT_EQ(Images(traced.diagram), 0);
  EXPECT_GE(Images(mapped.diagram), 10) << mapped.diagram.FullReport();
  EXPECT_TRUE(mapped.diagram.warnings.empty());
  EXPECT_LT(mapped.evaluations, 0.55 * traced.evaluations) << traced.evaluations << " " << mapped.evaluations;
  const std::vector<std::string>& names = mapped.diagram.unknown_names;
  const auto index = [&](const std::string& name) {
    return static_cast<int>(std::find(names.begin(), names.end(), name) - names.begin());
  };
  const auto period = [&](const Vector& u) { return u(index("t1")) + u(index("t2")) + u(index("t3")); };
  const auto at_zero_period = [&](const SpecialPoint& p) {
    return p.type == SpecialPointType::kTurningPoint && std::abs(period(p.u)) < 1e-3;
  };
  ExpectSameDiagram(traced.diagram, mapped.diagram, 1e-9, at_zero_period);
  // Every SB point located: the one in the cluster of nearly tangent crossings near H̄ ≈ 1.6115
  // on the four images of one branch stayed bracketed while the SB interpolant extrapolated from nodes
  // scattered by the noise (Segment::kMaxLebesgue).
  for (const SpecialPoint& p : mapped.diagram.special_points) {
    if (p.type == SpecialPointType::kSimpleBifurcation) {
      EXPECT_EQ(p.status, LocationStatus::kLocated) << p.BriefReport(names);
    }
  }

  const Branch* loop = nullptr;
  for (const Branch& b : mapped.diagram.branches) {
    if (b.reflected_from >= 0) loop = &b;
  }
  ASSERT_NE(loop, nullptr) << mapped.diagram.FullReport();
  EXPECT_EQ(loop->termination, TerminationReason::kClosedLoop);
  EXPECT_EQ(loop->symmetry, "mirror");
  const Symmetry mirror = TimeBasedShooting(MakeSlip(), IntegratorOptions{}).symmetries().front();
  ASSERT_EQ(mirror.name, "mirror");
  std::vector<const SpecialPoint*> pair;
  for (const SpecialPoint& p : loop->special_points) {
    if (at_zero_period(p)) pair.push_back(&p);
  }
  ASSERT_EQ(pair.size(), 2u) << loop->FullReport(names);
  EXPECT_EQ(mirror.Apply(pair[0]->u), pair[1]->u);
  // Every point of the reflected half is the mirror image of one of the traced half.
  const int j = loop->reflected_from - 1;
  for (int i = 1; i <= j; ++i) EXPECT_EQ(loop->points[2 * j + 1 - i].u, mirror.Apply(loop->points[i].u)) << i;
  EXPECT_EQ(loop->points.back().u, loop->points.front().u);
}

// With a branch budget the same branches make it in, with or without symmetries.
TEST(ExplorationSymmetry, BranchBudgetKeepsTheSameBranches) {
  const ScenarioRun traced = RunScenario("bouncing-rod", false, 7);
  const ScenarioRun mapped = RunScenario("bouncing-rod", true, 7);
  EXPECT_GE(Images(mapped.diagram), 2) << mapped.diagram.FullReport();
  ExpectSameDiagram(traced.diagram, mapped.diagram, 1e-9);
}

}  // namespace
}  // namespace hybridcont
