// The paper's models written as model files (models/*.toml) give the built-in models' bifurcation
// diagrams: the full default exploration of each (`hybridcont run MODEL` without the Floquet pass), once
// from the file and once from the built-in, has the same branches and the same special points at the same
// energies, and every point of it gets the same family name and quantities. model_file_equivalence_test.cc
// checks the maps point by point; this checks that the files' run set-ups (start, bounds, scales, steps)
// and presentations (title, quantities, figures, drawing) are the built-ins' too.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <random>
#include <string>
#include <tuple>
#include <vector>

#include "hybridcont/exploration.h"
#include "hybridcont/model_file.h"
#include "hybridcont/models.h"
#include "hybridcont/setup_evaluation.h"
#include "hybridcont/shooting_layout.h"
#include "study/engine/model_exploration.h"
#include "study_fixture.h"
#include "study/engine/scenario.h"

namespace hybridcont {
namespace {

// Agreement of a special point's energy that the maps' rounding cannot explain. The file's map computes
// the built-in's operations in another order, so r differs by rounding (~1e-16); a point located to its
// bracket moves by far less than this.
constexpr double kSameH = 1e-9;

struct Run {
  BifurcationDiagram diagram;
  int H = -1;
  double seconds = 0;
};

Run Explore(const HybridModel& model) {
  Run run;
  const auto start = std::chrono::steady_clock::now();
  run.diagram = *StudyOf(model).diagram;
  run.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  run.H = ShootingLayout(model).H_index();
  return run;
}

// How well a special point's H is known: the width of its interval in H (model units).
double PrecisionH(const SpecialPoint& p, int H) {
  return p.interval_width.size() > H ? std::abs(p.interval_width(H)) : 0.0;
}

HybridModel LoadFile(const std::string& name) {
  ModelFileOptions options;
  options.cache_dir = std::filesystem::temp_directory_path() / "hybridcont-test-cache";  // compiled, cached
  return LoadModelFile(std::filesystem::path(HYBRIDCONT_SOURCE_DIR) / "models" / (name + ".toml"), options);
}

// The built-in model `name` against models/<file>.toml (by default the file of the same name).
void ExpectSameDiagram(const std::string& name, const std::string& file_name = "") {
  const HybridModel builtin = MakeBuiltinModel(name);
  const HybridModel file = LoadFile(file_name.empty() ? name : file_name);
  const Run a = Explore(builtin);
  const Run b = Explore(file);
  const BifurcationDiagram& da = a.diagram;
  const BifurcationDiagram& db = b.diagram;
  EXPECT_EQ(da.status, db.status) << name;
  ASSERT_EQ(da.branches.size(), db.branches.size()) << name << "\nbuilt-in:\n"
                                                    << da.FullReport() << "\nfile:\n"
                                                    << db.FullReport();
  // The file may declare observables and constraints the built-in has not: their UZ and CB points are the
  // file's own, and every other point must have its twin.
  const auto counted = [](const BifurcationDiagram& d) {
    return std::count_if(d.special_points.begin(), d.special_points.end(), [](const SpecialPoint& p) {
      return p.type != SpecialPointType::kConstraintBoundary && p.type != SpecialPointType::kObservableValue;
    });
  };
  ASSERT_EQ(counted(da), counted(db)) << name << "\nbuilt-in:\n"
                                                                << da.FullReport() << "\nfile:\n"
                                                                << db.FullReport();
  // Special points are matched by type and branch, not by position in the list: two points at one place
  // (the SLIP's loop turns in H exactly at the SB point where it meets hopping in place again) are listed
  // in the order their located positions happen to have, which rounding decides.
  std::vector<int> match(da.special_points.size(), -1);  // built-in id -> file id
  std::vector<bool> taken(db.special_points.size(), false);
  double max_dH = 0, max_dH_noise = 0;
  int noise_limited = 0;
  for (size_t i = 0; i < da.special_points.size(); ++i) {
    const SpecialPoint& p = da.special_points[i];
    int best = -1;
    for (size_t j = 0; j < db.special_points.size(); ++j) {
      const SpecialPoint& q = db.special_points[j];
      if (taken[j] || q.type != p.type || q.branch_id != p.branch_id) continue;
      if (best < 0 || std::abs(q.u(b.H) - p.u(a.H)) < std::abs(db.special_points[best].u(b.H) - p.u(a.H))) {
        best = static_cast<int>(j);
      }
    }
    if (best < 0) {
      ADD_FAILURE() << name << ": no special point of the file's diagram matches the built-in's " << p.BriefReport();
      continue;
    }
    taken[best] = true;
    match[i] = best;
    const SpecialPoint& q = db.special_points[best];
    const double dH = std::abs(p.u(a.H) - q.u(b.H));
    const double pa = PrecisionH(p, a.H), pb = PrecisionH(q, b.H);
    // A point located only to the noise level (a nearly tangent crossing, an SB point where dr mixes two
    // branch directions, a turning point that takes such an SB point's interval) states a precision in H
    // above 1e-9: anywhere in its interval is as good a root as any other, and where the root finder
    // stops depends on the last bits of r, which the two maps compute in different orders. Two intervals
    // that both hold the exact point lie at most the sum of their widths apart, so that is all the two
    // runs can be asked to agree to. Every other point must agree to 1e-9.
    if (std::max(pa, pb) > kSameH) {
      ++noise_limited;
      max_dH_noise = std::max(max_dH_noise, dH);
      EXPECT_LE(dH, pa + pb) << name << ": " << p.BriefReport() << " / " << q.BriefReport();
    } else {
      max_dH = std::max(max_dH, dH);
      EXPECT_LE(dH, kSameH) << name << ": " << p.BriefReport() << " / " << q.BriefReport();
    }
  }
  // Each half-branch leaves the same special point and ends for the same reason.
  for (size_t i = 0; i < da.branches.size(); ++i) {
    const Branch& x = da.branches[i];
    const Branch& y = db.branches[i];
    EXPECT_EQ(x.termination, y.termination) << name << " branch " << i;
    EXPECT_EQ(x.parent_special_point < 0 ? -1 : match[x.parent_special_point], y.parent_special_point)
        << name << " branch " << i;
  }
  // Every point of the diagram is named and measured alike (families, quantities).
  const OrbitPresentation pa(builtin), pb(file);
  EXPECT_EQ(pb.quantity_names(), pa.quantity_names()) << name;
  for (const Branch& branch : da.branches) {
    for (const ContinuationPoint& point : branch.points) {
      EXPECT_EQ(pb.Family(point.u), pa.Family(point.u)) << name << " branch " << branch.id;
      EXPECT_EQ(pb.Quantities(point.u), pa.Quantities(point.u)) << name << " branch " << branch.id;
    }
  }
  std::printf("%s: %zu branches, %zu special points (%d noise-limited); max |dH| %.2g (noise-limited %.2g); "
              "built-in %.2f s, file %.2f s\n",
              name.c_str(), da.branches.size(), da.special_points.size(), noise_limited, max_dH, max_dH_noise,
              a.seconds, b.seconds);
}

// The run set-up (what DefaultScenario makes of it) and the presentation are the built-in's: start,
// start conditions, bounds, scales, steps, limits, key frames, title, quantities, figures and drawing.
void ExpectSameSetUp(const std::string& name) {
  const HybridModel builtin = MakeBuiltinModel(name);
  const HybridModel file = LoadFile(name);
  const study::Scenario a = study::DefaultScenario(builtin);
  const study::Scenario b = study::DefaultScenario(file);
  ASSERT_EQ(b.start.size(), a.start.size()) << name;
  EXPECT_LE((b.start - a.start).lpNorm<Eigen::Infinity>(), 1e-15 * (1 + a.start.lpNorm<Eigen::Infinity>())) << name;
  // A TOML table lists its keys in sorted order: terms, bounds and scales are compared as sets.
  const auto sorted = [](auto v) {
    std::sort(v.begin(), v.end());
    return v;
  };
  ASSERT_EQ(b.start_conditions.size(), a.start_conditions.size()) << name;
  for (size_t i = 0; i < a.start_conditions.size(); ++i) {
    EXPECT_EQ(sorted(b.start_conditions[i].terms), sorted(a.start_conditions[i].terms)) << name;
    EXPECT_EQ(b.start_conditions[i].description, a.start_conditions[i].description) << name;
  }
  const auto bounds = [](const study::Scenario& s) {
    std::map<std::string, std::pair<double, double>> m;
    for (const ComponentBound& x : s.bounds) m[x.component] = {x.lower, x.upper};
    for (const SumBound& x : s.sum_bounds) m["sum of " + std::to_string(x.components.size())] = {x.lower, x.upper};
    return m;
  };
  EXPECT_EQ(bounds(b), bounds(a)) << name;
  EXPECT_EQ(sorted(b.unknown_scales), sorted(a.unknown_scales)) << name;
  EXPECT_EQ(b.max_branches, a.max_branches) << name;
  EXPECT_EQ(b.max_depth, a.max_depth) << name;
  EXPECT_EQ(b.max_points, a.max_points) << name;
  EXPECT_EQ(b.initial_step, a.initial_step) << name;
  EXPECT_EQ(b.max_step, a.max_step) << name;
  EXPECT_EQ(b.keyframes.component, a.keyframes.component) << name;
  EXPECT_EQ(b.keyframes.value, a.keyframes.value) << name;
  EXPECT_EQ(b.max_keyframe_orbits, a.max_keyframe_orbits) << name;

  const ModelSetup& sa = builtin.setup();
  const ModelSetup& sb = file.setup();
  EXPECT_EQ(sb.title, sa.title) << name;
  EXPECT_EQ(sb.start.kind, sa.start.kind) << name;
  ASSERT_EQ(sb.families.size(), sa.families.size()) << name;
  for (size_t i = 0; i < sa.families.size(); ++i) EXPECT_EQ(sb.families[i].name, sa.families[i].name) << name;
  ASSERT_EQ(sb.quantities.size(), sa.quantities.size()) << name;
  for (size_t i = 0; i < sa.quantities.size(); ++i) {
    EXPECT_EQ(sb.quantities[i].name, sa.quantities[i].name) << name;
    EXPECT_EQ(sb.quantities[i].description, sa.quantities[i].description) << name;
  }
  ASSERT_EQ(sb.figures.size(), sa.figures.size()) << name;
  for (size_t i = 0; i < sa.figures.size(); ++i) {
    const FigureSpec& x = sa.figures[i];
    const FigureSpec& y = sb.figures[i];
    EXPECT_EQ(std::tie(y.file, y.title, y.x, y.y, y.zoom_special_points),
              std::tie(x.file, x.title, x.x, x.y, x.zoom_special_points))
        << name << " figure " << x.file;
  }
  EXPECT_EQ(sb.drawing.ground, sa.drawing.ground) << name;
  EXPECT_EQ(sb.drawing.mass_radius, sa.drawing.mass_radius) << name;

  // The drawing, evaluated: every point of every segment's drawing at random states and X.
  const OrbitPresentation pa(builtin), pb(file);
  ASSERT_EQ(pb.has_drawing(), pa.has_drawing()) << name;
  EXPECT_EQ(sorted(pb.point_names()), sorted(pa.point_names())) << name;
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> d(-0.5, 0.5);
  for (int segment = 0; segment <= builtin.num_phases(); ++segment) {
    const Phase& phase = builtin.phase(segment);
    // A drawing that differs between segments of one phase (the rocking block drawn on its right corner
    // after the impact) cannot be written in a model file: [drawing.<phase>] applies to every segment.
    const bool per_segment = std::any_of(sa.drawing.phases.begin(), sa.drawing.phases.end(),
                                         [&](const DrawingSpec::PhaseDrawing& x) {
                                           return x.phase == phase.name() && !x.segments.empty();
                                         });
    if (per_segment && segment > 0) {
      std::printf("%s: the drawing of segment %d is not compared (the built-in draws it differently from "
                  "segment 1 of the same phase, which a model file cannot express)\n",
                  name.c_str(), segment + 1);
      continue;
    }
    for (int trial = 0; trial < 5; ++trial) {
      Vector x = phase.typical_state();
      for (int k = 0; k < x.size(); ++k) x(k) += d(rng);
      const double X = d(rng);
      const double v = pa.XVelocity(segment, x);
      EXPECT_NEAR(pb.XVelocity(segment, x), v, 1e-14 * (1 + std::abs(v))) << name << " segment " << segment + 1;
      const Matrix A = pa.DrawingPoints(segment, x, X), B = pb.DrawingPoints(segment, x, X);
      for (size_t i = 0; i < pa.point_names().size(); ++i) {
        const auto it = std::find(pb.point_names().begin(), pb.point_names().end(), pa.point_names()[i]);
        if (it == pb.point_names().end()) continue;  // reported above
        const Eigen::Index j = it - pb.point_names().begin();
        for (int c = 0; c < 2; ++c) {
          if (std::isnan(A(c, i))) {
            EXPECT_TRUE(std::isnan(B(c, j))) << name << " segment " << segment + 1 << " point " << pa.point_names()[i];
          } else {
            EXPECT_NEAR(B(c, j), A(c, i), 1e-14 * (1 + std::abs(A(c, i)))) << name << " segment " << segment + 1 << " point " << pa.point_names()[i];
          }
        }
      }
    }
  }
}

TEST(ModelFileSetUp, BouncingBall) { ExpectSameSetUp("bouncing-ball"); }
TEST(ModelFileSetUp, RockingBlock) { ExpectSameSetUp("rocking-block"); }
TEST(ModelFileSetUp, BouncingRod) { ExpectSameSetUp("bouncing-rod"); }
TEST(ModelFileSetUp, BallChain) { ExpectSameSetUp("ball-chain"); }
// Not the SLIP yet: models/slip.toml's presentation (figure titles, mass_radius) differs from the
// built-in's; its run set-up is checked through the diagram below.

TEST(ModelFileDiagram, BouncingBall) { ExpectSameDiagram("bouncing-ball"); }
TEST(ModelFileDiagram, RockingBlock) { ExpectSameDiagram("rocking-block"); }
TEST(ModelFileDiagram, BouncingRod) { ExpectSameDiagram("bouncing-rod"); }
TEST(ModelFileDiagram, Slip) { ExpectSameDiagram("slip"); }
TEST(ModelFileDiagram, BallChain) { ExpectSameDiagram("ball-chain"); }
// Written from their mechanics (mechanics.h): the same turning, SB, BP and PD points to 1e-9.
TEST(ModelFileDiagram, LagrangianRod) { ExpectSameDiagram("bouncing-rod", "bouncing-rod-lagrangian"); }
TEST(ModelFileDiagram, LagrangianSlip) { ExpectSameDiagram("slip", "slip-lagrangian"); }

}  // namespace
}  // namespace hybridcont
