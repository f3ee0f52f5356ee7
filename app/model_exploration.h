// The exploration of a model's scenario, without any I/O: what `hybridcont run` and the benchmarks share.
//
//   ExplorationOptions options = ScenarioExplorationOptions(scenario);   // in the model's units
//   ModelExploration exploration(model, scenario, IntegratorOptions{}, options);  // validates (throws)
//   BifurcationDiagram d = exploration.Run([](const ProgressInfo&, const Vector& u) { ... });
//
// The engine works in scaled unknowns u ./ s (scaled_problem.h, Scenario::unknown_scales); bounds,
// targets and start conditions are converted on the way in and every point on the way out, so callers
// see the model's units only.
#ifndef HYBRIDCONT_APP_MODEL_EXPLORATION_H_
#define HYBRIDCONT_APP_MODEL_EXPLORATION_H_

#include <functional>
#include <memory>

#include "hybridcont/exploration.h"
#include "hybridcont/scaled_problem.h"
#include "hybridcont/timebased_shooting.h"
#include "scenario.h"

namespace hybridcont::app {

// Bounds, step sizes, depth and branch limits of the scenario.
ExplorationOptions ScenarioExplorationOptions(const Scenario& scenario);

class ModelExploration {
 public:
  // options are in the model's units. Throws std::invalid_argument for options that do not fit the
  // model (unknown component names, invalid values).
  ModelExploration(const HybridModel& model, const Scenario& scenario, const IntegratorOptions& integrator,
                   ExplorationOptions options);

  using PointCallback = std::function<void(const ProgressInfo& info, const Vector& u)>;
  // Explores from the scenario's start point; on_point sees every accepted point in model units.
  BifurcationDiagram Run(const PointCallback& on_point = PointCallback());

  TimeBasedShooting& shooting() { return shooting_; }
  const Vector& scales() const { return scaled_->scales(); }

 private:
  const HybridModel& model_;
  Scenario scenario_;
  TimeBasedShooting shooting_;
  std::unique_ptr<ScaledProblem> scaled_;
  ExplorationOptions options_;  // in scaled units
};

}  // namespace hybridcont::app

#endif  // HYBRIDCONT_APP_MODEL_EXPLORATION_H_
