// The observables of a model (observable.h) evaluated at a point u of the time-based map, with their
// exact gradients with respect to u: the Jacobian rows of observables that join the zero problem
// (shooting_layout.h, "Observables"), and the values written with every branch point.
//
// How each kind is computed (segments s of the phases the observable names; x_s(t) = φ_s(t, x̄_s; ξ)):
//   value      g(v, p), its gradient mapped onto u (free parameters through their columns);
//   integral   the quadrature state q' = g_i(x), q(0) = 0, integrated with the phase as one augmented
//              system (QuadraturePhase), so that dq(t_s)/d(x̄_s, ξ, p) are rows of the flow's own
//              sensitivities Φ, Ψ (eqs. `diffState`, `diffParam`) and dq/dt_s = g_i(x_s(t_s));
//   mean       integral / Σ t_s, by the quotient rule;
//   final      g_i(x_i(t_i)) at the end of segment i: ∇g times the sensitivities there, ∇g·f~ for t_i;
//   extremum   the accepted steps of the phase's flow sample g along the segment; the extreme sample's
//              neighbouring step holds the zero of ġ = ∇g·f~, found by TOMS 748 on short integrations from
//              the sample, to a few ulps in time. By the envelope theorem the gradient is ∇g(x(t*)) times the
//              sensitivities of x(t*) (one integration with sensitivities to t*), plus ∂g/∂p; dG/dt_s is
//              ġ(t_s) where the extremum is the segment's end, else 0. An extremum that falls between
//              samples without a sign change of ġ (two in one step) is not seen: the step control keeps steps
//              short compared with the curvature of smooth trajectories.
// Contract: one evaluator serves one thread (its integrators are scratch); `model` carries the parameter
// values of u (the shooting map's own copy when parameters are free) and outlives the evaluator; the
// layout is copied.
#ifndef HYBRIDCONT_ORBIT_OBSERVABLES_H_
#define HYBRIDCONT_ORBIT_OBSERVABLES_H_

#include <map>
#include <memory>
#include <utility>
#include <vector>

#include "hybridcont/flow.h"
#include "hybridcont/shooting_layout.h"
#include "hybridcont/zero_problem.h"

namespace hybridcont {

class ObservableEvaluator {
 public:
  ObservableEvaluator(const HybridModel& model, const ShootingLayout& layout, IntegratorOptions options);
  ~ObservableEvaluator();
  ObservableEvaluator(ObservableEvaluator&&) noexcept;
  ObservableEvaluator& operator=(ObservableEvaluator&&) noexcept;

  // Model observable `observable` (index into model.observables()) at u (layout's unknowns, of which only
  // the orbit's and the free parameters' are read): *value, and *du (row, size of u; optional) its
  // gradient. A failed integration or a mean over a zero total duration is a failure status naming it.
  EvaluationStatus Evaluate(int observable, const Vector& u, double* value, RowVector* du);

  // All observables of the model at u (no gradients); NaN where one fails.
  Vector EvaluateAll(const Vector& u);

  // An extremum observable that the model does not hold (kind kMinimum or kMaximum, `phases` with one
  // entry per phase of the model), evaluated as Evaluate evaluates the model's own; e.g. OwnEventObservable.
  EvaluationStatus EvaluateExtremum(const Observable& o, const Vector& u, double* value, RowVector* du);

  // Whether the last extremum evaluated lies inside its segment (not at an end): a constraint's boundary
  // is a zero of its interior minimum (observable.h).
  bool last_extremum_interior() const { return last_interior_; }
  // Where it was attained: the shooting segment and the time in it (0 <= |t| <= |t_s|).
  int last_extremum_segment() const { return last_segment_; }
  double last_extremum_time() const { return last_time_; }

  // Work of the integrations since the last ResetCounters().
  const FlowCounters& counters() const { return counters_; }
  void ResetCounters() { counters_ = FlowCounters(); }

 private:
  EvaluationStatus Integral(const Observable& o, int observable, const Vector& u, double* value, RowVector* du);
  EvaluationStatus Extremum(const Observable& o, const Vector& u, double* value, RowVector* du);
  // Whether guard observable o's segment s begins armed at u (observable.h); p: the parameter values, sign: 1
  // for o's minimum (-1 for a maximum).
  bool GuardArmedAtStart(const Observable& o, const Vector& u, const Vector& p, double sign, int s);
  EvaluationStatus Final(const Observable& o, const Vector& u, double* value, RowVector* du);
  // g(x_s(t)) on segment s and, with du, its gradient: ∇g times the sensitivities at t plus ∂g/∂p, and, where
  // t is the segment's end (is_end), ∇g·f~ for t_s.
  EvaluationStatus ValueAt(const SmoothFunction& g, int segment, double t, bool is_end, const Vector& u,
                           double* value, RowVector* du);
  Vector Parameters() const;
  void AddParameterGradient(const RowVector& dp, RowVector* du) const;

  const HybridModel* model_;
  ShootingLayout layout_;
  IntegratorOptions options_;
  std::vector<int> free_parameters_;  // model indices of the layout's free parameters
  std::vector<PhaseFlow> flows_;      // one per phase, with the free parameters' sensitivities
  // Quadrature phases and their flows, per (observable, phase), made at first use.
  struct Quadrature;
  std::map<std::pair<int, int>, std::unique_ptr<Quadrature>> quadratures_;
  FlowCounters counters_;
  bool last_interior_ = false;
  int last_segment_ = -1;
  double last_time_ = 0.0;
};

// Phase `phase`'s own event e_i as a guard observable (observable.h: a minimum that counts from where the
// event has been above 0, as an automaton's competing guard does), over the segments of that phase. Its
// smallest *interior* minimum is the margin by which the trajectory clears the event before the phase's
// end; it is 0 where the event is touched inside the phase, the grazing beyond which the orbit crosses its
// event early (classified missed-event). Reads `model`'s phase, which must outlive the observable; the
// gradient with respect to the parameters needs Phase::has_parameter_derivatives.
Observable OwnEventObservable(const HybridModel& model, int phase);

}  // namespace hybridcont

#endif  // HYBRIDCONT_ORBIT_OBSERVABLES_H_
