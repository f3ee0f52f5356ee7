#include "hybridcont/event_flow.h"

#include <cmath>
#include <cstdint>
#include <limits>
#include <sstream>
#include <stdexcept>

#include <boost/math/tools/toms748_solve.hpp>
#include <boost/numeric/odeint.hpp>
#include <boost/numeric/odeint/external/eigen/eigen.hpp>

#include "integration/augmented_rhs.h"

#include "hybridcont/internal/enum_names.h"
#include "hybridcont/internal/options_check.h"

namespace hybridcont {

namespace {

constexpr internal::EnumName<EventFlowStatus> kEventFlowStatusNames[] = {
    {EventFlowStatus::kEventReached, "event reached"},
    {EventFlowStatus::kGrazing, "grazing"},
    {EventFlowStatus::kZeroDuration, "zero-duration phase"},
    {EventFlowStatus::kGuardNotReached, "guard not reached"},
    {EventFlowStatus::kNonFinite, "non-finite value"},
    {EventFlowStatus::kStepTooSmall, "step size too small"},
    {EventFlowStatus::kMaxSteps, "maximum number of steps"},
};

}  // namespace

namespace odeint = boost::numeric::odeint;

std::string ToString(EventFlowStatus status) { return internal::EnumToString(kEventFlowStatusNames, status); }

std::string EventFlowOptions::Validate() const {
  return internal::OptionsCheck("EventFlowOptions")
      .Nested("integrator", integrator.Validate())
      .Positive("max_duration", max_duration)
      .Positive("grazing_tolerance", grazing_tolerance)
      .Positive("touch_tolerance", touch_tolerance)
      .Positive("start_tolerance", start_tolerance)
      .Require(grazing_tolerance < 1.0, "grazing_tolerance", grazing_tolerance, "must be < 1 (it bounds a sine)")
      .message();
}

std::string EventFlowResult::BriefReport() const {
  std::ostringstream os;
  os << ToString(status) << ": t = " << t << ", transversality " << transversality << ", "
     << counters.steps << " steps, " << counters.rhs_evaluations << " rhs evaluations";
  return os.str();
}

namespace {

using Dopri5 = odeint::runge_kutta_dopri5<Vector, double, Vector, double, odeint::vector_space_algebra>;
using DenseDopri5 = decltype(odeint::make_dense_output(1.0, 1.0, Dopri5()));

// Dormand–Prince with FSAL draws 6 new right-hand sides per attempted step (plus 1 to initialize).
constexpr int kRhsPerAttempt = 6;

// Bracket [a, b] of a root of fn, shrunk by TOMS 748 to a few ulps; returns the end with the smaller |fn|.
template <class Fn>
double LocateRoot(Fn&& fn, double a, double b, double fa, double fb) {
  if (fb == 0.0) return b;
  std::uintmax_t max_iter = 200;
  const auto tol = [](double lo, double hi) {
    return std::abs(hi - lo) <= 4.0 * std::numeric_limits<double>::epsilon() * std::max(std::abs(lo), std::abs(hi));
  };
  const auto bracket = boost::math::tools::toms748_solve(fn, a, b, fa, fb, tol, max_iter);
  return std::abs(fn(bracket.first)) <= std::abs(fn(bracket.second)) ? bracket.first : bracket.second;
}

}  // namespace

struct EventFlow::Workspace {
  internal::AugmentedRhsWorkspace rhs;
  // odeint sizes a stepper's buffers on first use only (initially_resizer): one stepper per size of the
  // augmented state, [x] and [x; Phi; Psi].
  DenseDopri5 dense_plain, dense_sensitivities;
  Vector z, z_at;
  Vector f;
  RowVector dg;
  long extra_evaluations = 0;
  Workspace(double atol, double rtol)
      : dense_plain(odeint::make_dense_output(atol, rtol, Dopri5())),
        dense_sensitivities(odeint::make_dense_output(atol, rtol, Dopri5())) {}

