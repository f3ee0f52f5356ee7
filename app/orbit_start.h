// The start of a run of a model without first integral (a passive walker, a forced oscillator): one
// periodic orbit at the model's parameter values, from the start the model declares, refined by Newton on
// the square shooting system at fixed parameters, then given the continuation parameter's value so that
// the family in it can be traced from there (ModelExploration::RunFromStarts).
//   - kind = "simulation": the declared x1 starts an event-driven simulation that settles on an
//     attracting orbit (simulation_start.h);
//   - kind = "guess" (or "singular"): the declared values are the guess.
//
//   OrbitStart s = FindOrbitStart(model, setup, exploration.shooting().layout());
//   if (s.ok) exploration.RunFromStarts({s.u}, ...);
#ifndef HYBRIDCONT_APP_ORBIT_START_H_
#define HYBRIDCONT_APP_ORBIT_START_H_

#include <string>

#include "hybridcont/shooting_layout.h"
#include "run_setup.h"

namespace hybridcont::app {

struct OrbitStart {
  bool ok = false;
  Vector u;            // in `free_layout`
  std::string report;  // how it was found, or why not
};

OrbitStart FindOrbitStart(const HybridModel& model, const RunSetup& setup, const ShootingLayout& free_layout);

}  // namespace hybridcont::app

#endif  // HYBRIDCONT_APP_ORBIT_START_H_
