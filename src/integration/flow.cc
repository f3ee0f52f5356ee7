#include "hybridcont/flow.h"

#include <cmath>
#include <sstream>

#include <boost/numeric/odeint.hpp>
#include <boost/numeric/odeint/external/eigen/eigen.hpp>

#include "hybridcont/internal/enum_names.h"
#include "hybridcont/internal/options_check.h"
#include "integration/augmented_rhs.h"

namespace hybridcont {

namespace odeint = boost::numeric::odeint;

namespace {

constexpr internal::EnumName<IntegratorMethod> kIntegratorMethodNames[] = {
    {IntegratorMethod::kDormandPrince54, "dopri5"},
    {IntegratorMethod::kFehlberg78, "rkf78"},
};

constexpr internal::EnumName<FlowStatus> kFlowStatusNames[] = {
    {FlowStatus::kSuccess, "success"},
    {FlowStatus::kNonFinite, "non-finite value"},
    {FlowStatus::kStepTooSmall, "step size too small"},
    {FlowStatus::kMaxSteps, "maximum number of steps"},
};

}  // namespace

std::string ToString(IntegratorMethod method) { return internal::EnumToString(kIntegratorMethodNames, method); }

bool FromString(const std::string& name, IntegratorMethod* method) {
  return internal::EnumFromString(kIntegratorMethodNames, name, method);
}

std::string ToString(FlowStatus status) { return internal::EnumToString(kFlowStatusNames, status); }

std::string IntegratorOptions::Validate() const {
  return internal::OptionsCheck("IntegratorOptions")
      .Positive("rtol", rtol)
      .Positive("atol", atol)
      .Positive("initial_step", initial_step)
      .Positive("min_step", min_step)
      .AtLeast("max_steps", max_steps, 1)
      .message();
}

namespace {

using State = Vector;
using Dopri5 = odeint::runge_kutta_dopri5<State, double, State, double, odeint::vector_space_algebra>;
using Rkf78 = odeint::runge_kutta_fehlberg78<State, double, State, double, odeint::vector_space_algebra>;
using ControlledDopri5 = odeint::controlled_runge_kutta<Dopri5>;
using ControlledRkf78 = odeint::controlled_runge_kutta<Rkf78>;

}  // namespace

struct PhaseFlow::Steppers {
  ControlledDopri5 dopri5;
  ControlledRkf78 rkf78;
  State z;
  internal::AugmentedRhsWorkspace rhs;
  Steppers(double atol, double rtol)
      : dopri5(odeint::default_error_checker<double, odeint::vector_space_algebra, odeint::default_operations>(atol, rtol)),
        rkf78(odeint::default_error_checker<double, odeint::vector_space_algebra, odeint::default_operations>(atol, rtol)) {}
};

PhaseFlow::PhaseFlow(const Phase& phase, IntegratorOptions options)
    : phase_(&phase), options_(options), steppers_(std::make_unique<Steppers>(options.atol, options.rtol)) {}
PhaseFlow::~PhaseFlow() = default;
PhaseFlow::PhaseFlow(PhaseFlow&&) noexcept = default;
PhaseFlow& PhaseFlow::operator=(PhaseFlow&&) noexcept = default;

void PhaseFlow::set_free_parameters(std::vector<int> parameters) {
  HYBRIDCONT_DEMAND(parameters.empty() || phase_->has_parameter_derivatives());
  steppers_->rhs.parameters = std::move(parameters);
}

FlowStatus PhaseFlow::Integrate(const Eigen::Ref<const Vector>& x0, const Eigen::Ref<const Vector>& xi, double t,
                                bool with_sensitivities, PhaseFlowResult* result) {
  return Integrate(x0, xi, t, with_sensitivities, result, Observer());
}

FlowStatus PhaseFlow::Integrate(const Eigen::Ref<const Vector>& x0, const Eigen::Ref<const Vector>& xi, double t,
                                bool with_sensitivities, PhaseFlowResult* result, const Observer& observer) {
  Steppers& s = *steppers_;
  internal::AugmentedRhsWorkspace& w = s.rhs;
  w.Start(*phase_, xi, with_sensitivities);
  const int n = w.n;
  const int k = w.k;
  result->counters = FlowCounters();
  result->jacobian_relaxed = false;
  result->message.clear();
  result->status = FlowStatus::kSuccess;

  State& z = s.z;
  w.InitialState(x0, &z);

  auto finish = [&](FlowStatus status, std::string message) {
    result->counters.rhs_evaluations = w.rhs_evaluations;
    result->status = status;
    result->message = std::move(message);
    result->x = z.head(n);
    if (with_sensitivities) {
      result->Phi = w.Phi(z);
      result->Psi = w.Psi(z);
    }
    return status;
  };
  if (!z.head(n).allFinite() || !w.xi.allFinite()) {
    return finish(FlowStatus::kNonFinite, "phase '" + phase_->name() + "': non-finite initial state or xi");
  }
  if (!std::isfinite(t)) {
    return finish(FlowStatus::kNonFinite, "phase '" + phase_->name() + "': non-finite duration");
  }
  if (observer) observer(0.0, z.head(n));
  if (t == 0.0) return finish(FlowStatus::kSuccess, "");

  // The xi·d2H term of A = df~/dx changes Phi by about |xi| |d2H| |t| |Phi|. On converged orbits |xi| is at
  // the Newton noise (~1e-13) and the term is orders of magnitude below the integrator's own error; the
  // nested-jet Hessians it needs were ~40% of a SLIP exploration. It is dropped only when, at x0,
  // |xi| |d2H| <= 1e-3 rtol max(|df|, 1): the Jacobian stays exact to the integration tolerance, and any
  // sizable xi (the at-rest branches, the derivative checks) keeps the exact term. A caller that needs dr
  // only to the relative tolerance set_jacobian_tolerance (the corrector, at the predictor) raises the bar.
  // The ξ-term of df~/dp (ξ·∂∇H/∂p, free parameters) is kept or dropped with it.
  if (with_sensitivities && (w.xi.array() != 0.0).any()) {
    Vector H;
    Matrix df, dH;
    std::vector<Matrix> d2H;
    phase_->VectorField(z.head(n), &w.f, &df);
    phase_->FirstIntegrals(z.head(n), &H, &dH, &d2H);
    double hessian_norm = 0.0;
    for (int j = 0; j < k; ++j) hessian_norm += std::abs(w.xi(j)) * d2H[j].cwiseAbs().maxCoeff();
    const double scale = std::max(df.cwiseAbs().maxCoeff(), 1.0);
    w.hessian_term = hessian_norm > std::max(1e-3 * options_.rtol, jacobian_tolerance_) * scale;
    result->jacobian_relaxed = !w.hessian_term && hessian_norm > 1e-3 * options_.rtol * scale;
  }
  const internal::AugmentedRhs system{&w};
  const double direction = t > 0.0 ? 1.0 : -1.0;
  double time = 0.0;
  double dt = direction * std::min(std::abs(t), options_.initial_step);
  s.dopri5.reset();
  long attempts = 0;
  while (direction * (t - time) > 0.0) {
    // Land exactly on t; the 1e-14 slack avoids a sliver step of round-off size.
    if (direction * (time + dt - t) > -1e-14 * std::max(1.0, std::abs(t))) dt = t - time;
    if (++attempts > options_.max_steps) {
      std::ostringstream os;
      os << "phase '" << phase_->name() << "': " << options_.max_steps << " steps exhausted at t = " << time
         << " of " << t;
      return finish(FlowStatus::kMaxSteps, os.str());
    }
    odeint::controlled_step_result step_result;
    if (options_.method == IntegratorMethod::kDormandPrince54) {
      step_result = s.dopri5.try_step(system, z, time, dt);
    } else {
      step_result = s.rkf78.try_step(system, z, time, dt);
    }
    if (w.nonfinite || !z.allFinite()) {
      std::ostringstream os;
      os << "phase '" << phase_->name() << "': model returned a non-finite value at t = "
         << (w.nonfinite ? w.nonfinite_time : time) << " (duration " << t << ")";
      if (w.nonfinite && !w.nonfinite_reason.empty()) os << ": " << w.nonfinite_reason;
      return finish(FlowStatus::kNonFinite, os.str());
    }
    if (step_result == odeint::success) {
      ++result->counters.steps;
      if (observer) observer(time, z.head(n));
    } else {
      ++result->counters.rejected_steps;
    }
    if (std::abs(dt) < options_.min_step && direction * (t - time) > 0.0) {
      std::ostringstream os;
      os << "phase '" << phase_->name() << "': step size " << std::abs(dt) << " below min_step "
         << options_.min_step << " at t = " << time;
      return finish(FlowStatus::kStepTooSmall, os.str());
    }
  }
  return finish(FlowStatus::kSuccess, "");
}

}  // namespace hybridcont
