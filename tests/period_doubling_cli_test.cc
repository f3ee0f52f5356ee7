// `hybridcont run slip --period-doubling`: the period-doubled family of hopping in place in the results.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "cli_runner.h"

namespace hybridcont::app {
namespace {

TEST(PeriodDoublingCli, SlipFamilyFromThePdPointOfHoppingInPlace) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "hybridcont_pd_cli_test";
  const CliResult r = RunTool({"run", "slip", "--period-doubling", "--verbose", "--out", dir.string(), "--quiet", "--no-plots",
                               "--threads", "1", "--overwrite"});
  ASSERT_EQ(r.code, 0) << r.err;
  std::ifstream summary_file(dir / "summary.json");
  const nlohmann::json summary = nlohmann::json::parse(summary_file);
  // The run's 23 half-branches are unchanged; the family from the PD point at H = 1.2828 follows (the PD point
  // at H = 1.24674, where a multiplier is +1 as well, is no simple bifurcation point of the doubled map).
  int run_branches = 0, doubled = 0, pd_at_12828 = -1;
  for (const nlohmann::json& sp : summary["special_points"]) {
    if (sp["type"] == "PD" && std::abs(sp["H"].get<double>() - 1.282809323809) < 1e-9) pd_at_12828 = sp["id"];
  }
  ASSERT_GE(pd_at_12828, 0);
  for (const nlohmann::json& b : summary["branches"]) {
    if (!b.contains("period_doubled_from")) {
      ++run_branches;
      continue;
    }
    ++doubled;
    EXPECT_EQ(b["period_doubled_from"], pd_at_12828);
    EXPECT_EQ(b["model"], "slip-x2");
    EXPECT_EQ(b["termination"], "bound-reached");
    // Stable from the PD point to the family's fold, unstable beyond it.
    ASSERT_EQ(b["stability_changes"].size(), 1u) << b.dump();
    EXPECT_EQ(b["stability_changes"][0]["stable"], false);
    // At the family's fold, located (not at a continuation point beside it).
    EXPECT_NEAR(b["stability_changes"][0]["H"].get<double>(), 1.282699642918, 1e-9);
    EXPECT_EQ(b["stability_changes"][0]["located"], true);
    std::ifstream csv(dir / b["file"].get<std::string>());
    std::string header, first;
    std::getline(csv, header);
    std::getline(csv, first);
    EXPECT_NE(header.find(",t6,"), std::string::npos) << header;  // the doubled layout's columns
    EXPECT_EQ(first.rfind("0,1.28280932380", 0), 0u) << first;    // starts at the PD point, T = 2 x 2.0664101712
    EXPECT_NE(first.find(",4.1328203424"), std::string::npos) << first;
  }
  EXPECT_EQ(run_branches, 23);
  EXPECT_EQ(doubled, 2);
  // The family's fold: a multiplier crosses +1 there, and the point is reported once, as the turning point
  // in H (not also as a Floquet BP).
  int family_tp = 0, family_bp = 0;
  for (const nlohmann::json& sp : summary["special_points"]) {
    if (!sp["H"].is_number() || std::abs(sp["H"].get<double>() - 1.282699642918) > 1e-9) continue;
    family_tp += sp["type"] == "TP";
    family_bp += sp["type"] == "BP";
  }
  EXPECT_EQ(family_tp, 2);
  EXPECT_EQ(family_bp, 0);
  EXPECT_NE(r.out.find("Period-doubled families"), std::string::npos);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace hybridcont::app
