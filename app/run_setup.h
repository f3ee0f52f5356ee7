// The validated set-up of `hybridcont run`: the integrator and exploration options and the model's scenario
// after every command-line option is applied and checked against the model.
//   RunSetup setup = MakeRunSetup(args, model);   // throws std::invalid_argument naming the bad option
#ifndef HYBRIDCONT_APP_RUN_SETUP_H_
#define HYBRIDCONT_APP_RUN_SETUP_H_

#include "commands.h"
#include "hybridcont/exploration.h"
#include "hybridcont/flow.h"
#include "hybridcont/model.h"
#include "scenario.h"

namespace hybridcont::app {

struct RunSetup {
  IntegratorOptions integrator;
  ExplorationOptions exploration;
  Scenario scenario;
};

// The model's default scenario with --rtol, --atol, --until, --bound, --max-branches, --threads and
// --no-symmetry applied. Throws std::invalid_argument ("--OPTION VALUE: why") for a value the library
// refuses or that makes no sense for a run (see the README, "Bad input").
RunSetup MakeRunSetup(const RunArguments& args, const HybridModel& model);

}  // namespace hybridcont::app

#endif  // HYBRIDCONT_APP_RUN_SETUP_H_
