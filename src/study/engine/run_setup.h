// The validated set-up of a study: the integrator and exploration options and the model's scenario after
// every option of StudyOptions is applied and checked against the model.
//   RunSetup setup = MakeRunSetup(args, model);   // throws std::invalid_argument naming the bad option
#ifndef HYBRIDCONT_STUDY_RUN_SETUP_H_
#define HYBRIDCONT_STUDY_RUN_SETUP_H_

#include "hybridcont/study.h"
#include "hybridcont/exploration.h"
#include "hybridcont/flow.h"
#include "hybridcont/model.h"
#include "hybridcont/shooting_layout.h"
#include "study/engine/scenario.h"

namespace hybridcont::study {

struct RunSetup {
  IntegratorOptions integrator;
  ExplorationOptions exploration;
  Scenario scenario;
  // --free/--fix: the parameter continued as an unknown and the unknown held fixed (empty: families in H).
  // exploration's bounds, targets and scales then include the parameter.
  FreeParameters free;
  // --monitor: observables and the values at which their crossings are located (UZ points).
  std::vector<std::pair<std::string, double>> monitors;
  // --extremum: observables joined to the unknowns whose turning points along the families are located
  // (ContinuationOptions::turning_point_components, besides the continued coordinate) and named EX.
  std::vector<std::string> extrema;
  // The options of the ordinary run in H that gives the starts of a run with free parameters (its
  // families' crossings of the fixed value): the scenario's, with --max-branches, --threads, --no-symmetry
  // and an H bound that contains the fixed value.
  ExplorationOptions seed_exploration;
  // --curves: the second parameter of the special-point curves and its bound (default: the parameter's
  // range within [value/4, 4 value]).
  std::string curve_parameter;
  ComponentBound curve_bound;
  // What the set-up changed that the user did not write, said before the run ("--until H=5 widens the
  // bound of H to [0, 5]").
  std::vector<std::string> notes;
  // The model's own values of the parameters options.parameters sets (in that order; empty without): where a
  // declared start fails at the values set, it is carried there from these (start_carry.h).
  std::vector<NamedValue> own_parameters;
};

// The model's default scenario with the options free, fix, curves, rtol, atol, until, bounds, max_branches,
// threads and use_symmetries applied. Throws StudyOptionError (naming the field) for a value the library
// refuses or that makes no sense for a study (see docs/bad-input.md).
RunSetup MakeRunSetup(const StudyOptions& options, const HybridModel& model);

// The exploration's bound on the coordinate `level` (H, or the run's parameter); an empty component: none.
ComponentBound LevelBound(const RunSetup& setup, const std::string& level);

}  // namespace hybridcont::study

#endif  // HYBRIDCONT_STUDY_RUN_SETUP_H_
