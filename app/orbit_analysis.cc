#include "orbit_analysis.h"

#include <algorithm>
#include <cmath>

#include "hybridcont/automaton_replay.h"
#include "hybridcont/classification.h"
#include "hybridcont/floquet.h"
#include "hybridcont/orbit_observables.h"

namespace hybridcont::app {

ReplayOptions ReplayOptionsFor(const IntegratorOptions& integrator) {
  ReplayOptions replay_options;
  replay_options.poincare.event.integrator.rtol = integrator.rtol;
  replay_options.poincare.event.integrator.atol = integrator.atol;
  return replay_options;
}

void AnalyzePoint(const HybridModel& model, const IntegratorOptions& integrator, TimeBasedShooting& floquet_map,
                  const ReplayOptions& replay_options, PointRecord* record) {
  const Vector u = OrbitPart(floquet_map.layout(), record->u);
  if (!ClassifyByUnknowns(model, u, ClassificationOptions{}, &record->classification)) {  // no trace needed
    const OrbitTrace trace(model, u, integrator);
    record->classification = ClassifyOrbit(model, u, trace, ClassificationOptions{});
  }
  // Floquet data first: its r + dr evaluation leaves r in the map's cache, so the residual below costs no
  // second integration on physical points.
  AnalyzePhysicalOrbit(model, floquet_map, replay_options, record->u, record);
  // Observables: those that joined the unknowns from u, the others evaluated at a physical point (empty
  // elsewhere, like the Floquet columns: a reversed-time orbit's mean speed means nothing for the mechanism).
  const std::vector<Observable>& observables = model.observables();
  if (!observables.empty()) {
    const ShootingLayout& layout = floquet_map.layout();
    ObservableEvaluator evaluator(model, layout, integrator);
    for (int j = 0; j < static_cast<int>(observables.size()); ++j) {
      const int k = layout.UnknownIndex(observables[j].name);
      double value = std::nan("");
      if (k >= 0) {
        value = record->u(k);
      } else if (!record->classification.physical || !evaluator.Evaluate(j, record->u, &value, nullptr).ok) {
        value = std::nan("");
      }
      record->observables.push_back({observables[j].name, value});
    }
  }
  Vector r;
  const EvaluationStatus status = floquet_map.Evaluate(record->u, &r, nullptr);
  record->residual = status.ok ? r.norm() : std::nan("");
}

bool IsPhysical(const HybridModel& model, const Vector& u, const IntegratorOptions& integrator) {
  return ClassifyPoint(model, u, integrator).physical;
}

Classification ClassifyPoint(const HybridModel& model, const Vector& u, const IntegratorOptions& integrator) {
  Classification c;
  if (!ClassifyByUnknowns(model, u, ClassificationOptions{}, &c)) {
    const OrbitTrace trace(model, u, integrator);
    c = ClassifyOrbit(model, u, trace, ClassificationOptions{});
  }
  return c;
}

void SetFreeParameters(const ShootingLayout& layout, const Vector& u, HybridModel* model) {
  for (int i = 0; i < layout.num_free_parameters(); ++i) {
    model->SetParameterValue(layout.parameter_model_index(i), u(layout.parameter_index(i)));
  }
}

void AnalyzePhysicalOrbit(const HybridModel& model, TimeBasedShooting& floquet_map, const ReplayOptions& replay_options,
                          const Vector& u, PointRecord* record) {
  const double nan = std::nan("");
  // Trivial multipliers (floquet.h): the flow direction, and with a first integral its level as well.
  const int trivial = model.num_first_integrals() > 0 ? 2 : 1;
  const int nontrivial = std::max(model.phase(0).dim() - trivial, 0);
  record->extra = {{"replay_error", nan}, {"stable", nan},        {"normal", nan}, {"num_unit", nan},
                   {"max_multiplier", nan}, {"bp_test", nan},     {"pd_test", nan}};
  for (int j = 0; j < nontrivial; ++j) {
    record->extra.push_back({"mu" + std::to_string(j + 1) + "_re", nan});
    record->extra.push_back({"mu" + std::to_string(j + 1) + "_im", nan});
  }
  // A word of an automaton: also the automaton's own event-driven simulation (automaton_replay.h).
  const int automaton_column = static_cast<int>(record->extra.size());
  if (model.automaton()) record->extra.push_back({"automaton_replay_error", nan});
  if (!record->classification.physical) return;
  const ReplayResult replay = ReplayOrbit(model, OrbitPart(floquet_map.layout(), u), replay_options);
  record->extra[0].second = replay.error;
  if (!replay.physical()) {
    record->classification = {false, OrbitClass::kReplayFailed, replay.message};
    return;
  }
  if (model.automaton()) {
    const AutomatonReplayResult automaton =
        ReplayAutomaton(model, OrbitPart(floquet_map.layout(), u), floquet_map.integrator_options());
    if (automaton.ok && automaton.same_word) {
      record->extra[automaton_column].second = automaton.return_error;
    } else {
      record->classification = {false, OrbitClass::kReplayFailed,
                                "simulating the automaton: " + (automaton.message.empty() ? "another word" : automaton.message)};
      return;
    }
  }
  FloquetOptions floquet_options;
  floquet_options.at_branch_point = record->at_branch_point;
  const FloquetResult floquet = ComputeFloquet(floquet_map, u, floquet_options);
  if (!floquet.ok()) return;
  record->stability = floquet.stability.ToString();
  record->extra[1].second = floquet.stable ? 1 : 0;
  record->extra[2].second = floquet.normal ? 1 : 0;
  record->extra[3].second = floquet.num_unit;
  record->extra[4].second = floquet.max_modulus;
  record->extra[kBpColumn].second = floquet.bp_test;
  record->extra[kPdColumn].second = floquet.pd_test;
  for (int j = 0; j < nontrivial && j < static_cast<int>(floquet.nontrivial.size()); ++j) {
    record->extra[7 + 2 * j].second = floquet.nontrivial[j].real();
    record->extra[8 + 2 * j].second = floquet.nontrivial[j].imag();
  }
}

}  // namespace hybridcont::app
