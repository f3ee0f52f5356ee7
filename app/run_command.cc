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
  for (const StudyOptionSpec& spec : StudyOptionSpecs()) {
    const std::string help = SayOptions(spec.help, FlagOf);
    if (spec.flag.empty()) continue;  // not an option of the command line
    if (spec.flag.rfind("--", 0) != 0) {  // the positional model
      NonEmpty(run->add_option(spec.field, args->model, help)->required());
    } else if (spec.kind == OptionKind::kSwitch) {
      run->add_flag(spec.flag, args->switches[spec.field], help);
    } else {
      // Every occurrence is kept, so that the library refuses an option given twice and names both texts.
      run->add_option(spec.flag, args->texts[spec.field], help)->option_text(spec.value_name)->allow_extra_args(false);
    }
  }
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

// The study the command line asks for: each option's text parsed and set by the library's declaration.
StudyOptions StudyOptionsOf(const RunArguments& args) {
  StudyOptions o;
  o.model = args.model;
  o.models_directory = ModelsDirectory().string();
  // The command line owns the machine: every core unless --threads says otherwise (the library's default is
  // one thread).
  o.threads = std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  for (const auto& [field, given] : args.switches) {
    if (given) SetStudyOption(&o, field, true);
  }
  for (const auto& [field, texts] : args.texts) {
    if (!texts.empty()) SetStudyOption(&o, field, ParseStudyOption(*FindStudyOption(field), texts));
  }
  return o;
}

// Progress on `out`. On a terminal one line, rewritten in place: the branch, its family, the point and the
// continued coordinate, the points so far and the time (the number of branches is what the run discovers, so
// no fraction of the whole is known in advance); each stage's first words on a line of their own. With
// --verbose a line per branch and per accepted point. In a pipe (a log, `| less`, a notebook's `!hybridcont`)
// none without --verbose: the answer is what a reader of the pipe wants.
StudyHooks PrintingHooks(const RunArguments& args, bool terminal, std::ostream& out, std::ostream& err) {
  StudyHooks hooks;
  hooks.on_note = [&err](const std::string& line) { err << "note: " << line << "\n"; };
  hooks.option_words = FlagOf;
  if (args.quiet || (!terminal && !args.verbose)) return hooks;
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
  StudyResult study;
  StudyOptions options;
  const bool terminal = &out == &std::cout && isatty(STDOUT_FILENO) == 1;
  try {
    options = StudyOptionsOf(args);
    if (options.out_dir.empty()) {
      // The default folder is named by the model: results/<model name>.
      options.out_dir = (fs::path("results") / MakeModelWithOverrides(args.model, {}, nullptr, false).name()).string();
    }
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
    if (study.branches.empty()) {
      err << "error: no family was traced: " << study.message << "\n";
    } else {  // the file word's start failed; the automaton's other starts gave the families written
      err << "error: the model's start failed, the families of its other starts are written: " << study.message << "\n";
    }
    return 1;
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
