// The command-line tool as a user meets it: exit codes, messages, files.
#include <gtest/gtest.h>

#include <sys/stat.h>
#include <sys/wait.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <regex>
#include <sstream>
#include <utility>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "cli_runner.h"
#include "hybridcont/study.h"

namespace hybridcont::app {
namespace {

namespace fs = std::filesystem;


fs::path TempDir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("hybridcont_cli_test_" + name);
  fs::remove_all(dir);
  return dir;
}

TEST(Cli, ListShowsModelsPhasesAndParameters) {
  const CliResult r = RunTool({"list"});
  EXPECT_EQ(r.code, 0);
  for (const char* s : {"bouncing-ball", "rocking-block", "bouncing-rod", "slip", "stance", "n = 5", "w2", "beta"}) {
    EXPECT_NE(r.out.find(s), std::string::npos) << s;
  }
}

// The built tool run as a user runs it (its models folder is found next to it): stdout and stderr together,
// and the exit code.
CliResult RunBuiltTool(const std::string& arguments) {
  CliResult r{0, "", ""};
  FILE* pipe = popen((std::string(HYBRIDCONT_CLI_PATH) + " " + arguments + " 2>&1").c_str(), "r");
  if (pipe == nullptr) return {-1, "", "popen failed"};
  char buffer[4096];
  for (std::size_t n; (n = fread(buffer, 1, sizeof buffer, pipe)) > 0;) r.out.append(buffer, n);
  const int status = pclose(pipe);
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

// `list` names the shipped model files after the built-ins, and a shipped file is found by its name alone; a
// name that is a path is not looked up in the models folder.
TEST(Cli, ShippedModelFilesAreListedAndFoundByName) {
  const CliResult all = RunBuiltTool("list");
  ASSERT_EQ(all.code, 0) << all.out;
  for (const char* s : {"model files in", "compass-gait ", "mass-chain ", "bipedal-slip "}) {
    EXPECT_NE(all.out.find(s), std::string::npos) << s;
  }
  const CliResult one = RunBuiltTool("list compass-gait");
  EXPECT_EQ(one.code, 0) << one.out;
  EXPECT_NE(one.out.find("phases (m = "), std::string::npos) << one.out;
  EXPECT_EQ(one.out.find("model files in"), std::string::npos);  // asked for one model: that one alone
  const CliResult path = RunBuiltTool("list ../models/compass-gait");
  EXPECT_EQ(path.code, 2);
  EXPECT_NE(path.out.find("unknown model"), std::string::npos) << path.out;
}

// The end of a run is the one-screen answer: each physical family with its physical and stable ranges and its
// located special points; --verbose gives the full report instead.
TEST(Cli, RunEndsWithTheOneScreenAnswer) {
  const fs::path dir = TempDir("answer");
  const CliResult r = RunTool({"run", "slip", "--out", dir.string(), "--no-plots", "--quiet"});
  ASSERT_EQ(r.code, 0) << r.err;
  for (const char* s : {"hopping in place (branch 2)", "  physical  H 1 .. 2", "  stable    H 1.282809324 .. 1.614433285   (PD4 .. BP6)",
                        "PD4    H = 1.282809324", "forward hopping (branch 5): the mirror image of branch 4, backward hopping", "more branches hold no physical orbit"}) {
    EXPECT_NE(r.out.find(s), std::string::npos) << s << "\n" << r.out;
  }
  EXPECT_EQ(r.out.find("turning-point in H (located)"), std::string::npos);  // the full report's lines
  const CliResult verbose = RunTool({"run", "slip", "--out", dir.string(), "--no-plots", "--quiet", "--verbose"});
  ASSERT_EQ(verbose.code, 0) << verbose.err;
  EXPECT_NE(verbose.out.find("turning-point in H (located)"), std::string::npos);
}

TEST(Cli, CheckPassesForEveryModel) {
  for (const char* model : {"bouncing-ball", "rocking-block", "bouncing-rod", "slip"}) {
    const CliResult r = RunTool({"check", model, "--points", "2"});
    EXPECT_EQ(r.code, 0) << model << "\n" << r.out << r.err;
    EXPECT_NE(r.out.find("shooting map: dr/du"), std::string::npos);
  }
  EXPECT_EQ(RunTool({"check", "slip", "--set", "k=20", "--set", "w2=3", "--points", "2"}).code, 0);
}

TEST(Cli, BadInputGetsAClearMessageAndNonZeroExit) {
  struct Case {
    std::vector<std::string> args;
    std::string message;
  };
  const std::vector<Case> cases = {
      {{"check", "pogo-stick"}, "unknown model 'pogo-stick'"},
      {{"check", "slip", "--set", "stiffness=3"}, "has no parameter 'stiffness'"},
      {{"check", "slip", "--set", "k"}, "expected NAME=VALUE"},
      {{"check", "slip", "--set", "k=abc"}, "'abc' is not a number"},
      {{"check", "slip", "--set", "k=nan"}, "is not finite"},
      {{"check", "slip", "--set", "k=inf"}, "is not finite"},
      {{"run", "slip", "--until", "Q=2", "--out", TempDir("bad_until").string()}, "Q"},
      {{"run", "slip", "--rtol", "-1", "--out", TempDir("bad_rtol").string()}, "rtol"},
      {{"run", "slip", "--max-branches", "0", "--out", TempDir("bad_branches").string()}, "--max-branches"},
      {{"run", "slip", "--threads", "0", "--out", TempDir("bad_threads").string()}, "--threads 0: must be >= 1"},
      {{"run", "slip", "--out", "/proc/hybridcont-cannot-write-here"}, "--out"},
      {{"frobnicate"}, ""},
  };
  for (const Case& c : cases) {
    const CliResult r = RunTool(c.args);
    EXPECT_NE(r.code, 0) << c.args[0] << " " << c.args.back();
    EXPECT_NE(r.err.find(c.message), std::string::npos) << "expected '" << c.message << "' in: " << r.err;
  }
  // nothing written half-way for rejected runs
  EXPECT_FALSE(fs::exists(TempDir("bad_until")));
  EXPECT_FALSE(fs::exists(TempDir("bad_rtol")));
}

// `run`'s options are the library's declaration (study_options.h): every declared flag is in the help with the
// declared help, and the options a message names are said as flags.
TEST(Cli, RunTakesEveryDeclaredOptionAndSaysOptionsAsFlags) {
  const CliResult help = RunTool({"run", "--help"});
  ASSERT_EQ(help.code, 0);
  for (const StudyOptionSpec& spec : StudyOptionSpecs()) {
    if (spec.flag.rfind("--", 0) != 0) continue;
    EXPECT_NE(help.out.find("  " + spec.flag + " "), std::string::npos) << spec.flag;
    const std::string said = SayOptions(spec.help, OptionFlag);
    EXPECT_NE(help.out.find(said.substr(0, 30)), std::string::npos) << spec.flag << ": " << said;
  }
  const CliResult note = RunTool({"run", "slip", "--until", "H=2.5", "--max-branches", "1", "--quiet", "--out",
                                  TempDir("note_words").string()});
  EXPECT_EQ(note.code, 0) << note.err;
  EXPECT_NE(note.err.find("note: --until H=2.5 lies outside the bound"), std::string::npos) << note.err;
  EXPECT_NE(note.err.find("(give --bound H=LOWER:UPPER to keep it)"), std::string::npos) << note.err;
  const CliResult twice = RunTool({"run", "slip", "--free", "k", "--free", "w2"});
  EXPECT_EQ(twice.code, 2);
  EXPECT_NE(twice.err.find("--free 'w2': given twice (first 'k'); give it once"), std::string::npos) << twice.err;
  const CliResult curves = RunTool({"run", "slip", "--free", "k", "--fix", "H=1.5", "--curves", "k"});
  EXPECT_EQ(curves.code, 2);
  EXPECT_NE(curves.err.find("--curves 'k': the families are continued in k already"), std::string::npos) << curves.err;
  fs::remove_all(TempDir("note_words"));
}

// A run never replaces a study it reads (the folder restarted from, the guide's), and a FIFO where a results
// folder's file belongs is refused, never opened (opening it would block until someone writes it).
TEST(Cli, ARunNeverReplacesTheStudyItReadsNorWaitsOnAFifo) {
  const fs::path saved = TempDir("read_saved"), fifo_folder = TempDir("read_fifo");
  ASSERT_EQ(RunTool({"run", "slip", "--quiet", "--out", saved.string()}).code, 0);
  const std::string before = [&] {
    std::ifstream f(saved / "summary.json");
    return std::string(std::istreambuf_iterator<char>(f), {});
  }();
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{"run", "slip", "--from", saved.string(), "--at", "PD4", "--out", saved.string()},
        std::vector<std::string>{"run", "slip", "--from", (saved / ".." / saved.filename()).string(), "--at", "PD4",
                                 "--out", saved.string()},
        std::vector<std::string>{"run", "slip", "--families-of", saved.string(), "--out", saved.string()}}) {
    const CliResult r = RunTool(args);
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_NE(r.err.find("is the study read by --"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("which this one would replace; name another folder for its results"), std::string::npos);
  }
  std::ifstream f(saved / "summary.json");
  EXPECT_EQ(std::string(std::istreambuf_iterator<char>(f), {}), before);  // the study read is kept
  fs::create_directories(fifo_folder);
  ASSERT_EQ(mkfifo((fifo_folder / "summary.json").c_str(), 0600), 0);
  const CliResult restart = RunTool({"run", "slip", "--from", fifo_folder.string(), "--at", "PD4", "--out",
                                     TempDir("read_fifo_out").string()});
  EXPECT_EQ(restart.code, 2);
  EXPECT_NE(restart.err.find("summary.json: not a regular file"), std::string::npos) << restart.err;
  const CliResult into = RunTool({"run", "slip", "--quiet", "--out", fifo_folder.string()});
  EXPECT_EQ(into.code, 2);
  EXPECT_NE(into.err.find("holds a summary.json that is not the results of a hybridcont run"), std::string::npos)
      << into.err;
  const CliResult plot = RunTool({"plot", fifo_folder.string()});
  EXPECT_NE(plot.code, 0);
  // A FIFO in a resume store is refused, never opened (the open would block the run).
  const fs::path resumed = TempDir("resume_fifo");
  ASSERT_EQ(RunTool({"run", "bouncing-ball", "--quiet", "--no-plots", "--out", resumed.string()}).code, 0);
  fs::create_directories(resumed / ".resume");
  ASSERT_EQ(mkfifo((resumed / ".resume" / "study.json").c_str(), 0600), 0);
  const CliResult resume =
      RunTool({"run", "bouncing-ball", "--quiet", "--no-plots", "--resume", "--out", resumed.string()});
  EXPECT_EQ(resume.code, 2);
  EXPECT_NE(resume.err.find("study.json: not a regular file"), std::string::npos) << resume.err;
  fs::remove_all(resumed);
  fs::remove_all(saved);
  fs::remove_all(fifo_folder);
}

// A model whose event has the wrong sign (the ball's phase ends where y crosses 0 upward): no orbit of it is
// physical, and the answer says which class its orbits have and what that class usually means.
TEST(Cli, AnAnswerWithoutPhysicalOrbitsNamesTheirClassAndWhatItMeans) {
  const fs::path dir = TempDir("wrong_sign");
  fs::create_directories(dir);
  std::ifstream in(fs::path(HYBRIDCONT_SOURCE_DIR) / "models" / "bouncing-ball.toml");
  std::string text((std::istreambuf_iterator<char>(in)), {});
  const std::string event = "event = \"y\"";
  ASSERT_NE(text.find(event), std::string::npos);
  text.replace(text.find(event), event.size(), "event = \"-y\"");
  std::ofstream(dir / "ball.toml") << text;
  const CliResult r = RunTool({"run", (dir / "ball.toml").string(), "--out", (dir / "out").string(), "--no-plots"});
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("0 branches with physical orbits"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("wrong-direction: a phase ends where its event is crossed upward"), std::string::npos) << r.out;
  fs::remove_all(dir);
}

// A model without first integral whose start is simulated, with its event's sign wrong (a rimless wheel whose
// stance would end where its spoke angle falls through alpha): the start fails, exit 1, and the answer says why
// and asks about the sign.
TEST(Cli, AStartThatNeverEndsItsPhaseSaysWhyInTheAnswer) {
  const fs::path dir = TempDir("wrong_sign_simulated");
  fs::create_directories(dir);
  std::ofstream(dir / "wheel.toml") << R"toml(hybridcont = 1
name = "wheel"
conservative = false
[parameters]
gamma = { value = 0.08, range = "[0, 0.5]" }
alpha = { value = 0.3, range = "(0, 1.5)" }
[[phases]]
name = "stance"
states = ["theta", "dtheta"]
ode = { theta = "dtheta", dtheta = "sin(theta + gamma)" }
event = "theta - alpha"
anchor = "-theta"
reset = { theta = "-alpha", dtheta = "cos(2*alpha)*dtheta" }
[start]
kind = "simulation"
values = { x1_theta = 0, x1_dtheta = 0.6 }
[run]
parameter = "gamma"
bounds = { gamma = [0.0, 0.3], period = [0, 200] }
)toml";
  const CliResult r = RunTool({"run", (dir / "wheel.toml").string(), "--out", (dir / "out").string(), "--no-plots"});
  EXPECT_EQ(r.code, 1) << r.err;
  // The answer wraps its lines at 100 characters: read as one text.
  const std::string out = std::regex_replace(r.out, std::regex("\n +"), " ");
  EXPECT_NE(out.find("no start point: start 1: event-driven simulation did not settle"), std::string::npos) << r.out;
  EXPECT_NE(out.find("the event stays above 0, where a phase goes on: is its sign the intended one?"),
            std::string::npos) << r.out;
  fs::remove_all(dir);
}

