// `hybridcont run MODEL --free P --fix H=c` (families in a model parameter at fixed H̄) and `--curves P`
// (two-parameter curves of special points), against closed forms of the SLIP.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli_runner.h"
#include "csv_columns.h"
#include "hybridcont/models.h"
#include "hybridcont/timebased_shooting.h"
#include "known_orbits.h"

namespace hybridcont::app {
namespace {

namespace fs = std::filesystem;

nlohmann::json ReadSummary(const fs::path& dir) {
  std::ifstream f(dir / "summary.json");
  return nlohmann::json::parse(f);
}

// |r| of the built-in SLIP's map with `parameter` at `value` (default: the stiffness k) at the orbit of a
// results file's row (infinite if it does not evaluate): an independent check of a model file's or a
// free-parameter run's points.
double BuiltinSlipResidual(const std::map<std::string, std::vector<double>>& columns, std::size_t row, double value,
                           const std::string& parameter = "k") {
  HybridModel at_k = MakeBuiltinModel("slip");
  at_k.SetParameter(parameter, value);
  TimeBasedShooting map(at_k, IntegratorOptions{});
  const ShootingLayout& layout = map.layout();
  Vector u(layout.num_unknowns()), res;
  for (int j = 0; j < layout.num_unknowns(); ++j) u(j) = columns.at(layout.unknown_names()[j])[row];
  return map.Evaluate(u, &res, nullptr).ok ? res.norm() : std::numeric_limits<double>::infinity();
}

// Hopping in place at H̄ = 1.5 continued in k over [15, 100]: the branches whose orbits all have zero
// forward speed are hopping in place, and every point equals the closed form at its k.
TEST(CliParameters, SlipHoppingInPlaceInStiffnessMatchesTheClosedForm) {
  const fs::path dir = fs::temp_directory_path() / "hybridcont_cli_free_k";
  const CliResult r = RunTool({"run", "slip", "--free", "k", "--fix", "H=1.5", "--bound", "k=15:100", "--out",
                               dir.string(), "--quiet", "--no-plots", "--threads", "1", "--overwrite"});
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json summary = ReadSummary(dir);
  EXPECT_EQ(summary["status"], "complete");
  EXPECT_EQ(summary["options"]["free"], nlohmann::json::array({"k"}));
  EXPECT_EQ(summary["options"]["fixed"]["H"], 1.5);
  EXPECT_TRUE(summary.contains("version"));
  const HybridModel slip = MakeBuiltinModel("slip");
  const ShootingLayout layout(slip);
  const std::vector<std::string> names = layout.unknown_names();
  int hopping_points = 0;
  double worst = 0, k_min = 1e300, k_max = -1e300;
  for (const nlohmann::json& b : summary["branches"]) {
    const auto columns = ReadColumns(dir / b["file"].get<std::string>());
    ASSERT_TRUE(columns.count("k")) << b["file"];
    const std::vector<double>& dx = columns.at("x2_dx");
    const bool hopping = std::all_of(dx.begin(), dx.end(), [](double v) { return std::abs(v) < 1e-10; });
    if (!hopping) continue;
    for (std::size_t row = 0; row < dx.size(); ++row) {
      const double k = columns.at("k")[row];
      HybridModel at_k = MakeBuiltinModel("slip");
      at_k.SetParameter("k", k);
      const Vector exact = SlipHoppingInPlace(at_k, layout, 1.5);
      for (int j = 0; j < layout.num_unknowns(); ++j) {
        worst = std::max(worst, std::abs(columns.at(names[j])[row] - exact(j)));
      }
      EXPECT_EQ(columns.at("H")[row], 1.5);
      k_min = std::min(k_min, k), k_max = std::max(k_max, k);
      ++hopping_points;
    }
  }
  EXPECT_GE(hopping_points, 20);
  EXPECT_LT(worst, 1e-8);
  EXPECT_NEAR(k_min, 15.0, 1e-9);
  EXPECT_NEAR(k_max, 100.0, 1e-9);
  RecordProperty("hopping_points", hopping_points);
  char text[32];
  std::snprintf(text, sizeof text, "%.3g", worst);
  RecordProperty("worst_deviation_from_closed_form", text);
  // Running branches off hopping in place at an SB point, reported with its k.
  bool sb = false;
  for (const nlohmann::json& sp : summary["special_points"]) {
    if (sp["type"] == "SB") sb = sp.contains("k") && sp["H"] == 1.5;
  }
  EXPECT_TRUE(sb);
}

// Forward hopping at a fixed flight speed (the state component x2_dx = 0.8) continued in k: every point
// holds the speed exactly while k and H̄ vary, and is an orbit of the SLIP at its k (the base map's residual
// there).
TEST(CliParameters, SlipAtFixedFlightSpeedInStiffness) {
  const fs::path dir = fs::temp_directory_path() / "hybridcont_cli_fix_speed";
  const CliResult r = RunTool({"run", "slip", "--free", "k", "--fix", "x2_dx=0.8", "--bound", "k=15:100", "--out",
                               dir.string(), "--quiet", "--no-plots", "--threads", "1", "--overwrite"});
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json summary = ReadSummary(dir);
  EXPECT_EQ(summary["options"]["fixed"]["x2_dx"], 0.8);
  int points = 0;
  double worst_speed = 0, worst_residual = 0, k_min = 1e300, k_max = -1e300, H_min = 1e300, H_max = -1e300;
  for (const nlohmann::json& b : summary["branches"]) {
    const auto columns = ReadColumns(dir / b["file"].get<std::string>());
    for (std::size_t row = 0; row < columns.at("k").size(); ++row) {
      const double k = columns.at("k")[row], H = columns.at("H")[row];
      worst_speed = std::max(worst_speed, std::abs(columns.at("x2_dx")[row] - 0.8));
      worst_residual = std::max(worst_residual, BuiltinSlipResidual(columns, row, k));
      k_min = std::min(k_min, k), k_max = std::max(k_max, k), H_min = std::min(H_min, H), H_max = std::max(H_max, H);
      ++points;
    }
  }
  EXPECT_GE(points, 20);
  EXPECT_LT(worst_speed, 1e-12);
  EXPECT_LT(worst_residual, 1e-9);
  EXPECT_GT(k_max - k_min, 10.0);
  EXPECT_GT(H_max - H_min, 0.01);
  std::printf("SLIP at flight speed 0.8: %d points, k in [%.3f, %.3f], H in [%.4f, %.4f]; speed off by %.1e, "
              "residual %.1e\n", points, k_min, k_max, H_min, H_max, worst_speed, worst_residual);
}

// The SLIP's first SB point (H̄ = 1 + π²/40 at w2 = 5) continued in (w2, H̄) over [2, 10]: along the whole
// curve H̄ = 1 + π²/(8 w2), the leg's swing half-period fitting the flight, whatever k.
TEST(CliParameters, SlipFirstSbCurveInSwingFrequencyMatchesTheClosedForm) {
  const fs::path dir = fs::temp_directory_path() / "hybridcont_cli_curves_w2";
  const CliResult r = RunTool({"run", "slip", "--curves", "w2", "--bound", "w2=2:10", "--out", dir.string(), "--quiet",
                               "--threads", "1", "--overwrite", "--plots"});
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json summary = ReadSummary(dir);
  EXPECT_EQ(summary["options"]["curves"]["parameter"], "w2");
  int first = -1;
  for (const nlohmann::json& sp : summary["special_points"]) {
    if (sp["type"] == "SB" && std::abs(sp["H"].get<double>() - (1 + M_PI * M_PI / 40)) < 1e-9 && first < 0) first = sp["id"];
  }
  ASSERT_GE(first, 0);
  const nlohmann::json* curve = nullptr;
  for (const nlohmann::json& c : summary["curves"]) {
    if (c["special_point"] == first) curve = &c;
  }
  ASSERT_NE(curve, nullptr) << summary["curves"].dump();
  EXPECT_EQ((*curve)["type"], "branch-point");
  const auto columns = ReadColumns(dir / (*curve)["file"].get<std::string>());
  const std::vector<double>&w2 = columns.at("w2"), &H = columns.at("H");
  double worst = 0;
  for (std::size_t i = 0; i < w2.size(); ++i) worst = std::max(worst, std::abs(H[i] - (1 + M_PI * M_PI / (8 * w2[i]))));
  EXPECT_LT(worst, 1e-8);
  EXPECT_NEAR(*std::min_element(w2.begin(), w2.end()), 2.0, 1e-9);
  EXPECT_NEAR(*std::max_element(w2.begin(), w2.end()), 10.0, 1e-9);
  EXPECT_GE(w2.size(), 10u);
  char text[32];
  std::snprintf(text, sizeof text, "%.3g", worst);
  RecordProperty("worst_deviation_from_closed_form", text);
  RecordProperty("points", static_cast<int>(w2.size()));
  EXPECT_TRUE(fs::exists(dir / "curves.png") || !r.err.empty());  // drawn where Python and matplotlib exist
}

// The SLIP's mean forward speed from the unknowns of an orbit alone: the body moves by −l sin α relative to
// the foot in stance (lift-off at l = l0 with the flight's α, touch-down state x̄_3, the nadir terms cancel)
// and by dx·t2 in flight; independent of the tool's quadrature.
double SlipSpeedFromUnknowns(const std::map<std::string, std::vector<double>>& c, std::size_t row) {
  const double stride = -std::sin(c.at("x2_alpha")[row]) + c.at("x3_l")[row] * std::sin(c.at("x3_alpha")[row]) +
                        c.at("x2_dx")[row] * c.at("t2")[row];
  return stride / c.at("T")[row];
}

// models/slip.toml's observable `speed` (mean forward speed) as a target: every branch that reaches it ends
// on it, and the speed computed from that orbit's unknowns agrees; `--monitor apex=1.2,1.1` locates UZ points
// at both values.
TEST(CliParameters, SlipModelFileRunsUntilAMeanSpeed) {
  const fs::path dir = fs::temp_directory_path() / "hybridcont_cli_until_speed";
  const std::string file = std::string(HYBRIDCONT_SOURCE_DIR) + "/models/slip.toml";
  const CliResult r = RunTool({"run", file, "--until", "speed=0.5", "--monitor", "apex=1.2,1.1", "--out", dir.string(),
                               "--quiet", "--no-plots", "--threads", "1", "--overwrite"});
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json summary = ReadSummary(dir);
  int reached = 0;
  double worst_target = 0, worst_independent = 0;
  for (const nlohmann::json& b : summary["branches"]) {
    const auto columns = ReadColumns(dir / b["file"].get<std::string>());
    ASSERT_TRUE(columns.count("speed") && columns.count("apex") && columns.count("stride")) << b["file"];
    if (b["termination"] != "target-reached") continue;
    const std::size_t last = columns.at("speed").size() - 1;
    worst_target = std::max(worst_target, std::abs(columns.at("speed")[last] - 0.5));
    worst_independent = std::max(worst_independent, std::abs(SlipSpeedFromUnknowns(columns, last) - 0.5));
    ++reached;
  }
  EXPECT_GE(reached, 2);  // forward hopping, and its mirror image traced too
  EXPECT_LT(worst_target, 1e-10);
  EXPECT_LT(worst_independent, 1e-9);
  int uz = 0, at_1_1 = 0;
  double worst_apex = 0;
  for (const nlohmann::json& sp : summary["special_points"]) {
    // Every special point lists the model's observables at it.
    EXPECT_TRUE(sp.contains("observables") && sp["observables"].contains("clearance")) << sp.dump();
    if (sp["type"] != "UZ") continue;
    const double apex = sp["observables"]["apex"].get<double>();
    const double target = std::abs(apex - 1.1) < std::abs(apex - 1.2) ? 1.1 : 1.2;
    at_1_1 += target == 1.1;
    ++uz;
    worst_apex = std::max({worst_apex, std::abs(apex - target), std::abs(sp["apex"].get<double>() - target)});
  }
  EXPECT_GE(uz - at_1_1, 1);
  EXPECT_GE(at_1_1, 1);
  EXPECT_LT(worst_apex, 1e-9);
  std::printf("until speed = 0.5: %d branches reached it, |speed - 0.5| <= %.1e (from the unknowns %.1e); %d UZ "
              "points at apex 1.2 and 1.1 (%.1e)\n", reached, worst_target, worst_independent, uz, worst_apex);
}

// A family held at a fixed mean forward speed while the leg stiffness varies: `--free k --fix speed=0.5`.
TEST(CliParameters, SlipModelFileAtFixedMeanSpeedInStiffness) {
  const fs::path dir = fs::temp_directory_path() / "hybridcont_cli_fix_mean_speed";
  const std::string file = std::string(HYBRIDCONT_SOURCE_DIR) + "/models/slip.toml";
  const CliResult r = RunTool({"run", file, "--free", "k", "--fix", "speed=0.5", "--bound", "k=15:100", "--out",
                               dir.string(), "--quiet", "--no-plots", "--threads", "1", "--overwrite"});
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json summary = ReadSummary(dir);
  int points = 0;
  double worst_speed = 0, worst_independent = 0, worst_residual = 0, k_min = 1e300, k_max = -1e300;
  for (const nlohmann::json& b : summary["branches"]) {
    const auto columns = ReadColumns(dir / b["file"].get<std::string>());
    for (std::size_t row = 0; row < columns.at("k").size(); ++row) {
      const double k = columns.at("k")[row];
      worst_speed = std::max(worst_speed, std::abs(columns.at("speed")[row] - 0.5));
      worst_independent = std::max(worst_independent, std::abs(SlipSpeedFromUnknowns(columns, row) - 0.5));
      worst_residual = std::max(worst_residual, BuiltinSlipResidual(columns, row, k));
      k_min = std::min(k_min, k), k_max = std::max(k_max, k);
      ++points;
    }
  }
  EXPECT_GE(points, 20);
  EXPECT_LT(worst_speed, 1e-12);
  EXPECT_LT(worst_independent, 1e-9);
  EXPECT_LT(worst_residual, 1e-9);
  EXPECT_GT(k_max - k_min, 10.0);
  std::printf("SLIP at mean speed 0.5: %d points, k in [%.3f, %.3f]; speed off by %.1e (from the unknowns %.1e), "
              "residual %.1e\n", points, k_min, k_max, worst_speed, worst_independent, worst_residual);
}

// The boundaries of the SLIP's physical hopping in (w2, H̄) at w2 around 25 (`--curves w2`): where the swing
// foot's dip in flight touches the ground (clearance = 0) and where the foot lands moving tangentially
// (touchdown = 0). Every curve point is an orbit of the built-in SLIP at its w2, and the closed-form flight
// (ballistic body, harmonic leg) has its lowest foot height 0, resp. a zero foot speed at touch-down.
TEST(CliParameters, SlipBoundariesOfPhysicalHoppingInSwingFrequency) {
  const fs::path dir = fs::temp_directory_path() / "hybridcont_cli_boundaries_w2";
  const std::string file = std::string(HYBRIDCONT_SOURCE_DIR) + "/models/slip.toml";
  const CliResult r = RunTool({"run", file, "--set", "w2=25", "--curves", "w2", "--bound", "w2=20:30", "--out",
                               dir.string(), "--quiet", "--no-plots", "--threads", "1", "--overwrite"});
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json summary = ReadSummary(dir);
  std::map<std::string, int> found;
  double worst_clearance = 0, worst_touchdown = 0, worst_residual = 0, w2_min = 1e300, w2_max = -1e300;
  for (const nlohmann::json& c : summary["curves"]) {
    if (c["type"] != "boundary") continue;
    const std::string name = c["name"];
    const auto columns = ReadColumns(dir / c["file"].get<std::string>());
    for (std::size_t row = 0; row < columns.at("H").size(); ++row) {
      const double w2 = columns.at("w2")[row], w = std::sqrt(w2), t2 = columns.at("t2")[row];
      const double y0 = columns.at("x2_y")[row], dy0 = columns.at("x2_dy")[row];
      const double a0 = columns.at("x2_alpha")[row], da0 = columns.at("x2_dalpha")[row];
      const auto alpha = [&](double t) { return a0 * std::cos(w * t) + da0 / w * std::sin(w * t); };
      const auto height = [&](double t) { return y0 + dy0 * t - 0.5 * t * t - std::cos(alpha(t)); };
      if (name == "clearance = 0") {
        // The lowest interior foot height: dense samples, then golden-section search around the lowest.
        const int n = 4000;
        int best = 1;
        for (int i = 1; i < n; ++i) best = height(t2 * i / n) < height(t2 * best / n) ? i : best;
        double a = t2 * (best - 1) / n, b = t2 * (best + 1) / n;
        for (int it = 0; it < 200; ++it) {
          const double c1 = b - 0.618033988749895 * (b - a), c2 = a + 0.618033988749895 * (b - a);
          (height(c1) < height(c2) ? b : a) = height(c1) < height(c2) ? c2 : c1;
        }
        worst_clearance = std::max(worst_clearance, std::abs(height(0.5 * (a + b))));
      } else if (name == "touchdown = 0") {
        const double da = -a0 * w * std::sin(w * t2) + da0 * std::cos(w * t2);
        worst_touchdown = std::max(worst_touchdown, std::abs((dy0 - t2) + std::sin(alpha(t2)) * da));
      }
      worst_residual = std::max(worst_residual, BuiltinSlipResidual(columns, row, w2, "w2"));
      w2_min = std::min(w2_min, w2), w2_max = std::max(w2_max, w2);
      ++found[name];
    }
  }
  EXPECT_GE(found["clearance = 0"], 5);
  EXPECT_GE(found["touchdown = 0"], 5);
  EXPECT_LT(worst_clearance, 1e-8);
  EXPECT_LT(worst_touchdown, 1e-8);
  EXPECT_LT(worst_residual, 1e-9);
  EXPECT_NEAR(w2_min, 20.0, 1e-9);
  EXPECT_NEAR(w2_max, 30.0, 1e-9);
  std::printf("boundaries in w2: %d points on clearance = 0 (closed-form minimum %.1e), %d on touchdown = 0 "
              "(closed-form foot speed %.1e), residual %.1e\n", found["clearance = 0"], worst_clearance,
              found["touchdown = 0"], worst_touchdown, worst_residual);
}

}  // namespace
}  // namespace hybridcont::app
