#include "figure_script.h"

#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "install_paths.h"

extern char** environ;  // the figure script inherits this process's environment

namespace hybridcont::app {

namespace fs = std::filesystem;

namespace {

// Everything readable from fd until end of file (reads interrupted by a signal are retried).
std::string ReadAll(int fd) {
  std::string output;
  char buffer[4096];
  for (ssize_t n; (n = read(fd, buffer, sizeof buffer)) != 0;) {
    if (n > 0) output.append(buffer, static_cast<std::size_t>(n));
    else if (errno != EINTR) break;
  }
  return output;
}

// The exit code of child pid; 128 + n when it was killed by signal n.
int WaitFor(pid_t pid) {
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
}

// Runs argv (argv[0] searched on PATH) with stdout and stderr into one pipe; sets its output and exit code
// (127 and a message as output when it cannot be started). False, with a warning on err, when no pipe
// can be made.
bool RunCapturingOutput(char* const argv[], std::string* output, int* rc, std::ostream& err) {
  int fds[2];
  if (pipe(fds) != 0) {
    err << "warning: cannot start the figure script (" << std::strerror(errno) << ")\n";
    return false;
  }
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addclose(&actions, fds[0]);
  posix_spawn_file_actions_adddup2(&actions, fds[1], 1);
  posix_spawn_file_actions_adddup2(&actions, fds[1], 2);
  posix_spawn_file_actions_addclose(&actions, fds[1]);
  pid_t pid = 0;
  const int spawned = posix_spawnp(&pid, argv[0], &actions, nullptr, argv, environ);
  posix_spawn_file_actions_destroy(&actions);
  close(fds[1]);
  if (spawned == 0) *output = ReadAll(fds[0]);
  close(fds[0]);
  *rc = 127;
  if (spawned == 0) {
    *rc = WaitFor(pid);
  } else {
    *output = std::string("cannot start ") + argv[0] + ": " + std::strerror(spawned) + "\n";
  }
  return true;
}

// Writes the script's output to dir/plot.log and repeats its error lines (with `all_messages` its
// warnings too) on err, then a warning when it failed.
void ReportOutput(const fs::path& dir, const std::string& output, int rc, std::ostream& err, bool all_messages) {
  std::error_code ec;
  const fs::path log = dir / "plot.log";
  bool logged = false;
  // `plot` on a damaged folder (exit 2) leaves the folder as it was: its messages are on err.
  if (fs::is_directory(dir, ec) && !(all_messages && rc == 2)) {
    std::ofstream f(log);
    logged = static_cast<bool>(f << output) && static_cast<bool>(f.flush());
  }
  std::istringstream lines(output);
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind("hybridcont_plot: error", 0) == 0 || (all_messages && line.rfind("hybridcont_plot:", 0) == 0)) {
      err << line << "\n";
    }
  }
  if (rc != 0 && !(all_messages && rc == 2)) {  // exit 2 of `plot`: its error line says it all
    err << "warning: drawing the figures failed" << (logged ? " (see " + log.string() + ")" : std::string()) << "\n";
  }
}

}  // namespace

int DrawFigures(const fs::path& dir, std::ostream& err, bool all_messages, const FigureOptions& options) {
  const fs::path script = PlotScriptPath();  // install_paths.h: this executable's own script
  if (script.empty()) {
    err << "warning: figure script not found (see `hybridcont --paths`); results are saved, figures skipped\n";
    return 1;
  }
  // Debian's python3 carries matplotlib (python3-matplotlib); prefer it over other pythons on PATH.
  std::error_code ec;
  const std::string python = fs::exists("/usr/bin/python3", ec) ? "/usr/bin/python3" : "python3";
  std::vector<std::string> words = {python, script.string(), dir.string()};
  if (options.svg) words.push_back("--svg");
  if (options.pdf) words.push_back("--pdf");
  if (options.all) words.push_back("--all");
  if (!options.x.empty()) words.insert(words.end(), {"--x", options.x, "--y", options.y});
  std::vector<char*> argv;
  for (std::string& w : words) argv.push_back(w.data());
  argv.push_back(nullptr);
  std::string output;
  int rc = 1;
  if (!RunCapturingOutput(argv.data(), &output, &rc, err)) return 1;
  ReportOutput(dir, output, rc, err, all_messages);
  return rc;
}

}  // namespace hybridcont::app
