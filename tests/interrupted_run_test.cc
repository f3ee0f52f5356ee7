// A run killed (SIGKILL) while it traces: summary.json is whole (written by renaming), lists every branch
// from its first point on ("termination": "running" until it ends), and every branch it lists has its
// file, whose rows are whole. The kill comes when the third branch file appears, whatever the time.
//
// Resumed (--resume), a run killed at any moment ends with the files of an uninterrupted run: every CSV file
// equal to the byte, summary.json equal but for the report's wall time and work counts.
#include <gtest/gtest.h>
#include <signal.h>
#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

namespace hybridcont {
namespace {

namespace fs = std::filesystem;

TEST(InterruptedRun, SummaryListsEveryBranchWithItsFileFromItsFirstPoint) {
  const fs::path out = fs::temp_directory_path() / ("hybridcont_interrupted_" + std::to_string(getpid()));
  fs::remove_all(out);
  const std::string model = std::string(HYBRIDCONT_SOURCE_DIR) + "/models/bipedal-slip.toml";
  const pid_t pid = fork();
  if (pid == 0) {
    const int null = open("/dev/null", O_WRONLY);
    dup2(null, 1), dup2(null, 2);
    execl(HYBRIDCONT_CLI_PATH, "hybridcont", "run", model.c_str(), "--out", out.c_str(), "--quiet", "--no-plots",
          "--threads", "1", static_cast<char*>(nullptr));
    _exit(127);
  }
  ASSERT_GT(pid, 0);
  // Wait for the third branch's file (or the end of the run), then kill.
  int status = 0;
  bool ended = false;
  for (int i = 0; i < 60000 && !ended; ++i) {  // a bound on the wait (10 min), not a timing of the run
    if (fs::exists(out / "branch-2.csv")) break;
    ended = waitpid(pid, &status, WNOHANG) == pid;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  if (!ended) {
    kill(pid, SIGKILL);
    ASSERT_EQ(waitpid(pid, &status, 0), pid);
  }
  std::ifstream in(out / "summary.json");
  const nlohmann::json summary = nlohmann::json::parse(in);  // whole: written by renaming
  ASSERT_TRUE(summary.is_object());
  int running = 0;
  for (const nlohmann::json& b : summary["branches"]) {
    const fs::path file = out / b["file"].get<std::string>();
    ASSERT_TRUE(fs::exists(file)) << b.dump();
    running += b["termination"] == "running";
    // Whole rows, as wide as the header.
    std::ifstream csv(file);
    std::string header, row;
    std::getline(csv, header);
    int rows = 0;
    while (std::getline(csv, row)) {
      EXPECT_EQ(std::count(row.begin(), row.end(), ','), std::count(header.begin(), header.end(), ',')) << file;
      ++rows;
    }
    if (b["termination"] != "running") EXPECT_EQ(rows, b["points"].get<int>()) << file;
  }
  EXPECT_GE(summary["branches"].size(), ended ? 1u : 2u);
  if (!ended) {
    EXPECT_TRUE(WIFSIGNALED(status));
    EXPECT_GE(running, 1);  // the branch traced when the kill came
    EXPECT_EQ(summary["status"], "running");
  }
  fs::remove_all(out);
}

// Runs the tool with `args` and kills it (SIGKILL) once `trigger` exists in `out` (or lets it end). True if
// it was killed.
bool RunAndKillWhen(const std::vector<std::string>& args, const fs::path& out, const std::string& trigger) {
  const pid_t pid = fork();
  if (pid == 0) {
    const int null = open("/dev/null", O_WRONLY);
    dup2(null, 1), dup2(null, 2);
    std::vector<char*> argv = {const_cast<char*>("hybridcont")};
    for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    execv(HYBRIDCONT_CLI_PATH, argv.data());
    _exit(127);
  }
  EXPECT_GT(pid, 0);
  int status = 0;
  for (int i = 0; i < 60000; ++i) {  // a bound on the wait (10 min), not a timing of the run
    if (!trigger.empty() && fs::exists(out / trigger)) {
      kill(pid, SIGKILL);
      waitpid(pid, &status, 0);
      return true;
    }
    if (waitpid(pid, &status, WNOHANG) == pid) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  kill(pid, SIGKILL);
  waitpid(pid, &status, 0);
  ADD_FAILURE() << "the run did not end";
  return true;
}

std::string Contents(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// summary.json without what varies from run to run: the report's wall time and work counts, and the thread
// count (which the results do not depend on).
nlohmann::json Comparable(const fs::path& summary) {
  nlohmann::json j = nlohmann::json::parse(Contents(summary));
  j["options"].erase("threads");
  std::string report = j["report"];
  report = report.substr(0, report.find("\nwall time"));
  j["report"] = report;
  return j;
}

std::vector<std::string> Files(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

TEST(InterruptedRun, ResumedAfterSigkillAtAnyMomentGivesTheUninterruptedRunsFiles) {
  const fs::path root = fs::temp_directory_path() / ("hybridcont_resume_" + std::to_string(getpid()));
  fs::remove_all(root);
  const std::vector<std::string> run = {"run", "slip", "--period-doubling", "--quiet", "--no-plots"};
  const auto with = [&](std::vector<std::string> extra, const fs::path& out) {
    std::vector<std::string> a = run;
    a.insert(a.end(), {"--out", out.string()});
    if (std::find(extra.begin(), extra.end(), "--threads") == extra.end()) a.insert(a.end(), {"--threads", "1"});
    a.insert(a.end(), extra.begin(), extra.end());
    return a;
  };
  const fs::path reference = root / "reference";
  ASSERT_FALSE(RunAndKillWhen(with({}, reference), reference, ""));
  ASSERT_FALSE(fs::exists(reference / ".resume"));  // a complete run keeps nothing for a resume
  const std::vector<std::string> expected = Files(reference);
  ASSERT_GT(expected.size(), 25u);  // 23 branches of the run, the period-doubled families, orbits
  // Kills while the run's own branches are traced (early, late), while the period-doubled families are,
  // and twice in a row (the second kill interrupts the resumed run). The last resume runs on two threads:
  // the results do not depend on it.
  const std::vector<std::vector<std::string>> kills = {{"branch-2.csv"}, {"branch-15.csv"}, {"branch-24.csv"},
                                                       {"branch-5.csv", "branch-12.csv"}};
  for (std::size_t k = 0; k < kills.size(); ++k) {
    const fs::path out = root / ("killed-" + std::to_string(k));
    bool killed = RunAndKillWhen(with({}, out), out, kills[k][0]);
    EXPECT_TRUE(killed) << kills[k][0];
    for (std::size_t again = 1; again < kills[k].size(); ++again) {
      killed = RunAndKillWhen(with({"--resume"}, out), out, kills[k][again]);
      EXPECT_TRUE(killed) << kills[k][again];
    }
    EXPECT_TRUE(fs::exists(out / ".resume"));
    std::vector<std::string> resume = {"--resume"};
    if (k + 1 == kills.size()) resume = {"--resume", "--threads", "2"};
    ASSERT_FALSE(RunAndKillWhen(with(resume, out), out, ""));
    EXPECT_FALSE(fs::exists(out / ".resume"));
    ASSERT_EQ(Files(out), expected) << "killed at " << kills[k][0];
    for (const std::string& name : expected) {
      if (name == "summary.json") {
        const nlohmann::json a = Comparable(out / name), b = Comparable(reference / name);
        std::string differs;
        for (const auto& [key, value] : b.items()) {
          if (a.value(key, nlohmann::json()) != value) differs += " " + key;
        }
        EXPECT_TRUE(a == b) << "summary.json differs in" << differs << ", killed at " << kills[k][0];
      } else {
        EXPECT_EQ(Contents(out / name), Contents(reference / name)) << name << ", killed at " << kills[k][0];
      }
    }
  }
  fs::remove_all(root);
}

// Branches the exploration abandoned (no physical orbit over its length: termination `abandoned`, the last
// termination reason) are kept by an interrupted run like any other and read back by the resumed one: the
// bipedal model's branches 20 to 23 are abandoned before branch 25 is written, where the run is killed. The
// resumed run's summary and its abandoned branches' files are the uninterrupted run's. (Its start points' rows,
// point 0 of the branches leaving the model's two starts, differ in the analysis columns by ~1e-11: their
// multipliers are not taken from the same evaluation after a resume. That is not this test's subject.)
TEST(InterruptedRun, AbandonedBranchesAreResumedAsTheyWere) {
  const fs::path root = fs::temp_directory_path() / ("hybridcont_resume_abandoned_" + std::to_string(getpid()));
  fs::remove_all(root);
  const std::string model = std::string(HYBRIDCONT_SOURCE_DIR) + "/models/bipedal-slip.toml";
  const auto args = [&](const fs::path& out, bool resume) {
    std::vector<std::string> a = {"run", model, "--quiet", "--no-plots", "--threads", "1", "--out", out.string()};
    if (resume) a.push_back("--resume");
    return a;
  };
  const fs::path reference = root / "reference", out = root / "killed";
  ASSERT_FALSE(RunAndKillWhen(args(reference, false), reference, ""));
  const nlohmann::json whole = nlohmann::json::parse(std::ifstream(reference / "summary.json"));
  std::vector<std::string> abandoned;
  for (const nlohmann::json& b : whole["branches"]) {
    if (b["termination"] == "abandoned" && b["id"] < 25) abandoned.push_back(b["file"].get<std::string>());
  }
  ASSERT_FALSE(abandoned.empty()) << "no branch abandoned before branch 25: the test no longer tests it";
  EXPECT_TRUE(RunAndKillWhen(args(out, false), out, "branch-25.csv"));
  ASSERT_TRUE(fs::exists(out / ".resume"));
  ASSERT_FALSE(RunAndKillWhen(args(out, true), out, ""));
  ASSERT_EQ(Files(out), Files(reference));
  EXPECT_EQ(Comparable(out / "summary.json"), Comparable(reference / "summary.json"));
  for (const std::string& name : abandoned) EXPECT_EQ(Contents(out / name), Contents(reference / name)) << name;
  fs::remove_all(root);
}

}  // namespace
}  // namespace hybridcont
