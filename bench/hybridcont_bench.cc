// Benchmarks: per built-in model, one evaluation of r and dr, one corrector solve, and the full
// exploration of the model's default scenario. Counters: points, Newton iterations per point, rejected
// steps, right-hand-side (RHS) evaluations and their ratio to the floor — one integration of every phase
// with sensitivities per accepted point (the RHS count of one r+dr evaluation at each accepted point,
// summed over the diagram; rhs_over_traced_floor: over the traced points only, without the images that
// symmetries map for free, nor the reflected halves of self-symmetric loops). newton_per_point is per traced
// point.
//
//   build/bench/hybridcont_bench --benchmark_filter=FullRun
#include <benchmark/benchmark.h>

#include <cmath>
#include <map>

#include <filesystem>
#include <fstream>

#include "hybridcont/corrector.h"
#include "hybridcont/model_file.h"
#include "hybridcont/models.h"
#include "hybridcont/study.h"
#include "study/engine/model_exploration.h"
#include "../tests/mass_chain_text.h"

namespace hybridcont::study {
namespace {

const char* const kModels[] = {"bouncing-ball", "rocking-block", "bouncing-rod", "slip"};

// A representative physical point per model: the middle physical point of the first branch with one.
struct Representative {
  Vector u;
  Vector tangent;
};

const Representative& RepresentativePoint(const std::string& name) {
  static std::map<std::string, Representative> cache;
  auto it = cache.find(name);
  if (it != cache.end()) return it->second;
  const HybridModel model = MakeBuiltinModel(name);
  const Scenario scenario = DefaultScenario(model);
  ModelExploration exploration(model, scenario, IntegratorOptions{}, ScenarioExplorationOptions(scenario));
  const BifurcationDiagram d = exploration.Run();
  Representative rep;
  for (const Branch& b : d.branches) {
    if (b.points.size() > 4) {
      // prefer a branch with positive durations (physical side)
      const ContinuationPoint& p = b.points[b.points.size() / 2];
      if (exploration.shooting().layout().Period(p.u) > 0 || rep.u.size() == 0) rep = {p.u, p.tangent};
      if (exploration.shooting().layout().Period(p.u) > 0) break;
    }
  }
  return cache.emplace(name, rep).first->second;
}

// One evaluation of the time-based map at the model's representative point: r and dr, or r alone (the
// integration without sensitivities, for comparison with the floor's r+dr).
void ShootingEvaluation(benchmark::State& state, bool with_jacobian) {
  const std::string name = kModels[state.range(0)];
  const HybridModel model = MakeBuiltinModel(name);
  const Representative& rep = RepresentativePoint(name);
  TimeBasedShooting shooting(model, IntegratorOptions{});
  Vector u = rep.u, r;
  Matrix dr;
  for (auto _ : state) {
    u(0) += 1e-15;  // defeat the cache: a new point each time
    shooting.Evaluate(u, &r, with_jacobian ? &dr : nullptr);
    benchmark::DoNotOptimize(r.data());
  }
  state.SetLabel(name);
  state.counters["rhs_per_eval"] =
      static_cast<double>(shooting.counters().rhs_evaluations) / static_cast<double>(shooting.num_evaluations());
  state.counters["N"] = shooting.num_equations();
}
void BM_ShootingEvaluate(benchmark::State& state) { ShootingEvaluation(state, true); }
BENCHMARK(BM_ShootingEvaluate)->DenseRange(0, 3)->Unit(benchmark::kMicrosecond);
void BM_ShootingResidual(benchmark::State& state) { ShootingEvaluation(state, false); }
BENCHMARK(BM_ShootingResidual)->DenseRange(0, 3)->Unit(benchmark::kMicrosecond);

void BM_CorrectorSolve(benchmark::State& state) {
  const std::string name = kModels[state.range(0)];
  const HybridModel model = MakeBuiltinModel(name);
  const Representative& rep = RepresentativePoint(name);
  TimeBasedShooting shooting(model, IntegratorOptions{});
  Corrector corrector(&shooting);
  // a predictor 1e-2 along the tangent: a typical continuation step
  const Vector u_pred = rep.u + 1e-2 * rep.tangent;
  Vector u;
  long iterations = 0, solves = 0;
  for (auto _ : state) {
    const CorrectorResult result = corrector.CorrectPseudoArclength(u_pred, rep.tangent, &u);
    iterations += result.iterations;
    ++solves;
    if (!result.converged()) state.SkipWithError(result.message.c_str());
  }
  state.SetLabel(name);
  state.counters["newton_iterations"] = static_cast<double>(iterations) / static_cast<double>(solves);
}
BENCHMARK(BM_CorrectorSolve)->DenseRange(0, 3)->Unit(benchmark::kMicrosecond);

// The full exploration of a model's default scenario on `threads` threads, with the counters above.
void FullRun(benchmark::State& state, const HybridModel& model, int threads) {
  const std::string name = model.name();
  const Scenario scenario = DefaultScenario(model);
  long points = 0, traced_points = 0, newton = 0, rejected = 0, rhs = 0, branches = 0;
  double floor_rhs = 0, traced_floor_rhs = 0;
  BifurcationDiagram diagram;
  ExplorationOptions options = ScenarioExplorationOptions(scenario);
  options.threads = threads;
  for (auto _ : state) {
    ModelExploration exploration(model, scenario, IntegratorOptions{}, options);
    const BifurcationDiagram d = exploration.Run();
    points = traced_points = newton = rejected = 0;
    for (const Branch& b : d.branches) {
      points += static_cast<long>(b.points.size());
      if (b.image_of < 0) traced_points += static_cast<long>(b.reflected_from >= 0 ? b.reflected_from : b.points.size());
      newton += b.newton_iterations;
      rejected += b.rejected_steps;
    }
    branches = static_cast<long>(d.branches.size());
    rhs = exploration.shooting().counters().rhs_evaluations;
    diagram = d;
  }
  {
    // The floor: one integration of every phase with sensitivities per accepted point — the
    // RHS count of one r+dr evaluation at each accepted point itself, summed. Over all points of the
    // diagram, and over the traced ones only (the points of branches mapped through a symmetry cost
    // nothing: rhs_over_traced_floor is the work per point the continuation itself did).
    TimeBasedShooting probe(model, IntegratorOptions{});
    Vector r;
    Matrix dr;
    for (const Branch& b : diagram.branches) {
      const size_t traced = b.image_of >= 0 ? 0 : b.reflected_from >= 0 ? b.reflected_from : b.points.size();
      for (size_t i = 0; i < b.points.size(); ++i) {
        const long before = probe.counters().rhs_evaluations;
        probe.Evaluate(b.points[i].u, &r, &dr);
        if (i < traced) traced_floor_rhs += static_cast<double>(probe.counters().rhs_evaluations - before);
      }
    }
    floor_rhs = static_cast<double>(probe.counters().rhs_evaluations);
  }
  state.SetLabel(name);
  state.counters["branches"] = static_cast<double>(branches);
  state.counters["points"] = static_cast<double>(points);
  state.counters["traced_points"] = static_cast<double>(traced_points);
  state.counters["newton_per_point"] = static_cast<double>(newton) / static_cast<double>(traced_points);
  state.counters["rejected"] = static_cast<double>(rejected);
  state.counters["rhs"] = static_cast<double>(rhs);
  state.counters["rhs_over_floor"] = static_cast<double>(rhs) / floor_rhs;
  state.counters["rhs_over_traced_floor"] = static_cast<double>(rhs) / traced_floor_rhs;
}
void BM_FullRun(benchmark::State& state) {
  const HybridModel model = MakeBuiltinModel(kModels[state.range(0)]);
  FullRun(state, model, static_cast<int>(state.range(1)));
}
// BM_FullRun/<model>/<threads>. Wall time: the exploration and the shooting map may run on several threads
// (ExplorationOptions::threads); on one thread the RHS count is the algorithm's work alone, on two it also
// counts the traces that the merge drops.
BENCHMARK(BM_FullRun)->ArgsProduct({{0, 1, 2, 3}, {1, 2}})->Unit(benchmark::kMillisecond)->Iterations(3)->UseRealTime();

// The whole study of a model (study.h, what `hybridcont run` computes): the exploration and every point's
// analysis (classification, replay, Floquet multipliers), ranges and key frames, without a folder.
// BM_Study/<model>/<threads>; counters: the work of the study's parts (StudyResult::work).
void BM_Study(benchmark::State& state) {
  StudyOptions options;
  options.model = kModels[state.range(0)];
  options.threads = static_cast<int>(state.range(1));
  StudyResult study;
  for (auto _ : state) study = RunStudy(options);
  state.counters["branches"] = static_cast<double>(study.branches.size());
  state.counters["rhs_continuation"] = static_cast<double>(study.work.rhs_evaluations);
  state.counters["rhs_analysis"] = static_cast<double>(study.work.analysis_rhs_evaluations);
  state.counters["rhs_tests"] = static_cast<double>(study.work.test_rhs_evaluations);
}
BENCHMARK(BM_Study)->ArgsProduct({{0, 1, 2, 3}, {1, 2}})->Unit(benchmark::kMillisecond)->Iterations(3)->UseRealTime();

// The same model written as a model file (models/<name>.toml), in the same run as BM_FullRun:
// BM_ModelFileFullRun/<model>/<variant>, variant 0 the built-in C++ model, 1 the file compiled (generated
// code, cache warm), 2 the file interpreted. One thread, so that the times compare the model functions.
void BM_ModelFileFullRun(benchmark::State& state) {
  const std::string name = kModels[state.range(0)];
  const int variant = static_cast<int>(state.range(1));
  ModelFileOptions options;
  options.compile = variant == 1;
  options.cache_dir = std::filesystem::temp_directory_path() / "hybridcont-bench-cache";
  const HybridModel model =
      variant == 0 ? MakeBuiltinModel(name)
                   : LoadModelFile(std::filesystem::path(HYBRIDCONT_SOURCE_DIR) / "models" / (name + ".toml"), options);
  FullRun(state, model, 1);
  state.SetLabel(name + (variant == 0 ? " built-in" : variant == 1 ? " file, compiled" : " file, interpreted"));
}
BENCHMARK(BM_ModelFileFullRun)->ArgsProduct({{0, 1, 2, 3}, {0, 1, 2}})->Unit(benchmark::kMillisecond)->Iterations(3)->UseRealTime();

// Models written from their mechanics (models/<name>-lagrangian.toml: T, V, impact laws; mechanics.h)
// against the same models in explicit form, in the same run: BM_LagrangianFullRun/<model>/<variant>, model
// 0 the bouncing rod, 1 the SLIP; variant 0 the built-in C++ model, 1 the explicit model file, 2 the
// Lagrangian model file (both compiled, cache warm). One thread.
void BM_LagrangianFullRun(benchmark::State& state) {
  const std::string name = state.range(0) == 0 ? "bouncing-rod" : "slip";
  const int variant = static_cast<int>(state.range(1));
  ModelFileOptions options;
  options.cache_dir = std::filesystem::temp_directory_path() / "hybridcont-bench-cache";
  const std::string file = name + (variant == 2 ? "-lagrangian" : "");
  const HybridModel model =
      variant == 0 ? MakeBuiltinModel(name)
                   : LoadModelFile(std::filesystem::path(HYBRIDCONT_SOURCE_DIR) / "models" / (file + ".toml"), options);
  FullRun(state, model, 1);
  state.SetLabel(name + (variant == 0 ? " built-in" : variant == 1 ? " explicit file" : " Lagrangian file"));
}
BENCHMARK(BM_LagrangianFullRun)->ArgsProduct({{0, 1}, {0, 1, 2}})->Unit(benchmark::kMillisecond)->Iterations(5)->UseRealTime();

// A model without first integral against a conservative one of the same size, in the same run: one r + dr
// evaluation at a gait (orbit) of each, BM_DissipativeMap/<model>: 0 the simplest walker (4 states, one
// phase, gamma free: no ξ, no H̄, one parameter column), 1 the bouncing pendulum (4 states, one phase, ξ
// and H̄). Counters: RHS evaluations per map evaluation and the map's size.
void BM_DissipativeMap(benchmark::State& state) {
  const bool walker = state.range(0) == 0;
  ModelFileOptions options;
  options.cache_dir = std::filesystem::temp_directory_path() / "hybridcont-bench-cache";
  const HybridModel model = LoadModelFile(
      std::filesystem::path(HYBRIDCONT_SOURCE_DIR) / "models" / (walker ? "simplest-walker.toml" : "bouncing-pendulum.toml"),
      options);
  TimeBasedShooting shooting(model, IntegratorOptions{}, walker ? FreeParameters{{"gamma"}, {}} : FreeParameters{});
  const ShootingLayout& layout = shooting.layout();
  Vector u = Vector::Zero(layout.num_unknowns());
  if (walker) {  // the long-period gait at gamma = 0.009 (tests/dissipative_models_test.cc)
    u << 2.0507748199878604, 0.20031090054455519, 0.40062180108911039, -0.19983247300537216, -0.015822999948390645,
        1.8316889328761317, -8.89e-29, -0.053210379845986026, -0.059377176638781719, -0.33977530977991061, 0.009;
  } else {  // the vertical bouncing at H = 0.5 with the pendulum swinging slightly (a non-trivial flow)
    u(layout.time_index(0)) = u(layout.time_index(1)) = std::sqrt(0.5);
    u(layout.state_offset(0)) = 0.25;
    u(layout.state_offset(0) + 1) = 0.1;
    u(layout.state_offset(1) + 2) = std::sqrt(0.5);
    u(layout.H_index()) = 0.5;
  }
  Vector r;
  Matrix dr;
  for (auto _ : state) {
    u(0) += 1e-15;  // defeat the cache: a new point each time
    if (!shooting.Evaluate(u, &r, &dr).ok) state.SkipWithError("evaluation failed");
    benchmark::DoNotOptimize(dr.data());
  }
  state.SetLabel(walker ? "simplest walker (no first integral)" : "bouncing pendulum (conservative)");
  state.counters["rhs_per_eval"] =
      static_cast<double>(shooting.counters().rhs_evaluations) / static_cast<double>(shooting.num_evaluations());
  state.counters["N"] = shooting.num_equations();
}
BENCHMARK(BM_DissipativeMap)->DenseRange(0, 1)->Unit(benchmark::kMicrosecond);

// What the first use of a model file costs: parse, generate, compile with the system compiler and load,
// into an empty cache (later uses load the cached library: BM_ModelFileLoad).
void ModelFileLoad(benchmark::State& state, bool cold) {
  const std::string name = kModels[state.range(0)];
  const std::filesystem::path cache = std::filesystem::temp_directory_path() / "hybridcont-bench-first-run";
  for (auto _ : state) {
    if (cold) std::filesystem::remove_all(cache);
    ModelFileOptions options;
    options.cache_dir = cache;
    const HybridModel model =
        LoadModelFile(std::filesystem::path(HYBRIDCONT_SOURCE_DIR) / "models" / (name + ".toml"), options);
    benchmark::DoNotOptimize(&model);
  }
  state.SetLabel(name);
}
void BM_ModelFileFirstLoad(benchmark::State& state) { ModelFileLoad(state, true); }
BENCHMARK(BM_ModelFileFirstLoad)->DenseRange(0, 3)->Unit(benchmark::kMillisecond)->Iterations(1)->UseRealTime();
void BM_ModelFileLoad(benchmark::State& state) { ModelFileLoad(state, false); }
BENCHMARK(BM_ModelFileLoad)->DenseRange(0, 3)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace hybridcont::study

namespace hybridcont::study {
namespace {

// Scaling in the number of phases: one corrector solve on the ball-chain with m phases from a
// perturbed closed-form orbit; reported per Newton iteration (an r + dr evaluation and a bordered solve).
void BM_ScalingNewtonStep(benchmark::State& state) {
  const int m = static_cast<int>(state.range(0));
  const HybridModel chain = MakeBallChain(m);
  TimeBasedShooting shooting(chain, IntegratorOptions{});
  const Vector exact = BallChainOrbit(chain, 0.5);
  Vector guess = exact;
  for (int i = 0; i < guess.size() - 2; ++i) guess(i) += 1e-4 * std::sin(1.0 + i);
  Corrector corrector(&shooting);
  Vector u;
  long iterations = 0;
  for (auto _ : state) {
    const CorrectorResult r = corrector.CorrectFixedComponent(guess, shooting.layout().H_index(), 0.5, &u);
    if (!r.converged()) state.SkipWithError(r.message.c_str());
    iterations += r.iterations;
  }
  state.counters["N"] = shooting.num_equations();
  state.counters["newton_iterations"] =
      benchmark::Counter(static_cast<double>(iterations), benchmark::Counter::kAvgIterations);
  state.counters["seconds_per_newton_step"] = benchmark::Counter(
      static_cast<double>(iterations), benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_ScalingNewtonStep)->Arg(1)->Arg(10)->Arg(100)->Arg(1000)->Unit(benchmark::kMillisecond)->UseRealTime();

// One r + dr evaluation of the time-based map of the mass chain against its state dimension:
// BM_LargeModelEvaluate/<masses>/<variant>, variant 0 interpreted, 1 compiled (generated code, cache warm).
// A continuation point costs 2–3 of them (bench/README.md).
void BM_LargeModelEvaluate(benchmark::State& state) {
  const int masses = static_cast<int>(state.range(0));
  const bool compiled = state.range(1) == 1;
  const std::filesystem::path file =
      std::filesystem::temp_directory_path() / ("hybridcont-bench-mass-chain-" + std::to_string(masses) + ".toml");
  std::ofstream(file) << test_models::MassChainText(masses);
  ModelFileOptions options;
  options.compile = compiled;
  options.cache_dir = std::filesystem::temp_directory_path() / "hybridcont-bench-cache";
  const HybridModel model = LoadModelFile(file, options);
  TimeBasedShooting shooting(model, IntegratorOptions{});
  shooting.set_threads(1);
  const ShootingLayout& layout = shooting.layout();
  Vector u = Vector::Zero(layout.num_unknowns()), r;
  for (int s = 0; s < layout.num_segments(); ++s) {
    u(layout.time_index(s)) = 0.8;
    for (int j = 0; j < layout.dim(s); ++j) u(layout.state_offset(s) + j) = 0.05 * std::sin(1.0 + j + 3 * s);
  }
  u(layout.H_index()) = 0.01;
  Matrix dr;
  for (auto _ : state) {
    u(0) += 1e-15;  // a new point each time
    if (!shooting.Evaluate(u, &r, &dr).ok) state.SkipWithError("evaluation failed");
    benchmark::DoNotOptimize(r.data());
  }
  state.counters["states"] = 2 * masses;
  state.counters["rhs_per_eval"] =
      static_cast<double>(shooting.counters().rhs_evaluations) / static_cast<double>(shooting.num_evaluations());
}
BENCHMARK(BM_LargeModelEvaluate)
    ->ArgsProduct({{2, 4, 6, 8, 9, 12, 16, 20, 24}, {0, 1}})
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace hybridcont::study
