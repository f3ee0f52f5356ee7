// `hybridcont run MODEL ...`: the complete bifurcation diagram of a built-in model, as data and figures.
//
// Order of work, so that bad input writes nothing: parse and validate every option, build the model,
// validate the exploration options against the problem, prepare the output folder; only then compute.
// Points are classified (physical or why not) and streamed to branch-<id>.csv as they are accepted (with
// --threads > 1: branch by branch as the exploration merges them, in the order of --threads 1).
#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>

#include "commands.h"
#include "hybridcont/classification.h"
#include "hybridcont/exploration.h"
#include "hybridcont/floquet.h"
#include "hybridcont/replay.h"
#include "hybridcont/test_function_root.h"
#include "hybridcont/models.h"
#include "hybridcont/timebased_shooting.h"
#include "install_paths.h"
#include "model_exploration.h"
#include "model_options.h"
#include "results_writer.h"
#include "scenario.h"

extern char** environ;  // the figure script inherits this process's environment

namespace hybridcont::app {

namespace fs = std::filesystem;

// What the command line accepts beyond the library's own checks (options that are valid for the library
// but make no sense for a run): see the README, "Bad input".
constexpr double kMinRtol = 1e-14;   // below, the error control chases rounding noise (eps = 2.2e-16)
constexpr double kMaxTolerance = 0.1;  // above, no digit of a located point means anything
constexpr int kMaxThreads = 256;     // each thread holds a copy of the problem; more are never useful

CLI::Option* NonEmpty(CLI::Option* option) {
  return option->check(CLI::Validator(
      [](const std::string& text) { return text.empty() ? std::string("an empty value is not allowed") : std::string(); },
      "", "non-empty"));
}

void AddRunOptions(CLI::App* run, RunArguments* args) {
  NonEmpty(run->add_option("model", args->model, "built-in model name (see `hybridcont list`) or model file (.toml)")
               ->required());
  NonEmpty(run->add_option("--set", args->assignments, "override a model parameter, NAME=VALUE (repeatable)"));
  NonEmpty(run->add_option("--until", args->until,
                           "end every branch exactly where a component of u reaches a value, NAME=VALUE, e.g. H=2 "
                           "(repeatable)"));
  NonEmpty(run->add_option("--bound", args->bounds,
                           "replace the model's bound on an unknown, NAME=LOWER:UPPER (e.g. H=0:2.7; 'period' is the "
                           "sum of the durations; an empty end is unbounded) (repeatable)"));
  NonEmpty(run->add_option("--out", args->out_dir, "results folder (default results/MODEL)"));
  NonEmpty(run->add_option("--rtol", args->rtol, "integrator relative tolerance (default 1e-10)"));
  NonEmpty(run->add_option("--atol", args->atol, "integrator absolute tolerance (default 1e-10)"));
  NonEmpty(run->add_option("--max-branches", args->max_branches, "maximum number of half-branches traced"));
  NonEmpty(run->add_option("--threads", args->threads,
                           "threads tracing half-branches concurrently (default: the machine's cores; 1 = one after "
                           "the other); the results do not depend on it"));
  NonEmpty(run->add_option("--formulation", args->formulation,
                           "time (default: time-based multiple shooting) or state (event-driven Poincare map)"));
  run->add_flag("--no-symmetry", args->no_symmetry,
               "trace every half-branch, also those that are images of traced ones under the model's symmetries");
  run->add_flag("--overwrite", args->overwrite,
                "replace the results of another model in --out (without it such a folder is refused)");
  run->add_flag("--quiet", args->quiet, "no progress lines");
  run->add_flag("--no-plots", args->no_plots, "do not draw figures");
}

namespace {

struct RunSetup {
  IntegratorOptions integrator;
  ExplorationOptions exploration;
  Scenario scenario;
};

nlohmann::json OptionsJson(const RunArguments& args, const RunSetup& setup) {
  nlohmann::json j;
  j["formulation"] = args.formulation;
  j["integrator"] = {{"method", ToString(setup.integrator.method)},
                     {"rtol", setup.integrator.rtol},
                     {"atol", setup.integrator.atol}};
  const ContinuationOptions& c = setup.exploration.continuation;
  j["continuation"] = {{"initial_step", c.initial_step},
                       {"min_step", c.min_step},
                       {"max_step", c.max_step},
                       {"max_points", c.max_points},
                       {"location_tolerance", c.location_tolerance}};
  nlohmann::json bounds = nlohmann::json::array();
  for (const auto& b : c.bounds) bounds.push_back({{"component", b.component}, {"lower", b.lower}, {"upper", b.upper}});
  for (const auto& b : c.sum_bounds) {
    bounds.push_back({{"sum_of", b.components}, {"lower", b.lower}, {"upper", b.upper}});
  }
  j["bounds"] = bounds;
  nlohmann::json targets = nlohmann::json::array();
  for (const auto& t : c.targets) targets.push_back({{"component", t.component}, {"value", t.value}});
  j["targets"] = targets;
  j["max_branches"] = setup.exploration.max_branches;
  j["max_depth"] = setup.exploration.max_depth;
  j["threads"] = setup.exploration.threads;
  j["use_symmetries"] = setup.exploration.use_symmetries;
  nlohmann::json conditions = nlohmann::json::array();
  for (const auto& sc : setup.scenario.start_conditions) conditions.push_back(sc.description);
  j["start_conditions"] = conditions;
  return j;
}

std::string SpecialPointTypeCode(SpecialPointType type) {
  switch (type) {
    case SpecialPointType::kSimpleBifurcation: return "SB";
    case SpecialPointType::kTurningPoint: return "TP";
    case SpecialPointType::kSingularStart: return "start";
  }
  return "?";
}

nlohmann::json SpecialPointsJson(const BifurcationDiagram& d, const ShootingLayout& layout) {
  nlohmann::json list = nlohmann::json::array();
  for (const SpecialPoint& sp : d.special_points) {
    const double H = sp.u.size() ? sp.u(layout.H_index()) : std::nan("");
    const double precision_H = sp.interval_width.size() ? sp.interval_width(layout.H_index()) : std::nan("");
    // "precision": the width of the interval that holds the point, as a distance in u (model units), like
    // the Floquet points' (LocateFloquetPoints); state-based runs know the widths of their own unknowns
    // only (x̄_1, ξ, H̄; NaN for the rest). "precision_arclength": the same interval along the branch in
    // the engine's scaled arclength (SpecialPoint::precision()).
    const double precision_u =
        sp.interval_width.size() ? sp.interval_width.array().isNaN().select(0.0, sp.interval_width.array()).matrix().norm()
                                 : sp.precision();
    nlohmann::json j = {{"id", sp.id},
                        {"type", SpecialPointTypeCode(sp.type)},
                        {"branch", sp.branch_id},
                        {"index", sp.index},
                        {"H", H},
                        {"T", sp.u.size() ? layout.Period(sp.u) : std::nan("")},
                        {"status", ToString(sp.status)},
                        {"precision", precision_u},
                        {"precision_arclength", sp.precision()},
                        {"precision_H", precision_H},
                        {"residual", sp.residual_norm},
                        {"component", sp.component},
                        {"duplicate_of", sp.duplicate_of},
                        {"message", sp.message}};
    j["u"] = std::vector<double>(sp.u.data(), sp.u.data() + sp.u.size());
    list.push_back(j);
  }
  return list;
}

// Runs the figure script on dir (no shell: any folder name is passed as it is) and returns its exit code
// (2: the script found the results malformed; 127: python could not be started; 128 + n: killed by signal
// n). Its output goes to dir/plot.log (when the folder is writable); its error lines — and with
// `all_messages` its warnings too — are repeated on err.
int DrawFigures(const fs::path& dir, std::ostream& err, bool all_messages) {
  const fs::path script = PlotScriptPath();  // install_paths.h: this executable's own script
  if (script.empty()) {
    err << "warning: figure script not found (see `hybridcont --paths`); results are saved, figures skipped\n";
    return 1;
  }
  // Debian's python3 carries matplotlib (python3-matplotlib); prefer it over other pythons on PATH.
  std::error_code ec;
  const std::string python = fs::exists("/usr/bin/python3", ec) ? "/usr/bin/python3" : "python3";
  const std::string script_text = script.string(), dir_text = dir.string();
  char* const argv[] = {const_cast<char*>(python.c_str()), const_cast<char*>(script_text.c_str()),
                        const_cast<char*>(dir_text.c_str()), nullptr};
  int fds[2];
  if (pipe(fds) != 0) {
    err << "warning: cannot start the figure script (" << std::strerror(errno) << ")\n";
    return 1;
  }
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addclose(&actions, fds[0]);
  posix_spawn_file_actions_adddup2(&actions, fds[1], 1);
  posix_spawn_file_actions_adddup2(&actions, fds[1], 2);
  posix_spawn_file_actions_addclose(&actions, fds[1]);
  pid_t pid = 0;
  const int spawned = posix_spawnp(&pid, python.c_str(), &actions, nullptr, argv, environ);
  posix_spawn_file_actions_destroy(&actions);
  close(fds[1]);
  std::string output;
  if (spawned == 0) {
    char buffer[4096];
    for (ssize_t n; (n = read(fds[0], buffer, sizeof buffer)) != 0;) {
      if (n > 0) output.append(buffer, static_cast<std::size_t>(n));
      else if (errno != EINTR) break;
    }
  }
  close(fds[0]);
  int rc = 127;
  if (spawned == 0) {
    int status = 0;
    while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
    rc = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
  } else {
    output = "cannot start " + python + ": " + std::strerror(spawned) + "\n";
  }
  const fs::path log = dir / "plot.log";
  bool logged = false;
  // `plot` on a damaged folder (exit 2) leaves the folder as it was: its messages are on err.
  if (fs::is_directory(dir, ec) && !(all_messages && rc == 2)) {
    std::ofstream f(log);
    logged = static_cast<bool>(f << output) && static_cast<bool>(f.flush());
  }
  std::istringstream lines(output);
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind("hybridcont_plot: error", 0) == 0 || (all_messages && line.rfind("hybridcont_plot:", 0) == 0)) {
      err << line << "\n";
    }
  }
  if (rc != 0) {
    err << "warning: drawing the figures failed" << (logged ? " (see " + log.string() + ")" : std::string()) << "\n";
  }
  return rc;
}

