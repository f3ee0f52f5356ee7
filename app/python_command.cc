#include "python_command.h"

#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <utility>

#include "install_paths.h"

extern char** environ;

// Set by CMakeLists.txt for this file alone: the Python the package was built for.
#ifndef HYBRIDCONT_PYTHON_EXECUTABLE
#define HYBRIDCONT_PYTHON_EXECUTABLE "python3"
#endif

namespace hybridcont::app {

int RunPythonModule(const std::string& module, const std::vector<std::string>& args, std::ostream& err) {
  const std::filesystem::path package = PythonPackageDirectory();
  if (package.empty()) {
    err << "error: the Python package is not built or installed (the full build makes it: pybind11-dev, "
           "python3-dev); `hybridcont " << module.substr(module.rfind('.') + 1) << "` needs it\n";
    return 127;
  }
  // The interpreter the package was built for (CMake's Python_EXECUTABLE); HYBRIDCONT_PYTHON overrides it.
  const char* chosen = std::getenv("HYBRIDCONT_PYTHON");
  const std::string python = chosen != nullptr && *chosen != '\0' ? chosen : HYBRIDCONT_PYTHON_EXECUTABLE;
  // The package first on PYTHONPATH: this tool's own, whatever else the environment holds.
  std::vector<std::string> environment;
  const char* old_path = std::getenv("PYTHONPATH");
  for (char** e = environ; *e != nullptr; ++e) {
    if (std::strncmp(*e, "PYTHONPATH=", 11) != 0) environment.emplace_back(*e);
  }
  std::string python_path = "PYTHONPATH=" + package.string();
  if (old_path != nullptr && *old_path != '\0') python_path.append(":").append(old_path);
  environment.push_back(std::move(python_path));
  std::vector<std::string> words = {python, "-m", module};
  words.insert(words.end(), args.begin(), args.end());
  std::vector<char*> argv, envp;
  for (std::string& w : words) argv.push_back(w.data());
  argv.push_back(nullptr);
  for (std::string& e : environment) envp.push_back(e.data());
  envp.push_back(nullptr);
  // A child that ends with this process: killed or interrupted, the command takes its Python process (and, through
  // it, the sweep's workers) down with it (PR_SET_PDEATHSIG), instead of leaving it computing unseen.
  const pid_t parent = getpid();
  const pid_t pid = fork();
  if (pid < 0) {
    err << "error: cannot start " << python << ": " << std::strerror(errno) << "\n";
    return 127;
  }
  if (pid == 0) {
    prctl(PR_SET_PDEATHSIG, SIGTERM);
    if (getppid() != parent) _exit(128 + SIGTERM);  // the parent ended before the request took effect
    execvpe(python.c_str(), argv.data(), envp.data());
    const std::string message = "error: cannot start " + python + ": " + std::strerror(errno) + "\n";
    [[maybe_unused]] const ssize_t written = write(STDERR_FILENO, message.data(), message.size());
    _exit(127);
  }
  int status = 0;
  pid_t waited;
  while ((waited = waitpid(pid, &status, 0)) < 0 && errno == EINTR) {
  }
  if (waited < 0) {
    err << "error: lost the Python process (" << std::strerror(errno) << ")\n";
    return 1;
  }
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
}

}  // namespace hybridcont::app
