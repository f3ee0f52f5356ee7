#include "hybridcont/expression_model.h"

#include "large_expression_phase.h"

#include <stdexcept>

#include "hybridcont/mechanics.h"

namespace hybridcont {
namespace {

// Everything the phases of an expression model point into; owned by the model's parameter block, which
// the model destroys after its phases.
struct ExpressionModelData {
  std::vector<ParameterInfo> infos;
  std::vector<double> values;  // never resized after construction: phases hold its data pointer
  std::vector<ExpressionPhaseSpec> phases;
  ExpressionProgram anchor;
  std::shared_ptr<const CompiledPrograms> compiled;
  std::vector<internal::ExpressionPhaseData> phase_data;  // one per phase, the anchor's last
};

// Points each phase's (and the anchor's) data at the programs, values and compiled code of `data`.
void BindPhaseData(ExpressionModelData* data) {
  const int m = static_cast<int>(data->phases.size());
  const auto entry = [&](int phase, ProgramKind kind) -> const std::array<CompiledProgramFn, kNumScalarKinds>* {
    if (!data->compiled) return nullptr;
    return &data->compiled->entries[5 * phase + static_cast<int>(kind)];
  };
  const auto param_jet_entry = [&](int phase, ProgramKind kind) -> CompiledParamJetFn {
    const std::size_t slot = 5 * phase + static_cast<int>(kind);
    if (!data->compiled || slot >= data->compiled->param_jet_entries.size()) return nullptr;
    return data->compiled->param_jet_entries[slot];
  };
  data->phase_data.assign(m + 1, internal::ExpressionPhaseData{});
  for (int i = 0; i < m; ++i) {
    internal::ExpressionPhaseData& d = data->phase_data[i];
    ExpressionPhaseSpec& p = data->phases[i];
    d.programs[0] = &p.vector_field;
    d.programs[1] = &p.integrals;
    d.programs[2] = &p.event;
    d.programs[3] = &p.reset;
    d.phase = &p;
    d.parameters = data->values.data();
    for (int k = 0; k < 4; ++k) {
      d.compiled[k] = entry(i, static_cast<ProgramKind>(k));
      d.compiled_param_jets[k] = param_jet_entry(i, static_cast<ProgramKind>(k));
    }
  }
  internal::ExpressionPhaseData& anchor = data->phase_data[m];
  anchor.programs[static_cast<int>(ProgramKind::kAnchor)] = &data->anchor;
  anchor.parameters = data->values.data();
  anchor.compiled[static_cast<int>(ProgramKind::kAnchor)] = entry(m, ProgramKind::kAnchor);
  anchor.compiled_param_jets[static_cast<int>(ProgramKind::kAnchor)] = param_jet_entry(m, ProgramKind::kAnchor);
}

class ExpressionParameterBlock final : public ParameterBlock,
                                       public internal::ParameterSeeding<internal::ExpressionPhaseData> {
 public:
  explicit ExpressionParameterBlock(std::unique_ptr<ExpressionModelData> data) : data_(std::move(data)) {}
  const std::vector<ParameterInfo>& infos() const override { return data_->infos; }
  double Get(int index) const override { return data_->values[index]; }
  void Set(int index, double value) override { data_->values[index] = value; }
  std::unique_ptr<ParameterBlock> Clone() const override {
    auto copy = std::make_unique<ExpressionModelData>(*data_);
    BindPhaseData(copy.get());
    return std::make_unique<ExpressionParameterBlock>(std::move(copy));
  }
  const void* BindingFor(int slot) const override { return &data_->phase_data.at(slot); }

  bool can_seed() const override { return true; }
  internal::ExpressionJetData<internal::ParamJet> SeedParamJets(const internal::ExpressionPhaseData& values,
                                                                 int index) const override {
    return Seed<internal::ParamJet>(values, index, internal::MakeParamJet);
  }
  internal::ExpressionJetData<internal::MixedJet> SeedMixedJets(const internal::ExpressionPhaseData& values,
                                                                 int index) const override {
    return Seed<internal::MixedJet>(values, index, internal::MakeMixedJet);
  }

 private:
  template <class S, class Make>
  internal::ExpressionJetData<S> Seed(const internal::ExpressionPhaseData& values, int index, Make make) const {
    // Seeded once per right-hand side with a free parameter: per-thread storage, no allocation once warm.
    thread_local std::vector<S> storage;
    storage.resize(data_->values.size());
    for (int i = 0; i < static_cast<int>(data_->values.size()); ++i) {
      storage[i] = make(data_->values[i], i == index ? 1.0 : 0.0);
    }
    internal::ExpressionJetData<S> d;
    d.base = &values;
    d.parameters = storage.data();
    return d;
  }

  std::unique_ptr<ExpressionModelData> data_;
};

}  // namespace

std::string internal::ExpressionFunctions::ExplainNonFinite(const Vector& x, const ExpressionPhaseData& d) {
  if (d.phase == nullptr || d.phase->coordinates.empty() || !x.allFinite()) return "";
  const ExpressionProgram& program = d.phase->mass_matrix;
  std::vector<double> entries(program.num_outputs());
  for (int k = 0; k < program.num_outputs(); ++k) entries[k] = program.EvaluateScalar(x.data(), d.parameters, k);
  std::vector<std::string> names;
  std::vector<double> q;
  for (int c : d.phase->coordinates) {  // ignorable coordinates (-1) do not enter M
    names.push_back(c >= 0 ? d.phase->state_names[c] : "(ignorable)");
    q.push_back(c >= 0 ? x(c) : 0.0);
  }
  return ExplainMassMatrix(entries, names, q);
}

HybridModel BuildExpressionModel(ExpressionModelSpec spec, std::shared_ptr<const CompiledPrograms> compiled) {
  const int m = static_cast<int>(spec.phases.size());
  if (m == 0) throw std::invalid_argument("model '" + spec.name + "': no phases");
  auto data = std::make_unique<ExpressionModelData>();
  data->infos = spec.parameters;
  for (const ParameterInfo& p : data->infos) data->values.push_back(p.default_value);
  data->phases = std::move(spec.phases);
  data->anchor = std::move(spec.anchor);
  data->compiled = std::move(compiled);
  const int expected_entries = 5 * m + 5;
  if (data->compiled && static_cast<int>(data->compiled->entries.size()) != expected_entries) {
    throw std::invalid_argument("model '" + spec.name + "': compiled code does not match the model");
  }
  BindPhaseData(data.get());
  ExpressionModelData* view = data.get();
  auto block = std::make_unique<ExpressionParameterBlock>(std::move(data));

  using ExpressionPhase = internal::AutoDiffPhase<internal::ExpressionFunctions, internal::ExpressionPhaseData>;
  using ExpressionAnchor = internal::AutoDiffAnchor<internal::ExpressionFunctions, internal::ExpressionPhaseData>;
  std::vector<std::unique_ptr<Phase>> phases;
  for (int i = 0; i < m; ++i) {
    const ExpressionPhaseSpec& p = view->phases[i];
    const int n = static_cast<int>(p.state_names.size());
    if (n < 1) throw std::invalid_argument("model '" + spec.name + "', phase '" + p.name + "': no states");
    const int next_dim = static_cast<int>(view->phases[(i + 1) % m].state_names.size());
    // Above the fixed-capacity jets' kMaxPhaseDim: the dynamic-size path (large_expression_phase.h).
    if (n > kMaxPhaseDim) {
      phases.push_back(std::make_unique<internal::LargeExpressionPhase>(p.name, p.state_names, next_dim,
                                                                        p.integrals.num_outputs(), p.typical_state,
                                                                        block.get(), i));
    } else {
      phases.push_back(std::make_unique<ExpressionPhase>(p.name, p.state_names, next_dim, p.typical_state, block.get(), i));
    }
  }
  internal::ValidatePhaseSizes(spec.name, phases);
  std::unique_ptr<Anchor> anchor_fn;
  if (static_cast<int>(view->phases[0].state_names.size()) > kMaxPhaseDim) {
    anchor_fn = std::make_unique<internal::LargeExpressionAnchor>(block.get(), m);
  } else {
    anchor_fn = std::make_unique<ExpressionAnchor>(block.get(), m);
  }
  HybridModel model(spec.name, spec.description, std::move(block), std::move(phases), std::move(anchor_fn));
  for (ModelSymmetry& s : spec.symmetries) model.AddSymmetry(std::move(s));
  for (Observable& o : spec.observables) model.AddObservable(std::move(o));
  model.SetSetup(std::move(spec.setup));
  return model;
}

}  // namespace hybridcont
