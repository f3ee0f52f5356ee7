#include "hybridcont/event_flow.h"

#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
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

// g and g_dot = dg · f~ at a time t of an integration.
struct GuardPoint {
  double t;
  double g;
  double g_dot;
};

// An event flow's buffers, kept from one integration to the next (EventFlow::Workspace).
struct EventFlowWorkspace {
  internal::AugmentedRhsWorkspace rhs;
  // odeint sizes a stepper's buffers on first use only (initially_resizer): one stepper per size of the
  // augmented state, [x] and [x; Phi; Psi].
  DenseDopri5 dense_plain, dense_sensitivities;
  Vector z, z_at;
  Vector f;
  RowVector dg;
  long extra_evaluations = 0;
  EventFlowWorkspace(double atol, double rtol)
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

// One integration of an event flow (EventFlow::Integrate): its workspace and dense output, the guard, the
// options, the prefix `where` of its messages and the caller's result, with the steps accepted so far.
struct EventFlowRun {
  EventFlowWorkspace& w;
  DenseDopri5& dense;
  const Guard& guard;
  const EventFlowOptions& options;
  const std::string& where;
  EventFlowResult* result;
  int n;
  bool with_sensitivities;
  long accepted;

  // Fills *result however the integration ends, and returns status: the message, the time t and the
  // augmented state z there (x, and Phi, Psi with sensitivities), g and g_dot with dg and f as last
  // evaluated (w.dg, w.f), the transversality |g_dot| / (|dg| |f~|) (0 where either vanishes) and the work.
  EventFlowStatus Finish(EventFlowStatus status, std::string message, double t, const Vector& z, double g,
                         double g_dot) const {
    result->status = status;
    result->message = std::move(message);
    result->t = t;
    result->x = z.head(n);
    if (with_sensitivities) {
      result->Phi = w.rhs.Phi(z);
      result->Psi = w.rhs.Psi(z);
    }
    result->f = w.f;
    result->g = g;
    result->dg = w.dg;
    result->g_dot = g_dot;
    const double scale = w.dg.norm() * w.f.norm();
    result->transversality = scale > 0.0 ? std::abs(g_dot) / scale : 0.0;
    result->counters.rhs_evaluations = w.rhs.rhs_evaluations + w.extra_evaluations;
    result->counters.steps = accepted;
    const long attempts = std::max(0L, (w.rhs.rhs_evaluations - 1) / kRhsPerAttempt);
    result->counters.rejected_steps = std::max(0L, attempts - accepted);
    return status;
  }

  // "<where>, t = <t>: " with t to 17 digits: the start of a message about time t.
  std::string At(double t) const {
    std::ostringstream os;
    os.precision(17);
    os << where << ", t = " << t << ": ";
    return os.str();
  }

  // The start x0 (with xi, the augmented state in w.z), passed to the observer: g and g_dot there in *g, *g_dot
  // (dg and f in w.dg, w.f) and whether the guard begins unarmed. A guard reached only from above that the
  // phase begins on or below is unarmed until the trajectory has left it upward; while it is, a rise by no
  // more than touch_tolerance that falls back (rounding, or a foot that starts on the ground and sinks into it
  // at once: the scuffing the model ignores) leaves it unarmed. Ends the integration with kNonFinite where x0,
  // xi, g or g_dot is not finite, with kZeroDuration where x0 lies on an armed guard moving down.
  std::optional<EventFlowStatus> Start(const Eigen::Ref<const Vector>& x0, const Eigen::Ref<const Vector>& xi,
                                       const EventFlow::Observer& observer, double* g, double* g_dot,
                                       bool* unarmed) const {
    if (!x0.allFinite() || !xi.allFinite()) {
      return Finish(EventFlowStatus::kNonFinite, where + ": non-finite initial state or xi", 0.0, w.z, 0.0, 0.0);
    }
    *g_dot = w.GuardRate(guard, x0, g);
    if (!std::isfinite(*g) || !std::isfinite(*g_dot)) {
      return Finish(EventFlowStatus::kNonFinite, At(0.0) + "guard or vector field non-finite at the initial state", 0.0,
                    w.z, *g, *g_dot);
    }
    if (observer) observer(0.0, x0);
    *unarmed = options.from_above && *g <= kGuardStartTolerance;
    if (*unarmed) {
      *g = std::min(*g, 0.0);  // on or below the guard: not above it
    } else if (std::abs(*g) <= options.start_tolerance && *g_dot < 0.0) {
      std::ostringstream os;
      os << where << ": the initial state lies on the guard (g = " << *g << ") moving down (g_dot = " << *g_dot
         << "): zero-duration phase";
      return Finish(EventFlowStatus::kZeroDuration, os.str(), 0.0, w.z, *g, *g_dot);
    }
    return std::nullopt;
  }

