#include "study/engine/scenario.h"

#include <fmt/format.h>

#include "hybridcont/expression.h"
#include "hybridcont/setup_evaluation.h"

namespace hybridcont::study {

Scenario DefaultScenario(const HybridModel& model) {
  const ModelSetup& setup = model.setup();
  const RunSpec& run = setup.run;
  Scenario s;
  s.start = StartPoint(model);
  for (const StartSpec::Condition& c : setup.start.conditions) s.start_conditions.push_back({c.terms, c.description});
  for (const BoundSpec& b : run.bounds) {
    const std::string field = "run.bounds." + b.component;
    const double lower = EvaluateSetupValue(model, b.lower, field + "[0]");
    const double upper = EvaluateSetupValue(model, b.upper, field + "[1]");
    if (!(lower < upper)) {  // a bound evaluates after --set: said at its line, with the values
      SourceLocation where = b.upper.where;
      where.field = field;
      throw ModelInputError(where, fmt::format("the lower end {:g} is not below the upper end {:g}", lower, upper));
    }
    if (b.component == "period") {
      std::vector<std::string> durations;
      for (int i = 0; i <= model.num_phases(); ++i) durations.push_back(std::string("t").append(std::to_string(i + 1)));
      s.sum_bounds.push_back({durations, lower, upper});
    } else {
      s.bounds.push_back({b.component, lower, upper});
    }
  }
  for (const auto& [name, value] : run.scales) {
    s.unknown_scales.push_back({name, EvaluateSetupValue(model, value, "run.scales." + name)});
  }
  s.max_branches = run.max_branches;
  s.max_depth = run.max_depth;
  s.max_points = run.max_points;
  s.initial_step = run.initial_step;
  s.max_step = run.max_step;
  s.keyframes = {run.keyframe_component, EvaluateSetupValue(model, run.keyframe_value, "run.keyframes.value")};
  s.max_keyframe_orbits = run.keyframe_orbits;
  s.describe = [presentation = OrbitPresentation(model)](const Vector& u) { return presentation.Family(u); };
  return s;
}

}  // namespace hybridcont::study