  // g_dot = dg · f~ at x (one extra, counted, evaluation of f~ without derivatives); also sets dg and f.
  double GuardRate(const Guard& guard, const Eigen::Ref<const Vector>& x, double* g) {
    *g = guard.Evaluate(x, &dg);
    ++extra_evaluations;
    rhs.phase->UnfoldedVectorField(x, rhs.xi, &f, nullptr, nullptr);
    return dg.dot(f);
  }
};

EventFlow::EventFlow(const Phase& phase, EventFlowOptions options)
    : phase_(&phase), options_(options) {
  if (const std::string why = options.Validate(); !why.empty()) throw std::invalid_argument(why);
  workspace_ = std::make_unique<Workspace>(options.integrator.atol, options.integrator.rtol);
}
EventFlow::~EventFlow() = default;
EventFlow::EventFlow(EventFlow&&) noexcept = default;
EventFlow& EventFlow::operator=(EventFlow&&) noexcept = default;

EventFlowStatus EventFlow::Integrate(const Eigen::Ref<const Vector>& x0, const Eigen::Ref<const Vector>& xi,
                                     const Guard& guard, bool with_sensitivities, EventFlowResult* result) {
  return Integrate(x0, xi, guard, with_sensitivities, result, Observer());
}

EventFlowStatus EventFlow::Integrate(const Eigen::Ref<const Vector>& x0, const Eigen::Ref<const Vector>& xi,
                                     const Guard& guard, bool with_sensitivities, EventFlowResult* result,
                                     const Observer& observer) {
  Workspace& w = *workspace_;
  internal::AugmentedRhsWorkspace& rhs = w.rhs;
  const int n = phase_->dim();
  rhs.Start(*phase_, xi, with_sensitivities);
  rhs.InitialState(x0, &w.z);
  w.extra_evaluations = 0;
  *result = EventFlowResult();
  long accepted = 0;

  const std::string where = "phase '" + phase_->name() + "', " + guard.name();
  // Fills *result from the augmented state z at time t (event data from the workspace's f, dg).
  auto finish = [&](EventFlowStatus status, std::string message, double t, const Vector& z, double g,
                    double g_dot) {
    result->status = status;
    result->message = std::move(message);
    result->t = t;
    result->x = z.head(n);
    if (with_sensitivities) {
      result->Phi = rhs.Phi(z);
      result->Psi = rhs.Psi(z);
    }
    result->f = w.f;
    result->g = g;
    result->dg = w.dg;
    result->g_dot = g_dot;
    const double scale = w.dg.norm() * w.f.norm();
    result->transversality = scale > 0.0 ? std::abs(g_dot) / scale : 0.0;
    result->counters.rhs_evaluations = rhs.rhs_evaluations + w.extra_evaluations;
    result->counters.steps = accepted;
    const long attempts = std::max(0L, (rhs.rhs_evaluations - 1) / kRhsPerAttempt);
    result->counters.rejected_steps = std::max(0L, attempts - accepted);
    return status;
  };
  auto at = [&](double t) {
    std::ostringstream os;
    os.precision(17);
    os << where << ", t = " << t << ": ";
    return os.str();
  };

  if (!x0.allFinite() || !xi.allFinite()) {
    return finish(EventFlowStatus::kNonFinite, where + ": non-finite initial state or xi", 0.0, w.z, 0.0, 0.0);
  }
  double g_prev = 0.0;
  double g_dot_prev = w.GuardRate(guard, x0, &g_prev);
  if (!std::isfinite(g_prev) || !std::isfinite(g_dot_prev)) {
    return finish(EventFlowStatus::kNonFinite, at(0.0) + "guard or vector field non-finite at the initial state",
                  0.0, w.z, g_prev, g_dot_prev);
  }
  if (observer) observer(0.0, x0);
  // A guard reached only from above that the phase begins on or below is unarmed until the trajectory has
  // left it upward; while it is, a rise by no more than touch_tolerance that falls back (rounding, or a foot
  // that starts on the ground and sinks into it at once: the scuffing the model ignores) leaves it unarmed.
  bool unarmed = options_.from_above && g_prev <= kGuardStartTolerance;
  if (unarmed) {
    g_prev = std::min(g_prev, 0.0);  // on or below the guard: not above it
  } else if (std::abs(g_prev) <= options_.start_tolerance && g_dot_prev < 0.0) {
    std::ostringstream os;
    os << where << ": the initial state lies on the guard (g = " << g_prev << ") moving down (g_dot = "
       << g_dot_prev << "): zero-duration phase";
    return finish(EventFlowStatus::kZeroDuration, os.str(), 0.0, w.z, g_prev, g_dot_prev);
  }

  double speed_prev = w.f.cwiseAbs().maxCoeff();  // |f~|_inf at the start of the current step
  DenseDopri5& dense = with_sensitivities ? w.dense_sensitivities : w.dense_plain;
  dense.initialize(w.z, 0.0, options_.integrator.initial_step);
  double t_prev = 0.0;
  auto g_at = [&](double t) {
    dense.calc_state(t, w.z_at);
    return guard.Evaluate(w.z_at.head(n), nullptr);
  };
  while (true) {
    if (accepted >= options_.integrator.max_steps) {
      std::ostringstream os;
      os << at(t_prev) << options_.integrator.max_steps << " steps exhausted before the guard was crossed";
      return finish(EventFlowStatus::kMaxSteps, os.str(), t_prev, dense.current_state(), g_prev, g_dot_prev);
    }
    std::pair<double, double> span;
    try {
      span = dense.do_step(internal::AugmentedRhs{&rhs});
    } catch (const std::exception& e) {  // odeint's step-size adjustment gave up
      return finish(EventFlowStatus::kStepTooSmall, at(t_prev) + e.what(), t_prev, dense.current_state(), g_prev,
                    g_dot_prev);
    }
    ++accepted;
    const Vector& z_new = dense.current_state();
    double t_new = span.second;
    if (rhs.nonfinite || !z_new.allFinite()) {
      const double t_bad = rhs.nonfinite ? rhs.nonfinite_time : t_new;
      return finish(EventFlowStatus::kNonFinite, at(t_bad) + "the model returned a non-finite value" +
                                                        (rhs.nonfinite_reason.empty() ? "" : ": " + rhs.nonfinite_reason), t_bad,
                    dense.previous_state(), g_prev, g_dot_prev);
    }
    double g_new = 0.0;
    double g_dot_new = w.GuardRate(guard, z_new.head(n), &g_new);
    if (!std::isfinite(g_new) || !std::isfinite(g_dot_new)) {
      return finish(EventFlowStatus::kNonFinite, at(t_new) + "guard or vector field non-finite", t_new, z_new, g_new,
                    g_dot_new);
    }

    // An exactly integrable flight (the rod's) is crossed in a few long steps while the guard oscillates
    // (sin of a fast angle): sample g on the interpolant so that no state component moves by more than
    // kMaxMotion between samples, and take the first downward sign change (the same rule as the physical
    // classification on the time-based trace, classification.h).
    constexpr double kMaxMotion = 0.02;
    constexpr int kMaxSamplesPerStep = 100000;
    const double speed_new = w.f.cwiseAbs().maxCoeff();
    const int samples = static_cast<int>(std::min<double>(
        kMaxSamplesPerStep, std::ceil(std::max(speed_prev, speed_new) * (t_new - t_prev) / kMaxMotion)));
    speed_prev = speed_new;
    double t_a = t_prev, g_a = g_prev;
    for (int k = 1; k < samples; ++k) {
      const double t_b = t_prev + (t_new - t_prev) * k / samples;
      const double g_b = g_at(t_b);
      if (g_a > 0.0 && g_b <= 0.0) {
        t_new = t_b;  // the crossing lies in (t_a, t_b]: treat that sub-interval as the step
        g_new = g_b;
        t_prev = t_a;
        g_prev = g_a;
        break;
      }
      t_a = t_b;
      g_a = g_b;
    }
    if (t_a > t_prev && g_a > 0.0 && g_new <= 0.0) {  // the crossing lies in the last sub-interval
      t_prev = t_a;
      g_prev = g_a;
    }
    // A downward crossing inside (t_prev, t_new]: g changes sign across the step, or g dips to <= 0 and
    // back inside it (two crossings within one step: found at the local minimum, where g_dot = 0).
    bool crossing = g_prev > 0.0 && g_new <= 0.0;
    double t_low = t_new, g_low = g_new;
    auto g_dot_at = [&](double t) {
      dense.calc_state(t, w.z_at);
      double g = 0.0;
      return w.GuardRate(guard, w.z_at.head(n), &g);
    };
    // g rises above 0 and falls back inside one step (a guard that begins on 0 moving up: a short flight's
    // landing guard starts where the lift-off left the body, at the touch-down height): the downward crossing
    // lies after the local maximum, where g_dot = 0. A maximum within touch_tolerance of 0 cannot be told from
    // a tangency: grazing, as for a dip.
    if (!crossing && g_prev <= 0.0 && g_new <= 0.0 && g_dot_prev > 0.0 && g_dot_new < 0.0) {
      const double t_max = LocateRoot(g_dot_at, t_prev, t_new, g_dot_prev, g_dot_new);
      dense.calc_state(t_max, w.z_at);
      double g_max = 0.0;
      const double g_dot_max = w.GuardRate(guard, w.z_at.head(n), &g_max);
      if (g_max > options_.touch_tolerance) {
        crossing = true;
        t_prev = t_max;
        g_prev = g_max;
      } else if (g_max > 0.0 && !unarmed) {
        std::ostringstream os;
        os << at(t_max) << "the trajectory rises above the guard by only " << g_max << " <= touch_tolerance "
           << options_.touch_tolerance << " and falls back: grazing";
        return finish(EventFlowStatus::kGrazing, os.str(), t_max, w.z_at, g_max, g_dot_max);
      }
    }
    if (!crossing && g_prev > 0.0 && g_new > 0.0 && g_dot_prev < 0.0 && g_dot_new > 0.0) {
      const double t_min = LocateRoot(g_dot_at, t_prev, t_new, g_dot_prev, g_dot_new);
      dense.calc_state(t_min, w.z_at);
      double g_min = 0.0;
      const double g_dot_min = w.GuardRate(guard, w.z_at.head(n), &g_min);
      if (g_min <= 0.0) {
        crossing = true;
        t_low = t_min;
        g_low = g_min;
      } else if (g_min <= options_.touch_tolerance) {
        std::ostringstream os;
        os << at(t_min) << "the trajectory touches the guard without crossing it (min g = " << g_min
           << " <= touch_tolerance " << options_.touch_tolerance << "): grazing";
        return finish(EventFlowStatus::kGrazing, os.str(), t_min, w.z_at, g_min, g_dot_min);
      }
    }
    if (crossing) {
      const double t_event = LocateRoot(g_at, t_prev, t_low, g_prev, g_low);
      dense.calc_state(t_event, w.z_at);
      double g = 0.0;
      const double g_dot = w.GuardRate(guard, w.z_at.head(n), &g);
      if (observer) observer(t_event, w.z_at.head(n));
      const double scale = w.dg.norm() * w.f.norm();
      const double ratio = scale > 0.0 ? std::abs(g_dot) / scale : 0.0;
      if (!(g_dot < 0.0) || ratio < options_.grazing_tolerance) {
        std::ostringstream os;
        os << at(t_event) << "grazing crossing: |g_dot|/(|dg||f|) = " << ratio << " (g_dot = " << g_dot
           << ") below grazing_tolerance " << options_.grazing_tolerance;
        return finish(EventFlowStatus::kGrazing, os.str(), t_event, w.z_at, g, g_dot);
      }
      return finish(EventFlowStatus::kEventReached, "", t_event, w.z_at, g, g_dot);
    }
    if (observer) observer(t_new, z_new.head(n));
    if (t_new >= options_.max_duration) {
      std::ostringstream os;
      os << where << ": not crossed within max_duration = " << options_.max_duration << " (g = " << g_new
         << " at t = " << t_new << ")";
      return finish(EventFlowStatus::kGuardNotReached, os.str(), t_new, z_new, g_new, g_dot_new);
    }
    if (dense.current_time_step() < options_.integrator.min_step) {
      std::ostringstream os;
      os << at(t_new) << "step size " << dense.current_time_step() << " below min_step "
         << options_.integrator.min_step;
      return finish(EventFlowStatus::kStepTooSmall, os.str(), t_new, z_new, g_new, g_dot_new);
    }
    t_prev = t_new;
    g_prev = g_new;
    g_dot_prev = g_dot_new;
    unarmed = unarmed && g_new <= 0.0;
  }
}

}  // namespace hybridcont
