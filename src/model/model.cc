#include "hybridcont/model.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <charconv>
#include <stdexcept>

namespace hybridcont {

namespace {
// Shortest decimal form that reads back to the same double ("40", "0.1", "1e-12").
std::string FormatNumber(double v) {
  char buffer[32];
  const auto [end, ec] = std::to_chars(buffer, buffer + sizeof buffer, v);
  return ec == std::errc() ? std::string(buffer, end) : std::to_string(v);
}
}  // namespace

Phase::Phase(std::string name, std::vector<std::string> state_names, int next_dim, int num_first_integrals,
             Vector typical_state)
    : name_(std::move(name)),
      state_names_(std::move(state_names)),
      next_dim_(next_dim),
      num_first_integrals_(num_first_integrals),
      typical_state_(std::move(typical_state)) {}

void Phase::ComputeUnfoldedVectorField(const Eigen::Ref<const Vector>& x, const Eigen::Ref<const Vector>& xi,
                                       Vector* f_tilde, Matrix* A, Matrix* B, bool include_hessian_term) const {
  const bool dissipative = (xi.array() != 0.0).any();
  const bool need_hessians = A != nullptr && dissipative && include_hessian_term;
  const bool need_gradients = B != nullptr || dissipative;
  VectorField(x, f_tilde, A);
  if (!need_gradients) return;
  // Per-thread scratch: this runs once per right-hand-side evaluation and must not allocate.
  thread_local Vector H;
  thread_local Matrix dH;
  thread_local std::vector<Matrix> d2H;
  FirstIntegrals(x, &H, &dH, need_hessians ? &d2H : nullptr);
  if (dissipative) {
    f_tilde->noalias() += dH.transpose() * xi;
    if (need_hessians) {
      for (int j = 0; j < xi.size(); ++j) *A += xi(j) * d2H[j];
    }
  }
  if (B) *B = dH.transpose();
}

HybridModel::HybridModel(std::string name, std::string description, std::unique_ptr<ParameterBlock> parameters,
                         std::vector<std::unique_ptr<Phase>> phases, std::unique_ptr<Anchor> anchor)
    : name_(std::move(name)),
      description_(std::move(description)),
      parameters_(std::move(parameters)),
      phases_(std::move(phases)),
      anchor_(std::move(anchor)) {
  for (const ParameterInfo& p : parameters_->infos()) {
    if (!p.range.Contains(p.default_value)) {
      throw std::invalid_argument("model '" + name_ + "': the default of parameter '" + p.name + "', " +
                                  FormatNumber(p.default_value) + ", is outside its range " + p.range.ToString());
    }
  }
}

void HybridModel::AddSymmetry(ModelSymmetry symmetry) {
  const std::string where = "model '" + name_ + "', symmetry '" + symmetry.name + "'";
  if (symmetry.name.empty()) throw std::invalid_argument("model '" + name_ + "': a symmetry needs a name");
  for (const ModelSymmetry& known : symmetries_) {
    if (known.name == symmetry.name) throw std::invalid_argument(where + ": declared twice");
  }
  if (symmetry.state_signs.size() != phases_.size()) {
    throw std::invalid_argument(where + ": " + std::to_string(symmetry.state_signs.size()) +
                                " sign vectors for " + std::to_string(phases_.size()) + " phases");
  }
  bool identity = !symmetry.reverses_time;
  for (size_t i = 0; i < phases_.size(); ++i) {
    const Vector& signs = symmetry.state_signs[i];
    const std::string phase = where + ", phase '" + phases_[i]->name() + "'";
    if (signs.size() != phases_[i]->dim()) {
      throw std::invalid_argument(phase + ": " + std::to_string(signs.size()) + " signs for " +
                                  std::to_string(phases_[i]->dim()) + " states");
    }
    for (int k = 0; k < signs.size(); ++k) {
      if (signs(k) != 1.0 && signs(k) != -1.0) {
        throw std::invalid_argument(phase + ": sign of state '" + phases_[i]->state_names()[k] + "' is " +
                                    std::to_string(signs(k)) + ", must be +1 or -1");
      }
      identity = identity && signs(k) == 1.0;
    }
  }
  if (identity) throw std::invalid_argument(where + ": is the identity");
  symmetries_.push_back(std::move(symmetry));
}

int HybridModel::FindObservable(const std::string& name) const {
  for (int i = 0; i < static_cast<int>(observables_.size()); ++i) {
    if (observables_[i].name == name) return i;
  }
  return -1;
}

bool IsLayoutName(const std::string& name) {
  const auto digits_from = [&](std::size_t i) {
    std::size_t j = i;
    while (j < name.size() && std::isdigit(static_cast<unsigned char>(name[j]))) ++j;
    return j;
  };
  if (name == "H" || name == "T" || name == "xi") return true;
  if (name.rfind("xi", 0) == 0) return digits_from(2) == name.size() && name.size() > 2;
  if (name[0] == 't') return name.size() > 1 && digits_from(1) == name.size();
  if (name[0] == 'x') {
    const std::size_t j = digits_from(1);
    return j > 1 && j < name.size() && name[j] == '_';
  }
  return false;
}

void HybridModel::AddObservable(Observable observable) {
  const std::string where = "model '" + name_ + "', observable '" + observable.name + "'";
  if (observable.name.empty()) throw std::invalid_argument("model '" + name_ + "': an observable needs a name");
  if (FindObservable(observable.name) >= 0) throw std::invalid_argument(where + ": declared twice");
  if (FindParameter(observable.name) >= 0) throw std::invalid_argument(where + ": is the name of a parameter");
  if (IsLayoutName(observable.name)) {
    throw std::invalid_argument(where + ": is the name of an unknown of the orbit (t<i>, x<i>_<state>, xi, H, T)");
  }
  if (observable.kind == ObservableKind::kValue) {
    if (!observable.value) throw std::invalid_argument(where + ": a value observable needs its function");
  } else {
    if (observable.phases.size() != phases_.size()) {
      throw std::invalid_argument(where + ": " + std::to_string(observable.phases.size()) + " phase functions for " +
                                  std::to_string(phases_.size()) + " phases");
    }
    if (std::none_of(observable.phases.begin(), observable.phases.end(), [](const auto& g) { return g != nullptr; })) {
      throw std::invalid_argument(where + ": names no phase");
    }
  }
  if (observable.constraint && observable.kind != ObservableKind::kMinimum && observable.kind != ObservableKind::kFinal) {
    throw std::invalid_argument(where + ": a constraint is a minimum or a final value that must stay >= 0");
  }
  if (observable.kind == ObservableKind::kFinal &&
      std::count_if(observable.phases.begin(), observable.phases.end(), [](const auto& g) { return g != nullptr; }) != 1) {
    throw std::invalid_argument(where + ": a final value names exactly one phase");
  }
  observables_.push_back(std::move(observable));
}

std::vector<std::string> HybridModel::WordModeNames() const {
  if (automaton_) return automaton_->ModeNames(word_);
  std::vector<std::string> names;
  for (const auto& phase : phases_) names.push_back(phase->name());
  return names;
}

std::string ToString(ObservableKind kind) {
  switch (kind) {
    case ObservableKind::kValue: return "value";
    case ObservableKind::kIntegral: return "integral";
    case ObservableKind::kMean: return "mean";
    case ObservableKind::kMinimum: return "minimum";
    case ObservableKind::kMaximum: return "maximum";
    case ObservableKind::kFinal: return "final";
  }
  HYBRIDCONT_UNREACHABLE();
}

int HybridModel::ParameterIndex(const std::string& name) const {
  const auto& infos = parameters_->infos();
  for (int i = 0; i < static_cast<int>(infos.size()); ++i) {
    if (infos[i].name == name) return i;
  }
  std::string known;
  for (const auto& info : infos) known += (known.empty() ? "" : ", ") + info.name;
  throw std::invalid_argument("model '" + name_ + "' has no parameter '" + name + "' (parameters: " + known + ")");
}

double HybridModel::parameter(const std::string& name) const { return parameters_->Get(ParameterIndex(name)); }

int HybridModel::FindParameter(const std::string& name) const {
  const auto& infos = parameters_->infos();
  for (int i = 0; i < static_cast<int>(infos.size()); ++i) {
    if (infos[i].name == name) return i;
  }
  return -1;
}

void HybridModel::SetParameter(const std::string& name, double value) { SetParameterValue(ParameterIndex(name), value); }

void HybridModel::SetParameterValue(int index, double value) {
  HYBRIDCONT_DEMAND(index >= 0 && index < static_cast<int>(parameters_->infos().size()));
  const std::string& name = parameters_->infos()[index].name;
  if (!std::isfinite(value)) {
    throw std::invalid_argument("parameter '" + name + "' of model '" + name_ + "' must be finite, got " +
                                std::to_string(value));
  }
  const ParameterRange& range = parameters_->infos()[index].range;
  if (!range.Contains(value)) {
    throw std::invalid_argument("parameter '" + name + "' of model '" + name_ + "' = " + FormatNumber(value) +
                                " is outside its range " + range.ToString() + " (" +
                                parameters_->infos()[index].description + ")");
  }
  parameters_->Set(index, value);
}

bool HybridModel::has_parameter_derivatives() const {
  for (const auto& phase : phases_) {
    if (!phase->has_parameter_derivatives()) return false;
  }
  return anchor_->has_parameter_derivatives();
}

bool HybridModel::is_cloneable() const {
  std::unique_ptr<ParameterBlock> block = parameters_->Clone();
  if (!block) return false;
  for (const auto& phase : phases_) {
    if (!phase->CloneWith(*block)) return false;
  }
  return anchor_->CloneWith(*block) != nullptr;
}

HybridModel HybridModel::Clone() const {
  std::unique_ptr<ParameterBlock> block = parameters_->Clone();
  HYBRIDCONT_DEMAND(block != nullptr);
  std::vector<std::unique_ptr<Phase>> phases;
  for (const auto& phase : phases_) {
    phases.push_back(phase->CloneWith(*block));
    HYBRIDCONT_DEMAND(phases.back() != nullptr);
  }
  std::unique_ptr<Anchor> anchor = anchor_->CloneWith(*block);
  HYBRIDCONT_DEMAND(anchor != nullptr);
  HybridModel copy(name_, description_, std::move(block), std::move(phases), std::move(anchor));
  copy.symmetries_ = symmetries_;
  copy.observables_ = observables_;
  copy.setup_ = setup_;
  copy.automaton_ = automaton_;
  copy.word_ = word_;
  return copy;
}

void Phase::ParameterDerivatives(const Eigen::Ref<const Vector>&, int, Vector*, Vector*, double*, Vector*) const {
  HYBRIDCONT_DEMAND(has_parameter_derivatives());  // callers ask only phases that have them
  HYBRIDCONT_UNREACHABLE();
}

void Phase::UnfoldedFieldParameterDerivative(const Eigen::Ref<const Vector>&, const Eigen::Ref<const Vector>&, int,
                                             Vector*, bool) const {
  HYBRIDCONT_DEMAND(has_parameter_derivatives());  // callers ask only phases that have them
  HYBRIDCONT_UNREACHABLE();
}

double Anchor::ParameterDerivative(const Eigen::Ref<const Vector>&, int) const {
  HYBRIDCONT_DEMAND(has_parameter_derivatives());
  HYBRIDCONT_UNREACHABLE();
}

std::string ParameterRange::ToString() const {
  const auto end = [](double v) {
    return std::isinf(v) ? std::string(v < 0 ? "-inf" : "inf") : FormatNumber(v);
  };
  return std::string(lower_closed ? "[" : "(") + end(lower) + ", " + end(upper) + (upper_closed ? "]" : ")");
}

namespace internal {

void ValidatePhaseSizes(const std::string& model_name, const std::vector<std::unique_ptr<Phase>>& phases) {
  const int m = static_cast<int>(phases.size());
  for (int i = 0; i < m; ++i) {
    const Phase& p = *phases[i];
    const Phase& next = *phases[(i + 1) % m];
    const std::string where = "model '" + model_name + "', phase '" + p.name() + "'";
    Vector f, x_next, H;
    p.VectorField(p.typical_state(), &f, nullptr);
    if (f.size() != p.dim()) {
      throw std::invalid_argument(where + ": vector field has " + std::to_string(f.size()) + " entries, the phase " +
                                  std::to_string(p.dim()) + " states");
    }
    p.Reset(p.typical_state(), &x_next, nullptr);
    if (x_next.size() != next.dim()) {
      throw std::invalid_argument(where + ": reset map returns " + std::to_string(x_next.size()) +
                                  " states, next phase '" + next.name() + "' has " + std::to_string(next.dim()));
    }
    if (p.num_first_integrals() != phases.front()->num_first_integrals()) {
      throw std::invalid_argument(where + ": " + std::to_string(p.num_first_integrals()) +
                                  " first integrals, phase 1 has " +
                                  std::to_string(phases.front()->num_first_integrals()) +
                                  " (a hybrid first integral exists in every phase)");
    }
  }
}

}  // namespace internal
}  // namespace hybridcont