TEST(Cli, RunBouncingBallWritesClassifiedBranchesThatMatchTheClosedForm) {
  const fs::path dir = TempDir("ball");
  const CliResult r = RunTool({"run", "bouncing-ball", "--out", dir.string(), "--quiet", "--no-plots"});
  ASSERT_EQ(r.code, 0) << r.err;
  std::ifstream summary_file(dir / "summary.json");
  const nlohmann::json summary = nlohmann::json::parse(summary_file);
  EXPECT_EQ(summary["model"], "bouncing-ball");
  ASSERT_EQ(summary["branches"].size(), 4u);  // orbit family both ways, at-rest xi-branch both ways
  int physical = 0, reversed = 0, at_rest = 0;
  double worst = 0.0;
  for (const auto& b : summary["branches"]) {
    std::ifstream csv(dir / b["file"].get<std::string>());
    std::string line;
    std::getline(csv, line);
    // header: index,H,T,xi,t1,t2,x1_y,x1_dy,x2_y,x2_dy,physical,classification,...
    EXPECT_EQ(line.rfind("index,H,T,xi,t1,t2,x1_y,x1_dy,x2_y,x2_dy,physical,classification,stability,residual", 0), 0u) << line;
    while (std::getline(csv, line)) {
      std::vector<std::string> cells;
      std::stringstream ss(line);
      for (std::string cell; std::getline(ss, cell, ',');) cells.push_back(cell);
      const double H = std::stod(cells[1]), T = std::stod(cells[2]);
      if (cells[10] == "1") {
        ++physical;
        worst = std::max(worst, std::abs(T - std::sqrt(8.0 * H)));
      }
      reversed += cells[11] == "reversed-time";
      at_rest += cells[11] == "at-rest";
    }
  }
  EXPECT_GT(physical, 10);
  EXPECT_GT(reversed, 10);
  EXPECT_GT(at_rest, 10);
  EXPECT_LT(worst, 1e-9);  // T = sqrt(8 H) on every physical point
}

}  // namespace
}  // namespace hybridcont::app

