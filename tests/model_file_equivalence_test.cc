// The paper's models written as model files (models/*.toml) are the built-in C++ models: the time-based
// shooting map r and its Jacobian dr agree at random points, interpreted and compiled.
#include <gtest/gtest.h>

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

void ExpectSameMap(const std::string& name, bool compile) {
  const HybridModel builtin = MakeBuiltinModel(name);
  ModelFileOptions options;
  options.compile = compile;
  options.cache_dir = std::filesystem::temp_directory_path() / "hybridcont-test-cache";
  const HybridModel file = LoadModelFile(ModelPath(name), options);
  ASSERT_EQ(ShootingLayout(file).unknown_names(), ShootingLayout(builtin).unknown_names());
  TimeBasedShooting a(builtin, IntegratorOptions{}), b(file, IntegratorOptions{});
  std::mt19937 rng(7);
  for (int trial = 0; trial < 10; ++trial) {
    const Vector u = RandomPoint(builtin, &rng, 0.2);
    Vector ra, rb;
    Matrix da, db;
    ASSERT_TRUE(a.Evaluate(u, &ra, &da).ok);
    ASSERT_TRUE(b.Evaluate(u, &rb, &db).ok) << name;
    const double scale = 1.0 + ra.lpNorm<Eigen::Infinity>();
    EXPECT_LE((ra - rb).lpNorm<Eigen::Infinity>(), 1e-12 * scale) << name << " trial " << trial;
    EXPECT_LE((da - db).lpNorm<Eigen::Infinity>(), 1e-12 * (1.0 + da.lpNorm<Eigen::Infinity>()))
        << name << " trial " << trial;
  }
}

TEST(ModelFileEquivalence, SlipInterpreted) { ExpectSameMap("slip", false); }
TEST(ModelFileEquivalence, SlipCompiled) { ExpectSameMap("slip", true); }

}  // namespace
}  // namespace hybridcont
