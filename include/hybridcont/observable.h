// Observables: named quantities of a periodic orbit that users measure (COCO's monitor functions, AUTO's
// user functions, BifurcationKit's record_from_solution), declared with the model.
//
// An observable is one of
//   value      g(v, p): a function of the orbit's unknowns v = [t_{m+1}, x̄_{m+1}, ..., t_1, x̄_1, ξ, H̄]
//              (the time-based layout without free parameters, shooting_layout.h) and the model's
//              parameters p: a state at a section ("x2_dx"), a duration, the period, a parameter;
//   integral   Σ_s ∫_0^{t_s} g_i(x_s(t), p) dt over the shooting segments s of the phases i it names
//              (segment m+1 is phase 1 again): a stride length, an impulse, a cost of transport's work;
//   mean       the integral divided by the summed durations of those segments: a mean forward speed;
//   minimum,   the extreme value of g_i(x_s(t)) over t in [0, t_s] and the same segments: a peak force, a
//   maximum    lowest foot height;
//   final      g_i at the end of the segment that phase i's event ends (segment i, before its reset), for
//              the one phase it names: a touch-down velocity, an impact angle.
// An admissibility constraint is a minimum that a physical orbit keeps >= 0 (ground force, foot clearance,
// a friction cone written as μ F_n − |F_t|), or a final value that it keeps >= 0 (the foot moving toward
// the ground at touch-down): the classification names the constraint an orbit violates, and a family
// crossing its boundary has a located special point there.
//
// A constraint's value is its smallest *interior* local minimum over the segments, or, where g has none,
// the smaller end value: a clearance that is 0 at both ends of the phase (the foot leaves and reaches the
// ground) is then 0 on admissible orbits and negative where the trajectory dips below, and its boundary
// (the dip touching 0, a grazing of the constraint) is a regular zero of the interior minimum.
//
// Functions come with exact gradients (SmoothFunction), so that an observable can be an equation of the
// zero problem (held fixed, or a continuation parameter of its own: shooting_layout.h, "Observables") with
// exact derivatives: through the flow's sensitivities for integrals and means, and by the envelope
// theorem for interior extrema (dG = ∇g(x(t*)) dx(t*): t* drops out, ġ(t*) = 0).
//
//   model.AddObservable({"speed", "mean forward speed", ObservableKind::kMean, nullptr,
//                        {stance_speed, flight_speed}});     // one SmoothFunction per phase
#ifndef HYBRIDCONT_OBSERVABLE_H_
#define HYBRIDCONT_OBSERVABLE_H_

#include <memory>
#include <string>
#include <vector>

#include "hybridcont/types.h"

namespace hybridcont {

// A smooth function g(x, p) of a vector x and the model's parameters p (all of them, in
// HybridModel::parameters() order), with gradients dx (row, size of x) and dp (row, size of p), each
// optional. Thread-safe for concurrent const calls.
class SmoothFunction {
 public:
  virtual ~SmoothFunction() = default;
  virtual double Evaluate(const Eigen::Ref<const Vector>& x, const Eigen::Ref<const Vector>& p, RowVector* dx,
                          RowVector* dp) const = 0;
};

enum class ObservableKind { kValue, kIntegral, kMean, kMinimum, kMaximum, kFinal };
std::string ToString(ObservableKind kind);

struct Observable {
  std::string name;         // a CSV column and an unknown's name: no other unknown or parameter has it
  std::string description;  // for reports
  ObservableKind kind = ObservableKind::kValue;
  // kValue: g(v, p) of the orbit's unknowns (see above).
  std::shared_ptr<const SmoothFunction> value;
  // Other kinds: g_i(x, p) per phase i of the model (num_phases entries); nullptr leaves phase i out.
  std::vector<std::shared_ptr<const SmoothFunction>> phases;
  // An admissibility constraint (kind kMinimum or kFinal): a physical orbit keeps the value >= 0.
  bool constraint = false;
  // A competing transition's guard (hybrid_automaton.h). It fires at a downward zero crossing, so it counts
  // only where it is reached from above: from the first time it is positive in its phase. A phase that begins
  // on it (within round-off: right after that very transition, or one with the same guard) or below it (a
  // swing foot under the ground as it passes the stance leg) leaves it unarmed until it has risen above 0;
  // where it never does, the value is -max g over its phases (>= 0: the margin by which it stays unreached).
  bool guard = false;
};

}  // namespace hybridcont

#endif  // HYBRIDCONT_OBSERVABLE_H_
