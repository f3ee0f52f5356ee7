// The CLI subcommands; each returns the process exit code.
#ifndef HYBRIDCONT_APP_COMMANDS_H_
#define HYBRIDCONT_APP_COMMANDS_H_

#include <map>
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

// `run`'s arguments: the study's options as the command line gives them (study_options.h declares each, its
// flag and help), parsed and checked by the library; and how the command speaks.
struct RunArguments {
  std::string model;
  std::map<std::string, std::vector<std::string>> texts;  // by field: the text of each occurrence of its flag
  std::map<std::string, bool> switches;                    // by field: the flag was given
  bool quiet = false;
  bool verbose = false;   // a line per point and the full report instead of the one-screen answer
  bool plots = false;     // also draw the PNG figures (report.html is written either way)
  bool no_plots = false;  // no PNG figures (the default; an explicit --no-plots wins over --plots)
};
void AddRunOptions(CLI::App* run, RunArguments* args);
// Refuses an empty value ("--atol ''"): a mistake, not a request for the default. Returns option.
CLI::Option* NonEmpty(CLI::Option* option);
int RunCommand(const RunArguments& args, std::ostream& out, std::ostream& err);

// `plot DIR`: the figures (FigureOptions: formats, --all, one diagram of two columns) and report.html.
int PlotCommand(const std::string& dir, const FigureOptions& figures, std::ostream& out, std::ostream& err);

}  // namespace hybridcont::app

#endif  // HYBRIDCONT_APP_COMMANDS_H_
