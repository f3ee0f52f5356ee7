#include "hybridcont/statebased_shooting.h"

#include <stdexcept>

namespace hybridcont {

StateBasedShooting::StateBasedShooting(const HybridModel& model, PoincareOptions options)
    : model_(&model), map_(model, options), layout_(model), n1_(model.phase(0).dim()),
      k_(model.num_first_integrals()), fixed_levels_(Vector::Zero(model.num_first_integrals() - 1)) {
  // Same names as the time-based layout for x̄_1, xi and H̄.
  const std::vector<std::string>& tb = layout_.unknown_names();
  for (int i = 0; i < n1_; ++i) names_.push_back(tb[layout_.state_offset(0) + i]);
  for (int j = 0; j < k_; ++j) names_.push_back(tb[layout_.xi_index(j)]);
  names_.push_back(tb[layout_.H_index()]);
}

void StateBasedShooting::SetFixedLevels(const Vector& levels) {
  if (levels.size() != fixed_levels_.size()) {
    throw std::invalid_argument("SetFixedLevels: expected " + std::to_string(fixed_levels_.size()) +
                                " levels (first integrals 2..k), got " + std::to_string(levels.size()));
  }
  fixed_levels_ = levels;
  cache_valid_ = false;
}

std::vector<Symmetry> StateBasedShooting::symmetries() const {
  std::vector<Symmetry> generators;
  for (const ModelSymmetry& s : model_->symmetries()) {
    if (s.reverses_time) continue;
    Vector signs = Vector::Ones(num_unknowns());
    signs.head(n1_) = s.state_signs[0];
    generators.push_back({s.name, std::move(signs)});
  }
  return SymmetryGroup(generators);
}

std::unique_ptr<ShootingProblem> StateBasedShooting::CopyWithTolerances(double tolerance_factor) const {
  PoincareOptions options = map_.options();
  options.event.integrator.rtol *= tolerance_factor;
  options.event.integrator.atol *= tolerance_factor;
  auto copy = std::make_unique<StateBasedShooting>(*model_, options);
  copy->SetFixedLevels(fixed_levels_);
  return copy;
}

Vector StateBasedShooting::FromTimeBased(const Vector& u_time) const {
  if (u_time.size() != layout_.num_unknowns()) {
    throw std::invalid_argument("StateBasedShooting::FromTimeBased: u has " + std::to_string(u_time.size()) +
                                " entries, the time-based layout has " + std::to_string(layout_.num_unknowns()));
  }
  Vector u(num_unknowns());
  u.head(n1_) = u_time.segment(layout_.state_offset(0), n1_);
  u.segment(n1_, k_) = u_time.segment(layout_.xi_index(), k_);
  u(H_index()) = u_time(layout_.H_index());
  return u;
}

EvaluationStatus StateBasedShooting::ToTimeBased(const Vector& u_state, Vector* u_time) {
  if (u_state.size() != num_unknowns()) {
    throw std::invalid_argument("StateBasedShooting::ToTimeBased: u has " + std::to_string(u_state.size()) +
                                " entries, expected " + std::to_string(num_unknowns()));
  }
  if (map_.options().section != PoincareSection::kAnchor) {
    return EvaluationStatus::Failure("ToTimeBased needs the anchor section (the time-based layout ends at the anchor)");
  }
  PoincareResult res;
  map_.Evaluate(u_state.head(n1_), u_state.segment(n1_, k_), false, &res);
  CountWork(res.counters);
  if (!res.ok()) return EvaluationStatus::Failure("state-based pass: " + res.message);
  Vector& u = *u_time;
  u.setZero(layout_.num_unknowns());
  for (int i = 0; i < layout_.num_segments(); ++i) {
    u(layout_.time_index(i)) = res.durations[i];
    u.segment(layout_.state_offset(i), layout_.dim(i)) = res.starts[i];
  }
  u.segment(layout_.xi_index(), k_) = u_state.segment(n1_, k_);
  u(layout_.H_index()) = u_state(H_index());
  return {};
}

EvaluationStatus StateBasedShooting::Evaluate(const Vector& u, Vector* r, Matrix* dr) {
  if (u.size() != num_unknowns()) {
    throw std::invalid_argument("StateBasedShooting::Evaluate: u has " + std::to_string(u.size()) +
                                " entries, expected " + std::to_string(num_unknowns()));
  }
  const bool need_jacobian = dr != nullptr;
  if (!cache_valid_ || (need_jacobian && !cached_jacobian_) || cached_u_ != u) {
    CountEvaluation();
    map_.Evaluate(u.head(n1_), u.segment(n1_, k_), need_jacobian, &map_result_);
    CountWork(map_result_.counters);
    cached_u_ = u;
    cached_jacobian_ = need_jacobian;
    cache_valid_ = true;
  }
  if (!map_result_.ok()) return EvaluationStatus::Failure("state-based map: " + map_result_.message);

  const int N = num_equations();
  const auto x0 = u.head(n1_);
  model_->phase(0).FirstIntegrals(x0, &H_, dr ? &dH_ : nullptr, nullptr);
  if (r) {
    r->resize(N);
    r->head(n1_) = map_result_.x - x0;
    (*r)(n1_) = H_(0) - u(H_index());
    for (int j = 1; j < k_; ++j) (*r)(n1_ + j) = H_(j) - fixed_levels_(j - 1);
    if (!r->allFinite()) return EvaluationStatus::Failure("state-based map: non-finite residual");
  }
  if (dr) {
    dr->setZero(N, N + 1);
    dr->topLeftCorner(n1_, n1_) = map_result_.dP_dx0 - Matrix::Identity(n1_, n1_);
    dr->block(0, n1_, n1_, k_) = map_result_.dP_dxi;
    dr->block(n1_, 0, k_, n1_) = dH_;
    (*dr)(n1_, H_index()) = -1.0;
    if (!dr->allFinite()) return EvaluationStatus::Failure("state-based map: Jacobian has non-finite entries");
  }
  return {};
}

}  // namespace hybridcont
