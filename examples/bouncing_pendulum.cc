// A mechanical model in C++ in the mass-matrix form: a pendulum (point mass m2 on a rod of length l) hanging
// from a slider (mass m1) that runs on a vertical rail and bounces elastically on a stop at y = 0.
// models/bouncing-pendulum.toml is the same system written from T and V; here M(q) q̈ = h(q, q̇) is written
// out and solved by SolveMassMatrix, and the reset is ImpactVelocities at the contact y = 0 (mechanics.h),
// both templates over the scalar type, so every derivative stays exact.
//
// State (y, theta, dy, dtheta); with s = sin(theta), c = cos(theta), M = m1 + m2:
//   [ M          m2 l s ] [ y''     ]   [ -m2 l c theta'^2 - M g ]
//   [ m2 l s     m2 l^2 ] [ theta'' ] = [ -m2 g l s              ],     H = T + M g y + m2 g l (1 - c).
// Checks: every derivative against finite differences; along the vertical bouncing (theta = 0) the period
// is 2 v/g with v = sqrt(2 H / M); at H = M g l / 2 the pendulum's two multipliers are both -1 (the period
// doubling). Exit code 0 if all hold. Built and run by the test suite.
#include <cmath>
#include <cstdio>

#include "hybridcont/continuation.h"
#include "hybridcont/hybridcont.h"
#include "hybridcont/mechanics.h"
#include "hybridcont/model_builder.h"

namespace {

using hybridcont::MassMatrix;
using hybridcont::StateVector;

struct PendulumParameters {
  double m1 = 1.0, m2 = 1.0, l = 1.0, g = 1.0;
};

template <class T>
MassMatrix<T> Mass(const StateVector<T>& x, const PendulumParameters& p) {
  using std::sin;
  MassMatrix<T> M(2, 2);
  const T coupling = p.m2 * p.l * sin(x(1));
  M << T(p.m1 + p.m2), coupling, coupling, T(p.m2 * p.l * p.l);
  return M;
}

struct Flight {
  // The state dimension: derivatives compiled for it only (optional; compiles several times faster).
  static constexpr int kDimension = 4;  // y, theta, dy, dtheta
  template <class T>
  static StateVector<T> VectorField(const StateVector<T>& x, const PendulumParameters& p) {
    using std::cos, std::sin;
    StateVector<T> h(2);
    h << -p.m2 * p.l * cos(x(1)) * x(3) * x(3) - (p.m1 + p.m2) * p.g, -p.m2 * p.g * p.l * sin(x(1));
    const StateVector<T> acc = hybridcont::SolveMassMatrix(Mass(x, p), h);
    StateVector<T> f(4);
    f << x(2), x(3), acc(0), acc(1);
    return f;
  }
  template <class T>
  static T FirstIntegral(const StateVector<T>& x, const PendulumParameters& p) {
    using std::cos, std::sin;
    const T kinetic = 0.5 * (p.m1 + p.m2) * x(2) * x(2) + p.m2 * p.l * sin(x(1)) * x(2) * x(3) +
                      0.5 * p.m2 * p.l * p.l * x(3) * x(3);
    return kinetic + (p.m1 + p.m2) * p.g * x(0) + p.m2 * p.g * p.l * (1.0 - cos(x(1)));
  }
  template <class T>
  static T Event(const StateVector<T>& x, const PendulumParameters&) {
    return x(0);  // the slider reaches the stop
  }
  template <class T>
  static StateVector<T> Reset(const StateVector<T>& x, const PendulumParameters& p) {
    StateVector<T> G(2), qdot(2);
    G << T(1.0), T(0.0);  // ∂g/∂q for g = y
    qdot << x(2), x(3);
    const StateVector<T> after = hybridcont::ImpactVelocities(Mass(x, p), G, qdot, 1.0);
    StateVector<T> y(4);
    y << x(0), x(1), after(0), after(1);
    return y;
  }
};

struct Apex {
  static constexpr int kDimension = 4;
  template <class T>
  static T Anchor(const StateVector<T>& x, const PendulumParameters&) {
    return x(2);
  }
};

hybridcont::HybridModel MakeBouncingPendulum() {
  hybridcont::ModelBuilder<PendulumParameters> b("bouncing-pendulum-cpp", "pendulum on a bouncing slider");
  b.Parameter("m1", &PendulumParameters::m1, "slider mass")
      .Parameter("m2", &PendulumParameters::m2, "pendulum mass")
      .Parameter("l", &PendulumParameters::l, "pendulum length")
      .Parameter("g", &PendulumParameters::g, "gravity");
  b.AddPhase<Flight>("flight", {"y", "theta", "dy", "dtheta"},
                     (hybridcont::Vector(4) << 0.3, 0.4, -0.2, 0.5).finished());
  b.SetAnchor<Apex>();
  return b.Build();
}

}  // namespace

int main() {
  using namespace hybridcont;
  const HybridModel model = MakeBouncingPendulum();
  const PendulumParameters p;
  const double M = p.m1 + p.m2;

  const DerivativeCheckReport check = CheckDerivatives(model, DerivativeCheckOptions{});
  if (!check.passed()) {
    std::printf("%s", check.Table().c_str());
    return 1;
  }

  // The vertical bouncing at H: apex at H/(M g), impact speed v, half period v/g.
  TimeBasedShooting shooting(model, IntegratorOptions{});
  const ShootingLayout& layout = shooting.layout();
  const auto vertical = [&](double H) {
    const double v = std::sqrt(2 * H / M);
    Vector u = Vector::Zero(layout.num_unknowns());
    u(layout.time_index(0)) = u(layout.time_index(1)) = v / p.g;
    u(layout.state_offset(0)) = H / (M * p.g);
    u(layout.state_offset(1) + 2) = v;
    u(layout.H_index()) = H;
    return u;
  };

  // Continue it from H = 0.5 to H = 1.5 and compare the period with 2 v/g.
  ContinuationOptions options;
  options.targets.push_back({"H", 1.5});
  Vector hint = Vector::Zero(layout.num_unknowns());
  hint(layout.H_index()) = 1.0;
  ContinuationStepper stepper(&shooting, options);
  stepper.Start(vertical(0.5), hint);
  while (stepper.Step() == StepStatus::kContinuing) {
  }
  double worst = 0.0;
  for (const ContinuationPoint& point : stepper.branch().points) {
    const double H = point.u(layout.H_index());
    worst = std::max(worst, std::abs(layout.Period(point.u) - 2 * std::sqrt(2 * H / M) / p.g));
  }

  // At H = M g l / 2 the pendulum's multipliers are -1 (twice).
  const FloquetResult at_pd = ComputeFloquet(shooting, vertical(0.5 * M * p.g * p.l));
  double pd_error = at_pd.ok() && at_pd.nontrivial.size() == 2 ? 0.0 : 1.0;
  for (const auto& mu : at_pd.nontrivial) pd_error = std::max(pd_error, std::abs(mu + 1.0));
  std::printf("%zu points of the vertical bouncing, worst |T - 2v/g| = %.2e; multipliers at H = %.1f: %s "
              "(distance from -1: %.1e)\n",
              stepper.branch().points.size(), worst, 0.5 * M * p.g * p.l, at_pd.BriefReport().c_str(), pd_error);
  // A double multiplier at -1 is computed to the square root of the evaluation error (~1e-5 at rtol 1e-10).
  return worst < 1e-10 && pd_error < 1e-4 && stepper.branch().points.size() > 5 ? 0 : 1;
}
