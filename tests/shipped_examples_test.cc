// Every model under models/ runs from its shipped start to what its file and the docs describe: the run
// completes, it has physical orbits, and every family its [[families]] rules name has a branch of physical
// orbits so named; the special points that end or split its physical and stable stretches are located where
// the run says so (summary.json's ranges name a special point only if it is located).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>
#include <set>
#include <string>

#include "cli_runner.h"
#include "hybridcont/study.h"
#include "study/io/summary_json.h"

namespace hybridcont::app {
namespace {

namespace fs = std::filesystem;

// The [[families]] names a model file declares (each `name = "..."` line after a [[families]] header).
std::set<std::string> DeclaredFamilies(const fs::path& file) {
  std::ifstream in(file);
  std::set<std::string> names;
  bool in_families = false;
  const std::regex name_line(R"re(^name\s*=\s*"([^"]*)")re");
  for (std::string line; std::getline(in, line);) {
    if (!line.empty() && line[0] == '[') in_families = line.rfind("[[families]]", 0) == 0;
    std::smatch m;
    if (in_families && std::regex_search(line, m, name_line)) names.insert(m[1]);
  }
  return names;
}

class ShippedExample : public testing::TestWithParam<std::string> {};

TEST_P(ShippedExample, RunsToItsNamedPhysicalFamilies) {
  const fs::path file = fs::path(HYBRIDCONT_SOURCE_DIR) / "models" / (GetParam() + ".toml");
  const fs::path out = fs::temp_directory_path() / ("hybridcont_example_" + GetParam());
  const CliResult r = RunTool({"run", file.string(), "--out", out.string(), "--quiet", "--no-plots", "--overwrite"});
  ASSERT_EQ(r.code, 0) << r.err;
  std::ifstream in(out / "summary.json");
  const nlohmann::json summary = nlohmann::json::parse(in);
  EXPECT_EQ(summary["status"], "complete");
  std::set<std::string> named;
  int physical_branches = 0;
  for (const nlohmann::json& b : summary["branches"]) {
    if (!b.contains("physical_ranges")) continue;
    ++physical_branches;
    named.insert(b["family"].get<std::string>());
    for (const char* key : {"physical_ranges", "stable_ranges"}) {
      for (const nlohmann::json& range : b[key]) {
        named.insert(range["family"].get<std::string>());  // a branch through a fold holds two families
        for (const char* end : {"from", "to"}) {
          const std::string how = range[std::string(end) + "_how"].get<std::string>();
          // An end at a special point is said with its status: a located one, or it says it is not.
          if (how.find(" #") != std::string::npos && how.rfind("start of the branch", 0) != 0) {
            EXPECT_NE(how.find("located"), std::string::npos) << GetParam() << " branch " << b["id"] << ": " << how;
          }
        }
      }
    }
  }
  EXPECT_GT(physical_branches, 0) << GetParam();
  // The folder read back is the study that wrote it: its families, folded again from the branches read back,
  // are those the run wrote from memory (summary.json's "families"), to the last bit; its special points and
  // key frames are all there; its model is rebuilt from its record.
  const StudyResult loaded = LoadStudy(out.string());
  EXPECT_EQ(study::FamiliesJson(loaded.families), summary["families"]) << GetParam();
  EXPECT_EQ(loaded.special_points.size(), summary["special_points"].size());
  ASSERT_EQ(loaded.orbits.size(), summary["orbits"].size());
  for (const StudyOrbit& o : loaded.orbits) {
    EXPECT_EQ(o.t.size(), o.x.size());
    EXPECT_FALSE(o.t.empty());
  }
  EXPECT_EQ(loaded.model_source.kind, StudyModelSource::Kind::kFile);
  EXPECT_EQ(ModelOfStudy(loaded).name(), loaded.model);
  std::set<std::string> expected = DeclaredFamilies(file);
  // The bouncing pendulum's swinging orbits repeat every second bounce: the period-doubled family of its
  // vertical bouncing, which `--period-doubling` follows (its file says so).
  if (GetParam() == "bouncing-pendulum") expected.erase("swinging bounce");
  for (const std::string& family : expected) {
    EXPECT_EQ(named.count(family), 1u) << GetParam() << ": no physical branch of the family '" << family << "'";
  }
  fs::remove_all(out);
}

INSTANTIATE_TEST_SUITE_P(Models, ShippedExample,
                         testing::Values("ball-ceiling", "ball-chain", "bipedal-slip", "bipedal-slip-swing",
                                         "bouncing-ball", "bouncing-pendulum", "bouncing-rod-lagrangian",
                                         "bouncing-rod", "compass-gait", "forced-impact-oscillator",
                                         "impacting-pendulum", "mass-chain", "rocking-block", "simplest-walker",
                                         "slip-lagrangian", "slip", "slip-running", "stiffening-slip",
                                         "vibrating-table"),
                         [](const testing::TestParamInfo<std::string>& info) {
                           std::string name = info.param;
                           for (char& c : name) c = c == '-' ? '_' : c;
                           return name;
                         });

// Every model file under models/ is in the list above.
TEST(ShippedExample, EveryModelFileIsListed) {
  std::set<std::string> files;
  for (const fs::directory_entry& e : fs::directory_iterator(fs::path(HYBRIDCONT_SOURCE_DIR) / "models")) {
    if (e.path().extension() == ".toml") files.insert(e.path().stem().string());
  }
  EXPECT_EQ(files.size(), 19u) << "a model file was added or removed: list it in ShippedExample's values";
}

}  // namespace
}  // namespace hybridcont::app
