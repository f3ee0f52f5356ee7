// The paper's models written as model files (models/*.toml) are the built-in C++ models: the time-based
// shooting map r and its Jacobian dr agree at random points, interpreted and compiled, for every built-in
// model (the ball chain with the registry's 10 phases).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <random>

#include "hybridcont/model_file.h"
#include "hybridcont/models.h"
#include "hybridcont/timebased_shooting.h"

namespace hybridcont {
namespace {

std::filesystem::path ModelPath(const std::string& name) {
  return std::filesystem::path(HYBRIDCONT_SOURCE_DIR) / "models" / (name + ".toml");
}

// Random points near the start: durations, states and xi perturbed by up to `spread`, so that every
// segment integrates a non-trivial stretch and the unfolding term xi*dH is active.
Vector RandomPoint(const HybridModel& model, std::mt19937* rng, double spread) {
  const ShootingLayout layout(model);
  std::uniform_real_distribution<double> d(-spread, spread);
  Vector u = BuiltinStartPoint(model);
  for (int i = 0; i < u.size(); ++i) u(i) += d(*rng);
  for (int i = 0; i <= model.num_phases(); ++i) u(layout.time_index(i)) = std::abs(u(layout.time_index(i))) + 0.05;
  return u;
}

// The built-in model `name` against models/<file>.toml (by default the file of the same name).
void ExpectSameMap(const std::string& name, bool compile, const std::string& file_name = "") {
  const HybridModel builtin = MakeBuiltinModel(name);
  ModelFileOptions options;
  options.compile = compile;
  options.cache_dir = std::filesystem::temp_directory_path() / "hybridcont-test-cache";
  const HybridModel file = LoadModelFile(ModelPath(file_name.empty() ? name : file_name), options);
  ASSERT_EQ(ShootingLayout(file).unknown_names(), ShootingLayout(builtin).unknown_names());
  TimeBasedShooting a(builtin, IntegratorOptions{}), b(file, IntegratorOptions{});
  std::mt19937 rng(7);
  double max_r = 0, max_dr = 0;
  for (int trial = 0; trial < 10; ++trial) {
    const Vector u = RandomPoint(builtin, &rng, 0.2);
    Vector ra, rb;
    Matrix da, db;
    ASSERT_TRUE(a.Evaluate(u, &ra, &da).ok);
    ASSERT_TRUE(b.Evaluate(u, &rb, &db).ok) << name;
    const double scale = 1.0 + ra.lpNorm<Eigen::Infinity>();
    const double dr_scale = 1.0 + da.lpNorm<Eigen::Infinity>();
    EXPECT_LE((ra - rb).lpNorm<Eigen::Infinity>(), 1e-12 * scale) << name << " trial " << trial;
    EXPECT_LE((da - db).lpNorm<Eigen::Infinity>(), 1e-12 * dr_scale) << name << " trial " << trial;
    max_r = std::max(max_r, (ra - rb).lpNorm<Eigen::Infinity>() / scale);
    max_dr = std::max(max_dr, (da - db).lpNorm<Eigen::Infinity>() / dr_scale);
  }
  std::printf("%s%s (%s): max |r_file - r_builtin| / (1 + |r|) = %.2g, max |dr_file - dr_builtin| / (1 + |dr|) = %.2g\n",
              name.c_str(), file_name.empty() ? "" : (" from " + file_name).c_str(), compile ? "compiled" : "interpreted",
              max_r, max_dr);
}

// The same declarations: phase and state names in order, typical states, parameters (defaults and
// ranges; a file lists them in any order), symmetries.
void ExpectSameDeclarations(const std::string& name) {
  const HybridModel builtin = MakeBuiltinModel(name);
  ModelFileOptions options;
  options.compile = false;
  const HybridModel file = LoadModelFile(ModelPath(name), options);
  EXPECT_EQ(file.name(), builtin.name());
  ASSERT_EQ(file.num_phases(), builtin.num_phases()) << name;
  for (int i = 0; i < builtin.num_phases(); ++i) {
    EXPECT_EQ(file.phase(i).name(), builtin.phase(i).name()) << name;
    EXPECT_EQ(file.phase(i).state_names(), builtin.phase(i).state_names()) << name << " phase " << i;
    EXPECT_EQ(file.phase(i).typical_state(), builtin.phase(i).typical_state()) << name << " phase " << i;
  }
  ASSERT_EQ(file.parameters().size(), builtin.parameters().size()) << name;
  for (const ParameterInfo& p : builtin.parameters()) {
    const auto& q = file.parameters();
    const auto it = std::find_if(q.begin(), q.end(), [&](const ParameterInfo& x) { return x.name == p.name; });
    ASSERT_NE(it, q.end()) << name << ": no parameter " << p.name;
    EXPECT_EQ(it->default_value, p.default_value) << name << "." << p.name;
    EXPECT_EQ(it->range.ToString(), p.range.ToString()) << name << "." << p.name;
  }
  ASSERT_EQ(file.symmetries().size(), builtin.symmetries().size()) << name;
  for (size_t k = 0; k < builtin.symmetries().size(); ++k) {
    const ModelSymmetry& a = builtin.symmetries()[k];
    const ModelSymmetry& b = file.symmetries()[k];
    EXPECT_EQ(b.name, a.name) << name;
    EXPECT_EQ(b.reverses_time, a.reverses_time) << name << " " << a.name;
    ASSERT_EQ(b.state_signs.size(), a.state_signs.size()) << name << " " << a.name;
    for (size_t i = 0; i < a.state_signs.size(); ++i) EXPECT_EQ(b.state_signs[i], a.state_signs[i]) << name << " " << a.name;
  }
}

TEST(ModelFileEquivalence, Declarations) {
  for (const std::string& name : BuiltinModelNames()) ExpectSameDeclarations(name);
}

TEST(ModelFileEquivalence, SlipInterpreted) { ExpectSameMap("slip", false); }
TEST(ModelFileEquivalence, SlipCompiled) { ExpectSameMap("slip", true); }
TEST(ModelFileEquivalence, BouncingBallInterpreted) { ExpectSameMap("bouncing-ball", false); }
TEST(ModelFileEquivalence, BouncingBallCompiled) { ExpectSameMap("bouncing-ball", true); }
TEST(ModelFileEquivalence, RockingBlockInterpreted) { ExpectSameMap("rocking-block", false); }
TEST(ModelFileEquivalence, RockingBlockCompiled) { ExpectSameMap("rocking-block", true); }
TEST(ModelFileEquivalence, BouncingRodInterpreted) { ExpectSameMap("bouncing-rod", false); }
TEST(ModelFileEquivalence, BouncingRodCompiled) { ExpectSameMap("bouncing-rod", true); }
TEST(ModelFileEquivalence, BallChainInterpreted) { ExpectSameMap("ball-chain", false); }
TEST(ModelFileEquivalence, BallChainCompiled) { ExpectSameMap("ball-chain", true); }

// Models written from their mechanics (mechanics.h): the rod from T, V and the elastic impact law at its
// two corners, the SLIP's stance from T and V in (alpha, l), its flight a Lagrangian point mass beside the
// explicit swing-leg equation.
TEST(ModelFileEquivalence, LagrangianRodInterpreted) { ExpectSameMap("bouncing-rod", false, "bouncing-rod-lagrangian"); }
TEST(ModelFileEquivalence, LagrangianRodCompiled) { ExpectSameMap("bouncing-rod", true, "bouncing-rod-lagrangian"); }
TEST(ModelFileEquivalence, LagrangianSlipInterpreted) { ExpectSameMap("slip", false, "slip-lagrangian"); }
TEST(ModelFileEquivalence, LagrangianSlipCompiled) { ExpectSameMap("slip", true, "slip-lagrangian"); }

// Second derivatives: the interpreter runs a phase's fixed-size Hessian jets over nested bounded-dynamic jets
// (expression_model.h, InterpretAsBoundedDynamic); its ∇²H and the unfolded field's A = df + Σ ξ_j ∇²H_j are
// the built-in model's (its own HessianJets) to rounding, at random states near each phase's typical one.
TEST(ModelFileEquivalence, InterpretedSecondDerivativesAreTheBuiltins) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> d(-0.2, 0.2);
  for (const std::string& name : {std::string("slip"), std::string("bouncing-rod"), std::string("rocking-block")}) {
    const HybridModel builtin = MakeBuiltinModel(name);
    ModelFileOptions options;
    options.compile = false;
    const HybridModel file = LoadModelFile(ModelPath(name), options);
    for (int i = 0; i < builtin.num_phases(); ++i) {
      const Phase& a = builtin.phase(i);
      const Phase& b = file.phase(i);
      for (int trial = 0; trial < 5; ++trial) {
        Vector x = a.typical_state();
        for (int j = 0; j < x.size(); ++j) x(j) += d(rng);
        Vector Ha, Hb;
        Matrix dHa, dHb;
        std::vector<Matrix> d2Ha, d2Hb;
        a.FirstIntegrals(x, &Ha, &dHa, &d2Ha);
        b.FirstIntegrals(x, &Hb, &dHb, &d2Hb);
        ASSERT_EQ(d2Ha.size(), d2Hb.size()) << name;
        EXPECT_LE((dHa - dHb).lpNorm<Eigen::Infinity>(), 1e-13 * (1 + dHa.lpNorm<Eigen::Infinity>())) << name;
        for (std::size_t k = 0; k < d2Ha.size(); ++k) {
          EXPECT_LE((d2Ha[k] - d2Hb[k]).lpNorm<Eigen::Infinity>(), 1e-13 * (1 + d2Ha[k].lpNorm<Eigen::Infinity>()))
              << name << " phase " << i << "\n" << d2Ha[k] << "\n" << d2Hb[k];
        }
        const Vector xi = Vector::Constant(static_cast<int>(Ha.size()), 0.3);
        Vector fa, fb;
        Matrix Aa, Ab, Ba, Bb;
        a.UnfoldedVectorField(x, xi, &fa, &Aa, &Ba, /*include_hessian_term=*/true);
        b.UnfoldedVectorField(x, xi, &fb, &Ab, &Bb, /*include_hessian_term=*/true);
        EXPECT_LE((fa - fb).lpNorm<Eigen::Infinity>(), 1e-13 * (1 + fa.lpNorm<Eigen::Infinity>())) << name;
        EXPECT_LE((Aa - Ab).lpNorm<Eigen::Infinity>(), 1e-13 * (1 + Aa.lpNorm<Eigen::Infinity>())) << name;
        EXPECT_LE((Ba - Bb).lpNorm<Eigen::Infinity>(), 1e-13 * (1 + Ba.lpNorm<Eigen::Infinity>())) << name;
      }
    }
  }
}

}  // namespace
}  // namespace hybridcont
