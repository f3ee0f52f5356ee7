#include "cli.h"

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <stdexcept>

#include "commands.h"
#include "hybridcont/models.h"
#include "hybridcont/version.h"
#include "install_paths.h"

namespace hybridcont::app {

int RunCli(int argc, const char* const* argv, std::ostream& out, std::ostream& err) {
  CLI::App app{"hybridcont: families of periodic orbits of conservative hybrid systems"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "hybridcont " HYBRIDCONT_VERSION);
  app.add_flag_callback(
      "--paths",
      [&out] {
        const auto shown = [](const std::filesystem::path& p) { return p.empty() ? "(not found)" : p.string(); };
        out << "plot script: " << shown(PlotScriptPath()) << "\nmodels: " << shown(ModelsDirectory()) << "\n";
        throw CLI::Success();  // like --version: print and exit 0, no subcommand needed
      },
      "print the figure script and the model folder this executable uses, and exit");

  std::vector<std::string> list_models;
  auto* list = app.add_subcommand("list", "list models (default: the built-in ones) with phases, dimensions and parameters");
  list->add_option("models", list_models, "built-in model names or model files (.toml)");

  CheckArguments check_args;
  auto* check = app.add_subcommand("check", "compare every derivative of a model with finite differences");
  check->add_option("model", check_args.model, "built-in model name or model file (.toml)")->required();
  check->add_option("--set", check_args.assignments, "override a parameter, NAME=VALUE (repeatable)");
  check->add_option("--points", check_args.points, "random points per phase")->check(CLI::PositiveNumber);
  check->add_option("--seed", check_args.seed, "seed of the random points");

  RunArguments run_args;
  auto* run = app.add_subcommand("run", "compute the bifurcation diagram of a built-in model or a model file");
  AddRunOptions(run, &run_args);

  std::string plot_dir;
  auto* plot = app.add_subcommand("plot", "draw the figures of saved results");
  plot->add_option("dir", plot_dir, "results folder written by `hybridcont run`")->required();

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // CLI11 formats help/version/usage errors itself
    std::ostringstream o, e2;
    const int code = app.exit(e, o, e2);
    out << o.str();
    err << e2.str();
    return code;
  }
  try {
    if (*list) return ListCommand(list_models, out, err);
    if (*check) return CheckCommand(check_args, out, err);
    if (*run) return RunCommand(run_args, out, err);
    if (*plot) return PlotCommand(plot_dir, out, err);
  } catch (const std::invalid_argument& e) {
    err << "error: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    err << "error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}

}  // namespace hybridcont::app
