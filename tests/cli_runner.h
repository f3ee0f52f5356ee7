// Runs the command-line tool in-process (app::RunCli) and captures its exit code and output.
#ifndef HYBRIDCONT_TESTS_CLI_RUNNER_H_
#define HYBRIDCONT_TESTS_CLI_RUNNER_H_

#include <sstream>
#include <string>
#include <vector>

#include "cli.h"

namespace hybridcont::app {

struct CliResult {
  int code;
  std::string out;
  std::string err;
};

// args without the program name, e.g. {"run", "slip", "--quiet"}.
inline CliResult RunTool(std::vector<std::string> args) {
  args.insert(args.begin(), "hybridcont");
  std::vector<const char*> argv;
  for (const auto& a : args) argv.push_back(a.c_str());
  std::ostringstream out, err;
  const int code = RunCli(static_cast<int>(argv.size()), argv.data(), out, err);
  return {code, out.str(), err.str()};
}

}  // namespace hybridcont::app

#endif  // HYBRIDCONT_TESTS_CLI_RUNNER_H_
