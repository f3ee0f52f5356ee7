// The Floquet test functions in the continuation (floquet_test_functions.h): the PD points the exploration
// locates on the bouncing rod and the SLIP, checked against the multipliers of floquet.h and the sign of
// PeriodDoublingTest, and their work counted apart from the continuation's (ModelExploration).
#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "hybridcont/floquet.h"
#include "hybridcont/floquet_test_functions.h"
#include "hybridcont/models.h"
#include "hybridcont/timebased_shooting.h"
#include "study/engine/model_exploration.h"

namespace hybridcont {
namespace {

struct ExplorationRun {
  HybridModel model;
  BifurcationDiagram diagram;
  long evaluations = 0;
  study::TestFunctionWork tests;
};

// The model's default exploration (one thread), with the parameters `set` changed first.
ExplorationRun Explore(const std::string& name, const std::vector<std::pair<std::string, double>>& set = {}) {
  ExplorationRun run{MakeBuiltinModel(name), {}, 0, {}};
  for (const auto& [parameter, value] : set) run.model.SetParameter(parameter, value);
  const study::Scenario scenario = study::DefaultScenario(run.model);
  ExplorationOptions options = study::ScenarioExplorationOptions(scenario);
  options.threads = 1;
  study::ModelExploration exploration(run.model, scenario, IntegratorOptions{}, options);
  run.diagram = exploration.Run();
  run.evaluations = exploration.num_evaluations();
  run.tests = exploration.test_function_work();
  return run;
}

std::vector<const SpecialPoint*> PdPoints(const BifurcationDiagram& d) {
  std::vector<const SpecialPoint*> points;
  for (const SpecialPoint& p : d.special_points) {
    if (p.type == SpecialPointType::kPeriodDoubling && p.duplicate_of < 0) points.push_back(&p);
  }
  return points;
}

// |μ + 1| of the multiplier closest to −1 at u (floquet.h).
double DistanceToMinusOne(TimeBasedShooting& shooting, const Vector& u) {
  const FloquetResult f = ComputeFloquet(shooting, u);
  EXPECT_TRUE(f.ok()) << f.message;
  double closest = std::numeric_limits<double>::infinity();
  for (const std::complex<double>& mu : f.nontrivial) closest = std::min(closest, std::abs(mu + 1.0));
  return closest;
}

// The two multipliers closest to −1 at u, closest first.
std::pair<std::complex<double>, std::complex<double>> PairAtMinusOne(TimeBasedShooting& shooting, const Vector& u) {
  const FloquetResult f = ComputeFloquet(shooting, u);
  EXPECT_TRUE(f.ok()) << f.message;
  std::vector<std::complex<double>> mu = f.nontrivial;
  EXPECT_GE(mu.size(), 2u);
  if (mu.size() < 2) return {};
  std::sort(mu.begin(), mu.end(), [](auto a, auto b) { return std::abs(a + 1.0) < std::abs(b + 1.0); });
  return {mu[0], mu[1]};
}

// The PD points of a diagram within 1e-6 of H̄ (unknown iH).
std::vector<const SpecialPoint*> PdPointsNear(const BifurcationDiagram& diagram, int iH, double H) {
  std::vector<const SpecialPoint*> near;
  for (const SpecialPoint* p : PdPoints(diagram)) {
    if (std::abs(p->u(iH) - H) < 1e-6) near.push_back(p);
  }
  return near;
}

double PdTest(TimeBasedShooting& shooting, const Vector& u) {
  Matrix dr;
  EXPECT_TRUE(shooting.Evaluate(u, nullptr, &dr).ok);
  return PeriodDoublingTest(dr, shooting.layout());
}

// The rod's two non-symmetric families (mirror images of each other) each have a PD point at the same H̄,
// located to 1e-9; for three rod radii.
//
// There the rod's reciprocal pair of multipliers (μ, 1/μ) collides at −1: a double eigenvalue of the
// deflated monodromy, so each computed multiplier moves by the square root of the evaluation error
// (measured 1.3e-6 … 3.2e-5 from −1, in symmetric pairs −1 ± δ or −1 ± iδ), while their mean, the trace
// of the pair's block, is well conditioned (measured within 1e-9 of −1). Asserted: the mean is −1 to
// 1e-6 and the product 1 (the pair is reciprocal).
class RodMirrorPd : public ::testing::TestWithParam<std::pair<double, double>> {};

TEST_P(RodMirrorPd, BothImagesLocatedWithAMultiplierAtMinusOne) {
  const auto [r, H] = GetParam();
  const ExplorationRun run = Explore("bouncing-rod", {{"r", r}});
  TimeBasedShooting shooting(run.model, IntegratorOptions{});
  const int iH = shooting.UnknownIndex("H");
  const std::vector<const SpecialPoint*> images = PdPointsNear(run.diagram, iH, H);
  ASSERT_EQ(images.size(), 2u) << run.diagram.FullReport();
  EXPECT_NE(images[0]->branch_id, images[1]->branch_id);
  for (const SpecialPoint* p : images) {
    EXPECT_EQ(p->status, LocationStatus::kLocated) << p->BriefReport();
    EXPECT_NEAR(p->u(iH), H, 1e-9) << p->BriefReport();
    EXPECT_LT(p->interval_width.norm(), 1e-9) << p->BriefReport();  // the precision in model units
    EXPECT_LT(p->precision(), 1e-9) << p->BriefReport();            // and along the branch
    const auto [mu1, mu2] = PairAtMinusOne(shooting, p->u);
    EXPECT_LT(std::abs(0.5 * (mu1 + mu2) + 1.0), 1e-6) << mu1 << " " << mu2;
    EXPECT_LT(std::abs(mu1 * mu2 - 1.0), 1e-6) << mu1 << " " << mu2;
  }
  // Mirror images: the same orbit traversed with the contacts exchanged, so the same period.
  EXPECT_NEAR(shooting.layout().Period(images[0]->u), shooting.layout().Period(images[1]->u), 1e-9);
}

INSTANTIATE_TEST_SUITE_P(Radii, RodMirrorPd,
                         ::testing::Values(std::pair{0.01, 0.515409213677}, std::pair{0.02, 0.530225755022},
                                           std::pair{0.05, 0.571185891986}));

// The rod's symmetric family: between its second turning point and its SB point the reciprocal pair goes
// round the unit circle, through −1 and back. A symmetric orbit is its half (the mirror-composed return
// map Q, P = Q²) traversed twice, so μ + 1/μ + 2 = (tr Q)²: the pair passes through −1 on the unit circle
// and PeriodDoublingTest has a double zero there, no sign change. It is located as a touching zero.
// Reference H̄: the minimum of tr P + 2 (from the multipliers of floquet.h) over a dense scan of the
// family in arclength steps of 1e-7 (one-parameter continuation, no test functions): 0.515403983675,
// 0.53018269001, 0.57044011592, |tr P + 2| <= 5e-12 there.
class RodSymmetricPd : public ::testing::TestWithParam<std::pair<double, double>> {};

TEST_P(RodSymmetricPd, LocatedWhereThePairTouchesMinusOne) {
  const auto [r, H] = GetParam();
  const ExplorationRun run = Explore("bouncing-rod", {{"r", r}});
  TimeBasedShooting shooting(run.model, IntegratorOptions{});
  const int iH = shooting.UnknownIndex("H");
  const std::vector<const SpecialPoint*> points = PdPointsNear(run.diagram, iH, H);
  ASSERT_EQ(points.size(), 1u) << run.diagram.FullReport();
  const SpecialPoint& pd = *points[0];
  EXPECT_EQ(pd.status, LocationStatus::kLocated) << pd.BriefReport();
  EXPECT_NEAR(pd.u(iH), H, 1e-9) << pd.BriefReport();
  EXPECT_LT(pd.precision(), 1e-9) << pd.BriefReport();
  EXPECT_NE(pd.message.find("touching zero"), std::string::npos) << pd.BriefReport();
  // On the symmetric family, between the turning and the SB point that bracket it.
  const Branch& branch = run.diagram.branches.at(pd.branch_id);
  double turning = -1, sb = -1;
  for (const SpecialPoint& p : branch.special_points) {
    if (p.index != pd.index) continue;
    if (p.type == SpecialPointType::kTurningPoint) turning = p.arclength;
    if (p.type == SpecialPointType::kSimpleBifurcation) sb = p.arclength;
  }
  EXPECT_LT(std::min(turning, sb), pd.arclength);
  EXPECT_GT(std::max(turning, sb), pd.arclength);
  const Vector& before = branch.points.at(pd.index).u;
  const Vector& after = branch.points.at(pd.index + 1).u;
  EXPECT_GT(PdTest(shooting, before) * PdTest(shooting, after), 0);  // no sign change across the step
  // The pair at −1: its mean −1 and its product 1 (a double root moves each root by the square root of
  // the evaluation error, see RodMirrorPd).
  const auto [mu1, mu2] = PairAtMinusOne(shooting, pd.u);
  EXPECT_LT(std::abs(0.5 * (mu1 + mu2) + 1.0), 1e-6) << mu1 << " " << mu2;
  EXPECT_LT(std::abs(mu1 * mu2 - 1.0), 1e-6) << mu1 << " " << mu2;
}

INSTANTIATE_TEST_SUITE_P(Radii, RodSymmetricPd,
                         ::testing::Values(std::pair{0.01, 0.515403983675}, std::pair{0.02, 0.53018269001},
                                           std::pair{0.05, 0.57044011592}));

// Hopping in place: PeriodDoublingTest changes sign across both PD points (the branch points that bracket
// each have opposite signs), each located to 1e-9 with a multiplier at −1 to 1e-6 (a simple one: the
// other nontrivial multiplier is near +1).
TEST(FloquetTestFunctions, SlipPdTestChangesSignWhereAMultiplierCrossesMinusOne) {
  const ExplorationRun run = Explore("slip");
  TimeBasedShooting shooting(run.model, IntegratorOptions{});
  const int iH = shooting.UnknownIndex("H");
  for (const double H : {1.246740110061, 1.282809323809}) {
    const SpecialPoint* pd = nullptr;
    for (const SpecialPoint* p : PdPoints(run.diagram)) {
      if (std::abs(p->u(iH) - H) < 1e-6) pd = p;
    }
    ASSERT_NE(pd, nullptr) << H << "\n" << run.diagram.FullReport();
    EXPECT_EQ(pd->status, LocationStatus::kLocated) << pd->BriefReport();
    EXPECT_NEAR(pd->u(iH), H, 1e-9) << pd->BriefReport();
    EXPECT_LT(DistanceToMinusOne(shooting, pd->u), 1e-6) << pd->BriefReport();
    const Branch& branch = run.diagram.branches.at(pd->branch_id);
    ASSERT_EQ(branch.id, pd->branch_id);
    const Vector& before = branch.points.at(pd->index).u;
    const Vector& after = branch.points.at(pd->index + 1).u;
    ASSERT_LT(before(iH), H);
    ASSERT_GT(after(iH), H);
    const double g_before = PdTest(shooting, before), g_after = PdTest(shooting, after);
    EXPECT_LT(g_before * g_after, 0) << H << ": " << g_before << " " << g_after;
  }
}

// The test functions' work is their own: counted by ModelExploration::test_function_work, never in the
// continuation's num_evaluations (a run's work is the sum).
TEST(FloquetTestFunctions, WorkIsCountedApartFromTheContinuations) {
  const ExplorationRun run = Explore("bouncing-rod");
  EXPECT_GT(run.tests.evaluations, 0);
  EXPECT_GT(run.tests.curve_evaluations, 0);  // the PD points were located on the test functions' copy
  EXPECT_LE(run.tests.curve_evaluations, run.tests.evaluations);
  EXPECT_GT(run.tests.counters.rhs_evaluations, 0);
  EXPECT_GT(run.evaluations, 0);
}

// An accepted point's values from the corrector's last evaluation (FloquetTestFunctions::
// EvaluateAtBranchPoint): the map that continuation evaluated at an iterate 1e-9 from the point serves every
// Floquet function without an integration of the test functions' own, with the values of an own evaluation
// at the point to the iterate's distance, and the point's residual extrapolated to the point (|r| at the
// iterate is ~|dr|·1e-9, at the point ~1e-15). A map that evaluated elsewhere is not taken.
TEST(FloquetTestFunctions, AcceptedPointValuedFromTheCorrectorsEvaluation) {
  const ExplorationRun run = Explore("slip");
  EXPECT_GT(run.tests.reused_points, 0);
  TimeBasedShooting continued(run.model, IntegratorOptions{});
  const int iH = continued.UnknownIndex("H");
  const Branch* hopping = nullptr;  // the family through the first PD point: physical, with multipliers
  const std::vector<const SpecialPoint*> pd = PdPoints(run.diagram);
  ASSERT_FALSE(pd.empty());
  hopping = &run.diagram.branches.at(pd.front()->branch_id);
  const Vector u = hopping->points.at(pd.front()->index).u;
  Vector direction = Vector::Ones(u.size()).normalized();
  const Vector at = u + 1e-9 * direction;
  Vector r;
  Matrix dr;
  ASSERT_TRUE(continued.Evaluate(at, &r, &dr).ok);
  const long continued_evaluations = continued.num_evaluations();

  FloquetTestFunctions reusing(run.model, IntegratorOptions{}), own(run.model, IntegratorOptions{});
  Vector from_corrector, from_own;
  reusing.EvaluateAtBranchPoint(u, &continued, at, &from_corrector);
  own.Evaluate(u, true, &from_own);
  EXPECT_EQ(reusing.reused_evaluations(), 1);
  EXPECT_EQ(reusing.shooting().num_evaluations(), 0);
  EXPECT_EQ(continued.num_evaluations(), continued_evaluations);  // its cache served
  EXPECT_EQ(own.shooting().num_evaluations(), 1);
  ASSERT_EQ(from_corrector.size(), from_own.size());
  for (Eigen::Index j = 0; j < from_own.size(); ++j) {
    if (std::isnan(from_own(j))) {
      EXPECT_TRUE(std::isnan(from_corrector(j))) << j;
    } else {
      EXPECT_NEAR(from_corrector(j), from_own(j), 1e-6 * (1 + std::abs(from_own(j)))) << j << " at H " << u(iH);
    }
  }
  ASSERT_TRUE(reusing.last_branch_point() && own.last_branch_point());
  const auto& a = *reusing.last_branch_point();
  const auto& b = *own.last_branch_point();
  EXPECT_TRUE(a.classification.physical);
  ASSERT_TRUE(a.floquet_known && b.floquet_known);
  ASSERT_EQ(a.floquet.nontrivial.size(), b.floquet.nontrivial.size());
  for (std::size_t j = 0; j < a.floquet.nontrivial.size(); ++j) {
    EXPECT_LT(std::abs(a.floquet.nontrivial[j] - b.floquet.nontrivial[j]), 1e-6) << j;
  }
  ASSERT_TRUE(a.residual_known && b.residual_known);
  EXPECT_GT(r.norm(), 1e-11);      // the iterate's own residual
  EXPECT_LT(a.residual, 1e-12);    // extrapolated to the point
  EXPECT_LT(b.residual, 1e-12);

  // The map evaluated elsewhere since: the functions integrate u themselves.
  ASSERT_TRUE(continued.Evaluate(u + 1e-3 * direction, &r, &dr).ok);
  FloquetTestFunctions fallback(run.model, IntegratorOptions{});
  Vector values;
  fallback.EvaluateAtBranchPoint(u, &continued, at, &values);
  EXPECT_EQ(fallback.reused_evaluations(), 0);
  EXPECT_EQ(fallback.shooting().num_evaluations(), 1);
  EXPECT_NEAR(values(1), from_own(1), 1e-12 * (1 + std::abs(from_own(1))));
}

}  // namespace
}  // namespace hybridcont
