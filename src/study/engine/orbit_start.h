// The start of a run of a model without first integral (a passive walker, a forced oscillator): one
// periodic orbit at the model's parameter values, from the start the model declares, refined by Newton on
// the square shooting system at fixed parameters, then given the continuation parameter's value so that
// the family in it can be traced from there (ModelExploration::RunFromStarts).
//   - kind = "simulation": the declared x1 starts an event-driven simulation that settles on an
//     attracting orbit (simulation_start.h);
//   - kind = "guess" (or "singular"): the declared values are the guess.
//
//   OrbitStarts s = FindOrbitStarts(model, setup, exploration.shooting().layout());
//   exploration.RunFromStarts(s.points, ...);
// Every start the model declares ([start], or each [[start]]) gives one point; a start that fails is
// reported and left out.
#ifndef HYBRIDCONT_STUDY_ORBIT_START_H_
#define HYBRIDCONT_STUDY_ORBIT_START_H_

#include <string>
#include <vector>

#include "hybridcont/shooting_layout.h"
#include "study/engine/run_setup.h"

namespace hybridcont::study {

struct OrbitStarts {
  std::vector<Vector> points;  // in `free_layout`
  std::string report;          // per start: how it was found, or why not
};

OrbitStarts FindOrbitStarts(const HybridModel& model, const RunSetup& setup, const ShootingLayout& free_layout);

}  // namespace hybridcont::study

#endif  // HYBRIDCONT_STUDY_ORBIT_START_H_
