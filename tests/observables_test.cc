// Observables of an orbit (observable.h, orbit_observables.h) on models/slip.toml: values against closed
// forms and independent integrations, gradients against central differences, and the shooting map with
// observables among its unknowns.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>

#include "hybridcont/flow.h"
#include "hybridcont/model_file.h"
#include "hybridcont/observable_test_functions.h"
#include "hybridcont/orbit_observables.h"
#include "hybridcont/timebased_shooting.h"
#include "known_orbits.h"

namespace hybridcont {
namespace {

HybridModel Slip() {
  ModelFileOptions options;
  options.compile = false;  // the observables do not depend on it; the interpreter needs no compiler
  return LoadModelFile(std::string(HYBRIDCONT_SOURCE_DIR).append("/models/slip.toml"), options);
}

// A point of the layout that is no orbit but has every phase moving: hopping in place at H̄ = 1.5 with the
// leg tilted and a forward speed, so that every term of every observable contributes.
Vector GenericPoint(const HybridModel& slip, const ShootingLayout& layout) {
  const ShootingLayout base(slip);
  Vector u = Vector::Zero(layout.num_unknowns());
  u.head(base.num_unknowns()) = SlipHoppingInPlace(slip, base, 1.5);
  u(layout.state_offset(0) + 0) = 0.05;   // x1_alpha
  u(layout.state_offset(0) + 2) = -0.3;   // x1_dalpha
  u(layout.state_offset(1) + 1) = 0.12;   // x2_alpha
  u(layout.state_offset(1) + 2) = 0.4;    // x2_dx
  u(layout.state_offset(1) + 4) = -0.6;   // x2_dalpha
  u(layout.state_offset(2) + 0) = -0.1;   // x3_alpha
  u(layout.state_offset(2) + 2) = -0.35;  // x3_dalpha
  u(layout.xi_index()) = 0.01;            // off the orbit: the unfolding term counts too
  return u;
}

int Index(const HybridModel& model, const std::string& name) {
  const int j = model.FindObservable(name);
  EXPECT_GE(j, 0) << name;
  return j;
}

// The stride from the geometry: the body moves by −l sin α relative to the foot in stance and by dx·t in
// flight; the stance segments' ends come from plain integrations of the phase.
double StrideByGeometry(const HybridModel& slip, const ShootingLayout& layout, const Vector& u) {
  const Vector xi = u.segment(layout.xi_index(), 1);
  PhaseFlow stance(slip.phase(0), IntegratorOptions{});
  double stride = 0.0;
  for (const int s : {0, 2}) {
    const Vector x0 = u.segment(layout.state_offset(s), 4);
    PhaseFlowResult end;
    EXPECT_TRUE(stance.Integrate(x0, xi, u(layout.time_index(s)), false, &end) == FlowStatus::kSuccess);
    stride += -end.x(1) * std::sin(end.x(0)) + x0(1) * std::sin(x0(0));
  }
  return stride + u(layout.state_offset(1) + 2) * u(layout.time_index(1));
}

TEST(Observables, IntegralMeanAndExtremaMatchIndependentValues) {
  const HybridModel slip = Slip();
  const ShootingLayout layout(slip);
  // ξ = 0: the stance integrand −l̇ sin α − l α̇ cos α is the rate of −l sin α on the model's flow only,
  // not on the unfolded one.
  Vector u = GenericPoint(slip, layout);
  u(layout.xi_index()) = 0.0;
  ObservableEvaluator evaluator(slip, layout, IntegratorOptions{});
  double stride = 0, speed = 0, apex = 0, force = 0;
  ASSERT_TRUE(evaluator.Evaluate(Index(slip, "stride"), u, &stride, nullptr).ok);
  ASSERT_TRUE(evaluator.Evaluate(Index(slip, "speed"), u, &speed, nullptr).ok);
  ASSERT_TRUE(evaluator.Evaluate(Index(slip, "apex"), u, &apex, nullptr).ok);
  ASSERT_TRUE(evaluator.Evaluate(Index(slip, "peak_force"), u, &force, nullptr).ok);
  const double expected_stride = StrideByGeometry(slip, layout, u);
  EXPECT_NEAR(stride, expected_stride, 1e-10);
  EXPECT_NEAR(speed, expected_stride / layout.Period(u), 1e-10);
  // The apex of the ballistic flight, y0 + dy0²/(2g).
  const Vector u0 = u;
  ASSERT_TRUE(evaluator.Evaluate(Index(slip, "apex"), u0, &apex, nullptr).ok);
  const double y0 = u0(layout.state_offset(1)), dy0 = u0(layout.state_offset(1) + 3);
  EXPECT_NEAR(apex, y0 + dy0 * dy0 / 2.0, 1e-12);
  EXPECT_TRUE(evaluator.last_extremum_interior());
  // The foot's height rate at touch-down, −(ẏ + l0 sin α α̇) at the end of flight: ballistic body, harmonic leg
  // (α'' = −w2 α).
  double touchdown = 0;
  ASSERT_TRUE(evaluator.Evaluate(Index(slip, "touchdown"), u0, &touchdown, nullptr).ok);
  const double t2 = u0(layout.time_index(1)), w = std::sqrt(5.0);
  const double a0 = u0(layout.state_offset(1) + 1), da0 = u0(layout.state_offset(1) + 4);
  const double a = a0 * std::cos(w * t2) + da0 / w * std::sin(w * t2);
  const double da = -a0 * w * std::sin(w * t2) + da0 * std::cos(w * t2);
  EXPECT_NEAR(touchdown, -((dy0 - t2) + std::sin(a) * da), 1e-10);
  // The leg force k (l0 − l) is largest at the nadir, the start of segment 1 (an end value).
  ASSERT_TRUE(evaluator.Evaluate(Index(slip, "peak_force"), u0, &force, nullptr).ok);
  EXPECT_NEAR(force, 40.0 * (1.0 - u0(layout.state_offset(0) + 1)), 1e-12);
  std::printf("stride %.12f (geometry %.12f), speed %.12f, apex %.12f\n", stride, expected_stride, speed, apex);
}

// Every observable's gradient, also in a free parameter, against central differences of its value.
TEST(Observables, GradientsMatchCentralDifferences) {
  const HybridModel slip = Slip();
  for (const char* free : {"", "k"}) {
    FreeParameters parameters;
    if (*free) parameters = FreeParameters{{free}, {{"H", 1.5}}, {}};
    HybridModel model = slip.Clone();
    const ShootingLayout layout(model, parameters);
    Vector u = GenericPoint(model, layout);
    if (*free) u(layout.parameter_index(0)) = 40.0;
    ObservableEvaluator evaluator(model, layout, IntegratorOptions{});
    for (int j = 0; j < static_cast<int>(model.observables().size()); ++j) {
      double value = 0;
      RowVector du;
      ASSERT_TRUE(evaluator.Evaluate(j, u, &value, &du).ok);
      double worst = 0;
      for (int i = 0; i < u.size(); ++i) {
        const double h = 1e-6 * std::max(1.0, std::abs(u(i)));
        Vector up = u, um = u;
        up(i) += h, um(i) -= h;
        double vp = 0, vm = 0;
        if (*free) model.SetParameterValue(layout.parameter_model_index(0), up(layout.parameter_index(0)));
        ASSERT_TRUE(evaluator.Evaluate(j, up, &vp, nullptr).ok);
        if (*free) model.SetParameterValue(layout.parameter_model_index(0), um(layout.parameter_index(0)));
        ASSERT_TRUE(evaluator.Evaluate(j, um, &vm, nullptr).ok);
        if (*free) model.SetParameterValue(layout.parameter_model_index(0), u(layout.parameter_index(0)));
        worst = std::max(worst, std::abs((vp - vm) / (2 * h) - du(i)) / (1.0 + std::abs(du(i))));
      }
      EXPECT_LT(worst, 1e-6) << model.observables()[j].name << (*free ? " with k free" : "");
      std::printf("%-10s %s gradient vs central differences: %.1e\n", model.observables()[j].name.c_str(),
                  *free ? "(k free)" : "        ", worst);
    }
  }
}

// The map with observables among its unknowns: its equations o − g(u) are zero at the completed point and
// its Jacobian rows are the gradients (central differences of r).
TEST(Observables, ShootingMapWithObservablesHasExactJacobian) {
  const HybridModel slip = Slip();
  TimeBasedShooting map(slip, IntegratorOptions{}, FreeParameters{{"k"}, {{"speed", 0.3}}, {"speed", "apex"}});
  const ShootingLayout& layout = map.layout();
  ASSERT_EQ(layout.num_observables(), 2);
  EXPECT_EQ(layout.unknown_names()[layout.observable_index(0)], "speed");
  Vector v(layout.num_unknowns() - 2);
  const Vector point = GenericPoint(slip, ShootingLayout(slip));
  v << point, 40.0;
  const Vector u = map.CompleteUnknowns(v);
  Vector r;
  Matrix dr;
  ASSERT_TRUE(map.Evaluate(u, &r, &dr).ok);
  // Zero to the integration's accuracy: the values were completed without sensitivities, whose integration
  // takes other steps.
  EXPECT_NEAR(r(layout.observable_row(0)), 0.0, 1e-10);
  EXPECT_NEAR(r(layout.observable_row(1)), 0.0, 1e-10);
  EXPECT_NEAR(r(layout.fixed_row(0)), u(layout.observable_index(0)) - 0.3, 1e-15);
  double worst = 0;
  for (int i = 0; i < u.size(); ++i) {
    const double h = 1e-6 * std::max(1.0, std::abs(u(i)));
    Vector up = u, um = u, rp, rm;
    up(i) += h, um(i) -= h;
    ASSERT_TRUE(map.Evaluate(up, &rp, nullptr).ok);
    ASSERT_TRUE(map.Evaluate(um, &rm, nullptr).ok);
    for (const int row : {layout.observable_row(0), layout.observable_row(1)}) {
      worst = std::max(worst, std::abs((rp(row) - rm(row)) / (2 * h) - dr(row, i)) / (1.0 + std::abs(dr(row, i))));
    }
  }
  EXPECT_LT(worst, 1e-6);
  EXPECT_TRUE(map.symmetries().empty());  // how an observable maps under the mirror is not declared
}

// A constraint (the swing foot's clearance in flight) is the interior minimum where the foot dips, the end
// value (0 at lift-off and touch-down) where it does not; its test function has no sign at an end value.
TEST(Observables, ConstraintIsTheInteriorMinimum) {
  const HybridModel slip = Slip();
  ASSERT_TRUE(slip.observables()[slip.FindObservable("clearance")].constraint);
  const ShootingLayout layout(slip);
  const int j = slip.FindObservable("clearance");
  ObservableEvaluator evaluator(slip, layout, IntegratorOptions{});
  // Hopping in place: the leg stays vertical, the foot rises and falls: 0 at both ends, no interior dip.
  Vector u = SlipHoppingInPlace(slip, layout, 1.5);
  double value = 1;
  ASSERT_TRUE(evaluator.Evaluate(j, u, &value, nullptr).ok);
  EXPECT_NEAR(value, 0.0, 1e-12);
  EXPECT_FALSE(evaluator.last_extremum_interior());
  // A leg swinging fast through the vertical in a low flight: the foot dips below the ground at α ≈ 0.
  u(layout.state_offset(1) + 0) = 0.98;   // y at lift-off: the foot 0.025 above the ground
  u(layout.state_offset(1) + 1) = 0.3;    // alpha at lift-off
  u(layout.state_offset(1) + 3) = 0.1;    // dy
  u(layout.state_offset(1) + 4) = -3.0;   // dalpha
  ASSERT_TRUE(evaluator.Evaluate(j, u, &value, nullptr).ok);
  EXPECT_TRUE(evaluator.last_extremum_interior());
  EXPECT_LT(value, 0.0);
}

}  // namespace
}  // namespace hybridcont
