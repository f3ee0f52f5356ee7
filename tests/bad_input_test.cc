// Bad and hostile input, table-driven: each row runs the built command-line tool (or the figure script) in
// a child process with a deadline and states the exit code and a fragment of the message it must give.
// A crash (a signal), a hang (the deadline), a Python traceback or an uncaught C++ exception fails the row
// whatever its expectations; a row refused as bad input (exit 2) must leave its folder exactly as it was;
// a summary.json left behind by a failed run must not say "complete". docs/bad-input.md lists the rows.
//
// The contract (docs/design/README.md, "Bad input"): bad input → a message naming the field and the value (and for model
// files the line), exit code 2, nothing written; a numerical failure → exit 1 with a status in the result.
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <fcntl.h>
#include <signal.h>
#include <sys/mount.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

namespace {

namespace fs = std::filesystem;

// A row that runs longer hangs. Generous, so that the sanitizers' slowdown (the full-disk row takes 19 s
// under AddressSanitizer) is never taken for a hang; the suite's speed is measured in bench/, not here.
constexpr double kDeadlineSeconds = 120;

// The folder of one row: work/ is the child's working directory and holds everything the row sets up.
struct Context {
  fs::path work;
  std::string skip;                         // set by a set-up that cannot run here (e.g. mount refused)
  std::vector<std::function<void()>> undo;  // run after the row, whatever happened
};
using Setup = std::function<void(Context&)>;

enum class Tool { kCli, kScript };

struct BadInputCase {
  std::string name;
  std::vector<std::string> argv;  // {work}: the row's folder; {models}: the source tree's models folder
  int exit_code;
  std::string message;  // a fragment of stderr (or stdout, for outcomes reported there)
  Setup setup = nullptr;
  Tool tool = Tool::kCli;
  std::function<void(const Context&)> check = nullptr;  // more about the files left behind
};

std::ostream& operator<<(std::ostream& os, const BadInputCase& c) { return os << c.name; }

std::string Replace(std::string text, const std::string& from, const std::string& to) {
  for (std::size_t at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size())) {
    text.replace(at, from.size(), to);
  }
  return text;
}

std::string ReadFile(const fs::path& path) {
  std::ifstream f(path, std::ios::binary);
  std::ostringstream s;
  s << f.rdbuf();
  return s.str();
}

void WriteFile(const fs::path& path, const std::string& text) {
  fs::create_directories(path.parent_path());
  std::ofstream(path, std::ios::binary) << text;
}

const fs::path kModels = fs::path(HYBRIDCONT_SOURCE_DIR) / "models";
std::string Ball() { return ReadFile(kModels / "bouncing-ball.toml"); }

// Every file below dir with its size and content hash: "nothing written" compares two of these.
std::map<std::string, std::string> Snapshot(const fs::path& dir) {
  std::map<std::string, std::string> files;
  std::error_code ec;
  for (auto it = fs::recursive_directory_iterator(dir, fs::directory_options::skip_permission_denied, ec);
       it != fs::recursive_directory_iterator(); it.increment(ec)) {
    if (ec) break;
    const fs::path& p = it->path();
    std::string what = it->is_directory(ec) ? "dir" : "other";
    if (it->is_regular_file(ec)) what = std::to_string(std::hash<std::string>{}(ReadFile(p)));
    files[p.lexically_relative(dir).string()] = what;
  }
  return files;
}

struct Outcome {
  int code = -1;
  int signal = 0;
  bool hung = false;
  double seconds = 0;
  std::string out, err;
};

