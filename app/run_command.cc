// `hybridcont run MODEL ...`: the options parsed into a study (study.h), its progress printed, its report and
// figures. The study itself — every computation and the results folder — is the library's.
#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <stdexcept>
#include <chrono>
#include <iostream>
#include <thread>

#include <unistd.h>

#include "hybridcont/study_answer.h"
#include "commands.h"
#include "figure_script.h"
#include "hybridcont/study.h"
#include "hybridcont/study_report.h"
#include "install_paths.h"
#include "option_parsing.h"

namespace hybridcont::app {

namespace fs = std::filesystem;

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
                           "end every branch exactly where an unknown or an observable of the model reaches a value, "
                           "NAME=VALUE, e.g. H=2 or speed=1 (repeatable)"));
  NonEmpty(run->add_option("--monitor", args->monitors,
                           "locate the points where an observable of the model reaches a value, NAME=VALUE, e.g. "
                           "speed=0.5, or several values, speed=0.5,0.8 (repeatable; special points UZ)"));
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
  NonEmpty(run->add_option("--free", args->free,
                           "continue the families in a model parameter instead of H, e.g. k (needs --fix)"));
  NonEmpty(run->add_option("--fix", args->fix,
                           "the unknown held fixed while --free varies, NAME=VALUE: H=1.5, a state x2_dx=0.8, a "
                           "duration t2=0 (where that phase vanishes) or an observable speed=1; starts are the physical families' crossings "
                           "of that value in the ordinary run"));
  NonEmpty(run->add_option("--curves", args->curves,
                           "after the run, continue every turning and SB point of the physical families in (H, "
                           "PARAMETER), e.g. w2 (bounds: --bound PARAMETER=LO:HI)"));
  run->add_flag("--no-symmetry", args->no_symmetry,
               "trace every half-branch, also those that are images of traced ones under the model's symmetries");
  run->add_flag("--overwrite", args->overwrite,
                "replace the results of another model in --out (without it such a folder is refused)");
  run->add_flag("--period-doubling", args->period_doubling,
                "explore the period-doubled family of every located PD point (the phase sequence traversed twice)");
  run->add_flag("--one-word", args->one_word,
                "a model given as an automaton: follow the start's phase sequence only, not the words its families "
                "lead into where a phase vanishes or a competing guard is touched");
  NonEmpty(run->add_option("--from", args->from,
                           "restart from a saved study (a results folder) at the point --at names, instead of the "
                           "model's start; the new families go to --out"));
  NonEmpty(run->add_option("--at", args->at,
                           "with --from: a special point's label (PD4, SB36, TP22: its type and id in that study), "
                           "a branch's end (B5) or one of its points (B5:12)"));
  NonEmpty(run->add_option("--as", args->as,
                           "with --from: continue (the family beyond the point), switch (every branch through an SB "
                           "point), period-doubled (the family born at a PD point), curve (the point in (H, --curves)), "
                           "free (the family in --free from the orbit); default: what the label's type implies"));
  NonEmpty(run->add_option("--families-of", args->families_of,
                           "a saved study of this model at nearby parameter values (a results folder): trace only "
                           "the half-branches whose counterparts there led to a family, not the whole exploration "
                           "(what a sweep does from grid point to grid point)"));
  NonEmpty(run->add_option("--family", args->families,
                           "with --families-of: continue only this family of it (its name, as the answer names it; "
                           "repeat for several)"));
  run->add_flag("--resume", args->resume,
                "continue the run interrupted in --out (killed, stopped, out of disk): the branches it traced are "
                "taken as they are, the rest computed; the options must be those of that run");
  run->add_flag("--quiet", args->quiet, "no progress");
  run->add_flag("--verbose", args->verbose,
                "a progress line per accepted point and the full report (every branch, special point and switch) "
                "instead of the one-screen answer");
  run->add_flag("--plots", args->plots,
                "also draw the PNG figures (matplotlib, a few seconds; `hybridcont plot DIR` draws them later); the "
                "interactive report.html is written either way");
  run->add_flag("--no-plots", args->no_plots, "draw no PNG figures (the default; kept for scripts that say so)");
}

