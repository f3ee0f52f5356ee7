#include "run_setup.h"

#include <fmt/format.h>

#include <algorithm>
#include <set>
#include <stdexcept>

#include "model_exploration.h"
#include "model_options.h"

namespace hybridcont::app {

namespace {

// What the command line accepts beyond the library's own checks (options that are valid for the library
// but make no sense for a run): see the README, "Bad input".
constexpr double kMinRtol = 1e-14;   // below, the error control chases rounding noise (eps = 2.2e-16)
constexpr double kMaxTolerance = 0.1;  // above, no digit of a located point means anything
constexpr int kMaxThreads = 256;     // each thread holds a copy of the problem; more are never useful

void ApplyTolerances(const RunArguments& args, IntegratorOptions* integrator) {
  if (args.rtol) integrator->rtol = *args.rtol;
  if (args.atol) integrator->atol = *args.atol;
  if (const std::string why = integrator->Validate(); !why.empty()) {
    throw std::invalid_argument("--rtol/--atol: " + why);
  }
  if (args.rtol && !(*args.rtol >= kMinRtol && *args.rtol <= kMaxTolerance)) {
    throw std::invalid_argument(fmt::format("--rtol {:g}: must lie in [{:g}, {:g}]", *args.rtol, kMinRtol, kMaxTolerance));
  }
  if (args.atol && !(*args.atol <= kMaxTolerance)) {
    throw std::invalid_argument(fmt::format("--atol {:g}: must lie in (0, {:g}]", *args.atol, kMaxTolerance));
  }
}

// One value per name: a repeated --set, --until or --bound is a mistake, not an override.
void RefuseRepeats(const std::string& option, const std::vector<std::string>& texts) {
  std::set<std::string> seen;
  for (const std::string& text : texts) {
    const std::string name = text.substr(0, text.find('='));
    if (!seen.insert(name).second) {
      throw std::invalid_argument(option + " '" + text + "': '" + name + "' is given twice");
    }
  }
}

// --until targets, then --bound bounds ("period": the sum of the durations), each replacing the model's
// bound on its unknown; a target outside a bound on its own unknown is refused.
void ApplyTargetsAndBounds(const RunArguments& args, const HybridModel& model, ContinuationOptions* c) {
  for (const std::string& u : args.until) {
    const auto [name, value] = ParseAssignment("--until", u);
    c->targets.push_back({name, value});
  }
  for (const std::string& text : args.bounds) {
    const BoundAssignment b = ParseBound("--bound", text);
    for (const ComponentTarget& t : c->targets) {
      if (t.component == b.name && !(t.value >= b.lower && t.value <= b.upper)) {
        throw std::invalid_argument(fmt::format("--until '{}={:g}' lies outside --bound '{}': no branch could reach it",
                                                t.component, t.value, text));
      }
    }
    if (b.name == "period") {
      std::vector<std::string> durations;
      for (int i = 0; i <= model.num_phases(); ++i) durations.push_back("t" + std::to_string(i + 1));
      c->sum_bounds.assign(1, SumBound{durations, b.lower, b.upper});
    } else {
      std::erase_if(c->bounds, [&](const ComponentBound& x) { return x.component == b.name; });
      c->bounds.push_back({b.name, b.lower, b.upper});
    }
  }
}

// A target beyond the model's default bound on the same unknown widens that bound to the target: the user
// asked to reach it (an explicit --bound on that unknown is kept as given).
void WidenBoundsToTargets(const RunArguments& args, ContinuationOptions* c) {
  for (const ComponentTarget& t : c->targets) {
    const bool explicit_bound = std::any_of(args.bounds.begin(), args.bounds.end(), [&](const std::string& text) {
      return text.rfind(t.component + "=", 0) == 0;
    });
    for (ComponentBound& b : c->bounds) {
      if (b.component != t.component || explicit_bound) continue;
      b.lower = std::min(b.lower, t.value);
      b.upper = std::max(b.upper, t.value);
    }
  }
}

void ApplyExplorationLimits(const RunArguments& args, ExplorationOptions* exploration) {
  if (args.max_branches) {
    if (*args.max_branches < 1) {
      throw std::invalid_argument("--max-branches " + std::to_string(*args.max_branches) + ": must be >= 1");
    }
    exploration->max_branches = *args.max_branches;
  }
  if (args.threads) {
    if (*args.threads < 1) throw std::invalid_argument("--threads " + std::to_string(*args.threads) + ": must be >= 1");
    if (*args.threads > kMaxThreads) {
      throw std::invalid_argument(fmt::format("--threads {}: must be <= {}", *args.threads, kMaxThreads));
    }
    exploration->threads = *args.threads;
  }
  if (args.no_symmetry) exploration->use_symmetries = false;
}

}  // namespace

RunSetup MakeRunSetup(const RunArguments& args, const HybridModel& model) {
  RunSetup setup;
  ApplyTolerances(args, &setup.integrator);
  RefuseRepeats("--until", args.until);
  RefuseRepeats("--bound", args.bounds);
  setup.scenario = DefaultScenario(model);
  setup.exploration = ScenarioExplorationOptions(setup.scenario);
  ApplyTargetsAndBounds(args, model, &setup.exploration.continuation);
  WidenBoundsToTargets(args, &setup.exploration.continuation);
  ApplyExplorationLimits(args, &setup.exploration);
  return setup;
}

}  // namespace hybridcont::app