// Extra CSV columns (order fixed: every row of a branch has the same header).
constexpr int kBpColumn = 5;
constexpr int kPdColumn = 6;

// Floquet multipliers, stability and the event-driven replay of a physical orbit (issue 5). A physical
// point whose replay does not return is reclassified "replay-failed". Columns of non-physical points stay
// empty: their monodromy has no meaning for the mechanical system.
void AnalyzePhysicalOrbit(const HybridModel& model, TimeBasedShooting& floquet_map, const ReplayOptions& replay_options,
                          const Vector& u, PointRecord* record) {
  const double nan = std::nan("");
  const int nontrivial = std::max(model.phase(0).dim() - 2, 0);
  record->extra = {{"replay_error", nan}, {"stable", nan},        {"normal", nan}, {"num_unit", nan},
                   {"max_multiplier", nan}, {"bp_test", nan},     {"pd_test", nan}};
  for (int j = 0; j < nontrivial; ++j) {
    record->extra.push_back({"mu" + std::to_string(j + 1) + "_re", nan});
    record->extra.push_back({"mu" + std::to_string(j + 1) + "_im", nan});
  }
  if (!record->classification.physical) return;
  const ReplayResult replay = ReplayOrbit(model, u, replay_options);
  record->extra[0].second = replay.error;
  if (!replay.physical()) {
    record->classification = {false, OrbitClass::kReplayFailed, replay.message};
    return;
  }
  const FloquetResult floquet = ComputeFloquet(floquet_map, u);
  if (!floquet.ok()) return;
  record->extra[1].second = floquet.stable ? 1 : 0;
  record->extra[2].second = floquet.normal ? 1 : 0;
  record->extra[3].second = floquet.num_unit;
  record->extra[4].second = floquet.max_modulus;
  record->extra[kBpColumn].second = floquet.bp_test;
  record->extra[kPdColumn].second = floquet.pd_test;
  for (int j = 0; j < nontrivial && j < static_cast<int>(floquet.nontrivial.size()); ++j) {
    record->extra[7 + 2 * j].second = floquet.nontrivial[j].real();
    record->extra[8 + 2 * j].second = floquet.nontrivial[j].imag();
  }
}

