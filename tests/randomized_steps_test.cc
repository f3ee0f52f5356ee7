// Nothing missed when the step size changes: the exploration of each built-in model under 20 randomized
// step-size settings (first step and largest step, each a random factor in [1/4, 2] of the scenario's)
// finds the special points of the default run again, as many of each type, each where the two runs'
// stated precisions (SpecialPoint::interval_width, componentwise) allow, and no others, on as many
// branches. A special point stepped over by a larger step, or found only by a lucky one, fails here.
//
// Points located to the noise level (next to an SB point: docs/design/continuation.md, "Location to the
// noise level", and turning points at one) are placed along their branch to their interval, but Newton's
// amplified noise may slide them along the crossing branch, beyond it (the bouncing rod's SB point by 5e-6
// in its states, at the same H̄ to 1e-9): for them the family's parameter H̄ is compared. The SLIP holds
// the hard cases: a turning point where all phase durations vanish (dr loses rank three there), SB points
// of crossing clusters located from two branches each, and a branch passing close by another.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "hybridcont/exploration.h"
#include "hybridcont/models.h"
#include "study/engine/model_exploration.h"

namespace hybridcont {
namespace {

struct Found {
  SpecialPointType type;
  Vector u;
  Vector width;        // SpecialPoint::interval_width
  bool noise_limited;  // located to the noise level, or a turning point at such an SB point
};

struct StepRun {
  std::vector<Found> found;
  int H = -1;  // index of H̄ in u
  int too_small = 0;  // branches that ended because the step fell below min_step
  size_t branches = 0;
};

StepRun SpecialPoints(const HybridModel& model, double initial_factor, double max_factor) {
  const study::Scenario scenario = study::DefaultScenario(model);
  ExplorationOptions options = study::ScenarioExplorationOptions(scenario);
  options.threads = 1;
  options.continuation.initial_step *= initial_factor;
  options.continuation.max_step *= max_factor;
  options.continuation.initial_step = std::min(options.continuation.initial_step, options.continuation.max_step);
  study::ModelExploration exploration(model, scenario, IntegratorOptions{}, options);
  const BifurcationDiagram diagram = exploration.Run();
  EXPECT_EQ(diagram.status, ExplorationStatus::kCompleted) << model.name() << ": " << diagram.message;
  StepRun run;
  run.H = exploration.shooting().UnknownIndex("H");
  run.branches = diagram.branches.size();
  for (const Branch& branch : diagram.branches) {
    run.too_small += branch.termination == TerminationReason::kStepTooSmall ? 1 : 0;
  }
  for (const SpecialPoint& sp : diagram.special_points) {
    if (sp.duplicate_of >= 0 || sp.status != LocationStatus::kLocated) continue;
    const bool noise = sp.message.find("noise level") != std::string::npos ||
                       sp.message.find("at the simple bifurcation point") != std::string::npos;
    const Vector width = sp.interval_width.size() == sp.u.size() ? sp.interval_width : Vector::Zero(sp.u.size());
    run.found.push_back({sp.type, sp.u, width, noise});
  }
  return run;
}

// How far f lies outside what r's and f's precisions allow (<= 0: the same point), and its distance.
double Excess(const Found& r, const Found& f, int H, double* distance) {
  if (r.noise_limited || f.noise_limited) {
    *distance = std::abs(f.u(H) - r.u(H));
    return *distance - (r.width(H) + f.width(H) + 1e-7 * (1 + std::abs(r.u(H))));
  }
  *distance = (f.u - r.u).norm();
  return ((f.u - r.u).cwiseAbs() - (r.width + f.width).cwiseAbs() -
          Vector::Constant(r.u.size(), 1e-7 * (1 + r.u.norm())))
      .maxCoeff();
}

class RandomizedSteps : public ::testing::TestWithParam<std::string> {};

TEST_P(RandomizedSteps, FindTheSameSpecialPoints) {
  const std::string name = GetParam();
  std::mt19937 rng(2026);
  std::uniform_real_distribution<double> log_factor(std::log(0.25), std::log(2.0));
  const HybridModel model = MakeBuiltinModel(name);
  const StepRun reference_run = SpecialPoints(model, 1.0, 1.0);
  const std::vector<Found>& reference = reference_run.found;
  std::map<SpecialPointType, int> counts;
  for (const Found& f : reference) ++counts[f.type];
  double worst = 0;
  int failed = 0, lost_branches = 0;
  for (int trial = 0; trial < 20; ++trial) {
    const double a = std::exp(log_factor(rng)), b = std::exp(log_factor(rng));
    const StepRun run = SpecialPoints(model, a, b);
    const std::vector<Found>& found = run.found;
    // No branch may end for a step too small: that loses every point and switch beyond it.
    EXPECT_EQ(run.too_small, 0) << name << ": first step x" << a << ", largest step x" << b;
    lost_branches += run.too_small;
    // The same families: a step onto a neighbouring branch would trace a traced family again (or miss one).
    EXPECT_EQ(run.branches, reference_run.branches) << name << ": first step x" << a << ", largest step x" << b;
    std::map<SpecialPointType, int> found_counts;
    for (const Found& f : found) ++found_counts[f.type];
    bool same = found_counts == counts;
    EXPECT_EQ(found_counts, counts) << name << ": first step x" << a << ", largest step x" << b;
    for (const Found& r : reference) {
      double excess = 1e300, distance = 1e300;
      for (const Found& f : found) {
        if (f.type != r.type || f.u.size() != r.u.size()) continue;
        double d;
        const double e = Excess(r, f, reference_run.H, &d);
        if (e < excess) excess = e, distance = d;
      }
      EXPECT_LE(excess, 0) << name << ": " << ToString(r.type) << " not found again (nearest " << distance
                           << " away) with first step x" << a << ", largest step x" << b;
      same = same && excess <= 0;
      worst = std::max(worst, distance);
    }
    same = same && run.branches == reference_run.branches;
    failed += same ? 0 : 1;
  }
  std::printf("%s: %zu special points (", name.c_str(), reference.size());
  for (const auto& [type, count] : counts) std::printf(" %s %d", ToString(type).c_str(), count);
  std::printf(" ); the same in %d of 20 randomized step settings, farthest %.1e; %d branches ended for a step "
              "below min_step\n", 20 - failed, worst, lost_branches);
}

INSTANTIATE_TEST_SUITE_P(BuiltIn, RandomizedSteps, ::testing::Values("bouncing-ball", "rocking-block", "bouncing-rod",
                                                                     "ball-chain", "slip"));

}  // namespace
}  // namespace hybridcont
