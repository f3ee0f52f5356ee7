// The starts of a run in a free model parameter p at a fixed H̄ = c (`run MODEL --free p --fix H=c`): the
// points where the physical families of the ordinary run in H̄ (at the model's p = p0) cross H̄ = c.
//
//   ParameterStarts starts = FindParameterStarts(model, setup, &free_map);   // free_map: p free, H̄ = c
//   exploration.RunFromStarts(starts.points, on_point, &skipped);
//
// Each crossing lies between two consecutive physical points of a branch (H̄ − c changes sign or vanishes):
// the chord's point at H̄ = c, appended with p0, is corrected by Newton on the free-parameter map with p
// held at p0, and kept if it converges to a physical orbit that is not already a start (same-point
// tolerance). The starts are regular points of the families in p, since a crossing of H̄ = c at fixed p0
// is a regular point of the family in p at fixed H̄ wherever the two-parameter surface is smooth.
#ifndef HYBRIDCONT_STUDY_PARAMETER_STARTS_H_
#define HYBRIDCONT_STUDY_PARAMETER_STARTS_H_

#include <string>
#include <vector>

#include "hybridcont/timebased_shooting.h"
#include "study/engine/run_setup.h"

namespace hybridcont::study {

struct ParameterStarts {
  std::vector<Vector> points;   // in the layout of the free-parameter map, model units
  int crossings = 0;            // physical crossings of H̄ = c found in the ordinary run
  int ordinary_branches = 0;    // half-branches of the ordinary run
  std::string report;           // one line per start and a count
};

// Runs the ordinary exploration (setup.seed_exploration, the model's scenario) without output and
// collects the starts; free_map is the time-based map with setup.free.
ParameterStarts FindParameterStarts(const HybridModel& model, const RunSetup& setup, TimeBasedShooting& free_map);

}  // namespace hybridcont::study

#endif  // HYBRIDCONT_STUDY_PARAMETER_STARTS_H_
