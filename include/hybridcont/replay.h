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
