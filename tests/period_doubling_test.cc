// The repeated model and the period-doubled family of the SLIP's hopping in place (period_doubling.h).
#include <gtest/gtest.h>

#include <cmath>
#include <complex>

#include "hybridcont/floquet.h"
#include "hybridcont/models.h"
#include "hybridcont/period_doubling.h"
#include "continuation_test_problems.h"
#include "known_orbits.h"

namespace hybridcont {
namespace {

TEST(RepeatedModel, PhasesLayoutSymmetriesAndSetUp) {
  const HybridModel slip = MakeSlip();
  const HybridModel doubled = RepeatedModel(slip, 2);
  EXPECT_EQ(doubled.name(), "slip-x2");
  ASSERT_EQ(doubled.num_phases(), 5);  // stance, flight, stance up to the section, stance, flight
  for (int i = 0; i < 5; ++i) EXPECT_EQ(doubled.phase(i).name(), i % 3 == 1 ? "flight" : "stance") << i;
  EXPECT_EQ(doubled.phase(2).next_dim(), 4);
  EXPECT_EQ(doubled.symmetries().size(), 2u);
  EXPECT_EQ(doubled.parameter("k"), slip.parameter("k"));
  HybridModel copy = RepeatedModel(slip, 2);
  EXPECT_THROW(copy.SetParameter("k", 50.0), std::invalid_argument);
  EXPECT_THROW(RepeatedModel(slip, 0), std::invalid_argument);
  // Bounds on every copy; the period bound times 2.
  int period_bounds = 0;
  for (const BoundSpec& b : doubled.setup().run.bounds) {
    if (b.component != "period") continue;
    ++period_bounds;
    EXPECT_EQ(b.upper.expression, "2*(20)");
  }
  EXPECT_EQ(period_bounds, 1);
  EXPECT_EQ(RepeatedModel(slip, 3).num_phases(), 8);
}

TEST(RepeatedModel, RepeatedOrbitIsAnOrbitWithTwiceThePeriodAndSquaredMultipliers) {
  const HybridModel slip = MakeSlip();
  const HybridModel doubled = RepeatedModel(slip, 2);
  TimeBasedShooting parent_map(slip, IntegratorOptions{}), doubled_map(doubled, IntegratorOptions{});
  const Vector u = SlipHoppingInPlace(slip, parent_map.layout(), 1.4);
  const Vector u2 = RepeatedOrbit(parent_map.layout(), u, 2);
  ASSERT_EQ(u2.size(), doubled_map.num_unknowns());
  EXPECT_TRUE(IsRepeatedOrbit(parent_map.layout(), u2, 2, 0.0));
  EXPECT_NEAR(doubled_map.layout().Period(u2), 2.0 * parent_map.layout().Period(u), 1e-14);
  Vector r;
  ASSERT_TRUE(doubled_map.Evaluate(u2, &r, nullptr).ok);
  EXPECT_LT(r.lpNorm<Eigen::Infinity>(), 1e-9);
  const FloquetResult parent = ComputeFloquet(parent_map, u), twice = ComputeFloquet(doubled_map, u2);
  ASSERT_TRUE(parent.ok() && twice.ok());
  EXPECT_LT((twice.monodromy - parent.monodromy * parent.monodromy).lpNorm<Eigen::Infinity>(), 1e-8);
  ASSERT_EQ(twice.nontrivial.size(), 2u);
  for (const std::complex<double>& mu : parent.nontrivial) {
    double nearest = 1e300;
    for (const std::complex<double>& nu : twice.nontrivial) nearest = std::min(nearest, std::abs(nu - mu * mu));
    EXPECT_LT(nearest, 1e-8) << mu;
  }
}

// The PD point of hopping in place at H = 1.2828093238 (floquet_test.cc) starts the period-doubled family:
// alternating hopping in place, the leg leaning to one side in one hop and to the other in the next (x1_alpha =
// −x4_alpha, forward speeds ±dx in the two flights, no net motion). Its second half-branch is its mirror image
// (mapped) and the same orbits shifted by one hop. Measured: the family turns at H = 1.2826996429 (a fold, where a
// multiplier crosses +1): linearly stable from the PD point to the fold, unstable from there on up to H = 2
// (largest multiplier 5.8373 there).
TEST(PeriodDoubling, SlipHoppingInPlaceFamilyStartsAtTwiceTheParentsPeriodAndLosesStabilityAtItsFold) {
  const HybridModel slip = MakeSlip();
  const HybridModel doubled = RepeatedModel(slip, 2);
  TimeBasedShooting parent_map(slip, IntegratorOptions{}), doubled_map(doubled, IntegratorOptions{});
  const ShootingLayout& layout = parent_map.layout();
  auto parent_floquet = [&](double H) { return ComputeFloquet(parent_map, SlipHoppingInPlace(slip, layout, H)); };
  const double H_pd = Bisect([&](double H) { return parent_floquet(H).pd_test; }, 1.25, 1.3);
  EXPECT_NEAR(H_pd, 1.2828093238, 1e-8);
  const Vector u_pd = SlipHoppingInPlace(slip, layout, H_pd);

  ExplorationOptions options;
  options.threads = 1;
  options.continuation.bounds = {{"xi", -1, 1}, {"H", 0, 2}};
  options.continuation.max_step = 0.1;
  const BifurcationDiagram d = ExplorePeriodDoubled(&doubled_map, layout, u_pd, options);
  ASSERT_EQ(d.status, ExplorationStatus::kCompleted) << d.FullReport();
  ASSERT_EQ(d.branches.size(), 2u) << d.FullReport();
  EXPECT_EQ(d.branches[1].image_of, 0);
  const Branch& family = d.branches[0];
  ASSERT_GE(family.points.size(), 10u);

  // Its start: twice the parent's period; the parent's −1 multiplier is +1, the other one squared.
  const Vector& start = family.points.front().u;
  EXPECT_NEAR(doubled_map.layout().Period(start), 2.0 * layout.Period(u_pd), 1e-10);
  const FloquetResult parent = ComputeFloquet(parent_map, u_pd), at_start = ComputeFloquet(doubled_map, start);
  ASSERT_TRUE(parent.ok() && at_start.ok());
  ASSERT_EQ(parent.nontrivial.size(), 2u);
  ASSERT_EQ(at_start.nontrivial.size(), 2u);
  EXPECT_NEAR(parent.nontrivial[0].real(), -1.0, 1e-8);  // sorted by modulus: −1, then 0.9015
  EXPECT_NEAR(parent.nontrivial[1].real(), 0.9015163, 1e-6);
  EXPECT_NEAR(at_start.nontrivial[0].real(), 1.0, 1e-8);
  EXPECT_NEAR(std::abs(at_start.nontrivial[1] - parent.nontrivial[1] * parent.nontrivial[1]), 0.0, 1e-8);
  EXPECT_NEAR(at_start.nontrivial[1].real(), 0.812732, 1e-6);
  EXPECT_EQ(at_start.num_unit, 3);

  // Beyond the start every orbit is period-doubled proper (not the parent traversed twice), and the
  // leg leans to opposite sides in the two hops.
  const int x1_alpha = doubled_map.layout().state_offset(0), x4_alpha = doubled_map.layout().state_offset(3);
  for (size_t i = 1; i < family.points.size(); ++i) {
    const Vector& u = family.points[i].u;
    EXPECT_FALSE(IsRepeatedOrbit(layout, u, 2, 1e-6)) << i;
    EXPECT_NEAR(u(x1_alpha), -u(x4_alpha), 1e-8) << i;
  }

  // Stability along the family: stable up to its fold, unstable after it (the multiplier near +1 crosses it).
  ASSERT_EQ(family.special_points.size(), 1u);
  const SpecialPoint& fold = family.special_points[0];
  EXPECT_EQ(fold.type, SpecialPointType::kTurningPoint);
  EXPECT_EQ(fold.status, LocationStatus::kLocated);
  EXPECT_NEAR(fold.u(fold.u.size() - 1), 1.2826996429, 1e-9);
  int changes = 0;
  bool previous = true;
  for (size_t i = 1; i < family.points.size(); ++i) {
    const FloquetResult f = ComputeFloquet(doubled_map, family.points[i].u);
    ASSERT_TRUE(f.ok()) << i;
    EXPECT_EQ(f.stable, static_cast<int>(i) <= fold.index) << i;
    if (f.stable != previous) ++changes;
    previous = f.stable;
  }
  EXPECT_EQ(changes, 1);
  const FloquetResult top = ComputeFloquet(doubled_map, family.points.back().u);
  EXPECT_NEAR(family.points.back().u(start.size() - 1), 2.0, 1e-12);
  EXPECT_NEAR(top.max_modulus, 5.83731, 1e-4);
}

// Away from a PD point the doubled orbit is a regular point: no period-doubled family starts there.
TEST(PeriodDoubling, RegularParentPointIsRefused) {
  const HybridModel slip = MakeSlip();
  const HybridModel doubled = RepeatedModel(slip, 2);
  TimeBasedShooting parent_map(slip, IntegratorOptions{}), doubled_map(doubled, IntegratorOptions{});
  ExplorationOptions options;
  options.threads = 1;
  const BifurcationDiagram d = ExplorePeriodDoubled(
      &doubled_map, parent_map.layout(), SlipHoppingInPlace(slip, parent_map.layout(), 1.4), options);
  EXPECT_EQ(d.status, ExplorationStatus::kStartFailed);
  EXPECT_TRUE(d.branches.empty());
  EXPECT_NE(d.message.find("not a simple bifurcation point"), std::string::npos) << d.message;
}

// ExplorationOptions::known_ray: the pitchfork explored from its parabola, with the trivial branch x = 0
// known elsewhere: the switch at (0, 0) traces nothing and counts both of its half-branches as known.
TEST(PeriodDoubling, KnownRaysAreNotTraced) {
  testing::Pitchfork pitchfork;
  ExplorationOptions options;
  options.threads = 1;
  options.continuation.bounds = {{"lambda", -1, 1}};
  const BifurcationDiagram all = Explore(&pitchfork, Eigen::Vector2d(0.5, 0.25), options);
  EXPECT_EQ(all.branches.size(), 4u);
  options.known_ray = [](const Vector& u, const Vector& v) {
    return u(0) == 0.0 || (std::abs(u(0)) < 1e-9 && std::abs(v(0)) < 1e-6 * v.norm());
  };
  const BifurcationDiagram known = Explore(&pitchfork, Eigen::Vector2d(0.5, 0.25), options);
  ASSERT_EQ(known.status, ExplorationStatus::kCompleted) << known.FullReport();
  EXPECT_EQ(known.branches.size(), 2u) << known.FullReport();
  ASSERT_EQ(known.switches.size(), 1u);
  EXPECT_EQ(known.switches[0].traced, 0);
  EXPECT_EQ(known.switches[0].skipped, 2);
}

}  // namespace
}  // namespace hybridcont
