// The paper's run of each built-in model: start point, bounds and the orbits drawn as key frames.
//
// These are the defaults of `hybridcont run MODEL`; every value can be overridden from the command line
// (--until, --max-branches, ...). They encode the paper's §4 set-up:
//   bouncing-ball  u0 = 0 (equilibrium), H <= 1
//   rocking-block  u0 = 0, up to the homoclinic limit H_max = m g l0 (1 - cos beta), stopping at T = 20
//   bouncing-rod   u0 = 0 (non-simple: kernel of dimension 3), symmetric direction t2 = t1 + t3, H <= 0.6
//   slip           the T0 = 2 pi sqrt(m/k) oscillation at H = m g l0, H <= 2
#ifndef HYBRIDCONT_APP_SCENARIO_H_
#define HYBRIDCONT_APP_SCENARIO_H_

#include <functional>
#include <string>
#include <vector>

#include "hybridcont/continuation.h"
#include "hybridcont/model.h"

namespace hybridcont::app {

// A linear condition sum_k coefficient_k * direction[component_k] = 0 on the start direction.
struct StartCondition {
  std::vector<std::pair<std::string, double>> terms;
  std::string description;  // e.g. "t2 = t1 + t3"
};

// Orbits drawn as key frames: on each physical branch, the point closest to `value` of `component`.
struct KeyframeTarget {
  std::string component;  // "H" or "T"
  double value;
};

struct Scenario {
  Vector start;
  std::vector<StartCondition> start_conditions;
  std::vector<ComponentBound> bounds;
  std::vector<SumBound> sum_bounds;
  // High enough that every default run completes its diagram (the SLIP has 23 half-branches to H = 2).
  int max_branches = 64;
  int max_depth = 3;
  int max_points = 600;
  double initial_step = 0.02;
  double max_step = 0.1;
  // Typical magnitudes of unknowns (by name) far from 1; the continuation works in u ./ scale
  // (scaled_problem.h). Unlisted unknowns have scale 1.
  std::vector<std::pair<std::string, double>> unknown_scales;
  KeyframeTarget keyframes{"H", 0.5};
  int max_keyframe_orbits = 4;
  // A short description of a physical orbit u (time-based layout) for figure titles.
  std::function<std::string(const Vector& u)> describe;
};

// Throws std::invalid_argument for a model without a paper scenario.
Scenario DefaultScenario(const HybridModel& model);

}  // namespace hybridcont::app

#endif  // HYBRIDCONT_APP_SCENARIO_H_