  // g at time t of the dense output (the state there left in w.z_at).
  double GuardAt(double t) const {
    dense.calc_state(t, w.z_at);
    return guard.Evaluate(w.z_at.head(n), nullptr);
  }

  // g and g_dot at time t of the dense output (the state there left in w.z_at, dg and f there in w.dg, w.f).
  GuardPoint GuardRateAt(double t) const {
    dense.calc_state(t, w.z_at);
    double g = 0.0;
    const double g_dot = w.GuardRate(guard, w.z_at.head(n), &g);
    return {t, g, g_dot};
  }

  // The extremum of g between t_a and t_b, where g_dot changes sign (from g_dot_a to g_dot_b): the zero of
  // g_dot on the dense output, with g and g_dot there as GuardRateAt gives them.
  GuardPoint GuardExtremum(double t_a, double t_b, double g_dot_a, double g_dot_b) const {
    const auto g_dot_at = [this](double t) { return GuardRateAt(t).g_dot; };
    return GuardRateAt(LocateRoot(g_dot_at, t_a, t_b, g_dot_a, g_dot_b));
  }

  // An exactly integrable flight (the rod's) is crossed in a few long steps while the guard oscillates
  // (sin of a fast angle): g is sampled on the interpolant so that no state component moves by more than
  // kMaxMotion between samples (speed_prev, speed_new: |f~|_inf at the step's ends), and the step
  // (*t_prev, *t_new] is narrowed to the sub-interval of the first downward sign change (the same rule as
  // the physical classification on the time-based trace, classification.h). Without one it stays as it is.
  void NarrowToFirstSampledCrossing(double speed_prev, double speed_new, double* t_prev, double* g_prev, double* t_new,
                                    double* g_new) const {
    constexpr double kMaxMotion = 0.02;
    constexpr int kMaxSamplesPerStep = 100000;
    const int samples = static_cast<int>(std::min<double>(
        kMaxSamplesPerStep, std::ceil(std::max(speed_prev, speed_new) * (*t_new - *t_prev) / kMaxMotion)));
    double t_a = *t_prev, g_a = *g_prev;
    for (int k = 1; k < samples; ++k) {
      const double t_b = *t_prev + (*t_new - *t_prev) * k / samples;
      const double g_b = GuardAt(t_b);
      if (g_a > 0.0 && g_b <= 0.0) {
        *t_new = t_b;  // the crossing lies in (t_a, t_b]: treat that sub-interval as the step
        *g_new = g_b;
        *t_prev = t_a;
        *g_prev = g_a;
        break;
      }
      t_a = t_b;
      g_a = g_b;
    }
    if (t_a > *t_prev && g_a > 0.0 && *g_new <= 0.0) {  // the crossing lies in the last sub-interval
      *t_prev = t_a;
      *g_prev = g_a;
    }
  }

