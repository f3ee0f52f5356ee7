#include "cli.h"

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <algorithm>
#include <cstdio>
#include <sstream>
#include <stdexcept>

#include "commands.h"
#include "hybridcont/models.h"
#include "hybridcont/version.h"
#include "install_paths.h"
#include "python_command.h"

namespace hybridcont::app {

namespace {

// A message as it may be printed to a terminal: valid UTF-8 and printable, with line breaks and tabs kept;
// any other control byte and any byte that is not part of a valid UTF-8 sequence written as \xNN (a model
// file's invalid byte, a newline or escape sequence inside an argument).
std::string Printable(const std::string& text) {
  std::string out;
  const auto escape = [&out](unsigned char c) {
    char buffer[5];
    std::snprintf(buffer, sizeof buffer, "\\x%02x", c);
    out += buffer;
  };
  for (std::size_t i = 0; i < text.size();) {
    const auto c = static_cast<unsigned char>(text[i]);
    if (c == '\n' || c == '\t' || (c >= 0x20 && c < 0x7f)) {
      out += static_cast<char>(c);
      ++i;
      continue;
    }
    // A UTF-8 sequence: its length from the lead byte, continuation bytes 10xxxxxx, no overlong form of a
    // two-byte sequence, nothing above U+10FFFF.
    const int length = c >= 0xc2 && c <= 0xdf ? 2 : c >= 0xe0 && c <= 0xef ? 3 : c >= 0xf0 && c <= 0xf4 ? 4 : 0;
    bool valid = length > 0 && i + length <= text.size();
    for (int k = 1; valid && k < length; ++k) valid = (static_cast<unsigned char>(text[i + k]) & 0xc0) == 0x80;
    if (valid) {
      out.append(text, i, length);
      i += length;
    } else {
      escape(c);
      ++i;
    }
  }
  return out;
}

}  // namespace

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
  auto* list = app.add_subcommand("list", "list models with phases, dimensions and parameters (default: the built-in ones, then the shipped model files by name)");
  list->add_option("models", list_models, "built-in model names or model files (.toml)");

  CheckArguments check_args;
  auto* check = app.add_subcommand("check", "compare every derivative of a model with finite differences");
  NonEmpty(check->add_option("model", check_args.model, "built-in model name or model file (.toml)")->required());
  NonEmpty(check->add_option("--set", check_args.assignments, "override a parameter, NAME=VALUE (repeatable)"));
  NonEmpty(check->add_option("--points", check_args.points, "random points per phase (1 to 1000)"));
  NonEmpty(check->add_option("--seed", check_args.seed, "seed of the random points"));

  RunArguments run_args;
  auto* run = app.add_subcommand("run", "compute the bifurcation diagram of a built-in model or a model file");
  AddRunOptions(run, &run_args);

  std::string plot_dir;
  FigureOptions figures;
  auto* plot = app.add_subcommand("plot", "draw the figures of saved results");
  NonEmpty(plot->add_option("dir", plot_dir, "results folder written by `hybridcont run`")->required());
  plot->add_flag("--svg", figures.svg, "also write every figure as SVG");
  plot->add_flag("--pdf", figures.pdf, "also write every figure as PDF");
  plot->add_flag("--all", figures.all,
                 "label every branch's special points and show every branch whole (by default the view "
                 "encloses the physical families)");
  auto* x_option = NonEmpty(plot->add_option("--x", figures.x, "with --y: draw only column Y over column X"));
  auto* y_option = NonEmpty(plot->add_option("--y", figures.y, "with --x: the column on the vertical axis"));
  x_option->needs(y_option);
  y_option->needs(x_option);

  // A study at every point of a parameter grid, on Dask: the Python package's command (python_command.h); its
  // arguments are its own (`hybridcont sweep --help`).
  auto* sweep = app.add_subcommand("sweep", "a study at every point of a parameter grid, on Dask (see `hybridcont sweep --help`)");
  sweep->prefix_command();
  sweep->set_help_flag();

  // A misspelt command would otherwise be reported as "A subcommand is required".
  const auto is_command = [&app](const std::string& word) {
    const auto commands = app.get_subcommands([](const CLI::App*) { return true; });
    return std::any_of(commands.begin(), commands.end(), [&](const CLI::App* c) { return c->check_name(word); });
  };
  if (argc > 1 && argv[1][0] != '-' && !is_command(argv[1])) {
    err << "error: unknown command '" << Printable(argv[1]) << "' (expected list, check, run, plot or sweep)\n"
        << "Run with --help for more information.\n";
    return 2;
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help and --version: CLI11 prints them (exit 0). Any other parse error (an unknown subcommand or
    // option, a value that does not convert, an option given twice) is bad input: exit code 2.
    if (e.get_exit_code() == static_cast<int>(CLI::ExitCodes::Success)) {
      std::ostringstream o, e2;
      const int code = app.exit(e, o, e2);
      out << o.str();
      err << e2.str();
      return code;
    }
    err << "error: " << Printable(e.what());
    // A model file named like an option ("-x.toml") is read as one: say how to name it.
    for (int i = 1; i < argc; ++i) {
      const std::string a = argv[i];
      if (a.size() > 5 && a[0] == '-' && a.compare(a.size() - 5, 5, ".toml") == 0) {
        err << " ('" << Printable(a) << "' is read as an option; name the model file ./" << Printable(a) << ")";
        break;
      }
    }
    err << "\nRun with --help for more information.\n";
    return 2;
  }
  try {
    if (*list) return ListCommand(list_models, out, err);
    if (*check) return CheckCommand(check_args, out, err);
    if (*run) return RunCommand(run_args, out, err);
    if (*plot) return PlotCommand(plot_dir, figures, out, err);
    if (*sweep) return RunPythonModule("hybridcont.sweeps", sweep->remaining(), err);
  } catch (const std::invalid_argument& e) {
    err << "error: " << Printable(e.what()) << "\n";
    return 2;
  } catch (const std::exception& e) {
    err << "error: " << Printable(e.what()) << "\n";
    return 1;
  }
  return 0;
}

}  // namespace hybridcont::app