// Runs argv in a child process in `cwd`; stdout and stderr go to files next to cwd.
Outcome Spawn(const std::vector<std::string>& argv, const fs::path& cwd) {
  const fs::path out_file = cwd.string() + ".stdout", err_file = cwd.string() + ".stderr";
  const auto start = std::chrono::steady_clock::now();
  const pid_t pid = fork();
  if (pid == 0) {
    if (chdir(cwd.c_str()) != 0) _exit(126);
    const int out = open(out_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int err = open(err_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int in = open("/dev/null", O_RDONLY);
    if (out < 0 || err < 0 || in < 0) _exit(126);
    dup2(in, 0), dup2(out, 1), dup2(err, 2);
    std::vector<char*> args;
    for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    execv(args[0], args.data());
    _exit(127);
  }
  Outcome o;
  int status = 0;
  while (true) {
    const pid_t done = waitpid(pid, &status, WNOHANG);
    o.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (done == pid) break;
    if (o.seconds > kDeadlineSeconds) {
      kill(pid, SIGKILL);
      waitpid(pid, &status, 0);
      o.hung = true;
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  if (!o.hung && WIFEXITED(status)) o.code = WEXITSTATUS(status);
  if (!o.hung && WIFSIGNALED(status)) o.signal = WTERMSIG(status);
  o.out = ReadFile(out_file);
  o.err = ReadFile(err_file);
  return o;
}

// ---- set-ups

// A finished run of the bouncing ball (--no-plots) in work/DIR.
Setup BallResults(const std::string& dir = "res") {
  return [dir](Context& c) {
    const Outcome o = Spawn(
        {HYBRIDCONT_CLI_PATH, "run", "bouncing-ball", "--out", dir, "--quiet", "--no-plots", "--threads", "1"}, c.work);
    if (o.code != 0) c.skip = "set-up run failed: " + o.err;
  };
}

// BallResults, then `edit` of the folder.
Setup BallResultsThen(std::function<void(const fs::path& res)> edit) {
  return [edit](Context& c) {
    BallResults()(c);
    if (c.skip.empty()) edit(c.work / "res");
  };
}

// Replaces text in the folder's summary.json.
Setup SummaryEdit(const std::string& from, const std::string& to) {
  return BallResultsThen([from, to](const fs::path& res) {
    const std::string text = ReadFile(res / "summary.json");
    EXPECT_NE(text.find(from), std::string::npos) << from;
    WriteFile(res / "summary.json", Replace(text, from, to));
  });
}

Setup File(const std::string& name, std::function<std::string()> text) {
  return [name, text](Context& c) { WriteFile(c.work / name, text()); };
}

// The bouncing ball's model file with one replacement.
Setup BallFile(const std::string& name, const std::string& from, const std::string& to) {
  return File(name, [from, to] {
    const std::string ball = Ball();
    EXPECT_NE(ball.find(from), std::string::npos) << from;
    return Replace(ball, from, to);
  });
}

std::string Repeat(const std::string& s, int n) {
  std::string r;
  for (int i = 0; i < n; ++i) r += s;
  return r;
}

// A tmpfs of `size` mounted at work/mnt (read-only with ro); unmounted after the row. Skips where mount
// is not permitted (no root, no CAP_SYS_ADMIN).
Setup Tmpfs(const std::string& size, bool read_only) {
  return [size, read_only](Context& c) {
    const fs::path mnt = c.work / "mnt";
    fs::create_directories(mnt);
    const std::string options = "size=" + size;
    if (mount("tmpfs", mnt.c_str(), "tmpfs", read_only ? MS_RDONLY : 0, options.c_str()) != 0) {
      c.skip = "cannot mount a tmpfs here (" + std::string(std::strerror(errno)) + "); needs root";
      return;
    }
    c.undo.push_back([mnt] { umount2(mnt.c_str(), MNT_DETACH); });
  };
}

// ---- checks of what a row left behind

nlohmann::json Summary(const fs::path& dir) {
  std::ifstream f(dir / "summary.json");
  return nlohmann::json::parse(f, nullptr, false);
}

// The folder describes one run of `model`: status complete, every CSV it holds is named in its summary.
std::function<void(const Context&)> OneCompleteResult(const std::string& dir, const std::string& model) {
  return [dir, model](const Context& c) {
    const nlohmann::json s = Summary(c.work / dir);
    ASSERT_TRUE(s.is_object());
    EXPECT_EQ(s["model"], model);
    EXPECT_EQ(s["status"], "complete");
    std::set<std::string> named;
    for (const auto& b : s["branches"]) named.insert(b["file"].get<std::string>());
    for (const auto& o : s["orbits"]) named.insert(o["file"].get<std::string>());
    for (const auto& e : fs::directory_iterator(c.work / dir)) {
      const std::string name = e.path().filename().string();
      if (e.path().extension() == ".csv") EXPECT_TRUE(named.count(name)) << name << " is not part of this result";
      EXPECT_NE(name, "H_T_xi.png") << "a figure of the earlier model remains";
    }
    for (const std::string& f : named) EXPECT_TRUE(fs::exists(c.work / dir / f)) << f;
  };
}

std::vector<std::string> Cli(std::vector<std::string> args) {
  args.insert(args.begin(), HYBRIDCONT_CLI_PATH);
  return args;
}
std::vector<std::string> Script(std::vector<std::string> args) {
  args.insert(args.begin(), {"/usr/bin/python3", std::string(HYBRIDCONT_SOURCE_DIR) + "/python/hybridcont_plot.py"});
  return args;
}

// A quick run into work/out whose options must be refused before anything is computed or written.
std::vector<std::string> Run(const std::string& model, std::vector<std::string> options) {
  std::vector<std::string> a = {"run", model, "--out", "out", "--quiet", "--no-plots"};
  a.insert(a.end(), options.begin(), options.end());
  return Cli(a);
}

const std::vector<BadInputCase>& Cases() {
  static const std::vector<BadInputCase> cases = {
      // ---------------------------------------------------------------- CLI: unknown names
      {"UnknownCommand", Cli({"frobnicate"}), 2, "unknown command 'frobnicate'"},
      {"NoCommand", Cli({}), 2, "A subcommand is required"},
      {"UnknownGlobalOption", Cli({"--bogus", "list"}), 2, "--bogus"},
      {"UnknownRunOption", Run("slip", {"--bogus"}), 2, "not expected: --bogus"},
      {"UnknownListOption", Cli({"list", "--set", "k=1"}), 2, "not expected: --set"},
      {"UnknownModelRun", Run("pogo-stick", {}), 2, "unknown model 'pogo-stick'"},
      {"UnknownModelCheck", Cli({"check", "pogo-stick"}), 2, "unknown model 'pogo-stick'"},
      {"UnknownModelList", Cli({"list", "pogo-stick"}), 2, "unknown model 'pogo-stick'"},
      {"EmptyModelName", Cli({"run", ""}), 2, "model: an empty value is not allowed"},
      {"RunWithoutModel", Cli({"run"}), 2, "model is required"},
      {"CheckWithoutModel", Cli({"check"}), 2, "model is required"},
      {"PlotWithoutFolder", Cli({"plot"}), 2, "dir is required"},
      {"PlotTwoFolders", Cli({"plot", "a", "b"}), 2, "not expected: b"},
      {"SetUnknownParameter", Run("slip", {"--set", "stiffness=3"}), 2, "model 'slip' has no parameter 'stiffness'"},
      {"CheckSetUnknownParameter", Cli({"check", "slip", "--set", "q=1"}), 2, "has no parameter 'q'"},
      {"UntilUnknownName", Run("slip", {"--until", "Q=2"}), 2, "\"Q\" is not an unknown"},
      {"BoundUnknownName", Run("slip", {"--bound", "Q=0:1"}), 2, "\"Q\" is not an unknown"},
      {"BoundPeriodMisspelt", Run("slip", {"--bound", "periods=0:9"}), 2, "\"periods\" is not an unknown"},
      {"RestartAtWithoutFrom", Run("slip", {"--at", "PD4"}), 2, "--at 'PD4': needs --from FOLDER"},
      {"RestartFromWithoutAt", Run("slip", {"--from", "results/slip"}), 2, "needs --at LABEL"},
      {"RestartFromNoStudy", Run("slip", {"--from", "/nonexistent-hybridcont", "--at", "PD4"}), 2,
       "--from/--at '/nonexistent-hybridcont' 'PD4': not a saved study: '/nonexistent-hybridcont': not a folder"},
      {"RestartUnknownKind", Run("slip", {"--from", "x", "--at", "PD4", "--as", "sideways"}), 2,
       "--as 'sideways': expected 'auto', 'continue', 'switch', 'period-doubled', 'curve' or 'free'"},
      {"FamiliesOfNoStudy", Run("slip", {"--families-of", "/nonexistent-hybridcont"}), 2,
       "--families-of '/nonexistent-hybridcont': not a saved study"},
      {"FamilyWithoutFamiliesOf", Run("slip", {"--family", "hopping in place"}), 2,
       "--family 'hopping in place': needs the saved study whose families are continued"},
      {"FreeWithoutFix", Run("slip", {"--free", "k"}), 2, "--free 'k': needs --fix NAME=VALUE"},
      {"FixWithoutFree", Run("slip", {"--fix", "H=1.5"}), 2, "--fix 'H=1.5': needs --free PARAMETER"},
      {"FreeUnknownParameter", Run("slip", {"--free", "kk", "--fix", "H=1.5"}), 2,
       "--free 'kk': model 'slip' has no such parameter"},
      {"FixNotAnUnknown", Run("slip", {"--free", "k", "--fix", "speed=1"}), 2, "--fix 'speed=1': 'speed' is not an unknown or observable of model 'slip' that can be held fixed"},
      {"MonitorNotAnObservable", Run("slip", {"--monitor", "speed=1"}), 2,
       "--monitor 'speed=1': 'speed' is not an observable of model 'slip' (it declares none)"},
      {"MonitorNotANumber", Run("slip", {"--monitor", "speed=fast"}), 2, "--monitor 'speed=fast': value 'fast' is not a number"},
      {"FixNotANumber", Run("slip", {"--free", "k", "--fix", "H=x"}), 2, "--fix 'H=x': value 'x' is not a number"},
      {"FreeStateFormulation", Run("slip", {"--free", "k", "--fix", "H=1.5", "--formulation", "state"}), 2,
       "--formulation state: --free 'k' needs the time-based formulation"},
      {"FreePeriodDoubling", Run("slip", {"--free", "k", "--fix", "H=1.5", "--period-doubling"}), 2,
       "--period-doubling: not with --free 'k'"},
      {"FreeUntilOutsideBound", Run("slip", {"--free", "k", "--fix", "H=1.5", "--bound", "k=10:20", "--until", "k=50"}),
       2, "--until 'k=50' lies outside --bound 'k=10:20'"},
      {"CurvesUnknownParameter", Run("slip", {"--curves", "zz"}), 2, "--curves 'zz': model 'slip' has no such parameter"},
      {"CurvesInTheFreeParameter", Run("slip", {"--curves", "k", "--free", "k", "--fix", "H=1.5"}), 2,
       "--curves 'k': the families are continued in k already; the curves need a second parameter"},
      {"PeriodDoublingWithAnObservableUnknown",
       Run("slip.toml", {"--period-doubling", "--extremum", "apex"}), 2,
       "--period-doubling: not with an observable among the unknowns ('apex'"},
      {"ExtremumNotAnObservable", Run("slip", {"--extremum", "zz"}), 2,
       "--extremum 'zz': not an observable of model 'slip' (it declares none)"},
      {"CurvesBoundExcludesValue", Run("slip", {"--curves", "w2", "--bound", "w2=6:10"}), 2,
       "--bound 'w2=6:10': excludes the model's w2 = 5"},
      // ---------------------------------------------------------------- CLI: malformed values
      {"SetNotANumber", Run("slip", {"--set", "k=abc"}), 2, "--set 'k=abc': value 'abc' is not a number"},
      {"SetTrailingText", Run("slip", {"--set", "k=3x"}), 2, "value '3x' is not a number"},
      {"SetEmptyValue", Run("slip", {"--set", "k="}), 2, "value '' is not a number"},
      {"SetWithoutEquals", Run("slip", {"--set", "k"}), 2, "--set 'k': expected NAME=VALUE"},
      {"SetWithoutName", Run("slip", {"--set", "=3"}), 2, "--set '=3': expected NAME=VALUE"},
      {"SetEmpty", Run("slip", {"--set", ""}), 2, "--set '': an empty value (give a value, or leave the option out)"},
      {"RtolTruncatedExponent", Run("slip", {"--rtol", "1e"}), 2, "--rtol '1e': value '1e' is not a number"},
      {"RtolWord", Run("slip", {"--rtol", "tight"}), 2, "--rtol 'tight': value 'tight' is not a number"},
      {"AtolEmpty", Run("slip", {"--atol", ""}), 2, "--atol '': an empty value (give a value, or leave the option out)"},
      {"OutEmpty", Run("slip", {"--out", ""}), 2, "--out '': an empty value (give a value, or leave the option out)"},
      {"BoundReversed", Run("slip", {"--bound", "H=2:1"}), 2, "--bound 'H=2:1': the lower end must be below"},
      {"BoundEqualEnds", Run("slip", {"--bound", "H=1:1"}), 2, "the lower end must be below the upper end"},
      {"BoundBothEndsEmpty", Run("slip", {"--bound", "H=:"}), 2, "--bound 'H=:': both ends are empty"},
      {"BoundWithoutColon", Run("slip", {"--bound", "H=2"}), 2, "--bound 'H=2': expected NAME=LOWER:UPPER"},
      {"BoundLowerNotANumber", Run("slip", {"--bound", "H=a:1"}), 2, "(lower end): value 'a' is not a number"},
      {"BoundEmpty", Run("slip", {"--bound", ""}), 2, "--bound '': an empty value (give a value, or leave the option out)"},
      {"UntilWithoutValue", Run("slip", {"--until", "H"}), 2, "--until 'H': expected NAME=VALUE"},
      {"UntilNotANumber", Run("slip", {"--until", "H=two"}), 2, "--until 'H=two': value 'two' is not a number"},
      {"MaxBranchesWord", Run("slip", {"--max-branches", "many"}), 2, "--max-branches 'many': not a whole number"},
      {"MaxBranchesFraction", Run("slip", {"--max-branches", "1.5"}), 2, "--max-branches '1.5': not a whole number"},
      {"ThreadsWord", Run("slip", {"--threads", "all"}), 2, "--threads 'all': not a whole number"},
      {"PointsWord", Cli({"check", "slip", "--points", "few"}), 2, "--points = few"},
      {"SeedNegative", Cli({"check", "slip", "--seed", "-1"}), 2, "--seed = -1"},
      {"SeedEmpty", Cli({"check", "slip", "--seed", ""}), 2, "--seed: an empty value is not allowed"},
      // ---------------------------------------------------------------- CLI: NaN and infinity
      {"SetNan", Run("slip", {"--set", "k=nan"}), 2, "--set 'k=nan': value 'nan' is not finite"},
      {"SetInf", Run("slip", {"--set", "k=inf"}), 2, "value 'inf' is not finite"},
      {"SetMinusInfinity", Run("slip", {"--set", "k=-infinity"}), 2, "value '-infinity' is not finite"},
      {"SetOverflow", Run("slip", {"--set", "k=1e999"}), 2, "value '1e999' is not finite (out of range)"},
      {"CheckSetNan", Cli({"check", "slip", "--set", "w2=NaN"}), 2, "value 'NaN' is not finite"},
      {"RtolNan", Run("slip", {"--rtol", "nan"}), 2, "--rtol 'nan': value 'nan' is not finite"},
      {"RtolInf", Run("slip", {"--rtol", "inf"}), 2, "--rtol 'inf': value 'inf' is not finite"},
      {"AtolNan", Run("slip", {"--atol", "nan"}), 2, "--atol 'nan': value 'nan' is not finite"},
      {"AtolMinusInf", Run("slip", {"--atol", "-inf"}), 2, "--atol '-inf': value '-inf' is not finite"},
      {"UntilNan", Run("slip", {"--until", "H=nan"}), 2, "--until 'H=nan': value 'nan' is not finite"},
      {"UntilInf", Run("slip", {"--until", "H=inf"}), 2, "value 'inf' is not finite"},
      {"BoundLowerNan", Run("slip", {"--bound", "H=nan:1"}), 2, "--bound 'H=nan:1' (lower end): value 'nan' is not finite"},
      {"BoundUpperInf", Run("slip", {"--bound", "H=0:inf"}), 2, "(upper end): value 'inf' is not finite"},
      {"MaxBranchesNan", Run("slip", {"--max-branches", "nan"}), 2, "--max-branches 'nan': not a whole number"},
      {"ThreadsInf", Run("slip", {"--threads", "inf"}), 2, "--threads 'inf': not a whole number"},
      {"PointsNan", Cli({"check", "slip", "--points", "nan"}), 2, "--points = nan"},
      // ---------------------------------------------------------------- CLI: values outside a parameter's range
      {"SlipMassNegative", Run("slip", {"--set", "m=-1"}), 2, "parameter 'm' of model 'slip' = -1 is outside its range (0, inf)"},
      {"SlipMassZero", Run("slip", {"--set", "m=0"}), 2, "= 0 is outside its range (0, inf)"},
      {"RockingBlockBeta2", Run("rocking-block", {"--set", "beta=2"}), 2, "parameter 'beta' of model 'rocking-block' = 2 is outside its range"},
      {"RodRadiusNegative", Cli({"check", "bouncing-rod", "--set", "r=-0.01"}), 2, "parameter 'r' of model 'bouncing-rod'"},
      {"ModelFileParameterOutsideRange", Run("{models}/bouncing-ball.toml", {"--set", "g=-9.81"}), 2, "parameter 'g' of model 'bouncing-ball' = -9.81 is outside its range"},
      // ---------------------------------------------------------------- CLI: tolerances that make no sense
      {"Rtol1", Run("slip", {"--rtol", "1"}), 2, "--rtol 1: must lie in [1e-14, 0.1]"},
      {"Rtol0", Run("slip", {"--rtol", "0"}), 2, "rtol = 0 must be finite and > 0"},
      {"RtolNegative", Run("slip", {"--rtol", "-1e-8"}), 2, "rtol = -1e-08 must be finite and > 0"},
      {"Rtol1e-300", Run("slip", {"--rtol", "1e-300"}), 2, "--rtol 1e-300: must lie in [1e-14, 0.1]"},
      {"AtolNegative", Run("slip", {"--atol", "-1"}), 2, "atol = -1 must be finite and > 0"},
      {"Atol0", Run("slip", {"--atol", "0"}), 2, "atol = 0 must be finite and > 0"},
      {"Atol1", Run("slip", {"--atol", "1"}), 2, "--atol 1: must lie in (0, 0.1]"},
      // ---------------------------------------------------------------- CLI: thread counts, branch limits, points
      {"Threads0", Run("slip", {"--threads", "0"}), 2, "--threads 0: must be >= 1"},
      {"ThreadsMinus1", Run("slip", {"--threads", "-1"}), 2, "--threads -1: must be >= 1"},
      {"Threads100000", Run("slip", {"--threads", "100000"}), 2, "--threads 100000: must be <= 256"},
      {"ThreadsOverflow", Run("slip", {"--threads", "99999999999"}), 2, "--threads '99999999999': out of range"},
      {"MaxBranches0", Run("slip", {"--max-branches", "0"}), 2, "--max-branches 0: must be >= 1"},
      {"MaxBranchesNegative", Run("slip", {"--max-branches", "-5"}), 2, "--max-branches -5: must be >= 1"},
      {"MaxBranchesOverflow", Run("slip", {"--max-branches", "99999999999"}), 2, "--max-branches '99999999999': out of range"},
      // a limit far above the diagram's size is no mistake: the diagram completes
      {"MaxBranchesHugeIsALimit", Run("bouncing-ball", {"--max-branches", "2147483647"}), 0, "", nullptr, Tool::kCli,
       OneCompleteResult("out", "bouncing-ball")},
      {"CheckPoints0", Cli({"check", "slip", "--points", "0"}), 2, "--points 0: must lie in [1, 1000]"},
      {"CheckPointsHuge", Cli({"check", "slip", "--points", "100000000"}), 2, "--points 100000000: must lie in [1, 1000]"},
      // ---------------------------------------------------------------- CLI: conflicting or repeated options
      {"RtolTwice", Run("slip", {"--rtol", "1e-8", "--rtol", "1e-9"}), 2, "--rtol '1e-9': given twice (first '1e-8'); give it once"},
      {"OutTwice", Run("slip", {"--out", "other"}), 2, "--out 'other': given twice"},
      {"FormulationTwice", Run("slip", {"--formulation", "time", "--formulation", "state"}), 2, "--formulation 'state': given twice (first 'time')"},
      {"SetTwice", Run("slip", {"--set", "k=20", "--set", "k=30"}), 2, "--set 'k=30': 'k' is given twice"},
      {"CheckSetTwice", Cli({"check", "slip", "--set", "k=20", "--set", "k=20"}), 2, "'k' is given twice"},
      {"UntilTwice", Run("slip", {"--until", "H=1", "--until", "H=1.5"}), 2, "--until 'H=1.5': 'H' is given twice"},
      {"BoundTwice", Run("slip", {"--bound", "H=0:1", "--bound", "H=0:2"}), 2, "--bound 'H=0:2': 'H' is given twice"},
      {"MonitorValueTwice", Run("slip.toml", {"--monitor", "apex=1.2,1.2"}), 2, "--monitor 'apex=1.2': is given twice"},
      {"UntilFarBeyondTheBound", Run("slip", {"--until", "H=1e300"}), 2,
       "--until 'H=1e+300' lies 1e+300 beyond the model's bound [0, 2] of H, more than 100 times its width"},
      {"UntilOutsideBound", Run("slip", {"--until", "H=2", "--bound", "H=0:1"}), 2, "--until 'H=2' lies outside --bound 'H=0:1'"},
      {"FormulationFoo", Run("slip", {"--formulation", "foo"}), 2, "--formulation 'foo': expected 'time' or 'state'"},
      {"FormulationUpperCase", Run("slip", {"--formulation", "TIME"}), 2, "--formulation 'TIME'"},
      {"FormulationEmpty", Run("slip", {"--formulation", ""}), 2, "--formulation '': an empty value (give a value, or leave the option out)"},
      // ---------------------------------------------------------------- output folders
      {"OutUnderAFile", Cli({"run", "bouncing-ball", "--out", "file/x", "--quiet", "--no-plots"}), 2,
       "--out 'file/x': cannot create the folder (Not a directory)", File("file", [] { return "x"; })},
      {"OutUnderEtcPasswd", Cli({"run", "bouncing-ball", "--out", "/etc/passwd/x", "--quiet", "--no-plots"}), 2,
       "--out '/etc/passwd/x': cannot create the folder"},
      {"OutIsAFile", Cli({"run", "bouncing-ball", "--out", "file", "--quiet", "--no-plots"}), 2,
       "--out 'file': exists and is not a folder", File("file", [] { return "x"; })},
      {"OutReadOnly", Cli({"run", "bouncing-ball", "--out", "mnt", "--quiet", "--no-plots"}), 2,
       "--out 'mnt': folder is not writable", Tmpfs("64k", true)},
      {"OutReadOnlySubfolder", Cli({"run", "bouncing-ball", "--out", "mnt/res", "--quiet", "--no-plots"}), 2,
       "--out 'mnt/res': cannot create the folder (Read-only file system)", Tmpfs("64k", true)},
      // a full disk in the middle of a run: exit 1, the message says which file, the folder not complete
      {"OutFull", Cli({"run", "slip", "--out", "mnt/res", "--quiet", "--no-plots", "--threads", "1"}), 1,
       "No space left on device", Tmpfs("64k", false), Tool::kCli,
       [](const Context& c) {
         const nlohmann::json s = Summary(c.work / "mnt" / "res");
         if (s.is_object()) EXPECT_NE(s["status"], "complete") << "a failed run claims to be complete";
         // no torn row: every CSV file ends with a whole row, and its rows are as wide as its header
         std::error_code ec;
         for (const auto& e : fs::directory_iterator(c.work / "mnt" / "res", ec)) {
           if (e.path().extension() != ".csv") continue;
           const std::string text = ReadFile(e.path());
           if (text.empty()) continue;
           EXPECT_EQ(text.back(), '\n') << e.path();
           std::istringstream rows(text);
           std::string row;
           std::set<long> widths;
           while (std::getline(rows, row)) widths.insert(std::count(row.begin(), row.end(), ','));
           EXPECT_EQ(widths.size(), 1u) << e.path();
         }
         EXPECT_NE(ReadFile(c.work.string() + ".stderr").find("failed (No space left on device)"), std::string::npos);
       }},
      {"OutHoldsAnotherModel", Cli({"run", "slip", "--out", "res", "--quiet", "--no-plots"}), 2,
       "--out 'res': holds the results of model 'bouncing-ball', not 'slip'; choose another folder or pass --overwrite",
       BallResults()},
      {"OutHoldsAnotherModelOverwrite",
       Cli({"run", "slip", "--out", "res", "--quiet", "--no-plots", "--overwrite", "--max-branches", "2"}), 0, "",
       BallResultsThen([](const fs::path& res) { WriteFile(res / "H_T_xi.png", "a figure of the ball"); }),
       Tool::kCli, OneCompleteResult("res", "slip")},
      {"OutHoldsTheSameModel", Cli({"run", "bouncing-ball", "--out", "res", "--quiet", "--no-plots"}), 0, "",
       BallResultsThen([](const fs::path& res) { WriteFile(res / "branch-99.csv", "index,H,T\n"); }), Tool::kCli,
       OneCompleteResult("res", "bouncing-ball")},
      {"OutHoldsAForeignSummary", Cli({"run", "slip", "--out", "res", "--quiet", "--no-plots"}), 2,
       "holds a summary.json that is not the results of a hybridcont run", File("res/summary.json", [] { return "{\"hello\": 1}"; })},
      {"OutHoldsADamagedSummary", Cli({"run", "bouncing-ball", "--out", "res", "--quiet", "--no-plots"}), 2,
       "holds a summary.json that is not the results of a hybridcont run",
       BallResultsThen([](const fs::path& res) { fs::resize_file(res / "summary.json", 100); })},
      {"OutSummaryIsAFolder", Cli({"run", "bouncing-ball", "--out", "res", "--quiet", "--no-plots"}), 2,
       "holds a summary.json that is not the results", [](Context& c) { fs::create_directories(c.work / "res/summary.json"); }},
      // a folder name that would break a shell command line: passed as it is, nothing else runs
      {"OutNameWithQuotes", Cli({"run", "bouncing-ball", "--out", "it's; touch pwned; '", "--quiet", "--plots"}), 0,
       "figures written to", nullptr, Tool::kCli,
       [](const Context& c) {
         EXPECT_FALSE(fs::exists(c.work / "pwned"));
         EXPECT_TRUE(fs::exists(c.work / "it's; touch pwned; '" / "H_T.png"));
       }},
      // ---------------------------------------------------------------- model files (hostile; model_file_errors_test.cc has the rest)
      {"ModelFileEmpty", Cli({"list", "m.toml"}), 2, "m.toml:1: hybridcont: missing field 'hybridcont'", File("m.toml", [] { return ""; })},
      {"ModelFileOnlyComments", Cli({"list", "m.toml"}), 2, "missing field 'hybridcont'", File("m.toml", [] { return "# nothing\n# here\n"; })},
      {"ModelFileBinaryGarbage", Cli({"check", "m.toml"}), 2, "m.toml:1: TOML syntax: Encountered invalid utf-8",
       File("m.toml", [] {
         std::string s;
         for (int i = 0; i < 4096; ++i) s += static_cast<char>((i * 131 + 7) % 256);
         return s;
       })},
      {"ModelFileNotUtf8", Cli({"list", "m.toml"}), 2, "m.toml:6: TOML syntax: Encountered invalid utf-8",
       BallFile("m.toml", "title = \"bouncing ball\"", "title = \"bouncing \xe9l\xe9ment\"")},
      {"ModelFileNulByte", Cli({"list", "m.toml"}), 2, "m.toml:6: TOML syntax",
       BallFile("m.toml", "title = ", std::string("title\0 = ", 9))},
      {"ModelFileIsAFolder", Cli({"run", "m.toml", "--out", "out"}), 2, "m.toml: cannot read the model file: it is a folder",
       [](Context& c) { fs::create_directories(c.work / "m.toml"); }},
      {"ModelFileMissing", Cli({"check", "nowhere.toml"}), 2, "nowhere.toml: cannot read the model file (No such file or directory)"},
      {"ModelFileUnderAFile", Cli({"check", "file/m.toml"}), 2, "file/m.toml: cannot read the model file (Not a directory)",
       File("file", [] { return "x"; })},
      {"ModelFileIsAFifo", Cli({"check", "m.toml"}), 2, "m.toml: cannot read the model file: not a regular file",
       [](Context& c) { ASSERT_EQ(mkfifo((c.work / "m.toml").c_str(), 0644), 0); }},
      {"ModelFileIsDevZero", Cli({"check", "m.toml"}), 2, "not a regular file",
       [](Context& c) { fs::create_symlink("/dev/zero", c.work / "m.toml"); }},
      {"ModelFileSymlinkLoop", Cli({"check", "m.toml"}), 2, "m.toml: cannot read the model file (Too many levels of symbolic links)",
       [](Context& c) { fs::create_symlink("m.toml", c.work / "m.toml"); }},
      {"ModelFileHuge", Cli({"check", "m.toml"}), 2, "the model file has 6000000 bytes; a model file has at most 4194304 bytes",
       File("m.toml", [] { return Repeat("# padding " + std::string(89, '.') + "\n", 60000); })},
      {"ModelFileDeepDottedKeys", Cli({"check", "m.toml"}), 2, "m.toml:1: keys nested more than 32 deep",
       File("m.toml", [] { return "[a" + Repeat(".a", 100000) + "]\n"; })},
      {"ModelFileDeepArrays", Cli({"check", "m.toml"}), 2, "m.toml:1: TOML syntax: Error while parsing value: exceeded maximum nested value depth",
       File("m.toml", [] { return "a = " + Repeat("[", 100000) + Repeat("]", 100000) + "\n"; })},
      {"ModelFileDeepInlineTables", Cli({"check", "m.toml"}), 2, "exceeded maximum nested value depth",
       File("m.toml", [] { return "a = " + Repeat("{x=", 5000) + "1" + Repeat("}", 5000) + "\n"; })},
      {"ModelFileDeepExpression", Cli({"check", "m.toml"}), 2, "m.toml:18: phases.flight.ode.y: in expression",
       BallFile("m.toml", "ode = { y = \"dy\"", "ode = { y = \"" + Repeat("(", 100000) + "dy" + Repeat(")", 100000) + "\"")},
      {"ModelFileHugeNumber", Cli({"list", "m.toml"}), 2, "m.toml:11: TOML syntax: Error while parsing floating-point: '1e400'",
       BallFile("m.toml", "g = { value = 1.0", "g = { value = 1e400")},
      {"ModelFileHugeInteger", Cli({"list", "m.toml"}), 2, "is not representable in 64 bits",
       BallFile("m.toml", "g = { value = 1.0", "g = { value = 99999999999999999999")},
      {"ModelFileVersionFromTheFuture", Cli({"list", "m.toml"}), 2,
       "m.toml:4: hybridcont: format version 9223372036854775807 is not supported (this hybridcont reads 1 to 1)",
       BallFile("m.toml", "hybridcont = 1", "hybridcont = 9223372036854775807")},
      {"ModelFileVersionNegative", Cli({"list", "m.toml"}), 2, "m.toml:4: hybridcont: format version -1 is not supported",
       BallFile("m.toml", "hybridcont = 1", "hybridcont = -1")},
      {"ModelFileVersionFraction", Cli({"list", "m.toml"}), 2, "hybridcont: expected the format version as an integer, got a number",
       BallFile("m.toml", "hybridcont = 1", "hybridcont = 1.5")},
      {"ModelFileVersionTwice", Cli({"list", "m.toml"}), 2, "m.toml:5: TOML syntax: Error while parsing key-value pair: cannot redefine existing integer 'hybridcont'",
       BallFile("m.toml", "hybridcont = 1", "hybridcont = 1\nhybridcont = 1")},
      {"ModelFileParametersTableTwice", Cli({"list", "m.toml"}), 2, "TOML syntax",
       File("m.toml", [] { return Ball() + "\n[parameters]\nk = { value = 1.0 }\n"; })},
      {"ModelFileInlineTableExtended", Cli({"list", "m.toml"}), 2, "m.toml:19: TOML syntax",
       BallFile("m.toml", "ode = { y = \"dy\", dy = \"-g\" }", "ode = { y = \"dy\", dy = \"-g\" }\node.y = \"dy\"")},
      {"ModelFileOldMacLineEnds", Cli({"list", "m.toml"}), 2, "m.toml:1: TOML syntax: Error while parsing comment: expected '\\n' after '\\r'",
       File("m.toml", [] { return Replace(Ball(), "\n", "\r"); })},
      // accepted: CRLF line endings and a byte-order mark are ordinary text files
      {"ModelFileCrlfAccepted", Cli({"list", "m.toml"}), 0, "phases (m = 1", File("m.toml", [] { return Replace(Ball(), "\n", "\r\n"); })},
      {"ModelFileBomAccepted", Cli({"list", "m.toml"}), 0, "phases (m = 1", File("m.toml", [] { return "\xef\xbb\xbf" + Ball(); })},
      // a parameter at the edge of double precision: the start fails numerically (exit 1, said in the report)
      // The start's kernel degenerates (every energy term overflows): refused before anything is written,
      // naming the kernel's directions.
      {"ModelFileExtremeParameterRuns", Cli({"run", "m.toml", "--out", "out", "--quiet", "--no-plots"}), 2,
       "is an orbit, but no family through it can be chosen", BallFile("m.toml", "m = { value = 1.0", "m = { value = 1e308"),
       Tool::kCli},
      // ---------------------------------------------------------------- `hybridcont plot` on damaged results
      {"PlotNoSuchFolder", Cli({"plot", "nowhere"}), 2, "plot 'nowhere': no such folder"},
      {"PlotFileNotFolder", Cli({"plot", "file"}), 2, "plot 'file': not a folder", File("file", [] { return "x"; })},
      {"PlotNoSummary", Cli({"plot", "res"}), 2, "plot 'res': no summary.json",
       BallResultsThen([](const fs::path& res) { fs::remove(res / "summary.json"); })},
      {"PlotEmptySummary", Cli({"plot", "res"}), 2, "cannot read res/summary.json: Expecting value",
       BallResultsThen([](const fs::path& res) { WriteFile(res / "summary.json", ""); })},
      {"PlotTruncatedSummary", Cli({"plot", "res"}), 2, "cannot read res/summary.json",
       BallResultsThen([](const fs::path& res) { fs::resize_file(res / "summary.json", 300); })},
      {"PlotSummaryNotJson", Cli({"plot", "res"}), 2, "cannot read res/summary.json",
       BallResultsThen([](const fs::path& res) { WriteFile(res / "summary.json", "model = slip\n"); })},
      {"PlotSummaryNotUtf8", Cli({"plot", "res"}), 2, "cannot read res/summary.json: 'utf-8' codec can't decode",
       BallResultsThen([](const fs::path& res) { WriteFile(res / "summary.json", "\xff\xfe{}"); })},
      {"PlotSummaryNestedDeep", Cli({"plot", "res"}), 2, "cannot read res/summary.json: nested too deeply",
       BallResultsThen([](const fs::path& res) { WriteFile(res / "summary.json", Repeat("[", 100000)); })},
      {"PlotSummaryIsAList", Cli({"plot", "res"}), 2, "res/summary.json is malformed: expected a JSON object",
       BallResultsThen([](const fs::path& res) { WriteFile(res / "summary.json", "[]"); })},
      {"PlotSummaryIsAFolder", Cli({"plot", "res"}), 2, "no summary.json in 'res'",
       BallResultsThen([](const fs::path& res) {
         fs::remove(res / "summary.json");
         fs::create_directories(res / "summary.json");
       })},
      {"PlotBranchesNotAList", Cli({"plot", "res"}), 2, "res/summary.json is malformed: 'branches' must be a list",
       SummaryEdit("\"branches\": [", "\"branches\": 5, \"x\": [")},
      {"PlotBranchIdAString", Cli({"plot", "res"}), 2, "'branches[0].id' must be a number", SummaryEdit("\"id\": 0,", "\"id\": \"zero\",")},
      {"PlotBranchIdNaN", Cli({"plot", "res"}), 2, "'branches[0].id' must be a number", SummaryEdit("\"id\": 0,", "\"id\": NaN,")},
      {"PlotModelNotAString", Cli({"plot", "res"}), 2, "'model' must be a string",
       SummaryEdit("\"model\": \"bouncing-ball\"", "\"model\": 3")},
      {"PlotBranchFileOutsideTheFolder", Cli({"plot", "res"}), 2,
       "'branches[0].file' must be a file name without a folder, got '../../etc/passwd'",
       SummaryEdit("\"branch-0.csv\"", "\"../../etc/passwd\"")},
      {"PlotMissingBranchCsv", Cli({"plot", "res"}), 2, "res/summary.json names res/branch-1.csv, which is missing",
       BallResultsThen([](const fs::path& res) { fs::remove(res / "branch-1.csv"); })},
      {"PlotEmptyBranchCsv", Cli({"plot", "res"}), 2, "cannot read res/branch-0.csv: empty file (no header)",
       BallResultsThen([](const fs::path& res) { WriteFile(res / "branch-0.csv", ""); })},
      {"PlotBranchCsvGarbageRow", Cli({"plot", "res"}), 2, "res/branch-0.csv:3: 4 cells, the header has",
       BallResultsThen([](const fs::path& res) {
         std::string text = ReadFile(res / "branch-0.csv");
         const std::size_t second_row = text.find('\n', text.find('\n') + 1) + 1;
         text.insert(second_row, "garbage,,,x\n");
         WriteFile(res / "branch-0.csv", text);
       })},
      {"PlotBranchCsvTruncated", Cli({"plot", "res"}), 2, "(a garbage or truncated row)",
       BallResultsThen([](const fs::path& res) { fs::resize_file(res / "branch-2.csv", 555); })},
      {"PlotBranchCsvHNotANumber", Cli({"plot", "res"}), 2, "res/branch-0.csv:2: H = 'abc' is not a number",
       BallResultsThen([](const fs::path& res) {
         std::string text = ReadFile(res / "branch-0.csv");
         const std::size_t h = text.find(',', text.find('\n')) + 1;
         text.replace(h, text.find(',', h) - h, "abc");
         WriteFile(res / "branch-0.csv", text);
       })},
      {"PlotBranchCsvNotUtf8", Cli({"plot", "res"}), 2, "cannot read res/branch-3.csv: 'utf-8' codec",
       BallResultsThen([](const fs::path& res) { WriteFile(res / "branch-3.csv", "\xff\xfe\x00garbage"); })},
      {"PlotMissingOrbitCsv", Cli({"plot", "res"}), 2, "res/summary.json names res/orbit-0.csv, which is missing",
       BallResultsThen([](const fs::path& res) { fs::remove(res / "orbit-0.csv"); })},
      // ---------------------------------------------------------------- the figure script called directly
      {"ScriptNoArguments", Script({}), 2, "the following arguments are required: results_dir", nullptr, Tool::kScript},
      {"ScriptUnknownOption", Script({"res", "--bogus"}), 2, "unrecognized arguments: --bogus", nullptr, Tool::kScript},
      {"ScriptTwoFolders", Script({"a", "b"}), 2, "unrecognized arguments: b", nullptr, Tool::kScript},
      {"ScriptFramesWord", Script({"res", "--frames", "x"}), 2, "argument --frames: invalid int value: 'x'", nullptr, Tool::kScript},
      {"ScriptFrames99", Script({"res", "--frames", "99"}), 2, "--frames must be between 2 and 16", nullptr, Tool::kScript},
      {"ScriptFramesNegative", Script({"res", "--frames=-3"}), 2, "--frames must be between 2 and 16", nullptr, Tool::kScript},
      {"ScriptNoSuchFolder", Script({"nowhere"}), 2, "results folder 'nowhere' does not exist", nullptr, Tool::kScript},
      {"ScriptFileNotFolder", Script({"file"}), 2, "'file' is not a folder", File("file", [] { return "x"; }), Tool::kScript},
      {"ScriptEmptyFolderName", Script({""}), 2, "results folder '' does not exist", nullptr, Tool::kScript},
      {"ScriptDamagedSummary", Script({"res"}), 2, "cannot read res/summary.json",
       BallResultsThen([](const fs::path& res) { fs::resize_file(res / "summary.json", 50); }), Tool::kScript},
      {"ScriptStatusNotAString", Script({"res"}), 2, "'status' must be a string",
       SummaryEdit("\"status\": \"complete\"", "\"status\": 1"), Tool::kScript},
      // ---------------------------------------------------------------- hostile names, numbers, sizes
      // a model named ".." would write its results into the working folder: refused, nothing written
      {"ModelNamedDots", Cli({"run", "m.toml", "--quiet", "--no-plots"}), 2, "m.toml:5: name: '..' is not a label",
       BallFile("m.toml", "name = \"bouncing-ball\"", "name = \"..\"")},
      {"ModelNamedDot", Cli({"run", "m.toml", "--quiet", "--no-plots"}), 2, "name: '.' is not a label",
       BallFile("m.toml", "name = \"bouncing-ball\"", "name = \".\"")},
      // a phase name that would tear the CSV (a comma, a quote, a newline)
      {"PhaseNameTearsCsv", Cli({"run", "m.toml", "--quiet", "--no-plots"}), 2, "phases[0].name: 'fl,ight\"' is not a label",
       BallFile("m.toml", "name = \"flight\"", "name = \"fl,ight\\\"\"")},
      {"SetHexadecimal", Run("slip", {"--set", "k=0x10"}), 2, "--set 'k=0x10': value '0x10' is not a number"},
      {"UntilWidensTheBound", Run("bouncing-ball", {"--until", "H=1.5", "--max-branches", "1"}), 0,
       "note: --until H=1.5 lies outside the bound [-1, 1] of H: the bound is widened to [-1, 1.5]"},
      {"CommandWithControlBytes", Cli({"fr\x1b[31mob\xff"}), 2, "unknown command 'fr\\x1b[31mob\\xff'"},
      {"ModelFileNamedLikeAnOption", Cli({"run", "-x.toml"}), 2, "name the model file ./-x.toml",
       File("-x.toml", [] { return Ball(); })},
      {"ModelFileTooManyPhases", Cli({"check", "m.toml"}), 2, "m.toml:3: phases: 101 phases; a model has at most 100",
       File("m.toml", [] { return "hybridcont = 1\nname = \"m\"\n" + Repeat("[[phases]]\nname = \"p\"\n", 101); })},
      {"ModelFileTooManyNames", Cli({"check", "m.toml"}), 2, "300 entries; a list of names has at most 256",
       File("m.toml", [] {
         std::string names;
         for (int i = 0; i < 300; ++i) names += (i ? ", " : "") + ("\"q" + std::to_string(i) + "\"");
         return Replace(Ball(), "states = [\"y\", \"dy\"]", "states = [" + names + "]");
       })},
      {"ModelFileHugeExpression", Cli({"check", "m.toml"}), 2, "more than 4000 operations in one expression",
       BallFile("m.toml", "ode = { y = \"dy\"", "ode = { y = \"dy" + Repeat("+dy*dy", 5000) + "\"")},
      // a bound whose ends are reversed: said at its line (it is evaluated after --set)
      {"BoundReversedInTheFile", Cli({"run", "m.toml", "--quiet", "--no-plots"}), 2,
       "m.toml:34: run.bounds.H: the lower end 1 is not below the upper end -1", BallFile("m.toml", "H = [-1, 1]", "H = [1, -1]")},
      // definitions and let quantities each using the next, 1,200 deep (named so that the first read uses the
      // second): refused naming the limit and the chain (resolving them recurses as deep as the chain)
      {"LetChainTooDeep", Cli({"list", "m.toml"}), 2,
       "more than 1000 deep: 'q0000' uses 'q0001' uses 'q0002' uses ... (995 more) uses", File("m.toml", [] {
         std::string lets = "let.q1199 = \"dy\"\n";
         for (int i = 0; i < 1199; ++i) lets += fmt::format("let.q{:04d} = \"q{:04d} + 1\"\n", i, i + 1);
         return Replace(Ball(), "ode = { y = \"dy\", dy = \"-g\" }",
                        lets + "ode = { y = \"dy\", dy = \"-g + 0*q0000\" }");
       })},
      {"DefinitionChainTooDeep", Cli({"list", "m.toml"}), 2,
       "definitions and let quantities that use one another more than 1000 deep: 'd0000' uses", File("m.toml", [] {
         std::string definitions = "[definitions]\nd1199 = \"g\"\n";
         for (int i = 0; i < 1199; ++i) definitions += fmt::format("d{:04d} = \"d{:04d} + 1\"\n", i, i + 1);
         return Replace(Replace(Ball(), "[[phases]]", definitions + "\n[[phases]]"), "dy = \"-g\" }",
                        "dy = \"-g + 0*d0000\" }");
       })},
      // a phase's let named like a definition would hide it in that phase only
      {"LetShadowsADefinition", Cli({"check", "m.toml"}), 2,
       "phases.flight.let.gg: 'gg' is also a definition ([definitions]); name it otherwise", File("m.toml", [] {
         return Replace(Replace(Ball(), "[[phases]]", "[definitions]\ngg = \"2*g\"\n\n[[phases]]"),
                        "ode = { y = \"dy\", dy = \"-g\" }", "let.gg = \"g\"\node = { y = \"dy\", dy = \"-gg\" }");
       })},
      // listing reads a model; it does not compile it
      {"ListDoesNotCompile", Cli({"list", "m.toml"}), 0, "1. flight         n = 2  (y, dy)",
       BallFile("m.toml", "ode = { y = \"dy\"", "ode = { y = \"dy*1.000000000123\""), Tool::kCli,
       [](const Context& c) { EXPECT_EQ(ReadFile(c.work.string() + ".stderr").find("compiling"), std::string::npos); }},
  };
  return cases;
}

class BadInput : public ::testing::TestWithParam<BadInputCase> {};

TEST_P(BadInput, ClearMessageRightExitCodeNoCrashNoHalfWrittenFolder) {
  const BadInputCase& c = GetParam();
  Context context;
  context.work = fs::temp_directory_path() / "hybridcont_bad_input" / c.name;
  fs::remove_all(context.work);
  fs::create_directories(context.work);
  struct Undo {
    Context* context;
    ~Undo() {
      for (auto& f : context->undo) f();
    }
  } undo{&context};
  if (c.setup) c.setup(context);
  if (!context.skip.empty()) GTEST_SKIP() << context.skip;
  if (HasFatalFailure()) return;
  std::vector<std::string> argv;
  for (const std::string& a : c.argv)
    argv.push_back(Replace(Replace(a, "{work}", context.work.string()), "{models}", kModels.string()));
  const auto before = Snapshot(context.work);
  const Outcome o = Spawn(argv, context.work);

  const std::string shown =
      "\n--- stderr:\n" + o.err + "\n--- stdout (end):\n" + o.out.substr(o.out.size() > 2000 ? o.out.size() - 2000 : 0);
  ASSERT_FALSE(o.hung) << "no exit within " << kDeadlineSeconds << " s" << shown;
  ASSERT_EQ(o.signal, 0) << "killed by signal " << o.signal << " (" << strsignal(o.signal) << ")" << shown;
  EXPECT_EQ(o.code, c.exit_code) << shown;
  EXPECT_TRUE(o.err.find(c.message) != std::string::npos || o.out.find(c.message) != std::string::npos)
      << "expected '" << c.message << "'" << shown;
  for (const char* crash : {"Traceback (most recent call last)", "terminate called", "Assertion", "Segmentation"}) {
    EXPECT_EQ(o.err.find(crash), std::string::npos) << crash << shown;
  }
  if (c.exit_code == 2 && o.code == 2) {
    // bad input: nothing written, nothing removed
    EXPECT_EQ(Snapshot(context.work), before) << "the folder changed although the input was refused" << shown;
  }
  // no folder below the row's one claims a complete result unless the run completed
  std::error_code ec;
  for (auto it = fs::recursive_directory_iterator(context.work, ec); it != fs::recursive_directory_iterator();
       it.increment(ec)) {
    if (ec || it->path().filename() != "summary.json" || !it->is_regular_file(ec)) continue;
    if (before.count(it->path().lexically_relative(context.work).string())) continue;  // the set-up's
    const nlohmann::json s = Summary(it->path().parent_path());
    if (o.code != 0 && o.code != 1) EXPECT_FALSE(s.is_object() && s.value("status", "") == "complete") << it->path();
  }
  if (c.check) c.check(context);
}

INSTANTIATE_TEST_SUITE_P(Table, BadInput, ::testing::ValuesIn(Cases()),
                         [](const ::testing::TestParamInfo<BadInputCase>& info) {
                           std::string name = info.param.name;
                           for (char& ch : name) {
                             if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
                           }
                           return name;
                         });

// `text` with its control bytes and the bytes that are no UTF-8 (a hostile argument's) as \xNN: the document
// stays valid UTF-8 and shows which bytes the row sent.
std::string Printable(const std::string& text) {
  std::string out;
  for (std::size_t i = 0; i < text.size();) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    const int length = c < 0x80 ? 1 : (c >> 5) == 0x6 ? 2 : (c >> 4) == 0xe ? 3 : (c >> 3) == 0x1e ? 4 : 0;
    bool valid = length > 0 && i + length <= text.size();
    for (int k = 1; valid && k < length; ++k) valid = (static_cast<unsigned char>(text[i + k]) >> 6) == 0x2;
    if (valid && !(length == 1 && (c < 0x20 || c == 0x7f))) {
      out.append(text, i, length);
      i += length;
    } else {
      out += fmt::format("\\x{:02x}", c);
      ++i;
    }
  }
  return out;
}

// The table, written as docs/bad-input.md shows it (run with --gtest_also_run_disabled_tests and
// HYBRIDCONT_BAD_INPUT_MD=path to regenerate the document).
TEST(BadInputTable, DISABLED_WriteMarkdown) {
  const char* path = std::getenv("HYBRIDCONT_BAD_INPUT_MD");
  ASSERT_NE(path, nullptr);
  std::ofstream md(path);
  md << "# Bad and hostile input\n\n"
     << "Generated from `tests/bad_input_test.cc` (the test `BadInputTable.DISABLED_WriteMarkdown`). Every row runs "
        "the built `hybridcont` (or `python/hybridcont_plot.py`) in a child process with a deadline; a signal, a "
        "hang, a Python traceback or an uncaught exception fails it, a refused row (exit 2) must leave its folder "
        "as it was, and a failed run must not leave a summary.json that says `complete`.\n\n";
  std::map<std::string, int> per_section, per_code;
  const auto section_of = [](const BadInputCase& c) -> std::string {
    const std::string& n = c.name;
    if (c.tool == Tool::kScript) return "figure script";
    if (n.rfind("Plot", 0) == 0) return "hybridcont plot";
    if (n.rfind("ModelFile", 0) == 0) return "model files";
    if (n.rfind("Out", 0) == 0) return "output folders";
    return "command line";
  };
  for (const BadInputCase& c : Cases()) {
    ++per_section[section_of(c)];
    ++per_code[std::to_string(c.exit_code)];
  }
  md << "| surface | cases |\n|---|---|\n";
  for (const auto& [s, n] : per_section) md << "| " << s << " | " << n << " |\n";
  md << "| **all** | **" << Cases().size() << "** |\n\nExit codes: ";
  for (const auto& [code, n] : per_code) md << code << " (" << n << " cases) ";
  md << "\n";
  for (const char* section : {"command line", "output folders", "model files", "hybridcont plot", "figure script"}) {
    md << "\n## " << section << "\n\n";
    if (std::string(section) == "model files") {
      md << "The model file's own content (fields, expressions, bad mechanics) is refused by the reader with file, "
            "line and field: those rows are in `docs/model-files.md`, \"Bad files and their messages\" "
            "(`tests/model_file_errors_test.cc`). A model that parses but does not conserve its energy is refused by "
            "`run` (exit 2, the phase or reset named) and flagged by `check` (exit 1, \"THE ENERGY IS NOT "
            "CONSERVED\"): `ModelFileErrorsCli.EnergyNotConservedIsRefused`.\n\n";
    }
    for (const BadInputCase& c : Cases()) {
      if (section_of(c) != section) continue;
      std::string args;
      for (std::size_t i = 1 + (c.tool == Tool::kScript); i < c.argv.size(); ++i) {
        std::string a = c.argv[i].size() > 40 ? c.argv[i].substr(0, 37) + "..." : c.argv[i];
        args += (args.empty() ? "" : " ") + (a.empty() || a.find(' ') != std::string::npos ? "'" + a + "'" : a);
      }
      std::string message = Replace(c.message, "|", "\\|");
      md << "- **" << c.name << "** `" << (c.tool == Tool::kScript ? "hybridcont_plot.py" : "hybridcont") << " "
         << Printable(args) << "` → exit " << c.exit_code << (message.empty() ? "" : ": `" + message + "`") << "\n";
    }
  }
  // What a row of one command cannot show: a state made by an earlier command, a process killed. Each has its test.
  md << "\n## Cases of more than one command\n\n"
     << "- **A run into the study it reads** (`run slip --from results/slip --at PD4`, its default `--out` being "
        "`results/slip`; `--families-of` the same folder): exit 2, `--out 'results/slip': is the study read by "
        "--from, which this one would replace; name another folder for its results`; the study is kept "
        "(`Cli.ARunNeverReplacesTheStudyItReadsNorWaitsOnAFifo`).\n"
     << "- **A FIFO named summary.json** in the folder restarted from, or in `--out`: refused before it is opened "
        "(`summary.json: not a regular file`, or `holds a summary.json that is not the results of a hybridcont "
        "run`), exit 2, never a blocked process (same test).\n"
     << "- **A resume store changed after it was written** (one stored point moved by 1e-3): exit 2, `--resume "
        "'.../.resume/branch-2.json: the stored branch does not match its digest ...; remove .../.resume to run the "
        "study afresh`; nothing written (`Study.ResumeRefusesAStoredBranchThatChanged`).\n"
     << "- **`sweep --overwrite` over a folder with the user's own files**: only what a sweep writes (sweep.json, "
        "points/, table.csv, sweep-report.html, map-*/plane-* figures) is removed "
        "(`test_overwrite_replaces_what_a_sweep_wrote_and_keeps_the_users_files`).\n"
     << "- **`sweep --grid k=1:2:100000000`**: exit 2, `grid: 100,000,000 grid points (k: 100000000), each a whole "
        "study: more than 10000; a mistyped count? (max_grid_points=N, --max-grid-points N, lifts the limit)`; "
        "`--grid k` given twice and `--workers` below 1 refused too "
        "(`test_the_tool_runs_a_sweep_and_refuses_a_bad_grid`).\n"
     << "- **`hybridcont sweep` killed**: its Python process gets SIGTERM (it was started with PR_SET_PDEATHSIG) "
        "and ends the sweep as Ctrl-C does, closing its workers; the grid points finished are kept for `--resume`.\n";
}

}  // namespace
