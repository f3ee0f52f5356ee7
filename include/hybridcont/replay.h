// Replay: an independent, event-driven re-simulation of a physical orbit found by the time-based map.
//
// The time-based map (eq. `timebased`) makes events equations; a solution may therefore end a phase at a
// zero of e_i that is not its *first* downward crossing, or at an upward one (paper Table `stateVStime`).
// Replay checks the orbit the way the physics runs it: from x̄_1 with xi of u, every phase is integrated
// until its event fires (event_flow.h: first transversal downward crossing), reset, and finally until the
// anchor fires. The orbit is confirmed when it returns to itself:
//
//     replay error      = | x_end - x̄_1 |                        (2-norm; states are O(1) in our units)
//     period error      = | T_replay - T_u | / |T_u|              (T_u = sum of the t_i of u)
//     event time error  = | t_i^E - t_i | / |T_u|, i = 1..m+1     (relative to the period: some t_i are ~0)
//
// A replay that does not close is examined before the orbit is refused. An ill-conditioned orbit amplifies
// every error: a short phase whose guard is met at a low crossing speed v (a flight of 4e-3 lifts the body
// by only 2e-6) ends δ/v later for a state δ off at its start, so the replay's own integration error
// (~rtol over the phases before) and the time-based solution's (x̄_1 of u is accurate to its integration
// error) can both leave a true orbit further than `tolerance` from x̄_1 after one replay. Two checks follow,
// each independent of the time-based solution but for its x̄_1:
//   1. the replay at tolerances `refined_tolerance_factor` times the given ones (integration error);
//   2. on that map, Newton for its fixed point with the first integrals held at their values at x̄_1 (the
//      rows dH δ = H(x̄_1) − H(x) fix the step along the family, where P − I is singular):
//          [dP/dx − I; dH] δ = −[P(x) − x; H(x) − H(x̄_1)]   (least squares),  x ← x + δ,
//      at most `fixed_point_iterations` steps from x = x̄_1 (the time-based solution's error).
// The orbit is confirmed (kReturned, with a message saying how) when the refined replay returns to within
// `tolerance`, from x̄_1 or from a fixed point x within `tolerance` of x̄_1 (fixed_point_distance).
// Otherwise the replay stays kNotClosed, with every figure in the message.
//
//   ReplayResult rp = ReplayOrbit(model, u, ReplayOptions{});
//   if (!rp.physical()) ...  // not a physical orbit (or not one to this accuracy): rp.message says why
#ifndef HYBRIDCONT_REPLAY_H_
#define HYBRIDCONT_REPLAY_H_

#include <string>
#include <vector>

#include "hybridcont/poincare_map.h"

namespace hybridcont {

struct ReplayOptions {
  // Event-driven integration (section must be kAnchor: u ends at the anchor).
  PoincareOptions poincare;
  // Largest replay error for which the orbit returns to itself. The time-based corrector converges to
  // |r| ~ 1e-10 and both integrations carry errors ~rtol = 1e-10 over O(10) time units; 1e-7 leaves two
  // orders of margin above that and stays far below any physically visible mismatch.
  double tolerance = 1e-7;
  // The examination of a replay that does not close (see the header comment): the integrator's tolerances
  // times this (not below 1e-14), then Newton steps on that map; 0 steps: none.
  double refined_tolerance_factor = 1e-2;
  int fixed_point_iterations = 4;

  std::string Validate() const;
};

enum class ReplayStatus {
  kReturned,     // every event fired transversally and the state came back within tolerance
  kNotClosed,    // the replay ran through, but x_end is not x̄_1 (error above tolerance)
  kEventFailed,  // a phase ended otherwise (grazing, zero duration, guard not reached, NaN): see message
};
std::string ToString(ReplayStatus status);

struct ReplayResult {
  ReplayStatus status = ReplayStatus::kReturned;
  std::string message;
  double error = 0.0;         // |x_end - x̄_1|
  double period = 0.0;        // replayed period t^A
  double period_error = 0.0;  // relative to the period of u
  std::vector<double> event_times;        // replayed t_1^E..t_m^E, t^A_{m+1}
  std::vector<double> event_time_errors;  // |t_i^E - t_i| / |T_u|
  double max_event_time_error = 0.0;
  // The replayed map's fixed point, when the replay from x̄_1 did not close and Newton found one (see the
  // header comment): its distance from x̄_1 and the Newton steps; 0 when the replay closed by itself.
  double fixed_point_distance = 0.0;
  int fixed_point_steps = 0;
  Vector x_end;
  FlowCounters counters;

  // The caller's verdict: only a returned replay confirms a physical orbit.
  bool physical() const { return status == ReplayStatus::kReturned; }
  std::string BriefReport() const;
};

// Replays u (time-based layout, shooting_layout.h) of model. Throws std::invalid_argument for a wrong
// size of u or invalid options; numerical outcomes are in the status.
ReplayResult ReplayOrbit(const HybridModel& model, const Vector& u, const ReplayOptions& options = {});

}  // namespace hybridcont

#endif  // HYBRIDCONT_REPLAY_H_
