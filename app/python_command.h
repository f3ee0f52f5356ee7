// Commands the tool hands to its Python package: `hybridcont sweep` runs the module hybridcont.sweeps (Dask
// lives in Python), found by the rule of install_paths.h, in the Python the package was built for
// (HYBRIDCONT_PYTHON overrides it), as a child process sharing the terminal (its progress, its Ctrl-C).
//   return RunPythonModule("hybridcont.sweeps", {"slip", "--grid", "k=10:160:8"}, err);
#ifndef HYBRIDCONT_APP_PYTHON_COMMAND_H_
#define HYBRIDCONT_APP_PYTHON_COMMAND_H_

#include <ostream>
#include <string>
#include <vector>

namespace hybridcont::app {

// The module's exit code (127 and a message on err when python or the package cannot be found or started;
// 128 + n when it was killed by signal n).
int RunPythonModule(const std::string& module, const std::vector<std::string>& args, std::ostream& err);

}  // namespace hybridcont::app

#endif  // HYBRIDCONT_APP_PYTHON_COMMAND_H_