namespace {

Formulation ParseFormulation(const std::string& text) {
  Formulation formulation;
  if (!FromString(text, &formulation)) {
    throw std::invalid_argument("--formulation '" + text + "': expected 'time' or 'state'");
  }
  return formulation;
}

// The study the command line asks for (its text parsed; the study validates the values).
StudyOptions StudyOptionsOf(const RunArguments& args) {
  StudyOptions o;
  o.model = args.model;
  o.models_directory = ModelsDirectory().string();
  for (const std::string& a : args.assignments) {
    const auto [name, value] = ParseAssignment("--set", a);
    o.parameters.push_back({name, value});
  }
  for (const std::string& a : args.until) {
    const auto [name, value] = ParseAssignment("--until", a);
    o.until.push_back({name, value});
  }
  for (const std::string& a : args.bounds) {
    o.bounds.push_back(ParseBound("--bound", a));
  }
  for (const std::string& a : args.monitors) {  // several values of one observable: NAME=V1,V2,...
    for (const NamedValue& v : ParseAssignments("--monitor", a)) o.monitors.push_back(v);
  }
  o.rtol = args.rtol;
  o.atol = args.atol;
  o.max_branches = args.max_branches;
  // The command line owns the machine: every core unless --threads says otherwise (the library's default is
  // one thread).
  o.threads = args.threads ? *args.threads : std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  o.formulation = ParseFormulation(args.formulation);
  o.use_symmetries = !args.no_symmetry;
  o.follow_word_changes = !args.one_word;
  o.period_doubling = args.period_doubling;
  o.free = args.free;
  if (!args.fix.empty()) {
    const auto [name, value] = ParseAssignment("--fix", args.fix);
    o.fix = NamedValue{name, value};
  }
  o.curves = args.curves;
  o.families_of = args.families_of;
  o.families = args.families;
  o.out_dir = args.out_dir;
  o.overwrite = args.overwrite;
  o.resume = args.resume;
  if (args.from.empty() != args.at.empty()) {
    throw std::invalid_argument(args.from.empty() ? "--at '" + args.at + "': needs --from FOLDER (a saved study)"
                                                  : "--from '" + args.from + "': needs --at LABEL (e.g. PD4, B5)");
  }
  if (!args.from.empty()) {
    RestartSpec r{args.from, args.at, RestartSpec::Kind::kAuto};
    bool known = false;
    for (const RestartSpec::Kind k : {RestartSpec::Kind::kAuto, RestartSpec::Kind::kContinue, RestartSpec::Kind::kSwitch,
                                      RestartSpec::Kind::kPeriodDoubled, RestartSpec::Kind::kCurve,
                                      RestartSpec::Kind::kFree}) {
      if (ToString(k) == args.as) r.kind = k, known = true;
    }
    if (!known) {
      throw std::invalid_argument("--as '" + args.as + "': expected continue, switch, period-doubled, curve or free");
    }
    o.restart = r;
  } else if (args.as != "auto") {
    throw std::invalid_argument("--as '" + args.as + "': needs --from FOLDER --at LABEL");
  }
  return o;
}

// Progress on `out`. On a terminal one line, rewritten in place: the branch, its family, the point and the
// continued coordinate, the points so far and the time (the number of branches is what the run discovers, so
// no fraction of the whole is known in advance); each stage's first words on a line of their own. In a pipe,
// or with --verbose, a line per branch and per accepted point.
StudyHooks PrintingHooks(const RunArguments& args, bool terminal, std::ostream& out, std::ostream& err) {
  StudyHooks hooks;
  hooks.on_note = [&err](const std::string& line) { err << "note: " << CommandLineWords(line) << "\n"; };
  if (args.quiet) return hooks;
  auto current = std::make_shared<int>(-1);
  if (terminal && !args.verbose) {
    struct Status {
      int points = 0;
      bool open = false;  // a status line is on the screen
      std::chrono::steady_clock::time_point start = std::chrono::steady_clock::now(), shown;
    };
    auto status = std::make_shared<Status>();
    hooks.on_point = [&out, status](const StudyPoint& p, const StudyBranch& b) {
      ++status->points;
      const auto now = std::chrono::steady_clock::now();
      if (status->open && now - status->shown < std::chrono::milliseconds(50)) return;  // ~20 updates a second
      status->shown = now;
      const auto at = std::find(b.unknown_names.begin(), b.unknown_names.end(), b.continued);
      const double x = at == b.unknown_names.end() ? std::nan("") : p.u(at - b.unknown_names.begin());
      out << fmt::format("\r\033[K  branch {} {}· point {} · {} = {:.6g} · {} points · {:.1f} s", b.id,
                         b.family.empty() ? "" : "(" + b.family + ") ", p.index, b.continued, x, status->points,
                         std::chrono::duration<double>(now - status->start).count())
          << std::flush;
      status->open = true;
    };
    hooks.on_progress = [&out, status](const StudyProgress& progress) {
      if (progress.message.empty()) return;
      if (status->open) out << "\r\033[K";
      status->open = false;
      out << progress.message << (progress.message.back() == '\n' ? "" : "\n") << std::flush;
    };
    hooks.on_branch = [](const StudyBranch&) {};
    return hooks;
  }
  hooks.on_point = [&out, current](const StudyPoint& p, const StudyBranch& b) {
    if (b.id != *current && b.origin.empty()) out << fmt::format("branch {}\n", b.id);
    *current = b.id;
    const auto at = std::find(b.unknown_names.begin(), b.unknown_names.end(), b.continued);
    const double x = at == b.unknown_names.end() ? std::nan("") : p.u(at - b.unknown_names.begin());
    out << fmt::format("  b{:<3} #{:<4} {} = {:<12.8f} T = {:<12.8f} step {:<9.3g} newton {}  {}{}\n", b.id, p.index,
                       b.continued, x, p.T, p.step, p.newton_iterations, ToString(p.analysis.classification.reason),
                       b.origin.empty() ? "" : " (" + b.origin + ")");
  };
  hooks.on_progress = [&out](const StudyProgress& progress) {
    if (progress.message.empty()) return;
    out << progress.message << (progress.message.back() == '\n' ? "" : "\n");
  };
  return hooks;
}

// report.html in `dir` (study_report.h, SaveStudyReport); false, with a note, when the tool lacks its assets or
// the file cannot be written.
bool WriteReport(const StudyResult& study, const std::string& dir, const HybridModel* model, std::ostream& err) {
  const ReportAssets assets = ReportAssetsOfTool();
  if (const std::string missing = assets.Missing(); !missing.empty()) {
    err << "note: no report.html: this installation lacks " << missing
        << " (the plotting library is installed from npm when the tool is built)\n";
    return false;
  }
  const std::string why = SaveStudyReport(study, dir, assets, model);
  if (!why.empty()) err << "note: no report.html: " << why << "\n";
  return why.empty();
}

// The model the study was computed on, for the report's animations; null, with the reason said, where it
// cannot be rebuilt (its model file has gone or changed since).
std::unique_ptr<HybridModel> ModelForReport(const StudyResult& study, std::ostream& err) {
  try {
    return std::make_unique<HybridModel>(ModelOfStudy(study, ModelsDirectory().string()));
  } catch (const std::invalid_argument& e) {
    err << "note: report.html without the orbits' animations: " << e.what() << "\n";
    return nullptr;
  }
}

}  // namespace

