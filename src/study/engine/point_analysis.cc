#include "study/engine/point_analysis.h"

#include <algorithm>
#include <cmath>

#include "hybridcont/classification.h"

namespace hybridcont::study {

ReplayOptions ReplayOptionsFor(const IntegratorOptions& integrator) { return OrbitAnalysisOptions::For(integrator).replay; }

void AnalyzePoint(const HybridModel& model, const IntegratorOptions& integrator, TimeBasedShooting& floquet_map,
                  const ReplayOptions& replay_options, PointRecord* record,
                  const FloquetTestFunctions::BranchPointAnalysis* known) {
  OrbitAnalysisOptions options;
  options.known = known;
  options.integrator = integrator;
  options.replay = replay_options;
  options.at_branch_point = record->at_branch_point;
  const OrbitAnalysis a = AnalyzeOrbit(model, floquet_map, record->u, options);
  record->classification = a.classification;
  record->stability = a.stability;
  record->residual = a.residual;
  record->observables = a.observables;
  record->extra = ExtraColumns(model, a);
  record->analysis = a;
}

std::vector<std::pair<std::string, double>> ExtraColumns(const HybridModel& model, const OrbitAnalysis& a) {
  const double nan = std::nan("");
  const auto flag = [&](bool value) { return a.floquet ? (value ? 1.0 : 0.0) : nan; };
  std::vector<std::pair<std::string, double>> extra = {
      {"replay_error", a.replay_error},
      {"stable", flag(a.stable)},
      {"normal", flag(a.normal)},
      {"num_unit", a.floquet ? a.num_unit : nan}, {"max_multiplier", a.max_multiplier},
      {"bp_test", a.bp_test},           {"pd_test", a.pd_test},
      {"multiplier_error", a.floquet ? a.multiplier_error : nan}};
  // A column pair per nontrivial multiplier (floquet.h: the flow direction, and with a first integral its
  // level, are the trivial ones), whether or not this point has multipliers: every row has the same header.
  const int trivial = model.num_first_integrals() > 0 ? 2 : 1;
  const int nontrivial = std::max(model.phase(0).dim() - trivial, 0);
  for (int j = 0; j < nontrivial; ++j) {
    const bool known = j < static_cast<int>(a.multipliers.size());
    extra.push_back({"mu" + std::to_string(j + 1) + "_re", known ? a.multipliers[j].real() : nan});
    extra.push_back({"mu" + std::to_string(j + 1) + "_im", known ? a.multipliers[j].imag() : nan});
  }
  if (model.automaton()) extra.push_back({"automaton_replay_error", a.automaton_replay_error});
  return extra;
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


}  // namespace hybridcont::study
