// Physical or not: the paper's solid vs dashed lines (Table `stateVStime` and the remark after it).
//
// A zero u of the time-based map is a periodic orbit of the mechanical system only if, in this order of
// checks (the first failing one is the reason):
//   xi = 0 (Thm 3.1; "at-rest" when all durations vanish too, e.g. the ball's xi-branch),
//   every t_i > 0 ("reversed-time" if some t_i < 0, "zero-duration" if some t_i = 0),
//   every event is crossed downward at the end of its phase (de·f < 0; "wrong-direction", "grazing"),
//   the anchor is crossed downward at the end of the return segment ("wrong-direction" where it is crossed
//   upward, "anchor-grazing" where it is touched),
//   the phase's event stays non-negative inside the phase — no earlier downward crossing and no start
//   beyond the guard, e.g. an end of the rod below the ground ("missed-event") — and no earlier anchor
//   crossing in the return segment ("missed-anchor"), searched on the dense output (orbit_trace.h).
//
//   Classification c = ClassifyOrbit(model, u, trace, ClassificationOptions{});
//   if (c.physical) ...; else std::cout << ToString(c.reason) << ": " << c.detail;
#ifndef HYBRIDCONT_CLASSIFICATION_H_
#define HYBRIDCONT_CLASSIFICATION_H_

#include <string>

#include "hybridcont/orbit_trace.h"

namespace hybridcont {

enum class OrbitClass {
  kPhysical,
  kAtRest,           // xi != 0 and all durations zero: an equilibrium of the dissipative unfolding
  kDissipative,      // xi != 0
  kReversedTime,     // some t_i < 0
  kZeroDuration,     // some t_i = 0 (violates As3)
  kWrongDirection,   // an event reached upward (de·f > 0)
  kGrazing,          // an event reached tangentially (de·f = 0, As2 violated)
  kAnchorGrazing,    // the anchor is not crossed transversally downward
  kMissedEvent,      // the event was crossed earlier in the phase, or the phase starts beyond it
  kMissedAnchor,     // the anchor was crossed earlier in the return segment
  kIntegrationFailed,
  kReplayFailed,     // passed every check on u, but event-driven re-simulation from x̄_1 does not return
  kConstraintViolated,  // an admissibility constraint of the model (observable.h) is negative
};
// Short hyphenated words used in the CSV files ("physical", "reversed-time", ...).
std::string ToString(OrbitClass c);
// The class of its word; false for anything else.
bool FromString(const std::string& text, OrbitClass* c);

struct ClassificationOptions {
  // |xi| above this is dissipative. Newton leaves |xi| ~ 1e-12 on orbits; branches at rest have |xi| ~ 1.
  double xi_tolerance = 1e-7;
  // |t_i| at or below this (relative to max(1, |T|)) counts as a zero duration.
  double duration_tolerance = 1e-7;
  // Normalized crossing speed (de·f) / (|de| |f|) above -this counts as grazing.
  double grazing_tolerance = 1e-6;
  // An admissibility constraint below -this is violated: its minimum is computed to the integrator's
  // tolerance (1e-10), and a constraint that is 0 at the ends of its phase (a foot clearance) must not
  // flip with the noise there.
  double constraint_tolerance = 1e-8;
  // Least interpolant evaluations per integrator step when searching earlier crossings (more where the
  // state moves fast: no component moves by more than 0.02 between samples).
  int samples_per_step = 8;
};

struct Classification {
  bool physical = false;
  OrbitClass reason = OrbitClass::kIntegrationFailed;
  std::string detail;  // which segment, time, value
};

Classification ClassifyOrbit(const HybridModel& model, const Vector& u, const OrbitTrace& trace,
                             const ClassificationOptions& options);

// ClassifyOrbit's checks on u alone (|ξ|, negative and zero durations), which need no trace: true, with
// *result set, when they decide; then ClassifyOrbit would return the same. Lets a caller skip the
// integration of the trace for most non-physical points (the SLIP: three of four points of its diagram).
bool ClassifyByUnknowns(const HybridModel& model, const Vector& u, const ClassificationOptions& options,
                        Classification* result);

}  // namespace hybridcont

#endif  // HYBRIDCONT_CLASSIFICATION_H_
