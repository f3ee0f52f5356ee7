// Exploration with symmetries (exploration.h, "Symmetries"): half-branches that are images of traced
// ones are mapped, and the diagram is the one traced without symmetries.
#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "continuation_test_problems.h"
#include "hybridcont/exploration.h"
#include "hybridcont/models.h"
#include "hybridcont/timebased_shooting.h"
#include "model_exploration.h"

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

int Images(const BifurcationDiagram& d) {
  int images = 0;
  for (const Branch& b : d.branches) images += b.image_of >= 0;
  return images;
}

// Same branches (count, terminations, ends) and special points as a diagram traced without symmetries.
void ExpectSameDiagram(const BifurcationDiagram& traced, const BifurcationDiagram& mapped, double tolerance) {
  ASSERT_EQ(traced.branches.size(), mapped.branches.size()) << traced.FullReport() << mapped.FullReport();
  for (size_t i = 0; i < traced.branches.size(); ++i) {
    const Branch& a = traced.branches[i];
    const Branch& b = mapped.branches[i];
    EXPECT_EQ(a.termination, b.termination) << "branch " << i;
    EXPECT_EQ(a.parent_special_point, b.parent_special_point) << "branch " << i;
    ASSERT_EQ(a.points.size(), b.points.size()) << "branch " << i;
    EXPECT_LE((a.points.back().u - b.points.back().u).lpNorm<Eigen::Infinity>(), tolerance) << "branch " << i;
  }
  ASSERT_EQ(traced.special_points.size(), mapped.special_points.size());
  for (size_t k = 0; k < traced.special_points.size(); ++k) {
    const SpecialPoint& a = traced.special_points[k];
    const SpecialPoint& b = mapped.special_points[k];
    EXPECT_EQ(a.type, b.type) << "special point " << k;
    EXPECT_EQ(a.status, b.status) << "special point " << k;
    EXPECT_LE((a.u - b.u).lpNorm<Eigen::Infinity>(), tolerance) << "special point " << k;
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

// The SLIP's complete diagram: with symmetries the same branches, SB and turning points as traced
// without, at about half the map evaluations.
TEST(ExplorationSymmetry, SlipDiagramIsTheTracedOneAtHalfTheWork) {
  const HybridModel model = MakeSlip();
  const app::Scenario scenario = app::DefaultScenario(model);
  BifurcationDiagram diagrams[2];
  long evaluations[2];
  for (const bool use : {false, true}) {
    ExplorationOptions options = app::ScenarioExplorationOptions(scenario);
    options.use_symmetries = use;
    options.threads = 1;
    app::ModelExploration exploration(model, scenario, IntegratorOptions{}, options);
    diagrams[use] = exploration.Run();
    evaluations[use] = exploration.num_evaluations();
  }
  const BifurcationDiagram& traced = diagrams[0];
  const BifurcationDiagram& mapped = diagrams[1];
  EXPECT_EQ(Images(traced), 0);
  EXPECT_GE(Images(mapped), 10) << mapped.FullReport();
  EXPECT_TRUE(mapped.warnings.empty());
  EXPECT_LT(evaluations[1], 0.65 * evaluations[0]) << evaluations[0] << " " << evaluations[1];
  // Same sets of special points (the order of two half-branches from an SB point may differ: the sign of
  // a switching direction computed there is arbitrary, a mapped one is the image's).
  ASSERT_EQ(traced.special_points.size(), mapped.special_points.size());
  for (const SpecialPoint& a : traced.special_points) {
    double nearest = 1e300;
    for (const SpecialPoint& b : mapped.special_points) {
      if (a.type == b.type) nearest = std::min(nearest, (a.u - b.u).lpNorm<Eigen::Infinity>());
    }
    // bracketed SB points are known to their bracket (~1e-4 in arclength), located ones to ~1e-10
    EXPECT_LE(nearest, a.status == LocationStatus::kLocated ? 1e-8 : 1e-3) << a.BriefReport();
  }
  ASSERT_EQ(traced.branches.size(), mapped.branches.size());
  std::vector<size_t> a, b;
  for (const Branch& x : traced.branches) a.push_back(x.points.size());
  for (const Branch& x : mapped.branches) b.push_back(x.points.size());
  std::sort(a.begin(), a.end());
  std::sort(b.begin(), b.end());
  EXPECT_EQ(a, b);
}

}  // namespace
}  // namespace hybridcont