// BP (a further multiplier crosses +1) and PD (one crosses -1) points: sign changes of the Floquet test
// functions between consecutive physical points of a branch, located on the branch (test_function_root.h),
// and pairs of crossings inside one step (FindHiddenRootPair: the SLIP's two −1 crossings of hopping in
// place, 0.036 apart in H̄, are found with steps up to 0.3 instead of only while a step falls between
// them). Returns report lines; appends the points to special_points.
constexpr double kStartNoise = 1e-3;
std::string LocateFloquetPoints(const BifurcationDiagram& diagram, const std::map<int, std::vector<double>>& bp,
                                const std::map<int, std::vector<double>>& pd, TimeBasedShooting& map,
                                const ShootingLayout& layout, nlohmann::json* special_points) {
  std::string report = "Floquet special points (multiplier crossings on physical orbits):\n";
  int count = 0;
  for (const Branch& b : diagram.branches) {
    for (const auto& [type, tests] : {std::pair{"BP", &bp}, std::pair{"PD", &pd}}) {
      const auto it = tests->find(b.id);
      if (it == tests->end()) continue;
      const std::vector<double>& values = it->second;
      const auto floquet_test = [type = std::string(type)](TimeBasedShooting& shooting, const Vector& u) {
        const FloquetResult f = ComputeFloquet(shooting, u);
        return f.ok() ? (type == "BP" ? f.bp_test : f.pd_test) : std::nan("");
      };
      const auto test = [&](const Vector& u) { return floquet_test(map, u); };
      const auto locate = [&](std::size_t i, const Vector& u_a, const Vector& u_b) {
        TestFunctionRootOptions options;
        options.refined_test = [&](ZeroProblem& refined, const Vector& u) {
          return floquet_test(dynamic_cast<TimeBasedShooting&>(refined), u);  // Refined keeps the type
        };
        const TestFunctionRoot root = LocateTestFunctionRoot(&map, u_a, u_b, test, options);
        nlohmann::json j = {{"id", static_cast<int>(special_points->size())},
                            {"type", type},
                            {"branch", b.id},
                            {"index", static_cast<int>(i)},
                            {"H", root.u(layout.H_index())},
                            {"T", layout.Period(root.u)},
                            {"status", root.located ? "located" : "bracketed"},
                            {"precision", root.precision},
                            // the same fields as the continuation's points: the width in H is bounded by
                            // the distance in u; an arclength, residual and component they do not have
                            {"precision_arclength", nullptr},
                            {"precision_H", root.precision},
                            {"residual", nullptr},
                            {"component", ""},
                            {"duplicate_of", -1},
                            {"message", root.message}};
        j["u"] = std::vector<double>(root.u.data(), root.u.data() + root.u.size());
        special_points->push_back(j);
        report += fmt::format("  {} on branch {} after point {}: H = {:.12f}, T = {:.12f} ({}, precision {:.1e}){}\n",
                              type, b.id, i, root.u(layout.H_index()), layout.Period(root.u),
                              root.located ? "located" : "bracketed", root.precision,
                              root.message.empty() ? "" : " " + root.message);
        ++count;
      };
      const std::size_t n = std::min(values.size(), b.points.size());
      for (std::size_t i = 0; i + 1 < n; ++i) {
        const bool finite = std::isfinite(values[i]) && std::isfinite(values[i + 1]);  // NaN: non-physical
        if (finite && values[i] != 0 && values[i + 1] != 0 && std::signbit(values[i]) != std::signbit(values[i + 1])) {
          // A branch that leaves a bifurcation point starts on it: where a test function vanishes there
          // (to kStartNoise of its value at the next point), its sign at the start is noise and the
          // "crossing" is that point itself, reported on the parent branch (SLIP: the branches leaving the
          // SB at H = 1.24674 reported it again as BPs). A test that is not small there is searched as usual.
          if (i == 0 && b.parent_special_point >= 0 && std::abs(values[0]) <= kStartNoise * std::abs(values[1])) continue;
          locate(i, b.points[i].u, b.points[i + 1].u);
        } else if (i >= 1) {
          // Two crossings inside one step cancel in the signs: a local minimum of |test| whose parabola
          // dips through zero is probed (FindHiddenRootPair), and a confirmed pair located on both sides.
          const HiddenRootPair pair = FindHiddenRootPair(
              &map, {&b.points[i - 1].u, &b.points[i].u, &b.points[i + 1].u},
              {b.points[i - 1].arclength, b.points[i].arclength, b.points[i + 1].arclength},
              {values[i - 1], values[i], values[i + 1]}, test);
          if (pair.found) {
            const std::size_t k = i - 1 + static_cast<std::size_t>(pair.segment);
            locate(k, b.points[k].u, pair.u);
            locate(k, pair.u, b.points[k + 1].u);
          }
        }
      }
    }
  }
  if (count == 0) report += "  none\n";
  return report;
}

