// A model larger than the fixed-capacity jets (models/mass-chain.toml: 24 states in one phase), on the
// dynamic-size path of expression models: its derivatives against differences, and a run end to end whose
// orbits are checked against the exact flow of the linear chain (a matrix exponential) and against the
// chain's scaling symmetry (piecewise linear with the stop at rest: the period is constant on a family).
#include <gtest/gtest.h>

#include <unsupported/Eigen/MatrixFunctions>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "cli_runner.h"
#include "csv_columns.h"
#include "hybridcont/derivative_check.h"
#include "hybridcont/model_file.h"
#include "hybridcont/shooting_layout.h"

namespace hybridcont {
namespace {

namespace fs = std::filesystem;

const std::string kFile = std::string(HYBRIDCONT_SOURCE_DIR) + "/models/mass-chain.toml";
constexpr int kMasses = 12;

HybridModel Chain() {
  ModelFileOptions options;
  options.compile = false;
  return LoadModelFile(kFile, options);
}

TEST(LargeModel, DerivativesOfTheDynamicPathAgreeWithDifferences) {
  const HybridModel chain = Chain();
  ASSERT_EQ(chain.phase(0).dim(), 2 * kMasses);
  DerivativeCheckOptions options;
  options.num_points = 2;
  const DerivativeCheckReport report = CheckDerivatives(chain, options);
  EXPECT_TRUE(report.passed()) << report.Table();
  std::printf("%s", report.Table().c_str());
}

// The free phase is linear, x' = A x: its flow is exp(A t).
Matrix ChainMatrix() {
  Matrix A = Matrix::Zero(2 * kMasses, 2 * kMasses);
  for (int i = 0; i < kMasses; ++i) {
    A(i, kMasses + i) = 1.0;
    A(kMasses + i, i) = i < kMasses - 1 ? -2.0 : -1.0;
    if (i > 0) A(kMasses + i, i - 1) = 1.0;
    if (i < kMasses - 1) A(kMasses + i, i + 1) = 1.0;
  }
  return A;
}

TEST(LargeModel, RunsEndToEndAndItsOrbitsAreThoseOfTheLinearChain) {
  const fs::path dir = fs::temp_directory_path() / "hybridcont_mass_chain";
  const app::CliResult r = app::RunTool({"run", kFile, "--out", dir.string(), "--quiet", "--no-plots", "--threads", "1",
                                         "--overwrite"});
  ASSERT_EQ(r.code, 0) << r.err;
  std::ifstream f(dir / "summary.json");
  const nlohmann::json summary = nlohmann::json::parse(f);
  const HybridModel chain = Chain();
  const ShootingLayout layout(chain);
  const Matrix A = ChainMatrix();
  int physical = 0, families = 0;
  double worst_flow = 0, worst_period = 0;
  for (const nlohmann::json& b : summary["branches"]) {
    // Every row has the header's number of cells (a multiplier list of 22 entries, a two-kind stability).
    std::ifstream rows(dir / b["file"].get<std::string>());
    std::string header, line;
    std::getline(rows, header);
    while (std::getline(rows, line)) {
      ASSERT_EQ(std::count(line.begin(), line.end(), ','), std::count(header.begin(), header.end(), ',')) << line;
    }
    const auto c = ReadColumns(dir / b["file"].get<std::string>());
    double period = std::nan("");
    bool family = false;
    for (std::size_t row = 0; row < c.at("H").size(); ++row) {
      if (c.at("physical")[row] != 1.0) continue;
      ++physical;
      family = true;
      // Segment 1 from x̄_1 over t1 to the stop, the impact, segment 2 over t2 back to x̄_1.
      Vector x1(2 * kMasses), x2(2 * kMasses);
      for (int j = 0; j < 2 * kMasses; ++j) {
        x1(j) = c.at(layout.unknown_names()[layout.state_offset(0) + j])[row];
        x2(j) = c.at(layout.unknown_names()[layout.state_offset(1) + j])[row];
      }
      Vector end1 = (A * c.at("t1")[row]).exp() * x1;
      end1(2 * kMasses - 1) = -end1(2 * kMasses - 1);  // elastic impact of the last mass
      const Vector end2 = (A * c.at("t2")[row]).exp() * x2;
      const double scale = std::max(1.0, x1.norm());
      worst_flow = std::max({worst_flow, (end1 - x2).norm() / scale, (end2 - x1).norm() / scale});
      if (std::isnan(period)) period = c.at("T")[row];
      worst_period = std::max(worst_period, std::abs(c.at("T")[row] - period));
    }
    families += family;
  }
  EXPECT_GE(physical, 10);
  EXPECT_GE(families, 1);
  EXPECT_LT(worst_flow, 1e-8);
  EXPECT_LT(worst_period, 1e-8);
  std::printf("mass chain (24 states): %zu half-branches, %d physical points on %d of them; orbits vs exp(At) %.1e, "
              "period constant to %.1e\n", summary["branches"].size(), physical, families, worst_flow, worst_period);
}

}  // namespace
}  // namespace hybridcont
