#include "study/engine/run_setup.h"

#include <fmt/format.h>

#include <algorithm>
#include <set>
#include <stdexcept>
#include <thread>

#include "hybridcont/setup_evaluation.h"
#include "study/engine/model_exploration.h"
#include "hybridcont/study.h"

namespace hybridcont::study {

namespace {

// What the command line accepts beyond the library's own checks (options that are valid for the library
// but make no sense for a run): see the README, "Bad input".
constexpr double kMinRtol = 1e-14;   // below, the error control chases rounding noise (eps = 2.2e-16)
constexpr double kMaxTolerance = 0.1;  // above, no digit of a located point means anything
constexpr int kMaxThreads = 256;     // each thread holds a copy of the problem; more are never useful

[[noreturn]] void Refuse(const std::string& field, int index, const std::string& message) {
  throw StudyOptionError(field, index, message);
}

std::string Text(const NamedValue& v) { return fmt::format("'{}={:g}'", v.name, v.value); }
std::string Text(const NamedInterval& b) {
  return fmt::format("'{}={}:{}'", b.name, std::isfinite(b.lower) ? fmt::format("{:g}", b.lower) : "",
                     std::isfinite(b.upper) ? fmt::format("{:g}", b.upper) : "");
}

void ApplyTolerances(const StudyOptions& args, IntegratorOptions* integrator) {
  if (args.rtol) integrator->rtol = *args.rtol;
  if (args.atol) integrator->atol = *args.atol;
  if (const std::string why = integrator->Validate(); !why.empty()) {
    Refuse(args.rtol ? "rtol" : "atol", -1, why);
  }
  if (args.rtol && !(*args.rtol >= kMinRtol && *args.rtol <= kMaxTolerance)) {
    Refuse("rtol", -1, fmt::format("{:g}: must lie in [{:g}, {:g}]", *args.rtol, kMinRtol, kMaxTolerance));
  }
  if (args.atol && !(*args.atol <= kMaxTolerance)) {
    Refuse("atol", -1, fmt::format("{:g}: must lie in (0, {:g}]", *args.atol, kMaxTolerance));
  }
}

// One value per name: a repeated name in `until`, `bounds` or `monitors` is a mistake, not an override.
template <typename Entry>
void RefuseRepeats(const std::string& field, const std::vector<Entry>& entries) {
  std::set<std::string> seen;
  for (std::size_t i = 0; i < entries.size(); ++i) {
    if (entries[i].name.empty()) Refuse(field, static_cast<int>(i), Text(entries[i]) + ": the name is empty");
    if (!seen.insert(entries[i].name).second) {
      Refuse(field, static_cast<int>(i), Text(entries[i]) + ": '" + entries[i].name + "' is given twice");
    }
  }
}

// --until targets, then --bound bounds ("period": the sum of the durations), each replacing the model's
// bound on its unknown; a target outside a bound on its own unknown is refused.
void ApplyTargetsAndBounds(const StudyOptions& args, const HybridModel& model, ContinuationOptions* c) {
  for (std::size_t i = 0; i < args.until.size(); ++i) {
    const NamedValue& u = args.until[i];
    if (!std::isfinite(u.value)) Refuse("until", static_cast<int>(i), Text(u) + ": the value is not finite");
    c->targets.push_back({u.name, u.value});
  }
  for (std::size_t i = 0; i < args.bounds.size(); ++i) {
    const NamedInterval& b = args.bounds[i];
    const int index = static_cast<int>(i);
    if (std::isnan(b.lower) || std::isnan(b.upper)) Refuse("bounds", index, Text(b) + ": an end is NaN");
    if (!std::isfinite(b.lower) && !std::isfinite(b.upper)) {
      Refuse("bounds", index, Text(b) + ": both ends are unbounded (an unknown without any bound is never reached; "
                                        "give at least one end, e.g. H=0:)");
    }
    if (!(b.lower < b.upper)) Refuse("bounds", index, Text(b) + ": the lower end must be below the upper end");
    for (std::size_t k = 0; k < args.until.size(); ++k) {
      const NamedValue& t = args.until[k];
      if (t.name == b.name && !(t.value >= b.lower && t.value <= b.upper)) {
        Refuse("until", static_cast<int>(k),
               fmt::format("{} lies outside {} {}: no branch could reach it", Text(t), MentionOption("bounds"), Text(b)));
      }
    }
    if (b.name == "period") {
      std::vector<std::string> durations;
      for (int i = 0; i <= model.num_phases(); ++i) durations.push_back(std::string("t").append(std::to_string(i + 1)));
      c->sum_bounds.assign(1, SumBound{durations, b.lower, b.upper});
    } else {
      std::erase_if(c->bounds, [&](const ComponentBound& x) { return x.component == b.name; });
      c->bounds.push_back({b.name, b.lower, b.upper});
    }
  }
}

// A target beyond the model's default bound on the same unknown widens that bound to the target: the user
// asked to reach it (an explicit --bound on that unknown is kept as given). A target further beyond the bound than
// kMaxWidening times its width is refused: the families would be followed through a range the model was never
// written for, until each branch's point limit (a mistyped exponent, --until H=1e300).
constexpr double kMaxWidening = 100;
void WidenBoundsToTargets(const StudyOptions& args, ContinuationOptions* c, std::vector<std::string>* notes) {
  for (const ComponentTarget& t : c->targets) {
    const bool explicit_bound = std::any_of(args.bounds.begin(), args.bounds.end(),
                                            [&](const NamedInterval& b) { return b.name == t.component; });
    for (ComponentBound& b : c->bounds) {
      if (b.component != t.component || explicit_bound || (t.value >= b.lower && t.value <= b.upper)) continue;
      const double lower = b.lower, upper = b.upper;
      const double beyond = std::max(lower - t.value, t.value - upper);
      if (std::isfinite(upper - lower) && beyond > kMaxWidening * (upper - lower)) {
        const auto given = std::find_if(args.until.begin(), args.until.end(),
                                        [&](const NamedValue& u) { return u.name == t.component; });
        Refuse("until", given == args.until.end() ? -1 : static_cast<int>(given - args.until.begin()),
               fmt::format("'{}={:g}' lies {:g} beyond the model's bound [{:g}, {:g}] of {}, more than {:g} times its "
                           "width: a mistake? (give {} {}=LOWER:UPPER to follow the families that far)",
                           t.component, t.value, beyond, lower, upper, t.component, kMaxWidening,
                           MentionOption("bounds"), t.component));
      }
      b.lower = std::min(b.lower, t.value);
      b.upper = std::max(b.upper, t.value);
      notes->push_back(fmt::format("{} {}={:g} lies outside the bound [{:g}, {:g}] of {}: the bound is widened "
                                   "to [{:g}, {:g}] (give {} {}=LOWER:UPPER to keep it)",
                                   MentionOption("until"), t.component, t.value, lower, upper, t.component, b.lower,
                                   b.upper, MentionOption("bounds"), t.component));
    }
  }
}

void ApplyExplorationLimits(const StudyOptions& args, ExplorationOptions* exploration) {
  if (args.max_branches) {
    if (*args.max_branches < 1) Refuse("max_branches", -1, std::to_string(*args.max_branches) + ": must be >= 1");
    exploration->max_branches = *args.max_branches;
  }
  if (args.threads < 1) Refuse("threads", -1, std::to_string(args.threads) + ": must be >= 1");
  if (args.threads > kMaxThreads) Refuse("threads", -1, fmt::format("{}: must be <= {}", args.threads, kMaxThreads));
  exploration->threads = args.threads;
  exploration->use_symmetries = args.use_symmetries;
}

// The default interval of a parameter p continued from its value v: its range within [v/4, 4v] (the
// mirror interval for v < 0, [-1, 1] around 0): a factor of four either way covers the questions a run in
// p answers (how a gait changes with stiffness, swing frequency) without reaching degenerate values.
ComponentBound DefaultParameterBound(const HybridModel& model, const std::string& name) {
  const ParameterInfo& info = model.parameters()[model.FindParameter(name)];
  const double v = model.parameter(name);
  double lower = v > 0 ? v / 4 : v < 0 ? 4 * v : -1.0, upper = v > 0 ? 4 * v : v < 0 ? v / 4 : 1.0;
  lower = std::max(lower, info.range.lower);
  upper = std::min(upper, info.range.upper);
  return {name, lower, upper};
}

// The named parameter of the model, or StudyOptionError naming the field and the value.
void RequireParameter(const std::string& field, const HybridModel& model, const std::string& name) {
  if (model.FindParameter(name) >= 0) return;
  std::string known;
  for (const ParameterInfo& info : model.parameters()) known += (known.empty() ? "" : ", ") + info.name;
  Refuse(field, -1, fmt::format("'{}': model '{}' has no such parameter (parameters: {})", name, model.name(), known));
}

// --free/--fix: the parameter joins the unknowns (scale: its value, so that steps are relative to it), with
// its default bound unless --bound names it. The ordinary run that gives the starts keeps the scenario's
// options with an H bound widened to the fixed value.
void ApplyFreeParameter(const StudyOptions& args, const HybridModel& model, RunSetup* setup) {
  setup->seed_exploration = setup->exploration;
  if (model.num_first_integrals() == 0) {
    // No first integral: the families are continued in a parameter (the model's run.parameter, or --free).
    const std::string parameter = args.free.empty() ? model.setup().run.parameter : args.free;
    if (args.fix) {
      Refuse("fix", -1, Text(*args.fix) + ": model '" + model.name() +
                                  "' has no first integral; its families are continued in one parameter alone");
    }
    if (parameter.empty()) {
      Refuse("free", -1, "model '" + model.name() + "' has no first integral: name the parameter its "
                         "families are continued in");
    }
    RequireParameter("free", model, parameter);
    if (!model.has_parameter_derivatives()) {
      Refuse("free", -1, fmt::format("'{}': model '{}' has no parameter derivatives", parameter, model.name()));
    }
    setup->free = FreeParameters{{parameter}, {}, {}};
    const std::string& declared = model.setup().run.parameter;
    if (parameter != declared) {
      // --free another parameter: the file's run.parameter is held at its value, so its bounds and scale,
      // set up for following it, have nothing to bound; the key frames are taken at the new one's value.
      const auto on_declared = [&](const auto& entry) { return entry.component == declared; };
      std::erase_if(setup->scenario.bounds, on_declared);
      std::erase_if(setup->exploration.continuation.bounds, on_declared);
      std::erase_if(setup->scenario.unknown_scales, [&](const auto& s) { return s.first == declared; });
      if (setup->scenario.keyframes.component == declared) {
        setup->scenario.keyframes = {parameter, model.parameter(parameter)};
      }
    }
    const double v = model.parameter(parameter);
    setup->scenario.unknown_scales.push_back({parameter, v != 0 ? std::abs(v) : 1.0});
    const bool bounded = std::any_of(setup->exploration.continuation.bounds.begin(),
                                     setup->exploration.continuation.bounds.end(),
                                     [&](const ComponentBound& b) { return b.component == parameter; });
    if (!bounded) {
      setup->scenario.bounds.push_back(DefaultParameterBound(model, parameter));
      setup->exploration.continuation.bounds.push_back(setup->scenario.bounds.back());
    }
    setup->exploration.start_conditions.clear();
    return;
  }
  if (args.free.empty() && !args.fix) return;
  if (args.free.empty()) Refuse("fix", -1, Text(*args.fix) + ": needs " + MentionOption("free") + " PARAMETER (the parameter that varies)");
  if (!args.fix) Refuse("free", -1, "'" + args.free + "': needs " + MentionOption("fix") + " NAME=VALUE (the unknown held fixed, e.g. H=1.5)");
  RequireParameter("free", model, args.free);
  if (!model.has_parameter_derivatives()) {
    Refuse("free", -1, fmt::format("'{}': model '{}' has no parameter derivatives", args.free, model.name()));
  }
  const std::string name = args.fix->name;
  const double value = args.fix->value;
  if (!std::isfinite(value)) Refuse("fix", -1, Text(*args.fix) + ": the value is not finite");
  // Any unknown of the orbit: H (families over the parameter at one energy), a duration (t2=0: the curve
  // where that phase vanishes, a boundary of the physical families), a state component (x1_dx=1.2: the
  // families at one apex speed).
  const std::vector<std::string> names = ShootingLayout(model).unknown_names();
  const bool observable = model.FindObservable(name) >= 0;
  if (!observable && (std::find(names.begin(), names.end(), name) == names.end() || name == "xi")) {
    std::string known;
    for (const std::string& n : names) known += n == "xi" ? "" : (known.empty() ? "" : ", ") + n;
    for (const Observable& o : model.observables()) known += ", " + o.name;
    Refuse("fix", -1, Text(*args.fix) + ": '" + name + "' is not an unknown or observable of model '" +
                                model.name() + "' that can be held fixed (" + known + ")");
  }
  setup->free = FreeParameters{{args.free}, {{name, value}}, {}};
  if (observable) setup->free.observables.push_back(name);
  ContinuationOptions& seed = setup->seed_exploration.continuation;
  for (ComponentBound& b : seed.bounds) {
    if (b.component == "H" && !(value >= b.lower && value <= b.upper)) {
      Refuse("fix", -1, fmt::format("{}: outside the model's H bound [{:g}, {:g}]", Text(*args.fix), b.lower,
                                              b.upper));
    }
  }
  const double v = model.parameter(args.free);
  setup->scenario.unknown_scales.push_back({args.free, v != 0 ? std::abs(v) : 1.0});
  setup->scenario.bounds.push_back(DefaultParameterBound(model, args.free));
  setup->exploration.continuation.bounds.push_back(setup->scenario.bounds.back());
  setup->exploration.start_conditions.clear();  // the starts are regular points of the families
}

// Observables named by --until, --bound and --monitor join the map's unknowns (shooting_layout.h,
// "Observables"), in the order named; --monitor names observables only.
void ApplyObservables(const StudyOptions& args, const HybridModel& model, RunSetup* setup) {
  // Several values of one observable are several monitors; the same value twice is a mistake.
  std::set<std::pair<std::string, double>> monitored;
  for (std::size_t i = 0; i < args.monitors.size(); ++i) {
    const NamedValue& m = args.monitors[i];
    if (m.name.empty()) Refuse("monitors", static_cast<int>(i), Text(m) + ": the name is empty");
    if (!monitored.insert({m.name, m.value}).second) {
      Refuse("monitors", static_cast<int>(i), Text(m) + ": is given twice");
    }
  }
  const auto join = [&](const std::string& name) {
    if (model.FindObservable(name) < 0) return;
    std::vector<std::string>& joined = setup->free.observables;
    if (std::find(joined.begin(), joined.end(), name) == joined.end()) joined.push_back(name);
  };
  for (const NamedValue& u : args.until) join(u.name);
  for (const NamedInterval& b : args.bounds) join(b.name);
  for (std::size_t i = 0; i < args.monitors.size(); ++i) {
    const auto [name, value] = args.monitors[i];
    if (!std::isfinite(value)) Refuse("monitors", static_cast<int>(i), Text(args.monitors[i]) + ": the value is not finite");
    if (model.FindObservable(name) < 0) {
      std::string known;
      for (const Observable& o : model.observables()) known += (known.empty() ? "" : ", ") + o.name;
      Refuse("monitors", static_cast<int>(i), Text(args.monitors[i]) + ": '" + name + "' is not an observable of model '" +
                                  model.name() + "' (" + (known.empty() ? "it declares none" : "observables: " + known) +
                                  ")");
    }
    join(name);
    setup->monitors.push_back({name, value});
  }
  // An extremum of an observable along a family is a turning point of its component once it joins the unknowns:
  // located by the continuation like a fold (with the continued coordinate, which the components then name).
  for (std::size_t i = 0; i < args.extrema.size(); ++i) {
    const std::string& name = args.extrema[i];
    if (model.FindObservable(name) < 0) {
      std::string known;
      for (const Observable& o : model.observables()) known += (known.empty() ? "" : ", ") + o.name;
      Refuse("extrema", static_cast<int>(i), "'" + name + "': not an observable of model '" + model.name() + "' (" +
                                                 (known.empty() ? "it declares none" : "observables: " + known) + ")");
    }
    if (std::find(setup->extrema.begin(), setup->extrema.end(), name) != setup->extrema.end()) {
      Refuse("extrema", static_cast<int>(i), "'" + name + "': is given twice");
    }
    join(name);
    setup->extrema.push_back(name);
  }
  if (!setup->extrema.empty()) {
    const std::string continued = ShootingLayout(model, setup->free).continued_name();
    std::vector<std::string>& turning = setup->exploration.continuation.turning_point_components;
    turning = {continued};
    turning.insert(turning.end(), setup->extrema.begin(), setup->extrema.end());
  }
}

// --curves: the parameter and its bound (taken out of --bound, whose other names are the run's unknowns).
void ApplyCurveParameter(const StudyOptions& args, const HybridModel& model, StudyOptions* run_args,
                         RunSetup* setup) {
  if (args.curves.empty()) return;
  RequireParameter("curves", model, args.curves);
  if (!model.has_parameter_derivatives()) {
    Refuse("curves", -1, fmt::format("'{}': model '{}' has no parameter derivatives", args.curves,
                                            model.name()));
  }
  // The curves are drawn in (a, p), a the coordinate the families are continued in: p must be another one.
  const std::string continued = !args.free.empty() ? args.free
                                : model.num_first_integrals() > 0 ? std::string("H") : model.setup().run.parameter;
  if (args.curves == continued) {
    Refuse("curves", -1, fmt::format("'{}': the families are continued in {} already; the curves need a second "
                                     "parameter", args.curves, continued));
  }
  setup->curve_parameter = args.curves;
  setup->curve_bound = DefaultParameterBound(model, args.curves);
  std::erase_if(run_args->bounds, [&](const NamedInterval& b) {
    if (b.name != args.curves) return false;
    const double v = model.parameter(args.curves);
    if (!(v >= b.lower && v <= b.upper)) {
      const auto at = std::find_if(args.bounds.begin(), args.bounds.end(),
                                   [&](const NamedInterval& x) { return x.name == b.name; });
      Refuse("bounds", static_cast<int>(at - args.bounds.begin()),
             fmt::format("{}: excludes the model's {} = {:g}, where the curves start", Text(b), args.curves, v));
    }
    setup->curve_bound.lower = b.lower, setup->curve_bound.upper = b.upper;
    return true;
  });
}

}  // namespace

RunSetup MakeRunSetup(const StudyOptions& given, const HybridModel& model) {
  RunSetup setup;
  StudyOptions args = given;
  ApplyTolerances(args, &setup.integrator);
  RefuseRepeats("until", args.until);
  RefuseRepeats("bounds", args.bounds);
  setup.scenario = DefaultScenario(model);
  setup.exploration = ScenarioExplorationOptions(setup.scenario);
  ApplyCurveParameter(given, model, &args, &setup);
  ApplyExplorationLimits(args, &setup.exploration);
  ApplyFreeParameter(args, model, &setup);
  ApplyObservables(args, model, &setup);
  // The period-doubled model (the phase sequence traversed twice) carries no observables: its families cannot be
  // followed with one among the unknowns.
  if (args.period_doubling && !setup.free.observables.empty()) {
    Refuse("period_doubling", -1, ": not with an observable among the unknowns ('" + setup.free.observables.front() +
                                      "', from " + MentionOption("monitors") + ", " + MentionOption("extrema") + ", " +
                                      MentionOption("until") + " or " + MentionOption("bounds") +
                                      "): the doubled model does not carry the model's observables");
  }
  // Family names read the points of this run's layout: with its free parameters at their values in u.
  setup.scenario.describe = [presentation = OrbitPresentation(model, setup.free)](const Vector& u) {
    return presentation.Family(u);
  };
  ApplyTargetsAndBounds(args, model, &setup.exploration.continuation);
  WidenBoundsToTargets(args, &setup.exploration.continuation, &setup.notes);
  // The continued coordinate with no bound: each branch is bounded by its number of points, said.
  const std::string continued = !setup.free.parameters.empty() ? setup.free.parameters.front()
                                : model.num_first_integrals() > 0 ? std::string("H")
                                                                  : model.setup().run.parameter;
  const auto& bounds = setup.exploration.continuation.bounds;
  if (!continued.empty() && std::none_of(bounds.begin(), bounds.end(), [&](const ComponentBound& b) {
        return b.component == continued && std::isfinite(b.lower) && std::isfinite(b.upper);
      })) {
    setup.notes.push_back(fmt::format("{} has no bound (run.bounds or {} {}=LOWER:UPPER): each branch ends after "
                                      "{} points (run.max_points)",
                                      continued, MentionOption("bounds"), continued, setup.exploration.continuation.max_points));
  }
  return setup;
}

ComponentBound LevelBound(const RunSetup& setup, const std::string& level) {
  for (const ComponentBound& b : setup.exploration.continuation.bounds) {
    if (b.component == level) return b;
  }
  return {};
}

}  // namespace hybridcont::study