int ComputeAndWrite(const RunArguments& args, const HybridModel& model, Formulation formulation,
                    const RunSetup& setup, ModelExploration& exploration, ResultsWriter& writer, std::ostream& out,
                    std::ostream& err);

}  // namespace

int RunCommand(const RunArguments& args, std::ostream& out, std::ostream& err) {
  // ---- 1. validate all input before anything is written
  HybridModel model = MakeModelWithOverrides(args.model, args.assignments, &err);
  Formulation formulation;
  if (!FromString(args.formulation, &formulation)) {
    throw std::invalid_argument("--formulation '" + args.formulation + "': expected 'time' or 'state'");
  }
  RunSetup setup;
  if (args.rtol) setup.integrator.rtol = *args.rtol;
  if (args.atol) setup.integrator.atol = *args.atol;
  if (const std::string why = setup.integrator.Validate(); !why.empty()) {
    throw std::invalid_argument("--rtol/--atol: " + why);
  }
  if (args.rtol && !(*args.rtol >= kMinRtol && *args.rtol <= kMaxTolerance)) {
    throw std::invalid_argument(fmt::format("--rtol {:g}: must lie in [{:g}, {:g}]", *args.rtol, kMinRtol, kMaxTolerance));
  }
  if (args.atol && !(*args.atol <= kMaxTolerance)) {
    throw std::invalid_argument(fmt::format("--atol {:g}: must lie in (0, {:g}]", *args.atol, kMaxTolerance));
  }
  // One value per name: a repeated --set, --until or --bound is a mistake, not an override.
  const auto refuse_repeats = [](const std::string& option, const std::vector<std::string>& texts) {
    std::set<std::string> seen;
    for (const std::string& text : texts) {
      const std::string name = text.substr(0, text.find('='));
      if (!seen.insert(name).second) {
        throw std::invalid_argument(option + " '" + text + "': '" + name + "' is given twice");
      }
    }
  };
  refuse_repeats("--until", args.until);
  refuse_repeats("--bound", args.bounds);
  setup.scenario = DefaultScenario(model);
  const Scenario& sc = setup.scenario;
  setup.exploration = ScenarioExplorationOptions(sc);
  ContinuationOptions& c = setup.exploration.continuation;
  for (const std::string& u : args.until) {
    const auto [name, value] = ParseAssignment("--until", u);
    c.targets.push_back({name, value});
  }
  for (const std::string& text : args.bounds) {
    const BoundAssignment b = ParseBound("--bound", text);
    for (const ComponentTarget& t : c.targets) {
      if (t.component == b.name && !(t.value >= b.lower && t.value <= b.upper)) {
        throw std::invalid_argument(fmt::format("--until '{}={:g}' lies outside --bound '{}': no branch could reach it",
                                                t.component, t.value, text));
      }
    }
    if (b.name == "period") {
      std::vector<std::string> durations;
      for (int i = 0; i <= model.num_phases(); ++i) durations.push_back("t" + std::to_string(i + 1));
      c.sum_bounds.assign(1, SumBound{durations, b.lower, b.upper});
    } else {
      std::erase_if(c.bounds, [&](const ComponentBound& x) { return x.component == b.name; });
      c.bounds.push_back({b.name, b.lower, b.upper});
    }
  }
  // A target beyond the model's default bound on the same unknown widens that bound to the target: the
  // user asked to reach it (an explicit --bound on that unknown is kept as given).
  for (const ComponentTarget& t : c.targets) {
    const bool explicit_bound = std::any_of(args.bounds.begin(), args.bounds.end(), [&](const std::string& text) {
      return text.rfind(t.component + "=", 0) == 0;
    });
    for (ComponentBound& b : c.bounds) {
      if (b.component != t.component || explicit_bound) continue;
      b.lower = std::min(b.lower, t.value);
      b.upper = std::max(b.upper, t.value);
    }
  }
  if (args.max_branches) {
    if (*args.max_branches < 1) {
      throw std::invalid_argument("--max-branches " + std::to_string(*args.max_branches) + ": must be >= 1");
    }
    setup.exploration.max_branches = *args.max_branches;
  }
  if (args.threads) {
    if (*args.threads < 1) throw std::invalid_argument("--threads " + std::to_string(*args.threads) + ": must be >= 1");
    if (*args.threads > kMaxThreads) {
      throw std::invalid_argument(fmt::format("--threads {}: must be <= {}", *args.threads, kMaxThreads));
    }
    setup.exploration.threads = *args.threads;
  }
  if (args.no_symmetry) setup.exploration.use_symmetries = false;
  nlohmann::json options_json = OptionsJson(args, setup);
  for (const auto& [name, scale] : sc.unknown_scales) options_json["unknown_scales"][name] = scale;
  std::unique_ptr<ModelExploration> exploration;
  try {
    exploration = std::make_unique<ModelExploration>(model, sc, setup.integrator, setup.exploration, formulation);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(std::string(args.until.empty() && args.bounds.empty() ? "" : "--until/--bound: ") +
                                e.what());
  }
  const fs::path dir = args.out_dir.empty() ? fs::path("results") / model.name() : fs::path(args.out_dir);
  ResultsWriter::PrepareDirectory(dir, model.name(), args.overwrite);

  // ---- 2. compute, streaming every accepted point
  ResultsWriter writer(dir, model, options_json);
  try {
    return ComputeAndWrite(args, model, formulation, setup, *exploration, writer, out, err);
  } catch (const std::exception& e) {
    // The folder must not look complete: the summary says "failed" (or, if it cannot be written, the last
    // one written says "running").
    writer.Fail(e.what());
    throw;
  }
}