  // The downward crossing in (t_prev, t_low] (g_prev > 0 >= g_low), located on the dense output and passed
  // to the observer: kEventReached, or kGrazing where g_dot there is not negative or the transversality
  // |g_dot| / (|dg| |f~|) is below grazing_tolerance.
  EventFlowStatus FinishAtCrossing(const EventFlow::Observer& observer, double t_prev, double g_prev, double t_low,
                                   double g_low) const {
    const auto g_at = [this](double t) { return GuardAt(t); };
    const GuardPoint event = GuardRateAt(LocateRoot(g_at, t_prev, t_low, g_prev, g_low));
    if (observer) observer(event.t, w.z_at.head(n));
    const double scale = w.dg.norm() * w.f.norm();
    const double ratio = scale > 0.0 ? std::abs(event.g_dot) / scale : 0.0;
    if (!(event.g_dot < 0.0) || ratio < options.grazing_tolerance) {
      std::ostringstream os;
      os << At(event.t) << "grazing crossing: |g_dot|/(|dg||f|) = " << ratio << " (g_dot = " << event.g_dot
         << ") below grazing_tolerance " << options.grazing_tolerance;
      return Finish(EventFlowStatus::kGrazing, os.str(), event.t, w.z_at, event.g, event.g_dot);
    }
    return Finish(EventFlowStatus::kEventReached, "", event.t, w.z_at, event.g, event.g_dot);
  }

  // After an accepted step to t_new (state z_new, g_new and g_dot_new there) without a crossing:
  // kGuardNotReached from max_duration on, kStepTooSmall where the step size fell below min_step; none else.
  std::optional<EventFlowStatus> FinishAtStepLimits(double t_new, const Vector& z_new, double g_new,
                                                    double g_dot_new) const {
    if (t_new >= options.max_duration) {
      std::ostringstream os;
      os << where << ": not crossed within max_duration = " << options.max_duration << " (g = " << g_new
         << " at t = " << t_new << ")";
      // A phase ends where its event falls through 0 from above: one that stays above never ends it (a model
      // file's event written with the opposite sign does so).
      if (g_new > 0) os << "; the event stays above 0, where a phase goes on: is its sign the intended one?";
      return Finish(EventFlowStatus::kGuardNotReached, os.str(), t_new, z_new, g_new, g_dot_new);
    }
    if (dense.current_time_step() < options.integrator.min_step) {
      std::ostringstream os;
      os << At(t_new) << "step size " << dense.current_time_step() << " below min_step " << options.integrator.min_step;
      return Finish(EventFlowStatus::kStepTooSmall, os.str(), t_new, z_new, g_new, g_dot_new);
    }
    return std::nullopt;
  }
};

}  // namespace

// The header keeps the workspace opaque; its type is the file's EventFlowWorkspace, which the integration's
// helpers above take.
struct EventFlow::Workspace : EventFlowWorkspace {
  using EventFlowWorkspace::EventFlowWorkspace;
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
  DenseDopri5& dense = with_sensitivities ? w.dense_sensitivities : w.dense_plain;
  const std::string where = "phase '" + phase_->name() + "', " + guard.name();
  EventFlowRun run{w, dense, guard, options_, where, result, n, with_sensitivities, /*accepted=*/0};

  double g_prev = 0.0, g_dot_prev = 0.0;
  bool unarmed = false;
  if (const std::optional<EventFlowStatus> ended = run.Start(x0, xi, observer, &g_prev, &g_dot_prev, &unarmed)) {
    return *ended;
  }

