// Phase flows: closed forms, conservation of H for xi = 0, strict growth for xi > 0 (paper Thm 3.1).
#include <gtest/gtest.h>

#include <cmath>

#include "hybridcont/flow.h"
#include "hybridcont/models.h"
#include "integration/augmented_rhs.h"

namespace hybridcont {
namespace {

double Energy(const Phase& phase, const Vector& x) {
  Vector H;
  phase.FirstIntegrals(x, &H, nullptr, nullptr);
  return H(0);
}

TEST(PhaseFlow, BallFlightMatchesClosedFormForwardAndBackward) {
  const HybridModel ball = MakeBouncingBall();
  PhaseFlow flow(ball.phase(0), IntegratorOptions{});
  Vector x0(2);
  x0 << 0.7, 0.4;
  for (double t : {0.9, -0.9}) {
    PhaseFlowResult res;
    ASSERT_EQ(flow.Integrate(x0, Vector::Zero(1), t, true, &res), FlowStatus::kSuccess);
    EXPECT_NEAR(res.x(0), 0.7 + 0.4 * t - 0.5 * t * t, 1e-12);
    EXPECT_NEAR(res.x(1), 0.4 - t, 1e-12);
    // Phi = [[1, t], [0, 1]] exactly
    EXPECT_NEAR(res.Phi(0, 1), t, 1e-12);
    EXPECT_NEAR(res.Phi(0, 0), 1.0, 1e-12);
    EXPECT_NEAR(res.Phi(1, 0), 0.0, 1e-12);
  }
}

TEST(PhaseFlow, ZeroDurationIsTheIdentityWithoutWork) {
  const HybridModel slip = MakeSlip();
  PhaseFlow flow(slip.phase(1), IntegratorOptions{});
  const Vector x0 = slip.phase(1).typical_state();
  PhaseFlowResult res;
  ASSERT_EQ(flow.Integrate(x0, Vector::Constant(1, 0.2), 0.0, true, &res), FlowStatus::kSuccess);
  EXPECT_EQ(res.x, x0);
  EXPECT_TRUE(res.Phi.isIdentity(0.0));
  EXPECT_TRUE(res.Psi.isZero(0.0));
  EXPECT_EQ(res.counters.rhs_evaluations, 0);
}

// The unfolded ball with xi: x' = [dy + xi m g, -g + xi m dy] is linear; its exact solution over t:
// with s = xi m, dy(t) = (dy0 - g/s) e^{s t} + g/s ... verify Psi against a finite difference instead and
// H growth against the identity dH/dt = xi |dH|^2.
class ConservationTest : public ::testing::TestWithParam<std::string> {};

TEST_P(ConservationTest, EnergyConservedForXiZeroAndGrowsForXiPositive) {
  const HybridModel model = MakeBuiltinModel(GetParam());
  for (int p = 0; p < model.num_phases(); ++p) {
    const Phase& phase = model.phase(p);
    IntegratorOptions opts;
    PhaseFlow flow(phase, opts);
    const Vector x0 = phase.typical_state();
    const double H0 = Energy(phase, x0);
    // xi = 0: H constant along the whole sampled trajectory, to the integrator tolerance.
    double worst = 0.0;
    PhaseFlowResult res;
    flow.Integrate(x0, Vector::Zero(1), 0.8, false, &res, [&](double, const Eigen::Ref<const Vector>& x) {
      worst = std::max(worst, std::abs(Energy(phase, x) - H0));
    });
    ASSERT_TRUE(res.ok()) << res.message;
    EXPECT_LT(worst, 50 * opts.rtol * std::max(1.0, std::abs(H0))) << phase.name();
    // xi > 0: dH/dt = xi |dH|^2 > 0, so H strictly increases step after step.
    double previous = -1e300;
    bool increasing = true;
    int samples = 0;
    flow.Integrate(x0, Vector::Constant(1, 0.1), 0.8, false, &res, [&](double, const Eigen::Ref<const Vector>& x) {
      const double H = Energy(phase, x);
      increasing = increasing && H > previous;
      previous = H;
      ++samples;
    });
    ASSERT_TRUE(res.ok());
    EXPECT_TRUE(increasing) << phase.name();
    EXPECT_GT(samples, 3);
    EXPECT_GT(Energy(phase, res.x), H0 + 1e-3);
    // ... and backward in time it decreases.
    flow.Integrate(x0, Vector::Constant(1, 0.1), -0.5, false, &res);
    EXPECT_LT(Energy(phase, res.x), H0 - 1e-4);
  }
}

INSTANTIATE_TEST_SUITE_P(AllModels, ConservationTest,
                         ::testing::Values("bouncing-ball", "rocking-block", "bouncing-rod", "slip"),
                         [](const auto& info) {
                           std::string s = info.param;
                           for (char& c : s) c = (c == '-') ? '_' : c;
                           return s;
                         });

TEST(PhaseFlow, ResetMapsConserveEnergy) {
  // Definition Df2: H_{i+1}(Delta_i(x)) = H_i(x) on the guard. The impacts of ball, block, rod conserve
  // energy for every configuration; the SLIP transitions only on the guard (leg at natural length).
  for (const std::string& name : BuiltinModelNames()) {
    const HybridModel model = MakeBuiltinModel(name);
    for (int p = 0; p < model.num_phases(); ++p) {
      Vector x = model.phase(p).typical_state();
      if (name == "slip" && p == 0) x(1) = model.parameter("l0");
      if (name == "slip" && p == 1) x(0) = model.parameter("l0") * std::cos(x(1));
      Vector y;
      model.phase(p).Reset(x, &y, nullptr);
      EXPECT_NEAR(Energy(model.phase(p + 1), y), Energy(model.phase(p), x), 1e-14) << name << " phase " << p;
    }
  }
}

TEST(PhaseFlow, NonFiniteModelValueIsReportedWithPhaseAndTime) {
  // SLIP stance divides by l: starting at l = 0 produces NaN/Inf at once.
  const HybridModel slip = MakeSlip();
  PhaseFlow flow(slip.phase(0), IntegratorOptions{});
  Vector x0(4);
  x0 << 0.1, 0.0, 0.3, -0.4;
  PhaseFlowResult res;
  EXPECT_EQ(flow.Integrate(x0, Vector::Zero(1), 0.5, true, &res), FlowStatus::kNonFinite);
  EXPECT_NE(res.message.find("phase 'stance'"), std::string::npos) << res.message;
  EXPECT_NE(res.message.find("t = 0"), std::string::npos) << res.message;
}

// f(x) = sqrt(x) on [0, ∞): finite at x = 0, its derivative is not. Only A = df/dx carries the Inf, and
// the sensitivities must report it (the right-hand side tests the sum of dz, which A·Phi reaches).
class SqrtPhase final : public Phase {
 public:
  SqrtPhase() : Phase("sqrt", {"x"}, 1, 1, Vector::Ones(1)) {}
  void VectorField(const Eigen::Ref<const Vector>& x, Vector* f, Matrix* df) const override {
    *f = x.cwiseAbs().cwiseSqrt();
    if (df) *df = Matrix::Constant(1, 1, 0.5 / std::sqrt(std::abs(x(0))));
  }
  void FirstIntegrals(const Eigen::Ref<const Vector>&, Vector* H, Matrix* dH, std::vector<Matrix>* d2H) const override {
    if (H) *H = Vector::Zero(1);
    if (dH) *dH = Matrix::Zero(1, 1);
    if (d2H) d2H->assign(1, Matrix::Zero(1, 1));
  }
  double Event(const Eigen::Ref<const Vector>& x, RowVector* de) const override {
    if (de) *de = RowVector::Ones(1);
    return x(0);
  }
  void Reset(const Eigen::Ref<const Vector>& x, Vector* x_next, Matrix* D) const override {
    *x_next = x;
    if (D) *D = Matrix::Identity(1, 1);
  }
};

// The right-hand side itself flags a Jacobian-only Inf and returns dz = 0, so that the stepper's
// arithmetic (its error estimate, its next step size) stays finite: an Inf reaching only the stages
// that Fehlberg's 7th-order solution weights by zero would otherwise leave z finite and the step size NaN.
TEST(AugmentedRhs, FlagsANonFiniteJacobianAndReturnsZero) {
  SqrtPhase phase;
  internal::AugmentedRhsWorkspace w;
  const int size = w.Start(phase, Vector::Zero(1), true);
  Vector z, dz;
  w.InitialState(Vector::Zero(1), &z);
  ASSERT_EQ(z.size(), size);
  w.Evaluate(z, dz, 0.25);
  EXPECT_TRUE(w.nonfinite);
  EXPECT_EQ(w.nonfinite_time, 0.25);
  EXPECT_TRUE(dz.isZero(0.0)) << dz.transpose();
  internal::AugmentedRhsWorkspace fine;
  fine.Start(phase, Vector::Zero(1), true);
  fine.InitialState(Vector::Ones(1), &z);
  fine.Evaluate(z, dz, 0.0);
  EXPECT_FALSE(fine.nonfinite);
  EXPECT_DOUBLE_EQ(dz(0), 1.0);   // f = sqrt(1)
  EXPECT_DOUBLE_EQ(dz(1), 0.5);   // dPhi = A Phi = 0.5 · 1
}

TEST(PhaseFlow, NonFiniteJacobianAloneIsReported) {
  SqrtPhase phase;
  PhaseFlow flow(phase, IntegratorOptions{});
  PhaseFlowResult res;
  // Without sensitivities the flow from x = 0 is fine (x(t) = t²/4 is one solution; RKF stays at 0).
  EXPECT_EQ(flow.Integrate(Vector::Zero(1), Vector::Zero(1), 0.5, false, &res), FlowStatus::kSuccess);
  EXPECT_EQ(flow.Integrate(Vector::Zero(1), Vector::Zero(1), 0.5, true, &res), FlowStatus::kNonFinite);
  EXPECT_NE(res.message.find("phase 'sqrt'"), std::string::npos) << res.message;
  EXPECT_NE(res.message.find("t = 0"), std::string::npos) << res.message;
}

TEST(IntegratorOptions, ValidateNamesFieldAndValue) {
  IntegratorOptions o;
  o.rtol = -1.0;
  EXPECT_NE(o.Validate().find("rtol = -1"), std::string::npos);
  o = IntegratorOptions();
  EXPECT_EQ(o.Validate(), "");
}

}  // namespace
}  // namespace hybridcont
