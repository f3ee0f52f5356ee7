// The hybridcont command-line tool: `list`, `check`, `run`, `plot`.
#ifndef HYBRIDCONT_APP_CLI_H_
#define HYBRIDCONT_APP_CLI_H_

#include <ostream>

namespace hybridcont::app {

// Runs the CLI; returns the process exit code. Output goes to out, diagnostics to err.
int RunCli(int argc, const char* const* argv, std::ostream& out, std::ostream& err);

}  // namespace hybridcont::app

#endif  // HYBRIDCONT_APP_CLI_H_
