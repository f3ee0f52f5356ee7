// Starting points without an equilibrium: an event-driven simulation that settles on an attracting orbit.
//
// A model without first integral (a passive walker, a damped forced oscillator) has no equilibrium to
// branch from in general; its stable gaits are found the way an experimenter finds them: start somewhere,
// let it run, and wait until every cycle repeats the last. From a state x1 of phase 1, the cycle of
// phases is simulated event by event (each phase until its event, event_flow.h, then its reset; phase 1
// again until the anchor), and each return to the Poincaré section is compared with the previous one.
// When two returns agree to `tolerance` the last cycle is the start: its states at the segment starts and
// its durations, as a point of the time-based layout at the model's parameter values, for Newton to refine.
//
//   SimulationStartResult s = SimulateToOrbit(model, x1, SimulationStartOptions{});
//   if (s.converged) u0 = s.u;   // ShootingLayout(model) without free parameters
//
// Contract: the phase sequence is the model's cycle; an event that is not reached within max_phase_time,
// a grazing or a non-finite state ends the simulation with the reason (converged = false). A cycle that
// does not settle within max_cycles (an unstable or chaotic gait, a walker that falls) is reported with
// the last change.
#ifndef HYBRIDCONT_SIMULATION_START_H_
#define HYBRIDCONT_SIMULATION_START_H_

#include <string>

#include "hybridcont/event_flow.h"
#include "hybridcont/model.h"

namespace hybridcont {

struct SimulationStartOptions {
  // Cycles simulated at most; a stable gait with multipliers of modulus 0.5 settles to 1e-9 in ~30.
  int max_cycles = 1000;
  // false: exactly max_cycles cycles, the last one returned as a guess whether or not it has settled (an
  // unstable orbit that the simulation passes close to, for Newton to converge to).
  bool require_convergence = true;
  // Convergence: max-norm change of the state at the section from one cycle to the next, relative to
  // 1 + |x|. Newton refines the result, so this only needs to reach its basin of attraction.
  double tolerance = 1e-9;
  // The longest a phase may last before its event counts as not reached.
  double max_phase_time = 1e3;
  EventFlowOptions integrator;
};

struct SimulationStartResult {
  bool converged = false;
  std::string message;  // why not, or how: "converged after 37 cycles (change 8e-10)"
  Vector u;             // the last cycle in the layout of ShootingLayout(model) (no free parameters)
  int cycles = 0;
  double change = 0;    // the last cycle-to-cycle change
};

SimulationStartResult SimulateToOrbit(const HybridModel& model, const Vector& x1,
                                      const SimulationStartOptions& options = {});

}  // namespace hybridcont

#endif  // HYBRIDCONT_SIMULATION_START_H_
