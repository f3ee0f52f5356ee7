// Continuation in a model parameter (shooting_layout.h, "Free parameters"): exact parameter derivatives of
// phases (against central differences), the time-based map's parameter column (against differences of r),
// model copies, and the SLIP's hopping in place traced in k at fixed H̄ against its closed form.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "hybridcont/continuation.h"
#include "hybridcont/model_file.h"
#include "hybridcont/models.h"
#include "hybridcont/timebased_shooting.h"
#include "known_orbits.h"

namespace hybridcont {
namespace {

// Central difference of a phase function in parameter `index` (step h relative to the value).
template <class Fn>
Vector ParameterDifference(HybridModel& model, int index, Fn&& fn) {
  const double p = model.parameter_value(index);
  const double h = 1e-6 * std::max(1.0, std::abs(p));
  model.SetParameterValue(index, p + h);
  const Vector plus = fn();
  model.SetParameterValue(index, p - h);
  const Vector minus = fn();
  model.SetParameterValue(index, p);
  return (plus - minus) / (2 * h);
}

void ExpectPhaseParameterDerivativesMatchDifferences(HybridModel& model) {
  ASSERT_TRUE(model.has_parameter_derivatives()) << model.name();
  for (int index = 0; index < static_cast<int>(model.parameters().size()); ++index) {
    for (int i = 0; i < model.num_phases(); ++i) {
      const Phase& phase = model.phase(i);
      const Vector x = phase.typical_state();
      Vector field, integrals, reset;
      double event = 0;
      phase.ParameterDerivatives(x, index, &field, &integrals, &event, &reset);
      const Vector fd_field = ParameterDifference(model, index, [&] {
        Vector f;
        phase.VectorField(x, &f, nullptr);
        return f;
      });
      const Vector fd_integrals = ParameterDifference(model, index, [&] {
        Vector H;
        phase.FirstIntegrals(x, &H, nullptr, nullptr);
        return H;
      });
      const Vector fd_event = ParameterDifference(model, index, [&] { return Vector::Constant(1, phase.Event(x, nullptr)); });
      const Vector fd_reset = ParameterDifference(model, index, [&] {
        Vector y;
        phase.Reset(x, &y, nullptr);
        return y;
      });
      const std::string where = model.name() + " phase " + phase.name() + " d/d" + model.parameters()[index].name;
      EXPECT_LT((field - fd_field).lpNorm<Eigen::Infinity>(), 1e-8) << where;
      EXPECT_LT((integrals - fd_integrals).lpNorm<Eigen::Infinity>(), 1e-8) << where;
      EXPECT_NEAR(event, fd_event(0), 1e-8) << where;
      EXPECT_LT((reset - fd_reset).lpNorm<Eigen::Infinity>(), 1e-8) << where;
      // The unfolded field's derivative, ξ-term included: ∂/∂p of f + ξ ∇H.
      const Vector xi = Vector::Constant(phase.num_first_integrals(), 0.3);
      Vector dfdp;
      phase.UnfoldedFieldParameterDerivative(x, xi, index, &dfdp, true);
      const Vector fd_unfolded = ParameterDifference(model, index, [&] {
        Vector f;
        phase.UnfoldedVectorField(x, xi, &f, nullptr, nullptr);
        return f;
      });
      EXPECT_LT((dfdp - fd_unfolded).lpNorm<Eigen::Infinity>(), 1e-8) << where << " (unfolded)";
    }
  }
}

TEST(FreeParameter, BuiltinPhasesDifferentiateInEveryParameter) {
  for (const std::string& name : BuiltinModelNames()) {
    HybridModel model = MakeBuiltinModel(name);
    ExpectPhaseParameterDerivativesMatchDifferences(model);
  }
}

TEST(FreeParameter, ModelFilePhasesDifferentiateInEveryParameter) {
  ModelFileOptions options;
  options.compile = false;
  HybridModel model = LoadModelFile(std::string(HYBRIDCONT_SOURCE_DIR) + "/models/slip.toml", options);
  ExpectPhaseParameterDerivativesMatchDifferences(model);
}

TEST(FreeParameter, ACloneHasItsOwnParameters) {
  HybridModel slip = MakeBuiltinModel("slip");
  HybridModel copy = slip.Clone();
  copy.SetParameter("k", 20.0);
  EXPECT_EQ(slip.parameter("k"), 40.0);
  EXPECT_EQ(copy.parameter("k"), 20.0);
  Vector f1, f2;
  const Vector x = slip.phase(0).typical_state();
  slip.phase(0).VectorField(x, &f1, nullptr);
  copy.phase(0).VectorField(x, &f2, nullptr);
  EXPECT_GT((f1 - f2).norm(), 1e-3);  // the copy's phases read the copy's k
}

// dr of the map with k free and H fixed against central differences of r, at a point off the curve
// with ξ != 0 (so that the ξ·∂∇H/∂k term counts).
TEST(FreeParameter, ParameterColumnOfTheTimeBasedMapIsExact) {
  HybridModel slip = MakeBuiltinModel("slip");
  TimeBasedShooting map(slip, IntegratorOptions{}, FreeParameters{{"k"}, {{"H", 1.5}}});
  const ShootingLayout& layout = map.layout();
  ASSERT_EQ(layout.num_unknowns(), ShootingLayout(slip).num_unknowns() + 1);
  ASSERT_EQ(layout.unknown_names().back(), "k");
  Vector u = Vector::Zero(layout.num_unknowns());
  u.head(ShootingLayout(slip).num_unknowns()) = SlipHoppingInPlace(slip, ShootingLayout(slip), 1.5);
  u(layout.parameter_index(0)) = 40.0;
  u(layout.xi_index()) = 0.02;
  u(layout.state_offset(0) + 2) += 0.05;
  map.set_jacobian_tolerance(0.0);
  Vector r;
  Matrix dr;
  ASSERT_TRUE(map.Evaluate(u, &r, &dr).ok);
  const int col = layout.parameter_index(0);
  const double h = 1e-5;
  Vector up = u, um = u, rp, rm;
  up(col) += h;
  um(col) -= h;
  ASSERT_TRUE(map.Evaluate(up, &rp, nullptr).ok);
  ASSERT_TRUE(map.Evaluate(um, &rm, nullptr).ok);
  const Vector fd = (rp - rm) / (2 * h);
  EXPECT_LT((dr.col(col) - fd).lpNorm<Eigen::Infinity>(), 1e-7 * std::max(1.0, fd.lpNorm<Eigen::Infinity>()));
  EXPECT_GT(dr.col(col).norm(), 1e-3);
  // The fixing row: H − 1.5.
  EXPECT_NEAR(r(layout.fixed_row(0)), u(layout.H_index()) - 1.5, 1e-15);
  EXPECT_EQ(dr(layout.fixed_row(0), layout.H_index()), 1.0);
}

TEST(FreeParameter, OutOfRangeParameterIsAnEvaluationFailure) {
  HybridModel slip = MakeBuiltinModel("slip");
  TimeBasedShooting map(slip, IntegratorOptions{}, FreeParameters{{"k"}, {{"H", 1.5}}});
  Vector u = Vector::Zero(map.num_unknowns());
  u(map.layout().parameter_index(0)) = -3.0;
  Vector r;
  const EvaluationStatus status = map.Evaluate(u, &r, nullptr);
  EXPECT_FALSE(status.ok);
  EXPECT_NE(status.message.find("'k'"), std::string::npos) << status.message;
}

TEST(FreeParameter, BadFreeParametersAreRefusedByName) {
  HybridModel slip = MakeBuiltinModel("slip");
  EXPECT_THROW(TimeBasedShooting(slip, IntegratorOptions{}, FreeParameters{{"kk"}, {{"H", 1.5}}}), std::invalid_argument);
  EXPECT_THROW(TimeBasedShooting(slip, IntegratorOptions{}, FreeParameters{{"k"}, {}}), std::invalid_argument);
  EXPECT_THROW(TimeBasedShooting(slip, IntegratorOptions{}, FreeParameters{{"k"}, {{"Q", 1.5}}}), std::invalid_argument);
}

// Hopping in place at H̄ = 1.5 traced in k from 40 over [15, 100]: every point equals the closed form at
// its k (known_orbits.h), and k is the family parameter.
TEST(FreeParameter, SlipHoppingInPlaceTracedInStiffnessMatchesTheClosedForm) {
  HybridModel slip = MakeBuiltinModel("slip");
  TimeBasedShooting map(slip, IntegratorOptions{}, FreeParameters{{"k"}, {{"H", 1.5}}});
  EXPECT_EQ(map.family_parameter(), "k");
  const ShootingLayout base(slip);
  const ShootingLayout& layout = map.layout();
  Vector u0 = Vector::Zero(layout.num_unknowns());
  u0.head(base.num_unknowns()) = SlipHoppingInPlace(slip, base, 1.5);
  u0(layout.parameter_index(0)) = 40.0;
  ContinuationOptions options;
  options.bounds = {{"k", 15.0, 100.0}};
  options.max_step = 2.0;
  options.detect_bifurcations = false;
  const Branch branch = TraceBranch(&map, u0, options);
  ASSERT_GE(branch.points.size(), 10u);
  double worst = 0;
  for (const ContinuationPoint& p : branch.points) {
    HybridModel at_k = MakeBuiltinModel("slip");
    at_k.SetParameter("k", p.u(layout.parameter_index(0)));
    const Vector exact = SlipHoppingInPlace(at_k, base, 1.5);
    worst = std::max(worst, (p.u.head(base.num_unknowns()) - exact).lpNorm<Eigen::Infinity>());
  }
  EXPECT_LT(worst, 1e-8);
  char text[32];
  std::snprintf(text, sizeof text, "%.3g", worst);
  RecordProperty("worst_deviation_from_closed_form", text);
  EXPECT_NEAR(branch.points.back().u(layout.parameter_index(0)), 100.0, 1e-9);
}

}  // namespace
}  // namespace hybridcont
