// A run killed (SIGKILL) while it traces: summary.json is whole (written by renaming), lists every branch
// from its first point on ("termination": "running" until it ends), and every branch it lists has its
// file, whose rows are whole. The kill comes when the third branch file appears, whatever the time.
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

}  // namespace
}  // namespace hybridcont