  double speed_prev = w.f.cwiseAbs().maxCoeff();  // |f~|_inf at the start of the current step
  dense.initialize(w.z, 0.0, options_.integrator.initial_step);
  double t_prev = 0.0;
  while (true) {
    if (run.accepted >= options_.integrator.max_steps) {
      std::ostringstream os;
      os << run.At(t_prev) << options_.integrator.max_steps << " steps exhausted before the guard was crossed";
      return run.Finish(EventFlowStatus::kMaxSteps, os.str(), t_prev, dense.current_state(), g_prev, g_dot_prev);
    }
    std::pair<double, double> span;
    try {
      span = dense.do_step(internal::AugmentedRhs{&rhs});
    } catch (const std::exception& e) {  // odeint's step-size adjustment gave up
      return run.Finish(EventFlowStatus::kStepTooSmall, run.At(t_prev) + e.what(), t_prev, dense.current_state(),
                        g_prev, g_dot_prev);
    }
    ++run.accepted;
    const Vector& z_new = dense.current_state();
    double t_new = span.second;
    if (rhs.nonfinite || !z_new.allFinite()) {
      const double t_bad = rhs.nonfinite ? rhs.nonfinite_time : t_new;
      return run.Finish(EventFlowStatus::kNonFinite,
                        run.At(t_bad) + "the model returned a non-finite value" +
                            (rhs.nonfinite_reason.empty() ? "" : ": " + rhs.nonfinite_reason),
                        t_bad, dense.previous_state(), g_prev, g_dot_prev);
    }
    double g_new = 0.0;
    double g_dot_new = w.GuardRate(guard, z_new.head(n), &g_new);
    if (!std::isfinite(g_new) || !std::isfinite(g_dot_new)) {
      return run.Finish(EventFlowStatus::kNonFinite, run.At(t_new) + "guard or vector field non-finite", t_new, z_new,
                        g_new, g_dot_new);
    }
    const double speed_new = w.f.cwiseAbs().maxCoeff();
    run.NarrowToFirstSampledCrossing(speed_prev, speed_new, &t_prev, &g_prev, &t_new, &g_new);
    speed_prev = speed_new;
    // A downward crossing inside (t_prev, t_new]: g changes sign across the step, or g dips to <= 0 and
    // back inside it (two crossings within one step: found at the local minimum, where g_dot = 0).
    bool crossing = g_prev > 0.0 && g_new <= 0.0;
    double t_low = t_new, g_low = g_new;
    // g rises above 0 and falls back inside one step (a guard that begins on 0 moving up: a short flight's
    // landing guard starts where the lift-off left the body, at the touch-down height): the downward crossing
    // lies after the local maximum, where g_dot = 0. A maximum within touch_tolerance of 0 cannot be told from
    // a tangency: grazing, as for a dip.
    if (!crossing && g_prev <= 0.0 && g_new <= 0.0 && g_dot_prev > 0.0 && g_dot_new < 0.0) {
      const GuardPoint peak = run.GuardExtremum(t_prev, t_new, g_dot_prev, g_dot_new);
      if (peak.g > options_.touch_tolerance) {
        crossing = true;
        t_prev = peak.t;
        g_prev = peak.g;
      } else if (peak.g > 0.0 && !unarmed) {
        std::ostringstream os;
        os << run.At(peak.t) << "the trajectory rises above the guard by only " << peak.g << " <= touch_tolerance "
           << options_.touch_tolerance << " and falls back: grazing";
        return run.Finish(EventFlowStatus::kGrazing, os.str(), peak.t, w.z_at, peak.g, peak.g_dot);
      }
    }
    if (!crossing && g_prev > 0.0 && g_new > 0.0 && g_dot_prev < 0.0 && g_dot_new > 0.0) {
      const GuardPoint dip = run.GuardExtremum(t_prev, t_new, g_dot_prev, g_dot_new);
      if (dip.g <= 0.0) {
        crossing = true;
        t_low = dip.t;
        g_low = dip.g;
      } else if (dip.g <= options_.touch_tolerance) {
        std::ostringstream os;
        os << run.At(dip.t) << "the trajectory touches the guard without crossing it (min g = " << dip.g
           << " <= touch_tolerance " << options_.touch_tolerance << "): grazing";
        return run.Finish(EventFlowStatus::kGrazing, os.str(), dip.t, w.z_at, dip.g, dip.g_dot);
      }
    }
    if (crossing) return run.FinishAtCrossing(observer, t_prev, g_prev, t_low, g_low);
    if (observer) observer(t_new, z_new.head(n));
    if (const std::optional<EventFlowStatus> ended = run.FinishAtStepLimits(t_new, z_new, g_new, g_dot_new)) {
      return *ended;
    }
    t_prev = t_new;
    g_prev = g_new;
    g_dot_prev = g_dot_new;
    unarmed = unarmed && g_new <= 0.0;
  }
}

}  // namespace hybridcont
