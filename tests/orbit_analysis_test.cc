// The typed analysis of one point (orbit_analysis.h): a physical orbit carries its replay, its multipliers
// (the same as floquet.h computes) and its stability; a non-physical one carries none of them.
#include <gtest/gtest.h>

#include <cmath>

#include "hybridcont/floquet.h"
#include "hybridcont/models.h"
#include "hybridcont/orbit_analysis.h"
#include "known_orbits.h"

namespace hybridcont {
namespace {

TEST(OrbitAnalysis, HoppingInPlaceIsPhysicalStableAndCarriesItsMultipliers) {
  const HybridModel slip = MakeSlip();
  TimeBasedShooting map(slip, IntegratorOptions{});
  const Vector u = SlipHoppingInPlace(slip, map.layout(), 1.5);  // stable from its PD at 1.2828 to 1.6144
  const OrbitAnalysis a = AnalyzeOrbit(slip, map, u, OrbitAnalysisOptions::For(IntegratorOptions{}));
  ASSERT_TRUE(a.classification.physical) << a.classification.detail;
  EXPECT_LT(a.residual, 1e-9);
  EXPECT_LT(a.replay_error, 1e-6);
  ASSERT_TRUE(a.floquet);
  EXPECT_TRUE(a.stable) << a.stability;
  EXPECT_FALSE(a.stability.empty());
  const FloquetResult f = ComputeFloquet(map, u);
  ASSERT_EQ(a.multipliers.size(), f.nontrivial.size());
  for (std::size_t j = 0; j < f.nontrivial.size(); ++j) EXPECT_EQ(a.multipliers[j], f.nontrivial[j]);
  EXPECT_EQ(a.max_multiplier, f.max_modulus);
  EXPECT_TRUE(std::isnan(a.automaton_replay_error));  // a cyclic model, no automaton
}

TEST(OrbitAnalysis, AReversedTimeOrbitHasNoReplayNoMultipliers) {
  const HybridModel ball = MakeBouncingBall();
  TimeBasedShooting map(ball, IntegratorOptions{});
  const ShootingLayout& layout = map.layout();
  Vector u = BallOrbit(layout, 0.5);
  u(layout.time_index(0)) *= -1;
  u(layout.time_index(1)) *= -1;
  u(layout.state_offset(1) + 1) *= -1;
  const OrbitAnalysis a = AnalyzeOrbit(ball, map, u, OrbitAnalysisOptions::For(IntegratorOptions{}));
  EXPECT_FALSE(a.classification.physical);
  EXPECT_EQ(a.classification.reason, OrbitClass::kReversedTime);
  EXPECT_FALSE(a.floquet);
  EXPECT_TRUE(a.multipliers.empty());
  EXPECT_TRUE(std::isnan(a.replay_error));
  EXPECT_TRUE(a.stability.empty());
  EXPECT_LT(a.residual, 1e-9);  // it solves r = 0: an orbit of the equations, not of the mechanism
}

}  // namespace
}  // namespace hybridcont
