// A model's default run, in numbers: its set-up (model_setup.h, declared with the model) evaluated at the
// model's current parameters.
//
//   HybridModel block = MakeRockingBlock();
//   block.SetParameter("beta", 0.2);
//   Scenario s = DefaultScenario(block);   // H <= m g l0 (1 - cos 0.2), key frames at half of it, ...
//
// These are the defaults of `hybridcont run MODEL`; values can be overridden from the command line
// (--until, --max-branches, ...). No model is named here: everything comes from model.setup().
#ifndef HYBRIDCONT_STUDY_SCENARIO_H_
#define HYBRIDCONT_STUDY_SCENARIO_H_

#include <functional>
#include <string>
#include <vector>

#include "hybridcont/continuation.h"
#include "hybridcont/model.h"

namespace hybridcont::study {

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
  // A short description of a physical orbit u (time-based layout) for figure titles: its family name
  // (OrbitPresentation::Family).
  std::function<std::string(const Vector& u)> describe;
};

// model.setup() evaluated: bounds (component "period" becomes a SumBound over all durations t1..t<m+1>),
// scales, steps and limits, the start point and its conditions, the key-frame target. Throws
// ModelInputError (a std::invalid_argument) naming the field of a value that does not evaluate.
Scenario DefaultScenario(const HybridModel& model);

}  // namespace hybridcont::study

#endif  // HYBRIDCONT_STUDY_SCENARIO_H_