namespace hybridcont::app {
namespace {

std::vector<std::map<std::string, std::string>> ReadCsv(const fs::path& file) {
  std::ifstream in(file);
  std::string line;
  std::getline(in, line);
  std::vector<std::string> header;
  {
    std::stringstream ss(line);
    for (std::string cell; std::getline(ss, cell, ',');) header.push_back(cell);
  }
  std::vector<std::map<std::string, std::string>> rows;
  while (std::getline(in, line)) {
    std::stringstream ss(line);
    std::map<std::string, std::string> row;
    std::size_t i = 0;
    for (std::string cell; std::getline(ss, cell, ',') && i < header.size(); ++i) row[header[i]] = cell;
    rows.push_back(row);
  }
  return rows;
}

// The state-based formulation traces the same normal orbits (T(H) of the ball's family).
TEST(Cli, StateBasedBallAgreesWithTheClosedForm) {
  const fs::path dir = TempDir("ball_state");
  const CliResult r = RunTool({"run", "bouncing-ball", "--formulation", "state", "--out", dir.string(), "--quiet",
                               "--no-plots"});
  ASSERT_EQ(r.code, 0) << r.err << r.out;
  std::ifstream summary_file(dir / "summary.json");
  const nlohmann::json summary = nlohmann::json::parse(summary_file);
  int physical = 0;
  double worst = 0.0, worst_replay = 0.0;
  for (const auto& b : summary["branches"]) {
    for (const auto& row : ReadCsv(dir / b["file"].get<std::string>())) {
      if (row.at("physical") != "1") continue;
      ++physical;
      worst = std::max(worst, std::abs(std::stod(row.at("T")) - std::sqrt(8.0 * std::stod(row.at("H")))));
      worst_replay = std::max(worst_replay, std::stod(row.at("replay_error")));
      EXPECT_EQ(row.at("stable"), "1");  // the ball's orbits are neutrally stable: multipliers all 1
    }
  }
  EXPECT_GT(physical, 5);
  EXPECT_LT(worst, 1e-8);
  EXPECT_LT(worst_replay, 1e-8);
}

// The SB points of the hopping-in-place branch are the +1 crossings of the Floquet multipliers,
// for both formulations.
TEST(Cli, SlipSimpleBifurcationsAreFloquetCrossingsInBothFormulations) {
  for (const char* formulation : {"time", "state"}) {
    const fs::path dir = TempDir(std::string("slip_") + formulation);
    const CliResult r = RunTool({"run", "slip", "--formulation", formulation, "--out", dir.string(), "--quiet",
                                 "--no-plots", "--max-branches", "6"});
    ASSERT_EQ(r.code, 0) << r.err;
    std::ifstream summary_file(dir / "summary.json");
    const nlohmann::json summary = nlohmann::json::parse(summary_file);
    std::vector<double> sb, bp, pd;
    for (const auto& sp : summary["special_points"]) {
      // One schema for every kind of special point (continuation's SB/TP/start, Floquet BP/PD).
      for (const char* key : {"id", "type", "branch", "index", "H", "T", "status", "precision", "precision_arclength",
                              "precision_H", "residual", "component", "duplicate_of", "message", "u"}) {
        EXPECT_TRUE(sp.contains(key)) << key << " missing in " << sp.dump();
      }
      // A branch leaving a bifurcation point does not report that point again (its first interval).
      if (sp["type"] == "BP" || sp["type"] == "PD") {
        EXPECT_TRUE(sp["index"] != 0 || summary["branches"][sp["branch"].get<int>()]["parent"] == -1) << sp.dump();
      }
      if (sp["type"] == "SB" && sp["status"] == "located") {
        sb.push_back(sp["H"]);
        // Precision in model units, integration error included, in both formulations (the state-based
        // one knows the widths of x̄_1, ξ and H̄): at least the width in H, and small here.
        EXPECT_GE(sp["precision"].get<double>(), sp["precision_H"].get<double>()) << sp.dump();
        EXPECT_GT(sp["precision_H"].get<double>(), 0.0) << sp.dump();
        EXPECT_LT(sp["precision"].get<double>(), 1e-8) << sp.dump();
      }
      if (sp["type"] == "BP") bp.push_back(sp["H"]);
      if (sp["type"] == "PD") pd.push_back(sp["H"]);
    }
    // the first SB above the start, located by continuation, and the first BP (multiplier +1)
    const auto near = [](const std::vector<double>& v, double x) {
      double best = 1e9;
      for (double y : v) best = std::min(best, std::abs(y - x));
      return best;
    };
    EXPECT_LT(near(sb, 1.24674011004), 1e-9) << formulation;
    EXPECT_LT(near(bp, 1.24674011004), 1e-9) << formulation;
    // The −1 crossing that ends the unstable stretch: 0.036 in H above the first, so the default steps
    // must resolve both (a step across both crossings would cancel the sign changes and miss them).
    EXPECT_LT(near(pd, 1.282809323809), 1e-9) << formulation;
  }
}

std::string ReadFile(const fs::path& file) {
  std::ifstream in(file);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// --threads changes nothing but the wall time. The progress lines, the report and every CSV
// file are those of --threads 1, byte for byte (the report's wall-time line and the folder aside), in both
// formulations.
// In a pipe (a log, `| less`, a notebook's `!hybridcont`) standard output holds the answer alone; a line per
// point only with --verbose.
TEST(Cli, InAPipeStandardOutputIsTheAnswerUnlessVerbose) {
  const fs::path dir = TempDir("pipe_answer");
  const CliResult plain = RunTool({"run", "slip", "--out", dir.string(), "--no-plots"});
  ASSERT_EQ(plain.code, 0) << plain.err;
  EXPECT_EQ(plain.out.find("branch 0\n"), std::string::npos) << plain.out;
  EXPECT_EQ(plain.out.rfind("\nslip: 5 branches with physical orbits of 23", 0), 0u) << plain.out;
  std::stringstream lines(plain.out);
  for (std::string line; std::getline(lines, line);) EXPECT_LE(line.size(), 100u) << line;  // a terminal's width
  const CliResult verbose = RunTool({"run", "slip", "--out", dir.string(), "--no-plots", "--verbose"});
  ASSERT_EQ(verbose.code, 0) << verbose.err;
  EXPECT_NE(verbose.out.find("branch 0\n"), std::string::npos);
  fs::remove_all(dir);
}

TEST(Cli, RunOnTwoThreadsWritesWhatTheSerialRunWrites) {
  for (const auto& [model, formulation] : {std::pair{"bouncing-rod", "time"}, std::pair{"bouncing-ball", "state"}}) {
    SCOPED_TRACE(std::string(model) + " " + formulation);
    std::string out[2];
    fs::path dirs[2];
    for (const int threads : {1, 2}) {
      dirs[threads - 1] = TempDir(std::string("threads_") + model + "_" + std::to_string(threads));
      const CliResult r = RunTool({"run", model, "--formulation", formulation, "--threads", std::to_string(threads),
                                   "--out", dirs[threads - 1].string(), "--no-plots", "--verbose"});
      ASSERT_EQ(r.code, 0) << r.err;
      std::stringstream lines(r.out);
      for (std::string line; std::getline(lines, line);) {
        if (line.rfind("wall time", 0) != 0 && line.rfind("results written", 0) != 0) out[threads - 1] += line + "\n";
      }
    }
    EXPECT_EQ(out[0], out[1]);
    EXPECT_NE(out[0].find("branch 1\n"), std::string::npos) << out[0];  // progress lines are there (--verbose)
    int files = 0;
    for (const auto& entry : fs::directory_iterator(dirs[0])) {
      if (entry.path().extension() != ".csv") continue;
      ++files;
      EXPECT_EQ(ReadFile(entry.path()), ReadFile(dirs[1] / entry.path().filename())) << entry.path().filename();
    }
    EXPECT_GE(files, 3);  // branches and orbits
  }
}

}  // namespace
}  // namespace hybridcont::app

namespace hybridcont::app {
namespace {

Matrix MonodromyOf(const nlohmann::json& orbit) {
  const auto& rows = orbit.at("monodromy");
  Matrix m(static_cast<Eigen::Index>(rows.size()), static_cast<Eigen::Index>(rows.size()));
  for (Eigen::Index i = 0; i < m.rows(); ++i) {
    for (Eigen::Index j = 0; j < m.cols(); ++j) m(i, j) = rows[static_cast<std::size_t>(i)][static_cast<std::size_t>(j)];
  }
  return m;
}

// dT/dH̄ from the branch tangent against the ball's closed form T = sqrt(8 H̄), dT/dH̄ = 4 / T; the key-frame
// orbit's monodromy: the ball's (a shear, both multipliers 1), and the SLIP's, whose eigenvalues hold the
// nontrivial multipliers its branch file lists at that point.
TEST(Cli, PeriodSlopeAndMonodromyAgreeWithTheClosedFormAndTheMultipliers) {
  {
    const fs::path dir = TempDir("ball_slope");
    const CliResult r = RunTool({"run", "bouncing-ball", "--out", dir.string(), "--quiet"});
    ASSERT_EQ(r.code, 0) << r.err << r.out;
    std::ifstream summary_file(dir / "summary.json");
    const nlohmann::json summary = nlohmann::json::parse(summary_file);
    int checked = 0;
    for (const auto& b : summary["branches"]) {
      for (const auto& row : ReadCsv(dir / b["file"].get<std::string>())) {
        if (row.at("physical") != "1" || std::stod(row.at("H")) < 0.05) continue;
        const double T = std::stod(row.at("T"));
        EXPECT_NEAR(std::stod(row.at("dT_dH")), 4.0 / T, 1e-8 * 4.0 / T) << "H = " << row.at("H");
        ++checked;
      }
    }
    EXPECT_GT(checked, 5);
    ASSERT_FALSE(summary["orbits"].empty());
    const Matrix m = MonodromyOf(summary["orbits"][0]);
    ASSERT_EQ(m.rows(), 2);
    EXPECT_NEAR(m.determinant(), 1.0, 1e-9);
    EXPECT_NEAR(m.trace(), 2.0, 1e-9);
  }
  const fs::path dir = TempDir("slip_monodromy");
  const CliResult r = RunTool({"run", "slip", "--out", dir.string(), "--quiet"});
  ASSERT_EQ(r.code, 0) << r.err << r.out;
  std::ifstream summary_file(dir / "summary.json");
  const nlohmann::json summary = nlohmann::json::parse(summary_file);
  int orbits = 0;
  for (const auto& orbit : summary["orbits"]) {
    const Matrix m = MonodromyOf(orbit);
    const Eigen::VectorXcd eigenvalues = m.eigenvalues();
    const auto rows = ReadCsv(dir / summary["branches"][orbit["branch"].get<std::size_t>()]["file"].get<std::string>());
    const auto& row = rows.at(orbit["index"].get<std::size_t>());
    for (int k = 1; row.count("mu" + std::to_string(k) + "_re") && !row.at("mu" + std::to_string(k) + "_re").empty(); ++k) {
      const std::complex<double> mu(std::stod(row.at("mu" + std::to_string(k) + "_re")),
                                    std::stod(row.at("mu" + std::to_string(k) + "_im")));
      double nearest = HUGE_VAL;
      for (const auto& e : eigenvalues) nearest = std::min(nearest, std::abs(e - mu));
      EXPECT_LT(nearest, 1e-6 * (1 + std::abs(mu))) << orbit["label"] << " mu" << k << " = " << mu;
    }
    ++orbits;
  }
  EXPECT_EQ(orbits, 3);  // hopping in place, forward and backward hopping
}

}  // namespace
}  // namespace hybridcont::app

namespace hybridcont::app {
namespace {

// `--curves k` continues the SLIP's PD point (where hopping in place turns stable) in (H, k): at a point of
// that curve far from the run's k, a run at that k locates its PD at the curve's H. LoadStudy reads the curves
// back as the run wrote them.
TEST(Cli, PeriodDoublingCurvePassesThroughThePeriodDoublingOfARunAtItsParameter) {
  const fs::path dir = TempDir("slip_pd_curve");
  const CliResult r = RunTool({"run", "slip", "--curves", "k", "--out", dir.string(), "--quiet"});
  ASSERT_EQ(r.code, 0) << r.err << r.out;
  const StudyResult loaded = LoadStudy(dir.string());
  EXPECT_EQ(loaded.curve_parameter, "k");
  const StudyCurve* pd = nullptr;
  for (const StudyCurve& c : loaded.curves) {
    if (c.type == "period-doubling") pd = &c;
  }
  ASSERT_NE(pd, nullptr);
  EXPECT_EQ(loaded.special_points.at(pd->special_point).Label(), "PD4");
  ASSERT_GT(pd->points.size(), 100u);  // sampled finely enough to draw (a quarter of the families' step)
  ASSERT_EQ(pd->columns[0], "H");
  ASSERT_EQ(pd->columns[1], "k");
  for (const double k_target : {15.0, 120.0}) {
    const Vector* at = nullptr;
    for (const Vector& u : pd->points) {
      if (!at || std::abs(u(1) - k_target) < std::abs((*at)(1) - k_target)) at = &u;
    }
    const std::string k = fmt::format("{:.17g}", (*at)(1));
    const fs::path there = TempDir("slip_pd_at_k");
    const CliResult run = RunTool({"run", "slip", "--set", "k=" + k, "--out", there.string(), "--quiet"});
    ASSERT_EQ(run.code, 0) << run.err;
    const StudyResult study = LoadStudy(there.string());
    double nearest = HUGE_VAL;
    for (const StudySpecialPoint& sp : study.special_points) {
      if (sp.code == "PD") nearest = std::min(nearest, std::abs(sp.H - (*at)(0)));
    }
    EXPECT_LT(nearest, 1e-8) << "k = " << k << ", curve H = " << (*at)(0);
  }
}

}  // namespace
}  // namespace hybridcont::app