namespace {

int ComputeAndWrite(const RunArguments& args, const HybridModel& model, Formulation formulation,
                    const RunSetup& setup, ModelExploration& exploration_ref, ResultsWriter& writer,
                    std::ostream& out, std::ostream& err) {
  const Scenario& sc = setup.scenario;
  ModelExploration* const exploration = &exploration_ref;
  const ShootingLayout& layout = exploration->shooting().layout();
  const fs::path& dir = writer.dir();
  // One map for residuals and Floquet data, separate from the engine's (whose cache stays intact).
  TimeBasedShooting floquet_map(model, setup.integrator);
  ReplayOptions replay_options;
  replay_options.poincare.event.integrator.rtol = setup.integrator.rtol;
  replay_options.poincare.event.integrator.atol = setup.integrator.atol;
  std::map<int, std::vector<double>> floquet_tests, pd_tests;  // per branch, per point (NaN if undefined)
  std::map<int, std::vector<bool>> physical;  // per branch, per accepted point
  int current_branch = -1;
  const auto start_time = std::chrono::steady_clock::now();
  const auto on_point = [&](const ProgressInfo& info, const Vector& u_problem) {
    // Every output uses the time-based layout (durations, x̄_i of every phase) whatever the formulation.
    Vector u;
    if (!exploration->ToTimeBased(u_problem, &u).ok) {
      floquet_tests[info.branch_id].push_back(std::nan(""));  // keep per-point alignment
      pd_tests[info.branch_id].push_back(std::nan(""));
      physical[info.branch_id].push_back(false);
      return;
    }
    PointRecord record;
    record.index = info.point_index;
    record.u = u;
    if (!ClassifyByUnknowns(model, u, ClassificationOptions{}, &record.classification)) {  // no trace needed
      const OrbitTrace trace(model, u, setup.integrator);
      record.classification = ClassifyOrbit(model, u, trace, ClassificationOptions{});
    }
    record.newton_iterations = info.newton_iterations;
    record.step = info.step;
    // Floquet data first: its r + dr evaluation leaves r in the map's cache, so the residual below costs
    // no second integration on physical points.
    AnalyzePhysicalOrbit(model, floquet_map, replay_options, u, &record);
    Vector r;
    const EvaluationStatus status = floquet_map.Evaluate(u, &r, nullptr);
    record.residual = status.ok ? r.norm() : std::nan("");
    floquet_tests[info.branch_id].push_back(record.extra[kBpColumn].second);
    pd_tests[info.branch_id].push_back(record.extra[kPdColumn].second);
    writer.AddPoint(info.branch_id, record);
    physical[info.branch_id].push_back(record.classification.physical);
    if (!args.quiet) {
      if (info.branch_id != current_branch) {
        out << fmt::format("branch {}\n", info.branch_id);
        current_branch = info.branch_id;
      }
      out << fmt::format("  b{:<3} #{:<4} H = {:<12.8f} T = {:<12.8f} step {:<9.3g} newton {}  {}\n", info.branch_id,
                         info.point_index, u(layout.H_index()), layout.Period(u), info.step, info.newton_iterations,
                         ToString(record.classification.reason));
    }
  };
  BifurcationDiagram diagram = exploration->Run(on_point);
  if (formulation == Formulation::kStateBased) {  // everything downstream reads the time-based layout
    const auto convert = [&](Vector* u) {
      Vector u_time;
      if (u->size() && exploration->ToTimeBased(*u, &u_time).ok) *u = u_time;
      else *u = Vector::Constant(layout.num_unknowns(), std::nan(""));
    };
    // Widths of the unknowns both layouts have (x̄_1, ξ, H̄: the same names), NaN for the others.
    const std::vector<std::string> state_names = diagram.unknown_names, time_names = layout.unknown_names();
    const auto convert_width = [&](Vector* width) {
      if (width->size() != static_cast<Eigen::Index>(state_names.size())) return width->resize(0);
      Vector w = Vector::Constant(layout.num_unknowns(), std::nan(""));
      for (size_t i = 0; i < state_names.size(); ++i) {
        const auto it = std::find(time_names.begin(), time_names.end(), state_names[i]);
        if (it != time_names.end()) w(it - time_names.begin()) = (*width)(static_cast<Eigen::Index>(i));
      }
      *width = w;
    };
    for (Branch& b : diagram.branches) {
      for (ContinuationPoint& p : b.points) convert(&p.u), p.tangent.resize(0);
      for (SpecialPoint& sp : b.special_points) convert(&sp.u), convert_width(&sp.interval_width);
    }
    for (SpecialPoint& sp : diagram.special_points) convert(&sp.u), convert_width(&sp.interval_width);
    diagram.unknown_names = layout.unknown_names();
  }
  // ---- 3. summary, key-frame orbits, report, figures
  for (const Branch& b : diagram.branches) writer.EndBranch(b);
  nlohmann::json special_points = SpecialPointsJson(diagram, layout);
  const std::string floquet_report =
      LocateFloquetPoints(diagram, floquet_tests, pd_tests, floquet_map, layout, &special_points);
  writer.SetSpecialPoints(special_points);
  int orbits = 0;
  for (const Branch& b : diagram.branches) {
    if (orbits >= sc.max_keyframe_orbits) continue;
    // the physical point of this branch closest to the key-frame target (classified during the run)
    const std::vector<bool>& flags = physical[b.id];
    int best = -1;
    double best_distance = 1e300;
    for (int i = 0; i < static_cast<int>(b.points.size()) && i < static_cast<int>(flags.size()); ++i) {
      if (!flags[i]) continue;
      const Vector& u = b.points[i].u;
      const double value = sc.keyframes.component == "T" ? layout.Period(u) : u(layout.H_index());
      const double distance = std::abs(value - sc.keyframes.value);
      if (distance < best_distance) best = i, best_distance = distance;
    }
    if (best < 0) continue;
    const Vector& u = b.points[best].u;
    const OrbitTrace trace(model, u, setup.integrator);
    writer.AddOrbit(trace, b.id, best, u(layout.H_index()), layout.Period(u), sc.describe(u));
    ++orbits;
  }
  // Wall time of the whole computation (exploration, classification and replays, Floquet multipliers and
  // their crossings, key-frame orbits, and the branch and orbit files written on the way), before the
  // summary, report and figures; the work of the exploration and of the Floquet multipliers.
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_time).count();
  const std::string report =
      diagram.FullReport() + floquet_report +
      fmt::format("\nwall time {:.3f} s, {} right-hand-side evaluations in {} map evaluations; Floquet multipliers "
                  "and their crossings: {} right-hand-side evaluations in {} map evaluations\n",
                  seconds, exploration->counters().rhs_evaluations, exploration->num_evaluations(),
                  floquet_map.counters().rhs_evaluations, floquet_map.num_evaluations());
  writer.SetReport(report);
  out << report;
  if (!writer.Finish()) {
    // A full disk (or a folder removed under us): what could be written stays, marked as not complete.
    const std::string why = writer.write_error();
    writer.Fail(why);
    err << "error: " << why << "; the results in " << dir.string()
        << "/ are incomplete (summary.json, if present, says status 'running' or 'failed')\n";
    return 1;
  }
  out << fmt::format("results written to {}/ (summary.json, branch-*.csv, orbit-*.csv)\n", dir.string());
  if (!args.no_plots && DrawFigures(dir, err, false) == 0) out << fmt::format("figures written to {}/\n", dir.string());
  return diagram.status == ExplorationStatus::kStartFailed ? 1 : 0;
}

}  // namespace

int PlotCommand(const std::string& dir, std::ostream& out, std::ostream& err) {
  std::error_code ec;
  if (!fs::exists(dir, ec)) throw std::invalid_argument("plot '" + dir + "': no such folder");
  if (!fs::is_directory(dir, ec)) throw std::invalid_argument("plot '" + dir + "': not a folder");
  if (!fs::exists(fs::path(dir) / "summary.json", ec)) {
    throw std::invalid_argument("plot '" + dir + "': no summary.json (run `hybridcont run MODEL --out " + dir + "` first)");
  }
  const int rc = DrawFigures(dir, err, true);
  if (rc == 0) out << "figures written to " << dir << "/\n";
  return rc == 0 ? 0 : rc == 2 ? 2 : 1;  // 2: the script found the results malformed (bad input)
}

}  // namespace hybridcont::app
