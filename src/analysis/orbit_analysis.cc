#include "hybridcont/orbit_analysis.h"

#include <cmath>

#include "hybridcont/automaton_replay.h"
#include "hybridcont/floquet.h"
#include "hybridcont/orbit_observables.h"
#include "hybridcont/orbit_trace.h"

namespace hybridcont {

OrbitAnalysisOptions OrbitAnalysisOptions::For(const IntegratorOptions& integrator) {
  OrbitAnalysisOptions options;
  options.integrator = integrator;
  options.replay.poincare.event.integrator.rtol = integrator.rtol;
  options.replay.poincare.event.integrator.atol = integrator.atol;
  return options;
}

namespace {

// The replays and the multipliers of a physical orbit (a replay that does not return demotes it).
void AnalyzePhysical(const HybridModel& model, TimeBasedShooting& floquet_map, const Vector& u, const Vector& orbit,
                     const OrbitAnalysisOptions& options, OrbitAnalysis* a) {
  const FloquetTestFunctions::BranchPointAnalysis* known = options.known;
  const ReplayResult replay = known != nullptr && known->replayed ? known->replay : ReplayOrbit(model, orbit, options.replay);
  a->replay_error = replay.error;
  if (!replay.physical()) {
    a->classification = {false, OrbitClass::kReplayFailed, replay.message};
    return;
  }
  if (model.automaton()) {  // a word of an automaton: also the automaton's own simulation
    const AutomatonReplayResult automaton = ReplayAutomaton(model, orbit, floquet_map.integrator_options());
    if (!(automaton.ok && automaton.same_word)) {
      a->classification = {false, OrbitClass::kReplayFailed,
                           "simulating the automaton: " + (automaton.message.empty() ? "another word" : automaton.message)};
      return;
    }
    a->automaton_replay_error = automaton.return_error;
  }
  FloquetOptions floquet_options;
  floquet_options.at_branch_point = options.at_branch_point;
  const bool reuse = known != nullptr && known->floquet_known && !options.at_branch_point;
  const FloquetResult floquet = reuse ? known->floquet : ComputeFloquet(floquet_map, u, floquet_options);
  if (!floquet.ok()) return;
  a->floquet = true;
  a->stability = floquet.stability.ToString();
  a->stable = floquet.stable;
  a->stability_undetermined = floquet.stability.undetermined;
  a->multiplier_error = floquet.multiplier_error;
  a->normal = floquet.normal;
  a->num_unit = floquet.num_unit;
  a->max_multiplier = floquet.max_modulus;
  a->bp_test = floquet.bp_test;
  a->pd_test = floquet.pd_test;
  a->multipliers.assign(floquet.nontrivial.begin(), floquet.nontrivial.end());
}

}  // namespace

OrbitAnalysis AnalyzeOrbit(const HybridModel& model, TimeBasedShooting& floquet_map, const Vector& u,
                           const OrbitAnalysisOptions& options) {
  OrbitAnalysis a;
  const ShootingLayout& layout = floquet_map.layout();
  const Vector orbit = u.head(layout.num_orbit_unknowns());
  if (options.known != nullptr) {
    a.classification = options.known->classification;
  } else if (!ClassifyByUnknowns(model, orbit, ClassificationOptions{}, &a.classification)) {  // no trace needed
    const OrbitTrace trace(model, orbit, options.integrator);
    a.classification = ClassifyOrbit(model, orbit, trace, ClassificationOptions{});
  }
  // The multipliers first: their r + dr evaluation leaves r in the map's cache, so the residual below costs
  // no second integration on physical points.
  if (a.classification.physical) AnalyzePhysical(model, floquet_map, u, orbit, options, &a);
  const std::vector<Observable>& observables = model.observables();
  if (!observables.empty()) {
    ObservableEvaluator evaluator(model, layout, options.integrator);
    for (int j = 0; j < static_cast<int>(observables.size()); ++j) {
      const int k = layout.UnknownIndex(observables[j].name);
      double value = OrbitAnalysis::kUndefined;
      if (k >= 0) {
        value = u(k);
      } else if (!a.classification.physical || !evaluator.Evaluate(j, u, &value, nullptr).ok) {
        value = OrbitAnalysis::kUndefined;
      }
      a.observables.push_back({observables[j].name, value});
    }
  }
  if (options.known != nullptr && options.known->residual_known) {
    a.residual = options.known->residual;  // from the test functions' evaluation at u
  } else {
    // With dr, as the corrector and the test functions evaluate the map: r of the same integration (one
    // without sensitivities takes other steps, and its |r| of a converged point is that difference, ~1e-11).
    Vector r;
    Matrix dr;
    const EvaluationStatus status = floquet_map.Evaluate(u, &r, &dr);
    a.residual = status.ok ? r.norm() : OrbitAnalysis::kUndefined;
  }
  return a;
}

}  // namespace hybridcont
