// Multipliers accurate relative to their own size (floquet.h, "Multipliers accurate relative to their own
// size") and the stability class of each orbit.
//
// The bouncing rod's return map is symplectic (elastic impacts, a Hamiltonian flow), so its nontrivial
// multipliers come in pairs μ, 1/μ: the product of the pair is 1 exactly, whatever the orbit. Along every
// family of the rod's diagram, with multipliers up to 1e8 in modulus, the product computed from the
// monodromy alone drifts from 1 (the small one loses its digits), and from the inverse product it stays 1.
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>

#include <gtest/gtest.h>

#include "hybridcont/exploration.h"
#include "hybridcont/floquet.h"
#include "hybridcont/models.h"
#include "study/engine/model_exploration.h"

namespace hybridcont {
namespace {

// The default exploration of a built-in model, on one thread.
struct DefaultRun {
  explicit DefaultRun(const std::string& name) : model(MakeBuiltinModel(name)) {
    const study::Scenario scenario = study::DefaultScenario(model);
    ExplorationOptions options = study::ScenarioExplorationOptions(scenario);
    options.threads = 1;
    exploration = std::make_unique<study::ModelExploration>(model, scenario, IntegratorOptions{}, options);
    diagram = exploration->Run();
  }
  HybridModel model;
  std::unique_ptr<study::ModelExploration> exploration;
  BifurcationDiagram diagram;
};

TEST(FloquetAccuracy, RodPairProductIsOneAlongEveryFamily) {
  DefaultRun run("bouncing-rod");
  const HybridModel& model = run.model;
  const BifurcationDiagram& diagram = run.diagram;
  TimeBasedShooting& shooting = run.exploration->shooting();
  FloquetOptions monodromy_only;
  monodromy_only.product_inverse = false;
  double worst_before = 0, worst_after = 0, largest = 0;
  int points = 0;
  for (const Branch& branch : diagram.branches) {
    for (const auto& point : branch.points) {
      if (std::abs(point.u(shooting.UnknownIndex("xi"))) > 1e-8) continue;  // multipliers need ξ = 0
      const FloquetResult before = ComputeFloquet(shooting, point.u, monodromy_only);
      const FloquetResult after = ComputeFloquet(shooting, point.u);
      if (!before.ok() || !after.ok()) continue;
      ASSERT_EQ(after.nontrivial.size(), 2u);
      const double modulus = std::abs(after.nontrivial[0]);
      if (modulus > 1e8) continue;
      // Off the unit circle the small one comes from the inverse product (on it both are of modulus 1
      // and the monodromy gives them to its own accuracy).
      if (modulus > 1.0 + 1e-6) EXPECT_TRUE(after.from_inverse_product) << modulus;
      // The large multiplier is the same number either way.
      EXPECT_LT(std::abs(after.nontrivial[0] - before.nontrivial[0]), 1e-12 * modulus);
      const double pb = std::abs(before.nontrivial[0] * before.nontrivial[1] - 1.0);
      const double pa = std::abs(after.nontrivial[0] * after.nontrivial[1] - 1.0);
      EXPECT_LT(pa, 1e-8) << "|mu| = " << modulus << " at H = " << point.u(shooting.UnknownIndex("H"));
      worst_before = std::max(worst_before, pb);
      worst_after = std::max(worst_after, pa);
      largest = std::max(largest, modulus);
      ++points;
    }
  }
  EXPECT_GT(points, 100);
  EXPECT_GT(largest, 1e4);
  // The orbit with the largest multiplier, again with the integrator 1000 times more precise (rtol 1e-13):
  // the small multiplier from the inverse product agrees with that computation relative to its own size;
  // from the monodromy alone it did not. (The rod's flights are parabolas, which the integrator follows
  // exactly at any tolerance, so what the monodromy alone loses is the rounding of one eigenvalue
  // problem holding both multipliers: eps·|μ| against 1/|μ|.)
  const Vector* hardest = nullptr;
  double hardest_modulus = 0;
  for (const Branch& branch : diagram.branches) {
    for (const auto& point : branch.points) {
      if (std::abs(point.u(shooting.UnknownIndex("xi"))) > 1e-8) continue;
      const FloquetResult f = ComputeFloquet(shooting, point.u);
      if (f.ok() && f.nontrivial.size() == 2 && std::abs(f.nontrivial[0]) > hardest_modulus &&
          std::abs(f.nontrivial[0]) <= 1e8) {
        hardest_modulus = std::abs(f.nontrivial[0]);
        hardest = &point.u;
      }
    }
  }
  ASSERT_NE(hardest, nullptr);
  IntegratorOptions precise;
  precise.rtol = precise.atol = 1e-13;
  TimeBasedShooting precise_map(model, precise);
  const FloquetResult reference = ComputeFloquet(precise_map, *hardest);
  const FloquetResult after = ComputeFloquet(shooting, *hardest);
  const FloquetResult before = ComputeFloquet(shooting, *hardest, monodromy_only);
  ASSERT_TRUE(reference.ok() && after.ok() && before.ok());
  const auto relative = [&](const FloquetResult& f) {
    return std::abs(f.nontrivial[1] - reference.nontrivial[1]) / std::abs(reference.nontrivial[1]);
  };
  EXPECT_LT(relative(after), 1e-6);
  std::printf("rod at |mu| = %.3g: the small multiplier %.10e against rtol 1e-13 (%.10e): relative %.1e from the "
              "inverse product, %.1e from the monodromy alone\n", hardest_modulus, std::abs(after.nontrivial[1]),
              std::abs(reference.nontrivial[1]), relative(after), relative(before));
  std::printf("rod: %d orbits, |mu| up to %.3g; |mu1 mu2 - 1| at most %.2e from the monodromy alone, %.2e from "
              "the inverse product\n", points, largest, worst_before, worst_after);
}

// The SLIP's return map is not symplectic: along hopping in place two real multipliers pass through a
// product of 1 near H̄ = 1.71 (1.94 · 0.499 → 2.40 · 0.444), so the bialternate product changes sign there,
// but no complex pair is on the unit circle: a neutral saddle, which must not be reported as an NS point.
TEST(FloquetAccuracy, SlipNeutralSaddleIsNoNeimarkSackerPoint) {
  DefaultRun run("slip");
  const BifurcationDiagram& diagram = run.diagram;
  for (const SpecialPoint& sp : diagram.special_points) {
    EXPECT_NE(sp.type, SpecialPointType::kNeimarkSacker) << sp.BriefReport();
  }
  TimeBasedShooting& shooting = run.exploration->shooting();
  int sign_changes = 0;
  for (const Branch& branch : diagram.branches) {
    double previous = std::nan("");
    for (const auto& point : branch.points) {
      const FloquetResult f = ComputeFloquet(shooting, point.u);
      if (!f.ok() || f.nontrivial.size() != 2) continue;
      const bool real_pair = f.nontrivial[0].imag() == 0 && f.nontrivial[1].imag() == 0;
      if (real_pair && std::isfinite(previous) && std::signbit(previous) != std::signbit(f.ns_test)) ++sign_changes;
      previous = real_pair ? f.ns_test : std::nan("");
    }
  }
  EXPECT_GE(sign_changes, 1);  // the neutral saddle is there, and dropped
}

TEST(FloquetAccuracy, StabilityClassNamesTheKindOfInstability) {
  FloquetOptions options;
  const Vector f0 = Vector::Unit(4, 0);
  const auto classify = [&](const Matrix& M) {
    // A monodromy with the flow direction e0 fixed (one trivial multiplier, no first integral) and M on
    // the other three coordinates.
    Matrix P = Matrix::Identity(4, 4);
    P.bottomRightCorner(3, 3) = M;
    return AnalyzeMonodromy(P, f0, RowVector(), options).stability.ToString();
  };
  EXPECT_EQ(classify(Eigen::Vector3d(0.5, -0.2, 0.1).asDiagonal()), "asymptotically stable");
  EXPECT_EQ(classify(Eigen::Vector3d(1.0 + 1e-3, 0.2, 0.1).asDiagonal()), "unstable (saddle)");
  EXPECT_EQ(classify(Eigen::Vector3d(-1.5, -2.0, 0.1).asDiagonal()), "unstable (2 flip)");
  Matrix rotation = Matrix::Zero(3, 3);  // a complex pair of modulus 1.2 and a saddle multiplier 3
  rotation << 0, -1.2, 0, 1.2, 0, 0, 0, 0, 3;
  EXPECT_EQ(classify(rotation), "unstable (saddle and oscillatory)");
  rotation(0, 1) = -1, rotation(1, 0) = 1, rotation(2, 2) = 0.3;  // a pair on the unit circle
  EXPECT_EQ(classify(rotation), "neutrally stable");
}

// The multipliers' error is twice the monodromy's measured defect on its known eigenvector (floquet.h,
// "Accuracy of the multipliers"): a monodromy that maps the flow direction e0 to (1 + d) e0 is off by d, its
// multipliers said to be within 2d. What they cannot tell at that error is withheld; what they can is said.
TEST(FloquetAccuracy, WhatTheMultipliersCannotTellIsWithheld) {
  const Vector f0 = Vector::Unit(3, 0);
  const auto analyze = [&](double defect, double mu1, double mu2) {
    Matrix P = Matrix::Zero(3, 3);
    P.diagonal() << 1.0 + defect, mu1, mu2;
    return AnalyzeMonodromy(P, f0, RowVector());
  };
  const FloquetResult exact = analyze(0.0, 0.99, 0.5);  // as before: a verdict at circle_tolerance
  EXPECT_EQ(exact.multiplier_error, 0.0);
  EXPECT_EQ(exact.stability.ToString(), "asymptotically stable");

  const FloquetResult near = analyze(0.025, 0.99, 0.5);  // 0.99 lies within 0.05 of the circle
  EXPECT_NEAR(near.multiplier_error, 0.05, 1e-15);
  EXPECT_TRUE(near.stability.undetermined);
  EXPECT_EQ(near.stability.ToString(), "undetermined (multipliers uncertain to 5e-02)");
  EXPECT_FALSE(near.stable);
  EXPECT_FALSE(near.asymptotically_stable);
  EXPECT_TRUE(std::isfinite(near.bp_test));  // the values stay; a branch point's are withheld by the tests

  const FloquetResult clear = analyze(0.025, 0.68, 0.5);  // inside by far more than the error
  EXPECT_EQ(clear.stability.ToString(), "asymptotically stable");

  const FloquetResult outside = analyze(0.025, 0.99, 1.5);  // one clearly outside: unstable whatever 0.99 is
  EXPECT_EQ(outside.stability.ToString(), "unstable (saddle)");

  EXPECT_TRUE(analyze(0.025, -0.97, 0.5).stability.undetermined);

  // Below circle_tolerance the error changes nothing: the verdict at the tolerance stands.
  const FloquetResult small = analyze(4e-7, 1.0 + 5e-7, 0.5);
  EXPECT_FALSE(small.stability.undetermined);
  EXPECT_EQ(small.stability.ToString(), "neutrally stable");
}

}  // namespace
}  // namespace hybridcont
