// The bouncing rod's bifurcation diagram (paper §4.3) through the run command's exploration: the symmetric
// family (t2 = t1 + t3) with two turning points and a simple bifurcation point below H = 0.6, and the two
// non-symmetric families switched from it. Located values are checked at two integrator tolerances.
#include <cmath>
#include <cstdio>
#include <vector>

#include <gtest/gtest.h>

#include "hybridcont/exploration.h"
#include "hybridcont/models.h"
#include "study_fixture.h"

namespace hybridcont {
namespace {

struct RodRun {
  BifurcationDiagram diagram;
  int t1 = -1, t2 = -1, t3 = -1, H = -1;
};

RodRun ExploreRod(double rtol) {
  const HybridModel model = MakeBuiltinModel("bouncing-rod");
  RodRun run;
  run.diagram = *StudyOf(model, WithTolerance(rtol)).diagram;
  const ShootingLayout shooting(model);
  run.t1 = shooting.UnknownIndex("t1");
  run.t2 = shooting.UnknownIndex("t2");
  run.t3 = shooting.UnknownIndex("t3");
  run.H = shooting.UnknownIndex("H");
  return run;
}

double Period(const RodRun& run, const Vector& u) { return u(run.t1) + u(run.t2) + u(run.t3); }
double Asymmetry(const RodRun& run, const Vector& u) { return std::abs(u(run.t2) - u(run.t1) - u(run.t3)); }

// The forward-time symmetric family: leaves the singular start, its points have T > 0.
const Branch* SymmetricFamily(const RodRun& run) {
  for (const Branch& branch : run.diagram.branches) {
    if (branch.depth == 1 && branch.points.size() > 10 && Period(run, branch.points.back().u) > 0) return &branch;
  }
  return nullptr;
}

struct RodNumbers {
  std::vector<double> turning_H, turning_T;
  double sb_H = 0, sb_T = 0, sb_precision = 0;
};

RodNumbers CheckRod(double rtol) {
  const RodRun run = ExploreRod(rtol);
  const BifurcationDiagram& d = run.diagram;
  RodNumbers numbers;
  const Branch* family = SymmetricFamily(run);
  EXPECT_NE(family, nullptr) << d.FullReport();
  if (family == nullptr) return numbers;
  EXPECT_EQ(family->termination, TerminationReason::kBoundReached) << family->FullReport();
  for (const ContinuationPoint& p : family->points) EXPECT_LT(Asymmetry(run, p.u), 1e-9);
  const SpecialPoint* sb = nullptr;
  for (const SpecialPoint& point : family->special_points) {
    EXPECT_EQ(point.status, LocationStatus::kLocated) << point.BriefReport();
    if (point.type == SpecialPointType::kTurningPoint) {
      numbers.turning_H.push_back(point.u(run.H));
      numbers.turning_T.push_back(Period(run, point.u));
    } else if (point.type == SpecialPointType::kSimpleBifurcation) {
      sb = &point;
    }
  }
  EXPECT_GE(numbers.turning_H.size(), 2u) << family->FullReport();
  EXPECT_NE(sb, nullptr) << family->FullReport();
  if (sb == nullptr) return numbers;
  numbers.sb_H = sb->u(run.H);
  numbers.sb_T = Period(run, sb->u);
  numbers.sb_precision = sb->precision();
  EXPECT_LT(numbers.sb_H, 0.6);
  std::printf("rtol %g: TP H = %.12f (T = %.12f), %.12f (T = %.12f); SB H = %.12f (T = %.10f), precision %.2g [%s]\n",
              rtol, numbers.turning_H[0], numbers.turning_T[0], numbers.turning_H[1], numbers.turning_T[1],
              numbers.sb_H, numbers.sb_T, numbers.sb_precision, sb->message.c_str());

  // The two non-symmetric families leave the SB (its diagram id) and break the symmetry more and more.
  int switched = 0;
  for (const Branch& branch : d.branches) {
    if (branch.parent_special_point != sb->id) continue;
    ++switched;
    EXPECT_GT(branch.points.size(), 10u) << branch.FullReport();
    EXPECT_NE(branch.termination, TerminationReason::kKnownBranch) << branch.FullReport();
    EXPECT_TRUE(branch.termination == TerminationReason::kBoundReached ||
                branch.termination == TerminationReason::kMaxPoints)
        << branch.FullReport();
    for (size_t i = 2; i < std::min<size_t>(branch.points.size(), 12); ++i) {
      EXPECT_GT(Asymmetry(run, branch.points[i].u), Asymmetry(run, branch.points[i - 1].u)) << i;
    }
    EXPECT_GT(Asymmetry(run, branch.points.back().u), 1e-3);
  }
  EXPECT_EQ(switched, 2) << d.FullReport();
  return numbers;
}

TEST(RodExplorationTest, SymmetricFamilyTurningPointsSimpleBifurcationAndSwitchedFamilies) {
  const RodNumbers coarse = CheckRod(1e-10);
  const RodNumbers fine = CheckRod(1e-11);
  ASSERT_GE(coarse.turning_H.size(), 2u);
  ASSERT_GE(fine.turning_H.size(), 2u);
  // Digits that agree at rtol 1e-10 and 1e-11.
  EXPECT_NEAR(coarse.turning_H[0], 0.575079834994, 1e-11);
  EXPECT_NEAR(coarse.turning_T[0], 0.101818381318, 1e-11);
  EXPECT_NEAR(coarse.turning_H[1], 0.515402566519, 1e-11);
  EXPECT_NEAR(coarse.turning_T[1], 0.491388991201, 1e-11);
  for (int i = 0; i < 2; ++i) {
    EXPECT_NEAR(fine.turning_H[i], coarse.turning_H[i], 1e-11);
    EXPECT_NEAR(fine.turning_T[i], coarse.turning_T[i], 1e-11);
  }
  // The SB is located to the noise level: H to ~1e-11, T to its arclength precision (~1e-8).
  EXPECT_NEAR(coarse.sb_H, 0.51540793993, 3e-11);
  EXPECT_NEAR(fine.sb_H, coarse.sb_H, 3e-11);
  EXPECT_NEAR(coarse.sb_T, 0.4981236, 1e-7);
  EXPECT_NEAR(fine.sb_T, coarse.sb_T, 2 * std::max(coarse.sb_precision, fine.sb_precision));
  EXPECT_LT(coarse.sb_precision, 1e-6);
  EXPECT_LT(fine.sb_precision, 1e-6);
}

}  // namespace
}  // namespace hybridcont
