// The CLI subcommands; each returns the process exit code.
#ifndef HYBRIDCONT_APP_COMMANDS_H_
#define HYBRIDCONT_APP_COMMANDS_H_

#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "figure_script.h"

namespace CLI {
class App;
class Option;
}

namespace hybridcont::app {

// Built-in models, or the given ones (names or model files).
int ListCommand(const std::vector<std::string>& models, std::ostream& out, std::ostream& err);

struct CheckArguments {
  std::string model;
  std::vector<std::string> assignments;
  int points = 5;
  unsigned seed = 20251122;
};
int CheckCommand(const CheckArguments& args, std::ostream& out, std::ostream& err);

struct RunArguments {
  std::string model;
  std::vector<std::string> assignments;
  std::vector<std::string> until;
  std::vector<std::string> bounds;     // NAME=LOWER:UPPER, replacing the model's bound on NAME
  std::vector<std::string> monitors;   // OBSERVABLE=VALUE: located where the observable reaches VALUE
  std::string out_dir;
  std::optional<double> rtol;          // unset: library default
  std::optional<double> atol;
  std::optional<int> max_branches;     // unset: the model's scenario default
  std::optional<int> threads;          // unset: ExplorationOptions default (the machine's cores)
  std::string formulation = "time";
  bool quiet = false;
  bool verbose = false;                // a line per point and the full report instead of the one-screen answer
  bool plots = false;                  // also draw the PNG figures (report.html is written either way)
  bool no_plots = false;               // no PNG figures (the default; an explicit --no-plots wins over --plots)
  bool no_symmetry = false;            // trace every half-branch instead of mapping images
  bool overwrite = false;              // replace another model's results in --out (refused otherwise)
  bool one_word = false;               // an automaton: follow the start's word only (no phase-sequence changes)
  bool period_doubling = false;        // explore the period-doubled family of every located PD point
  bool resume = false;                 // continue the study interrupted in --out
  std::string families_of;             // a saved study whose families guide this one (StudyOptions::families_of)
  std::vector<std::string> families;   // only these of its families (StudyOptions::families)
  std::string from;                    // a saved study (results folder) to restart from, at label `at`
  std::string at;                      // "PD4", "SB36", "B5", "B5:12"
  std::string as = "auto";             // what to do there: continue, switch, period-doubled, curve, free
  std::string free;                    // a model parameter continued as an unknown (needs `fix`)
  std::string fix;                     // NAME=VALUE: the unknown held fixed while `free` varies, e.g. H=1.5
  std::string curves;                  // a model parameter: trace special points in (H, it) after the run
};
void AddRunOptions(CLI::App* run, RunArguments* args);
// Refuses an empty value ("--atol ''"): a mistake, not a request for the default. Returns option.
CLI::Option* NonEmpty(CLI::Option* option);
int RunCommand(const RunArguments& args, std::ostream& out, std::ostream& err);

// `plot DIR`: the figures (FigureOptions: formats, --all, one diagram of two columns) and report.html.
int PlotCommand(const std::string& dir, const FigureOptions& figures, std::ostream& out, std::ostream& err);

}  // namespace hybridcont::app

#endif  // HYBRIDCONT_APP_COMMANDS_H_
