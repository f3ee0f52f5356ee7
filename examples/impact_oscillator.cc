// Writing your own model: an elastic impact oscillator, continued with the hybridcont library.
//
// A mass m on a spring k (rest at x = 0) hits a rigid wall at x = gap and bounces back elastically.
// One phase (m = 1): free oscillation until x reaches the wall; the reset reverses the velocity; the
// anchor is the left turning point (v crosses zero upward, i.e. a = -v crosses downward).
// Closed form of the impacting family (amplitude A = sqrt(2H/k) > gap, omega = sqrt(k/m)):
//     T(H) = 2 acos(-gap / A) / omega.
// The program traces the family from H = 0.6 to H = 2 and checks T(H) at every point; exit code 0 if
// all agree to 1e-8. It is built and run by the test suite.
#include <cmath>
#include <cstdio>

#include "hybridcont/continuation.h"
#include "hybridcont/hybridcont.h"
#include "hybridcont/model_builder.h"

namespace {

using hybridcont::StateVector;

struct OscillatorParameters {
  double m = 1.0;    // mass
  double k = 1.0;    // spring stiffness
  double gap = 0.5;  // distance of the wall from the spring's rest position
};

// The single phase: functions written once, as templates over the scalar type T.
struct FreeOscillation {
  // The state dimension: derivatives compiled for it only (optional; compiles several times faster).
  static constexpr int kDimension = 2;  // x, v
  template <class T>
  static StateVector<T> VectorField(const StateVector<T>& x, const OscillatorParameters& p) {
    StateVector<T> f(2);
    f << x(1), -p.k / p.m * x(0);
    return f;
  }
  template <class T>
  static T FirstIntegral(const StateVector<T>& x, const OscillatorParameters& p) {
    return 0.5 * p.m * x(1) * x(1) + 0.5 * p.k * x(0) * x(0);
  }
  template <class T>
  static T Event(const StateVector<T>& x, const OscillatorParameters& p) {
    return p.gap - x(0);  // reaches zero, downward, when the mass hits the wall
  }
  template <class T>
  static StateVector<T> Reset(const StateVector<T>& x, const OscillatorParameters&) {
    StateVector<T> y(2);
    y << x(0), -x(1);  // elastic impact
    return y;
  }
};

struct LeftTurningPoint {
  static constexpr int kDimension = 2;
  template <class T>
  static T Anchor(const StateVector<T>& x, const OscillatorParameters&) {
    return -x(1);
  }
};

hybridcont::HybridModel MakeImpactOscillator() {
  hybridcont::ModelBuilder<OscillatorParameters> b("impact-oscillator", "spring-mass hitting a wall");
  b.Parameter("m", &OscillatorParameters::m, "mass")
      .Parameter("k", &OscillatorParameters::k, "spring stiffness")
      .Parameter("gap", &OscillatorParameters::gap, "wall position");
  b.AddPhase<FreeOscillation>("free", {"x", "v"}, (hybridcont::Vector(2) << 0.1, 0.2).finished());
  b.SetAnchor<LeftTurningPoint>();
  return b.Build();
}

double ClosedFormPeriod(double H, const OscillatorParameters& p) {
  const double A = std::sqrt(2.0 * H / p.k), omega = std::sqrt(p.k / p.m);
  return 2.0 * std::acos(-p.gap / A) / omega;
}

}  // namespace

int main() {
  using namespace hybridcont;
  const HybridModel model = MakeImpactOscillator();
  const OscillatorParameters p;

  // 1. Every derivative the library will use, against finite differences.
  const DerivativeCheckReport check = CheckDerivatives(model, DerivativeCheckOptions{});
  if (!check.passed()) {
    std::printf("%s", check.Table().c_str());
    return 1;
  }

  // 2. A starting orbit from the closed form at H = 0.6: left turning point -> wall -> left turning point.
  TimeBasedShooting shooting(model, IntegratorOptions{});
  const ShootingLayout& layout = shooting.layout();
  const double H0 = 0.6, A = std::sqrt(2 * H0 / p.k), omega = std::sqrt(p.k / p.m);
  const double t_wall = std::acos(-p.gap / A) / omega;
  Vector u0 = Vector::Zero(layout.num_unknowns());
  u0(layout.time_index(0)) = t_wall;
  u0(layout.state_offset(0)) = -A;  // x1 = [-A, 0]
  u0(layout.time_index(1)) = t_wall;
  u0(layout.state_offset(1)) = p.gap;  // x2 = [gap, -v]
  u0(layout.state_offset(1) + 1) = -A * omega * std::sin(omega * t_wall);
  u0(layout.H_index()) = H0;

  // 3. Continue the family up to H = 2 (exactly), in the direction of growing H.
  ContinuationOptions options;
  options.targets.push_back({"H", 2.0});
  Vector hint = Vector::Zero(layout.num_unknowns());
  hint(layout.H_index()) = 1.0;
  ContinuationStepper stepper(&shooting, options);
  stepper.Start(u0, hint);
  while (stepper.Step() == StepStatus::kContinuing) {
  }
  const Branch& branch = stepper.branch();

  double worst = 0.0;
  for (const ContinuationPoint& point : branch.points) {
    const double H = point.u(layout.H_index());
    worst = std::max(worst, std::abs(layout.Period(point.u) - ClosedFormPeriod(H, p)));
  }
  const double H_end = branch.points.back().u(layout.H_index());
  std::printf("%s\n%zu points, H from %.3f to %.12f, worst |T - T_exact| = %.2e\n", branch.BriefReport().c_str(),
              branch.points.size(), H0, H_end, worst);
  const bool ok = branch.termination == TerminationReason::kTargetReached && std::abs(H_end - 2.0) < 1e-12 &&
                  worst < 1e-8 && branch.points.size() > 5;
  return ok ? 0 : 1;
}
