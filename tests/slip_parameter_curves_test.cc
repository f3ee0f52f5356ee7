// Two-parameter curves of the SLIP's special points (special_point_curve.h) on the time-based map with a
// free model parameter (shooting_layout.h, "Free parameters"), against closed forms.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <tuple>

#include "hybridcont/continuation.h"
#include "hybridcont/corrector.h"
#include "hybridcont/floquet.h"
#include "hybridcont/models.h"
#include "hybridcont/special_point_curve.h"
#include "hybridcont/timebased_shooting.h"
#include "known_orbits.h"

namespace hybridcont {
namespace {

// The map with p free and held at its model value by the fixing row (the one-parameter family in H̄),
// and a point of hopping in place at H̄ on it.
struct SlipFamilyInH {
  HybridModel slip = MakeBuiltinModel("slip");
  TimeBasedShooting map;
  SlipFamilyInH(const std::string& p)
      : map(slip, IntegratorOptions{}, FreeParameters{{p}, {{p, slip.parameter(p)}}}) {}
  Vector HoppingInPlace(double H) const {
    const ShootingLayout base(slip);
    Vector u = Vector::Zero(map.num_unknowns());
    u.head(base.num_unknowns()) = SlipHoppingInPlace(slip, base, H);
    u(map.layout().parameter_index(0)) = map.layout().fixed_value(0);
    return u;
  }
};

// The first SB point of hopping in place lies where the flight time equals half a swing period of the
// leg, H̄ = 1 + π²/(8 w2) (m = g = l0 = 1), whatever k: its curve in (w2, H̄) over w2 ∈ [2, 10].
TEST(SlipParameterCurves, FirstSimpleBifurcationCurveInSwingFrequencyMatchesTheClosedForm) {
  SlipFamilyInH family("w2");
  ContinuationOptions options;
  options.bounds = {{"H", 1.1, 1.4}};
  options.max_step = 0.05;
  options.turning_point_components = {"H"};
  const Branch branch = TraceBranch(&family.map, family.HoppingInPlace(1.1), options);
  const SpecialPoint* sb = nullptr;
  for (const SpecialPoint& sp : branch.special_points) {
    if (sp.type == SpecialPointType::kSimpleBifurcation && !sb) sb = &sp;
  }
  ASSERT_NE(sb, nullptr) << branch.FullReport(family.map.unknown_names());
  const int H = family.map.layout().H_index();
  EXPECT_NEAR(sb->u(H), 1 + M_PI * M_PI / 40, 1e-9);

  SpecialPointCurveOptions curve_options;
  curve_options.continuation.bounds = {{"w2", 2.0, 10.0}};
  curve_options.continuation.max_step = 0.5;
  const SpecialPointCurve curve =
      TraceSpecialPointCurve(&family.map, *sb, family.map.layout().fixed_row(0), "H", curve_options);
  ASSERT_NE(curve.status, CurveStatus::kStartFailed) << curve.message;
  const Vector w2 = curve.Column("w2"), h = curve.Column("H");
  EXPECT_NEAR(w2.minCoeff(), 2.0, 1e-9);
  EXPECT_NEAR(w2.maxCoeff(), 10.0, 1e-9);
  double worst = 0;
  for (int i = 0; i < w2.size(); ++i) worst = std::max(worst, std::abs(h(i) - (1 + M_PI * M_PI / (8 * w2(i)))));
  EXPECT_LE(worst, 1e-8) << curve.FullReport();
  RecordProperty("points", static_cast<int>(w2.size()));
  char text[32];
  std::snprintf(text, sizeof text, "%.3g", worst);
  RecordProperty("worst_error", text);
  if (curve.unknown_names.back() == "beta") EXPECT_LT(curve.Column("beta").cwiseAbs().maxCoeff(), 1e-8);
}


// The period-doubling point of hopping in place at stiffness k, from the one-parameter problem alone: the
// closed-form orbit at H̄ (known_orbits.h) and its Floquet multipliers, pd_test bisected in H̄.
double PeriodDoublingLevel(double k, double lo, double hi) {
  HybridModel slip = MakeBuiltinModel("slip");
  slip.SetParameter("k", k);
  TimeBasedShooting map(slip, IntegratorOptions{});
  const auto pd = [&](double H) { return ComputeFloquet(map, SlipHoppingInPlace(slip, map.layout(), H)).pd_test; };
  double f_lo = pd(lo);
  EXPECT_LT(f_lo * pd(hi), 0) << "no -1 crossing of hopping in place in [" << lo << ", " << hi << "] at k = " << k;
  for (int i = 0; i < 60 && hi - lo > 1e-13; ++i) {
    const double mid = 0.5 * (lo + hi), f = pd(mid);
    (f * f_lo > 0 ? lo : hi) = mid;
    if (f * f_lo > 0) f_lo = f;
  }
  return 0.5 * (lo + hi);
}

// The upper end of hopping in place's stability band, a multiplier through -1 near H̄ = 1.2828 at k = 40,
// continued in (k, H̄) over k ∈ [15, 100] as the zero curve of pd_test (floquet.h) and compared with the
// one-parameter problem at k = 20, 40, 80.
TEST(SlipParameterCurves, PeriodDoublingCurveInStiffnessMatchesOneParameterRuns) {
  SlipFamilyInH family("k");
  const double H40 = PeriodDoublingLevel(40.0, 1.27, 1.30);
  EXPECT_NEAR(H40, 1.282809323809, 1e-9);
  TimeBasedShooting floquet_map(family.slip, IntegratorOptions{}, FreeParameters{{"k"}, {{"k", 40.0}}});
  CurveDefinition definition;
  definition.kind = CurveKind::kTestFunction;
  definition.fix_row = family.map.layout().fixed_row(0);
  definition.family_parameter = "H";
  definition.test = {"pd", [&](const Vector& u) {
                       const FloquetResult fl = ComputeFloquet(floquet_map, u);
                       return fl.ok() ? fl.pd_test : std::nan("");
                     }, nullptr};
  SpecialPointCurveOptions options;
  options.continuation.bounds = {{"k", 15.0, 100.0}};
  options.continuation.max_step = 2.0;
  const SpecialPointCurve curve = TraceSpecialPointCurve(&family.map, definition, family.HoppingInPlace(H40), options);
  ASSERT_NE(curve.status, CurveStatus::kStartFailed) << curve.message;
  const Vector k = curve.Column("k");
  EXPECT_NEAR(k.minCoeff(), 15.0, 1e-9);
  EXPECT_NEAR(k.maxCoeff(), 100.0, 1e-9);
  SpecialPointCurveProblem problem(&family.map, definition, curve.points[curve.start_index], options);
  Corrector corrector(&problem);
  const int k_index = family.map.layout().parameter_index(0);
  const int H_index = family.map.layout().H_index();
  for (const auto& [k_star, lo, hi] : {std::tuple{20.0, 1.2, 1.4}, {40.0, 1.27, 1.30}, {80.0, 1.2, 1.4}}) {
    int nearest = 0;
    for (int i = 0; i < k.size(); ++i) {
      if (std::abs(k(i) - k_star) < std::abs(k(nearest) - k_star)) nearest = i;
    }
    Vector on_curve;
    const CorrectorResult result = corrector.CorrectFixedComponent(curve.points[nearest], k_index, k_star, &on_curve);
    ASSERT_TRUE(result.converged()) << result.message;
    const double one_parameter = PeriodDoublingLevel(k_star, on_curve(H_index) - 0.01, on_curve(H_index) + 0.01);
    EXPECT_NEAR(on_curve(H_index), one_parameter, 1e-9) << "k = " << k_star;
    char text[64];
    std::snprintf(text, sizeof text, "%.12f (difference %.2g)", on_curve(H_index), on_curve(H_index) - one_parameter);
    RecordProperty("H_pd_at_k_" + std::to_string(static_cast<int>(k_star)), text);
  }
}

}  // namespace
}  // namespace hybridcont