int RunCommand(const RunArguments& args, std::ostream& out, std::ostream& err) {
  StudyOptions options = StudyOptionsOf(args);
  if (options.out_dir.empty()) {
    // The default folder is named by the model: results/<model name>.
    options.out_dir = (fs::path("results") / MakeModelWithOverrides(args.model, {}, nullptr, false).name()).string();
  }
  StudyResult study;
  const bool terminal = &out == &std::cout && isatty(STDOUT_FILENO) == 1;
  try {
    study = RunStudy(options, PrintingHooks(args, terminal, out, err));
  } catch (const StudyOptionError& e) {
    throw CommandLineError(e);
  }
  if (terminal && !args.quiet && !args.verbose) out << "\r\033[K";  // the status line
  out << (args.verbose ? study.report : OneScreenAnswer(study, study.work.wall_seconds));
  const std::string& dir = options.out_dir;
  if (!study.write_error.empty()) {
    // A full disk (or a folder removed under us): what could be written stays, marked as not complete.
    err << "error: " << study.write_error << "; the results in " << dir
        << "/ are incomplete (summary.json, if present, says status 'running' or 'failed')\n";
    return 1;
  }
  // The model again (compiled code cached) for the orbits' drawings; without it the report has no animations.
  const std::unique_ptr<HybridModel> model = ModelForReport(study, err);
  const bool report = WriteReport(study, dir, model.get(), err);
  out << fmt::format("results written to {}/ (summary.json, branch-*.csv, orbit-*.csv{})\n", dir,
                     report ? ", report.html: open it in a browser" : "");
  if (study.status == ExplorationStatus::kStartFailed) {
    err << "error: no family was traced: " << study.message << "\n";
    return 1;  // nothing to draw
  }
  // The figures wait for matplotlib for seconds, the computation takes a fraction of that: drawn on request.
  if (args.plots && !args.no_plots && DrawFigures(dir, err, false) == 0) {
    out << fmt::format("figures written to {}/\n", dir);
  }
  return 0;
}

int PlotCommand(const std::string& dir, const FigureOptions& figures, std::ostream& out, std::ostream& err) {
  std::error_code ec;
  if (!fs::exists(dir, ec)) throw std::invalid_argument("plot '" + dir + "': no such folder");
  if (!fs::is_directory(dir, ec)) throw std::invalid_argument("plot '" + dir + "': not a folder");
  if (!fs::exists(fs::path(dir) / "summary.json", ec)) {
    throw std::invalid_argument("plot '" + dir + "': no summary.json (run `hybridcont run MODEL --out " + dir + "` first)");
  }
  // The figures first: the script checks the folder and names what is damaged (exit 2, nothing written). The
  // figure of the curves shades the regions of the report the run wrote (report.html, rewritten below).
  const int rc = DrawFigures(dir, err, true, figures);
  if (rc == 0 && !figures.x.empty()) {  // one diagram asked for: nothing else is redrawn
    out << "figure written to " << (fs::path(dir) / (figures.y + "_" + figures.x + ".png")).string() << "\n";
    return 0;
  }
  if (rc == 0) {
    out << "figures written to " << dir << "/\n";
    const StudyResult study = LoadStudy(dir);
    // the study's own model (its record: never another of the same name) draws the orbits
    const std::unique_ptr<HybridModel> model = ModelForReport(study, err);
    if (WriteReport(study, dir, model.get(), err)) out << "report written to " << dir << "/report.html\n";
  }
  return rc == 0 ? 0 : rc == 2 ? 2 : 1;  // 2: the script found the results malformed (bad input)
}

}  // namespace hybridcont::app
