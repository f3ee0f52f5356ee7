// `hybridcont run` and `hybridcont plot` (filled in by the exploration work).
#include <CLI/CLI.hpp>

#include "commands.h"

namespace hybridcont::app {

void AddRunOptions(CLI::App* run, RunArguments* args) {
  run->add_option("model", args->model, "built-in model name")->required();
}

int RunCommand(const RunArguments&, std::ostream&, std::ostream& err) {
  err << "error: run is not available yet\n";
  return 1;
}

int PlotCommand(const std::string&, std::ostream&, std::ostream& err) {
  err << "error: plot is not available yet\n";
  return 1;
}

}  // namespace hybridcont::app
