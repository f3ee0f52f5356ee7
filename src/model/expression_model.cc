#include "hybridcont/expression_model.h"

#include <algorithm>

#include "expression_phases.h"
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

void internal::InterpretJets(const ExpressionProgram& program, const double* p, const Jet* x, Jet* out) {
  program.Evaluate(x, p, out);
}
void internal::InterpretJets(const ExpressionProgram& program, const double* p, const Jet2* x, Jet2* out) {
  program.Evaluate(x, p, out);
}

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

ExpressionModelSpec ExpressionWordSpec(const ExpressionModelSpec& spec, const Word& word) {
  HYBRIDCONT_DEMAND(spec.automaton != nullptr);
  const ExpressionAutomatonSpec& a = *spec.automaton;
  ExpressionModelSpec w;
  w.name = spec.name;
  w.description = spec.description;
  w.parameters = spec.parameters;
  w.anchor = spec.anchor;
  for (int k : word) w.phases.push_back(a.phases[k]);
  for (const ModelSymmetry& s : a.symmetries) {
    ModelSymmetry mapped = s;
    mapped.state_signs.clear();
    for (int k : word) mapped.state_signs.push_back(s.state_signs[k]);
    w.symmetries.push_back(std::move(mapped));
  }
  const bool file_word = word == a.word;
  for (const Observable& o : a.observables) {
    if (o.kind == ObservableKind::kValue) {
      if (file_word) w.observables.push_back(o);  // a function of the file word's unknowns
      continue;
    }
    Observable mapped = o;
    mapped.phases.clear();
    for (int k : word) mapped.phases.push_back(o.phases[k]);
    const bool any = std::any_of(mapped.phases.begin(), mapped.phases.end(), [](const auto& g) { return g != nullptr; });
    const int named = static_cast<int>(std::count_if(mapped.phases.begin(), mapped.phases.end(),
                                                     [](const auto& g) { return g != nullptr; }));
    // A final value names one phase: in a word that visits its mode twice it is the first visit's.
    if (o.kind == ObservableKind::kFinal && named > 1) {
      bool first = true;
      for (auto& g : mapped.phases) {
        if (g && !first) g = nullptr;
        if (g) first = false;
      }
    }
    if (any) w.observables.push_back(std::move(mapped));
  }
  w.setup = a.setup;
  if (!file_word) {
    w.setup.start = StartSpec{};
    w.setup.more_starts.clear();
    w.setup.word_starts.clear();
    w.setup.quantities.clear();
    w.setup.figures.clear();
  }
  // The family rules of this word: the file word's own, or those declared for it.
  auto& rules = w.setup.families;
  rules.erase(std::remove_if(rules.begin(), rules.end(),
                             [&](const FamilyRule& r) { return file_word ? !r.word.empty() : r.word != word; }),
              rules.end());
  for (FamilyRule& r : rules) r.word.clear();
  // Drawings of the modes the word visits (a file's drawing keyed by mode covers all of its words); those
  // for given segments of the file's word do not apply to another.
  auto& drawings = w.setup.drawing.phases;
  drawings.erase(std::remove_if(drawings.begin(), drawings.end(),
                                [&](const DrawingSpec::PhaseDrawing& d) {
                                  return (!file_word && !d.segments.empty()) ||
                                         std::none_of(w.phases.begin(), w.phases.end(),
                                                      [&](const ExpressionPhaseSpec& p) { return p.name == d.phase; });
                                }),
                 drawings.end());
  return w;
}

ExpressionModelSpec ExpressionCatalogueSpec(const ExpressionModelSpec& spec) {
  HYBRIDCONT_DEMAND(spec.automaton != nullptr);
  ExpressionModelSpec c;
  c.name = spec.name;
  c.parameters = spec.parameters;
  c.phases = spec.automaton->phases;
  c.anchor = spec.anchor;
  return c;
}

namespace {

// The compiled entry points of a word, picked from the catalogue's (null stays null).
std::shared_ptr<const CompiledPrograms> WordPrograms(const std::shared_ptr<const CompiledPrograms>& catalogue,
                                                     int num_catalogue_phases, const Word& word) {
  if (!catalogue) return nullptr;
  auto w = std::make_shared<CompiledPrograms>();
  const bool param_jets = !catalogue->param_jet_entries.empty();
  for (int k : word) {
    for (int kind = 0; kind < 5; ++kind) {
      w->entries.push_back(catalogue->entries[5 * k + kind]);
      if (param_jets) w->param_jet_entries.push_back(catalogue->param_jet_entries[5 * k + kind]);
    }
  }
  for (int kind = 0; kind < 5; ++kind) {
    w->entries.push_back(catalogue->entries[5 * num_catalogue_phases + kind]);
    if (param_jets) w->param_jet_entries.push_back(catalogue->param_jet_entries[5 * num_catalogue_phases + kind]);
  }
  w->library = catalogue->library;
  return w;
}

}  // namespace

HybridModel BuildExpressionModel(ExpressionModelSpec spec, std::shared_ptr<const CompiledPrograms> compiled) {
  if (spec.automaton) {
    std::shared_ptr<const ExpressionAutomatonSpec> a = spec.automaton;
    const int num_catalogue = static_cast<int>(a->phases.size());
    if (compiled && static_cast<int>(compiled->entries.size()) != 5 * num_catalogue + 5) {
      throw std::invalid_argument("model '" + spec.name + "': compiled code does not match the model");
    }
    // The factory keeps the spec (header, anchor, catalogue) and the compiled code alive.
    auto base = std::make_shared<const ExpressionModelSpec>(spec);
    auto automaton = HybridAutomaton::Create(
        spec.name, a->modes, a->transitions, a->anchor_mode, [base, compiled, num_catalogue](const Word& word) {
          ExpressionModelSpec w = ExpressionWordSpec(*base, word);
          return BuildExpressionModel(std::move(w), WordPrograms(compiled, num_catalogue, word));
        });
    return automaton->ModelForWord(a->word);
  }
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
      phases.push_back(internal::MakeExpressionPhase(n, p, next_dim, block.get(), i));
    }
  }
  internal::ValidatePhaseSizes(spec.name, phases);
  std::unique_ptr<Anchor> anchor_fn;
  if (static_cast<int>(view->phases[0].state_names.size()) > kMaxPhaseDim) {
    anchor_fn = std::make_unique<internal::LargeExpressionAnchor>(block.get(), m);
  } else {
    anchor_fn = internal::MakeExpressionAnchor(static_cast<int>(view->phases[0].state_names.size()), block.get(), m);
  }
  HybridModel model(spec.name, spec.description, std::move(block), std::move(phases), std::move(anchor_fn));
  for (ModelSymmetry& s : spec.symmetries) model.AddSymmetry(std::move(s));
  for (Observable& o : spec.observables) model.AddObservable(std::move(o));
  model.SetSetup(std::move(spec.setup));
  return model;
}

}  // namespace hybridcont
