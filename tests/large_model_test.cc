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
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "cli_runner.h"
#include "csv_columns.h"
#include "hybridcont/derivative_check.h"
#include "hybridcont/model_file.h"
#include "hybridcont/shooting_layout.h"
#include "hybridcont/timebased_shooting.h"
#include "mass_chain_text.h"

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

// Generated code for a phase above the fixed-capacity jets (ScalarKind::kValueJacobian, jets of the phase's
// exact dimension): r and dr of the time-based map, also in a free parameter, equal the interpreter's to
// rounding (the same operations over other storage), and the compiled model's derivatives agree with
// differences, at 24 states and at 48 (a chain of 24 masses written out here).
TEST(LargeModel, CompiledPhasesEqualTheInterpretedOnes) {
  const fs::path cache = fs::temp_directory_path() / "hybridcont_large_model_cache";
  for (const int masses : {12, 24}) {
    fs::path file = kFile;
    if (masses != kMasses) {
      // The shipped file's chain lengthened.
      file = fs::temp_directory_path() / "hybridcont-mass-chain-48.toml";
      std::ofstream(file) << test_models::MassChainText(masses);
    }
    std::ostringstream log;
    ModelFileOptions compiled_options, interpreted_options;
    compiled_options.cache_dir = cache;
    compiled_options.log = &log;
    interpreted_options.compile = false;
    const HybridModel compiled = LoadModelFile(file, compiled_options);
    const HybridModel interpreted = LoadModelFile(file, interpreted_options);
    ASSERT_EQ(log.str().find("runs interpreted"), std::string::npos) << log.str();
    ASSERT_EQ(compiled.phase(0).dim(), 2 * masses);
    for (const bool free : {false, true}) {
      const FreeParameters parameters = free ? FreeParameters{{"k"}, {{"H", 0.01}}, {}} : FreeParameters{};
      TimeBasedShooting a(compiled, IntegratorOptions{}, parameters), b(interpreted, IntegratorOptions{}, parameters);
      const ShootingLayout& layout = a.layout();
      Vector u = Vector::Zero(layout.num_unknowns());
      for (int s = 0; s < layout.num_segments(); ++s) {
        u(layout.time_index(s)) = 0.8;
        for (int j = 0; j < layout.dim(s); ++j) u(layout.state_offset(s) + j) = 0.05 * std::sin(1.0 + j + 3 * s);
      }
      u(layout.H_index()) = 0.01;
      u(layout.xi_index()) = 1e-3;  // the ξ·∇²H term in the sensitivities
      if (free) u(layout.parameter_index(0)) = 1.1;
      Vector ra, rb;
      Matrix da, db;
      ASSERT_TRUE(a.Evaluate(u, &ra, &da).ok);
      ASSERT_TRUE(b.Evaluate(u, &rb, &db).ok);
      EXPECT_LE((ra - rb).norm(), 1e-14 * (1 + rb.norm())) << masses;
      EXPECT_LE((da - db).norm(), 1e-14 * (1 + db.norm())) << masses << " free " << free;
    }
    DerivativeCheckOptions check;
    check.num_points = 1;
    const DerivativeCheckReport report = CheckDerivatives(compiled, check);
    EXPECT_TRUE(report.passed()) << report.Table();
  }
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
