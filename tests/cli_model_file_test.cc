// The command line with model files, parameter ranges and bounds, as a user meets it.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "cli_runner.h"

namespace hybridcont::app {
namespace {

namespace fs = std::filesystem;


fs::path Fresh(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("hybridcont_cli_model_file_" + name);
  fs::remove_all(dir);
  return dir;
}

std::string SlipFile() { return (fs::path(HYBRIDCONT_SOURCE_DIR) / "models" / "slip.toml").string(); }

// The largest H of every branch file of a results folder.
double LargestH(const fs::path& dir) {
  double largest = -1e300;
  for (const auto& entry : fs::directory_iterator(dir)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind("branch-", 0) != 0) continue;
    std::ifstream f(entry.path());
    std::string header, line;
    std::getline(f, header);
    while (std::getline(f, line)) {
      // H is the second column (index,H,T,...)
      const std::size_t a = line.find(',');
      largest = std::max(largest, std::stod(line.substr(a + 1, line.find(',', a + 1) - a - 1)));
    }
  }
  return largest;
}

TEST(CliModelFile, ParameterOutsideItsRangeIsRefusedAndNothingIsWritten) {
  for (const std::string& model : {std::string("slip"), SlipFile()}) {
    const fs::path out = Fresh("range");
    const CliResult r = RunTool({"run", model, "--set", "k=-40", "--out", out.string(), "--no-plots"});
    EXPECT_EQ(r.code, 2) << r.err;
    for (const char* part : {"'k'", "-40", "(0, inf)"}) EXPECT_NE(r.err.find(part), std::string::npos) << part << ": " << r.err;
    EXPECT_FALSE(fs::exists(out));
    const CliResult m = RunTool({"run", model, "--set", "m=0", "--out", out.string(), "--no-plots"});
    EXPECT_EQ(m.code, 2);
    EXPECT_NE(m.err.find("'m'"), std::string::npos) << m.err;
    EXPECT_FALSE(fs::exists(out));
  }
}

TEST(CliModelFile, BoundFromTheCommandLineReplacesTheModelsBound) {
  const fs::path out = Fresh("bound");
  const CliResult r =
      RunTool({"run", "slip", "--bound", "H=0:2.7", "--max-branches", "3", "--out", out.string(), "--no-plots", "--quiet"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NEAR(LargestH(out), 2.7, 0.1);  // past the model's bound H <= 2
  EXPECT_GT(LargestH(out), 2.6);
  const CliResult until =
      RunTool({"run", "slip", "--until", "H=2.7", "--max-branches", "3", "--out", out.string(), "--no-plots", "--quiet"});
  ASSERT_EQ(until.code, 0) << until.err;
  EXPECT_NEAR(LargestH(out), 2.7, 1e-9);  // ends exactly at the target
  for (const char* bad : {"H=2:1", "H", "H=a:2", "H=0:inf", "nosuch=0:1"}) {
    const fs::path none = Fresh("bound_bad");
    const CliResult b = RunTool({"run", "slip", "--bound", bad, "--out", none.string(), "--no-plots"});
    EXPECT_EQ(b.code, 2) << bad << ": " << b.err;
    EXPECT_NE(b.err.find("--bound"), std::string::npos) << bad << ": " << b.err;
    EXPECT_FALSE(fs::exists(none)) << bad;
  }
}

TEST(CliModelFile, ListAndCheckTakeModelFiles) {
  const CliResult list = RunTool({"list", SlipFile()});
  EXPECT_EQ(list.code, 0) << list.err;
  for (const char* s : {"stance", "flight", "n = 5", "(0, inf)", "leg stiffness"}) {
    EXPECT_NE(list.out.find(s), std::string::npos) << s;
  }
  const CliResult check = RunTool({"check", SlipFile(), "--points", "2"});
  EXPECT_EQ(check.code, 0) << check.out << check.err;
  EXPECT_NE(check.out.find("all derivatives agree"), std::string::npos);
}

// Every shipped model file passes `hybridcont check` as a user first runs it (default points and seed): its
// derivatives, and its energy on every word an automaton may take. Points where a flow leaves the model's
// domain (the stiffening spring's unfolded flow) or an observable has a kink are drawn again, not failures.
TEST(CliModelFile, EveryShippedModelPassesCheck) {
  int files = 0;
  for (const auto& entry : fs::directory_iterator(fs::path(HYBRIDCONT_SOURCE_DIR) / "models")) {
    if (entry.path().extension() != ".toml") continue;
    ++files;
    const CliResult check = RunTool({"check", entry.path().string()});
    EXPECT_EQ(check.code, 0) << entry.path() << "\n" << check.out << check.err;
    EXPECT_EQ(check.out.find("FAIL"), std::string::npos) << entry.path() << "\n" << check.out;
  }
  EXPECT_GE(files, 17);
}

TEST(CliModelFile, MissingOrMalformedFileIsBadInput) {
  const fs::path out = Fresh("malformed");
  const CliResult missing = RunTool({"run", "/nonexistent/model.toml", "--out", out.string(), "--no-plots"});
  EXPECT_EQ(missing.code, 2);
  EXPECT_NE(missing.err.find("/nonexistent/model.toml"), std::string::npos) << missing.err;
  const fs::path bad = fs::temp_directory_path() / "hybridcont_cli_model_file_bad.toml";
  std::ifstream in(SlipFile());
  std::stringstream text;
  text << in.rdbuf();
  std::string s = text.str();
  s.replace(s.find("ode.dl = \""), 10, "ode.dl = \"q + ");  // an unknown symbol in the stance phase
  std::ofstream(bad) << s;
  const CliResult r = RunTool({"run", bad.string(), "--out", out.string(), "--no-plots"});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find(bad.string() + ":"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("phases.stance.ode.dl"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("unknown symbol 'q'"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
}

}  // namespace
}  // namespace hybridcont::app
