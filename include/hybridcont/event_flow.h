// Event-driven phase integration: integrate until a guard crosses zero downward (paper eq.
// `time2transition`, the state-based column of Table `stateVStime`).
//
// A phase of the unfolded system x' = f~(x, xi) (eq. `hybridDynamicsNum`) runs from x0 until the first
// time t_E > 0 at which its guard g (the phase's event function e_i, or the anchor a of phase 1) crosses
// zero from + to -:
//
//     t_E(x0) = inf { t > 0 : g(phi(t, x0; xi)) = 0,  g_dot = dg · f~ < 0 }.
//
// Trigger rule, exactly:
//   - a crossing is a sign change g > 0  ->  g <= 0 between two accepted steps; it is located by a
//     bracketing root finder (TOMS 748) on the step's dense-output interpolant, never by re-integrating,
//     to a bracket of a few ulps in time. x, Phi = dphi/dx0 and Psi = dphi/dxi at t_E come from the same
//     interpolant (the sensitivities are part of the integrated state, so they share its accuracy);
//   - a start on the guard moving up (g(x0) = 0, g_dot > 0: the state right after a reset, e.g. the ball
//     at y = 0 with dy > 0) is not an event; a start on the guard moving down is a zero-duration phase
//     (kZeroDuration: it violates assumption As3 and the state-based map is undefined there);
//   - transversality (assumption As2, eq. `noGrazing`) is measured by the ratio
//         |g_dot| / (|dg| |f~|),
//     the sine of the angle between the flow and the guard; below grazing_tolerance the crossing is
//     reported as kGrazing (the saltation matrix, eq. `Saltation`, would divide by ~0). A trajectory that
//     touches the guard without crossing it (g has a local minimum in [0, touch_tolerance]) is grazing too:
//     an exact tangency cannot be told from a tangential crossing in floating point.
//   - no crossing within max_duration is kGuardNotReached, not a hang; NaN/Inf from the model is
//     kNonFinite with phase and time.
//
//   EventFlow flow(model.phase(0), EventFlowOptions{});
//   EventFlowResult res;
//   flow.Integrate(x0, xi, PhaseEventGuard(model.phase(0)), /*with_sensitivities=*/true, &res);
//   if (res.ok()) { res.t, res.x, res.Phi, res.Psi, res.g_dot ... }
//
// Stepping is Boost.Odeint's dense-output Dormand–Prince 5(4) (its 4th-order continuous extension is the
// interpolant; odeint offers no dense output for Fehlberg 7(8)), with the error control over the whole
// augmented state [x; Phi; Psi], as in PhaseFlow (flow.h).
#ifndef HYBRIDCONT_EVENT_FLOW_H_
#define HYBRIDCONT_EVENT_FLOW_H_

#include <functional>
#include <memory>
#include <string>

#include "hybridcont/flow.h"

namespace hybridcont {

// A guard g: X_i -> R whose downward zero crossing ends an event-driven integration.
class Guard {
 public:
  virtual ~Guard() = default;
  // g(x) and, if dg != nullptr, its gradient (row).
  virtual double Evaluate(const Eigen::Ref<const Vector>& x, RowVector* dg) const = 0;
  // For messages, e.g. "event of phase 'flight'" or "anchor".
  virtual std::string name() const = 0;
};

// The event function e_i of a phase.
class PhaseEventGuard : public Guard {
 public:
  explicit PhaseEventGuard(const Phase& phase) : phase_(&phase) {}
  double Evaluate(const Eigen::Ref<const Vector>& x, RowVector* dg) const override { return phase_->Event(x, dg); }
  std::string name() const override { return "event of phase '" + phase_->name() + "'"; }

 private:
  const Phase* phase_;
};

// The anchor a of the Poincaré section (phase 1).
class AnchorGuard : public Guard {
 public:
  explicit AnchorGuard(const Anchor& anchor) : anchor_(&anchor) {}
  double Evaluate(const Eigen::Ref<const Vector>& x, RowVector* da) const override { return anchor_->Evaluate(x, da); }
  std::string name() const override { return "anchor"; }

 private:
  const Anchor* anchor_;
};

// Any other guard, given as a function (tests, user-defined sections).
class FunctionGuard : public Guard {
 public:
  using Function = std::function<double(const Eigen::Ref<const Vector>&, RowVector*)>;
  FunctionGuard(std::string name, Function g) : name_(std::move(name)), g_(std::move(g)) {}
  double Evaluate(const Eigen::Ref<const Vector>& x, RowVector* dg) const override { return g_(x, dg); }
  std::string name() const override { return name_; }

 private:
  std::string name_;
  Function g_;
};

// An automaton's guard at most this where its phase begins is on it, not above it: the phase begins where
// the transition before it fired, and a guard equal to that one's (two legs landing at the same height) is 0
// there up to the corrector's tolerance. One value for every place that decides a crossing (the event flow,
// the guard constraints, the classification and the automaton's simulation).
inline constexpr double kGuardStartTolerance = 1e-8;

struct EventFlowOptions {
  // rtol, atol, initial_step, min_step and max_steps as for time-based flows (the same accuracy for both
  // formulations makes their results comparable). `method` is not used: event location needs a dense
  // output, and odeint has one for Dormand–Prince 5(4) only.
  IntegratorOptions integrator;
  // A phase whose guard is not crossed within this time returns kGuardNotReached. 100 time units is ~16
  // periods of the slowest built-in motion (SLIP stance at k = 40 has T0 ~ 1): a real event is long past.
  double max_duration = 100.0;
  // Crossings with |g_dot| / (|dg| |f~|) below this are kGrazing. The saltation matrix divides by g_dot,
  // so with an integration error ~rtol = 1e-10 a ratio of 1e-7 already costs ~3 of the ~10 digits of the
  // Jacobian; below that the state-based map is not worth trusting (paper §3.4: it must fail there).
  double grazing_tolerance = 1e-7;
  // A local minimum of g in [0, touch_tolerance] without a crossing is a grazing touch. Of the order of the
  // integration error of g (atol-sized): a smaller dip cannot be told from a tangential crossing.
  double touch_tolerance = 1e-9;
  // |g(x0)| at or below this counts as "starting on the guard" (then g_dot decides: moving down is a
  // zero-duration phase, moving up is ignored). Round-off of a reset map lands within ~1e-15 of the guard.
  double start_tolerance = 1e-12;
  // A hybrid automaton's guard (observable.h) fires where it is crossed from above: a start on it (within
  // kGuardStartTolerance) or below it is then a guard not yet armed, integrated on until it has been above 0,
  // not a zero-duration phase.
  bool from_above = false;

  // Empty if valid; otherwise names the field, its value and the violated constraint.
  std::string Validate() const;
};

enum class EventFlowStatus {
  kEventReached,     // transversal downward crossing located
  kGrazing,          // tangential crossing or touch (ratio < grazing_tolerance): assumption As2 violated
  kZeroDuration,     // x0 lies on the guard moving down: the phase has zero duration (As3 violated)
  kGuardNotReached,  // no crossing within max_duration
  kNonFinite,        // the model or guard returned NaN/Inf (message: phase, time)
  kStepTooSmall,     // step size fell below min_step (or odeint gave up adjusting it)
  kMaxSteps,         // max_steps accepted steps without reaching the guard
};
std::string ToString(EventFlowStatus status);

struct EventFlowResult {
  EventFlowStatus status = EventFlowStatus::kEventReached;
  std::string message;  // empty on success
  // Event time t_E (on failure: the time reached, or of the grazing point).
  double t = 0.0;
  Vector x;    // x^- = phi(t_E, x0; xi)
  Matrix Phi;  // dphi/dx0 at t_E (fixed t; the event-time sensitivity is the saltation's job), n x n
  Matrix Psi;  // dphi/dxi at t_E, n x k
  Vector f;            // f~(x^-, xi)
  double g = 0.0;      // g(x^-), ~0
  RowVector dg;        // dg(x^-)
  double g_dot = 0.0;  // dg · f~ (< 0 for a transversal downward crossing)
  double transversality = 0.0;  // |g_dot| / (|dg| |f~|), in [0, 1]
  FlowCounters counters;        // rhs_evaluations include the few extra f~ evaluations of the guard checks

  bool ok() const { return status == EventFlowStatus::kEventReached; }
  // One line: status, t_E, transversality, work.
  std::string BriefReport() const;
};

class EventFlow {
 public:
  // Keeps a reference to phase. Throws std::invalid_argument if options are invalid.
  EventFlow(const Phase& phase, EventFlowOptions options);
  ~EventFlow();
  EventFlow(EventFlow&&) noexcept;
  EventFlow& operator=(EventFlow&&) noexcept;

  // Integrates forward from x0 with unfolding parameters xi (size k) until guard crosses zero downward.
  // Fills *result and returns its status; never throws for numerical outcomes.
  EventFlowStatus Integrate(const Eigen::Ref<const Vector>& x0, const Eigen::Ref<const Vector>& xi,
                            const Guard& guard, bool with_sensitivities, EventFlowResult* result);

  // Same, calling observer(t, x) at the start, after every accepted step before the event, and at t_E.
  using Observer = PhaseFlow::Observer;
  EventFlowStatus Integrate(const Eigen::Ref<const Vector>& x0, const Eigen::Ref<const Vector>& xi,
                            const Guard& guard, bool with_sensitivities, EventFlowResult* result,
                            const Observer& observer);

  const Phase& phase() const { return *phase_; }
  const EventFlowOptions& options() const { return options_; }

 private:
  struct Workspace;
  const Phase* phase_;
  EventFlowOptions options_;
  std::unique_ptr<Workspace> workspace_;
};

}  // namespace hybridcont

#endif  // HYBRIDCONT_EVENT_FLOW_H_
