#include "hybridcont/timebased_shooting.h"

#include <algorithm>
#include <exception>
#include <limits>
#include <stdexcept>
#include <thread>

#include "hybridcont/orbit_observables.h"
#include "shooting/worker_team.h"

namespace hybridcont {

namespace {
// The model evaluated on: the caller's, or with free parameters a copy of it (checked first).
std::unique_ptr<HybridModel> OwnCopyIfFree(const HybridModel& model, const FreeParameters& free) {
  if (free.parameters.empty()) return nullptr;
  if (!model.has_parameter_derivatives()) {
    throw std::invalid_argument("model '" + model.name() +
                                "' cannot differentiate with respect to its parameters, so none can be free (a C++ "
                                "model needs a parameter struct over the scalar type: model_builder.h)");
  }
  if (!model.is_cloneable()) {
    throw std::invalid_argument("model '" + model.name() + "' has phases that cannot be copied, so none of its "
                                "parameters can be free");
  }
  return std::make_unique<HybridModel>(model.Clone());
}
}  // namespace

TimeBasedShooting::TimeBasedShooting(const HybridModel& model, IntegratorOptions options, FreeParameters free)
    : own_model_(OwnCopyIfFree(model, free)),
      model_(own_model_ ? own_model_.get() : &model),
      options_(options),
      free_(std::move(free)),
      threads_(std::max(1, static_cast<int>(std::thread::hardware_concurrency()))),
      layout_(model, free_),
      fixed_levels_(Vector::Zero(std::max(0, model.num_first_integrals() - 1))) {
  if (const std::string why = options.Validate(); !why.empty()) throw std::invalid_argument(why);
  const int m = model_->num_phases();
  std::vector<int> parameters;
  for (int i = 0; i < layout_.num_free_parameters(); ++i) parameters.push_back(layout_.parameter_model_index(i));
  for (int i = 0; i <= m; ++i) {
    integrators_.emplace_back(model_->phase(i), options);
    integrators_.back().set_free_parameters(parameters);
  }
  flows_.resize(m + 1);
  if (layout_.num_observables() > 0) observables_ = std::make_unique<ObservableEvaluator>(*model_, layout_, options);
}

void TimeBasedShooting::SetFixedValue(int i, double value) {
  layout_.set_fixed_value(i, value);
  free_.fixed.at(i).second = value;
  cache_valid_ = false;
}

EvaluationStatus TimeBasedShooting::SetParameters(const Vector& u) {
  for (int i = 0; i < layout_.num_free_parameters(); ++i) {
    const int index = layout_.parameter_model_index(i);
    const double value = u(layout_.parameter_index(i));
    if (value == model_->parameter_value(index)) continue;
    try {
      own_model_->SetParameterValue(index, value);
    } catch (const std::invalid_argument& e) {
      return EvaluationStatus::Failure(e.what());
    }
  }
  return {};
}

Vector TimeBasedShooting::CompleteUnknowns(const Vector& u) {
  const int s = layout_.num_observables();
  HYBRIDCONT_DEMAND(u.size() == layout_.num_unknowns() - s);
  Vector v = Vector::Zero(layout_.num_unknowns());
  v.head(u.size()) = u;
  const bool parameters_ok = SetParameters(v).ok;
  for (int j = 0; j < s; ++j) {
    double value = std::numeric_limits<double>::quiet_NaN();
    if (parameters_ok && !observables_->Evaluate(layout_.observable_model_index(j), v, &value, nullptr).ok) {
      value = std::numeric_limits<double>::quiet_NaN();
    }
    v(layout_.observable_index(j)) = value;
  }
  return v;
}

TimeBasedShooting::~TimeBasedShooting() = default;
TimeBasedShooting::TimeBasedShooting(TimeBasedShooting&&) noexcept = default;
TimeBasedShooting& TimeBasedShooting::operator=(TimeBasedShooting&&) noexcept = default;

void TimeBasedShooting::SetFixedLevels(const Vector& levels) {
  if (levels.size() != fixed_levels_.size()) {
    throw std::invalid_argument("SetFixedLevels: expected " + std::to_string(fixed_levels_.size()) +
                                " levels (first integrals 2..k), got " + std::to_string(levels.size()));
  }
  fixed_levels_ = levels;
  cache_valid_ = false;
}

void TimeBasedShooting::set_threads(int threads) {
  if (threads < 1) {
    throw std::invalid_argument("TimeBasedShooting::set_threads: threads = " + std::to_string(threads) +
                                " must be >= 1");
  }
  threads_ = threads;
  team_.reset();
}

std::vector<Symmetry> TimeBasedShooting::symmetries() const {
  // An observable's value under a symmetry is not declared (a mean speed flips with the mirror, an apex
  // height does not): with observables among the unknowns, the images are traced, not mapped.
  if (layout_.num_observables() > 0) return {};
  std::vector<Symmetry> generators;
  for (const ModelSymmetry& s : model_->symmetries()) {
    const double time = s.reverses_time ? -1.0 : 1.0;
    Vector signs = Vector::Ones(layout_.num_unknowns());
    for (int i = 0; i < layout_.num_segments(); ++i) {
      signs(layout_.time_index(i)) = time;
      signs.segment(layout_.state_offset(i), layout_.dim(i)) = s.state_signs[i % model_->num_phases()];
    }
    for (int j = 0; j < layout_.num_first_integrals(); ++j) signs(layout_.xi_index(j)) = time;
    generators.push_back({s.name, std::move(signs)});
  }
  // An unknown held at c != 0 must not change sign: such an element maps solutions to u_j = -c.
  std::vector<Symmetry> group = SymmetryGroup(generators);
  std::erase_if(group, [&](const Symmetry& g) {
    for (int i = 0; i < layout_.num_fixed(); ++i) {
      if (g.signs(layout_.fixed_index(i)) < 0 && layout_.fixed_value(i) != 0.0) return true;
    }
    return false;
  });
  return group;
}

std::unique_ptr<ShootingProblem> TimeBasedShooting::CopyWithTolerances(double tolerance_factor) const {
  IntegratorOptions options = options_;
  options.rtol *= tolerance_factor;
  options.atol *= tolerance_factor;
  auto copy = std::make_unique<TimeBasedShooting>(*model_, options, free_);
  copy->SetFixedLevels(fixed_levels_);
  copy->set_threads(1);
  return copy;
}

EvaluationStatus TimeBasedShooting::Integrate(const Vector& u, bool sensitivities) {
  if (EvaluationStatus status = SetParameters(u); !status.ok) {
    cached_u_ = u;
    cached_sensitivities_ = sensitivities;
    cached_jacobian_tolerance_ = 0.0;
    cache_valid_ = true;
    cached_status_ = status;
    return status;
  }
  const int k = layout_.num_first_integrals();
  const auto xi = u.segment(layout_.xi_index(), k);
  const int segments = layout_.num_segments();
  const auto integrate = [&](int i) {
    const double t = u(layout_.time_index(i));
    const auto x0 = u.segment(layout_.state_offset(i), layout_.dim(i));
    integrators_[i].set_jacobian_tolerance(jacobian_tolerance_);
    integrators_[i].Integrate(x0, xi, t, sensitivities, &flows_[i]);
  };
  // Concurrently: every segment, then the loop below reads them in order, so the status (first failing
  // segment), the counters (segments up to it) and an exception (from the first segment that threw) are
  // those of the serial loop, which stops there.
  const int team =
      std::min(threads_, segments / (sensitivities ? kMinSegmentsPerThreadWithJacobian : kMinSegmentsPerThread));
  std::vector<std::exception_ptr> errors;
  if (team > 1) {
    if (team_ == nullptr) team_ = std::make_unique<internal::WorkerTeam>(threads_);
    errors.resize(segments);
    team_->ForEach(segments, team, [&](int i) {
      try {
        integrate(i);
      } catch (...) {
        errors[i] = std::current_exception();  // not on a helper thread: rethrown below, in order
      }
    });
  }
  EvaluationStatus status;
  bool relaxed = false;
  for (int i = 0; i < segments; ++i) {
    if (team <= 1) {
      integrate(i);
    } else if (errors[i]) {
      std::rethrow_exception(errors[i]);
    }
    CountWork(flows_[i].counters);
    relaxed = relaxed || flows_[i].jacobian_relaxed;
    if (!flows_[i].ok()) {
      status = EvaluationStatus::Failure("segment " + std::to_string(i + 1) + ": " + flows_[i].message);
      break;
    }
  }
  // The observables joining the unknowns, from their own integrations (orbit_observables.h).
  const int num_observables = layout_.num_observables();
  observable_values_.resize(num_observables);
  observable_gradients_.resize(num_observables, u.size());
  for (int j = 0; j < num_observables && status.ok; ++j) {
    RowVector gradient;
    status = observables_->Evaluate(layout_.observable_model_index(j), u, &observable_values_(j),
                                    sensitivities ? &gradient : nullptr);
    if (sensitivities) observable_gradients_.row(j) = gradient;
    CountWork(observables_->counters());
    observables_->ResetCounters();
  }
  cached_u_ = u;
  cached_sensitivities_ = sensitivities;
  // Exact unless some segment actually left a term out (zero durations, ξ = 0: nothing to leave out).
  cached_jacobian_tolerance_ = relaxed ? jacobian_tolerance_ : 0.0;
  cache_valid_ = true;
  cached_status_ = status;
  return status;
}

namespace {

// Where the Jacobian's blocks go: Add(row, col, block) adds a block (entries of blocks that overlap sum).
// Add(row, col, value) one entry, AddDiagonal(row, col, n, value) value·I (n x n). None allocates once warm.
struct DenseSink {
  Matrix* dr;
  template <class Block>
  void Add(int row, int col, const Block& block) {
    dr->block(row, col, block.rows(), block.cols()).noalias() += block;
  }
  void Add(int row, int col, double value) { (*dr)(row, col) += value; }
  void AddDiagonal(int row, int col, int n, double value) {
    dr->block(row, col, n, n).diagonal().array() += value;
  }
};
struct TripletSink {
  std::vector<Eigen::Triplet<double>>* triplets;
  Matrix* scratch;  // the block evaluated once (products are not re-evaluated per coefficient)
  template <class Block>
  void Add(int row, int col, const Block& block) {
    scratch->noalias() = block;
    for (int j = 0; j < scratch->cols(); ++j) {
      for (int i = 0; i < scratch->rows(); ++i) triplets->emplace_back(row + i, col + j, (*scratch)(i, j));
    }
  }
  void Add(int row, int col, double value) { triplets->emplace_back(row, col, value); }
  void AddDiagonal(int row, int col, int n, double value) {
    for (int i = 0; i < n; ++i) triplets->emplace_back(row + i, col + i, value);
  }
};

}  // namespace

EvaluationStatus TimeBasedShooting::Evaluate(const Vector& u, Vector* r, Matrix* dr) {
  if (dr == nullptr) return Assemble<DenseSink>(u, r, nullptr);
  const int N = layout_.num_equations();
  dr->setZero(N, layout_.num_unknowns());  // N + 1, or N for the square system of a model without first integral
  DenseSink sink{dr};
  const EvaluationStatus status = Assemble(u, r, &sink);
  if (status.ok && !dr->allFinite()) return EvaluationStatus::Failure("Jacobian has non-finite entries");
  return status;
}

EvaluationStatus TimeBasedShooting::EvaluateSparse(const Vector& u, Vector* r, SparseMatrix* dr) {
  if (dr == nullptr) return Assemble<TripletSink>(u, r, nullptr);
  triplets_.clear();
  TripletSink sink{&triplets_, &block_scratch_};
  const EvaluationStatus status = Assemble(u, r, &sink);
  if (!status.ok) return status;
  const int N = layout_.num_equations();
  dr->resize(N, layout_.num_unknowns());
  dr->setFromTriplets(triplets_.begin(), triplets_.end());
  if (!Eigen::Map<const Vector>(dr->valuePtr(), dr->nonZeros()).allFinite()) {
    return EvaluationStatus::Failure("Jacobian has non-finite entries");
  }
  return status;
}

template <class Sink>
EvaluationStatus TimeBasedShooting::Assemble(const Vector& u, Vector* r, Sink* dr) {

  if (u.size() != layout_.num_unknowns()) {
    throw std::invalid_argument("TimeBasedShooting::Evaluate: u has " + std::to_string(u.size()) +
                                " entries, expected " + std::to_string(layout_.num_unknowns()));
  }
  const bool need_sensitivities = dr != nullptr;
  if (!cache_valid_ || cached_u_ != u ||
      (need_sensitivities && (!cached_sensitivities_ || cached_jacobian_tolerance_ > jacobian_tolerance_))) {
    CountEvaluation();
    Integrate(u, need_sensitivities);
  }
  if (!cached_status_.ok) return cached_status_;

  const int m = model_->num_phases();
  const int k = layout_.num_first_integrals();
  const int q = layout_.num_free_parameters();
  const int N = layout_.num_equations();
  const auto xi = u.segment(layout_.xi_index(), k);
  if (r) r->resize(N);

  Vector f_tilde;
  for (int i = 0; i <= m; ++i) {
    const Phase& phase = model_->phase(i);
    const PhaseFlowResult& flow = flows_[i];
    const int next = (i + 1) % (m + 1);
    const int n_out = layout_.dim(next);
    const int row = layout_.block_row(i);
    double event;
    if (i < m) {
      // shooting + event: Delta_i(phi_i) - x̄_{i+1}, e_i(phi_i)
      phase.Reset(flow.x, &out_, dr ? &D_ : nullptr);
      event = phase.Event(flow.x, dr ? &de_ : nullptr);
    } else {
      // periodicity + anchor: phi_1(t_{m+1}, x̄_{m+1}) - x̄_1, a(phi_1)
      out_ = flow.x;
      if (dr) D_.setIdentity(n_out, n_out);
      event = model_->anchor().Evaluate(flow.x, dr ? &de_ : nullptr);
    }
    if (!out_.allFinite() || !std::isfinite(event)) {
      return EvaluationStatus::Failure("segment " + std::to_string(i + 1) + " (phase '" + phase.name() +
                                       "'): " + (i < m ? "reset map or event function" : "anchor") +
                                       " returned a non-finite value");
    }
    const auto x_next = u.segment(layout_.state_offset(next), n_out);
    if (r) {
      r->segment(row, n_out) = out_ - x_next;
      (*r)(row + n_out) = event;
    }
    if (dr) {
      phase.UnfoldedVectorField(flow.x, xi, &f_tilde, nullptr, nullptr);
      const int ct = layout_.time_index(i);
      dr->Add(row, ct, D_ * f_tilde);
      dr->Add(row, ct + 1, D_ * flow.Phi);
      dr->Add(row + n_out, ct, de_.dot(f_tilde));
      dr->Add(row + n_out, ct + 1, de_ * flow.Phi);
      if (k > 0) {
        dr->Add(row, layout_.xi_index(), D_ * flow.Psi.leftCols(k));
        dr->Add(row + n_out, layout_.xi_index(), de_ * flow.Psi.leftCols(k));
      }
      // Free parameters: through the flow (D Psi_p, de Psi_p) and the reset/event (anchor) themselves.
      for (int p = 0; p < q; ++p) {
        const int col = layout_.parameter_index(p);
        const int index = layout_.parameter_model_index(p);
        double de_dp = 0.0;
        if (i < m) {
          phase.ParameterDerivatives(flow.x, index, nullptr, nullptr, &de_dp, &dp_out_);
        } else {
          dp_out_.setZero(n_out);
          de_dp = model_->anchor().ParameterDerivative(flow.x, index);
        }
        dr->Add(row, col, D_ * flow.Psi.col(k + p) + dp_out_);
        dr->Add(row + n_out, col, de_.dot(flow.Psi.col(k + p)) + de_dp);
      }
      // C: -I on x̄_{i+1}
      dr->AddDiagonal(row, layout_.state_offset(next), n_out, -1.0);
    }
  }
  // First integrals at x̄_1: H_1 - H̄ (unknown level), H_j - H̄_j fixed for j >= 2 (none without).
  if (k > 0) AssembleFirstIntegrals(u, r, dr);
  // Fixing rows: u_j − c_j.
  for (int i = 0; i < layout_.num_fixed(); ++i) {
    if (r) (*r)(layout_.fixed_row(i)) = u(layout_.fixed_index(i)) - layout_.fixed_value(i);
    if (dr) dr->Add(layout_.fixed_row(i), layout_.fixed_index(i), 1.0);
  }
  // Observables: o_j − g_j(u), gradient row −∇g_j (zero in the observables' own columns) plus e_{o_j}.
  for (int j = 0; j < layout_.num_observables(); ++j) {
    const int row = layout_.observable_row(j);
    if (r) (*r)(row) = u(layout_.observable_index(j)) - observable_values_(j);
    if (dr) {
      dr->Add(row, 0, -observable_gradients_.row(j));
      dr->Add(row, layout_.observable_index(j), 1.0);
    }
  }
  return r == nullptr || r->allFinite() ? EvaluationStatus{}
                                        : EvaluationStatus::Failure("first integral returned a non-finite value");
}

template <class Sink>
void TimeBasedShooting::AssembleFirstIntegrals(const Vector& u, Vector* r, Sink* dr) {
  const int k = layout_.num_first_integrals();
  const int q = layout_.num_free_parameters();
  const int n1 = layout_.dim(0);
  const auto x1 = u.segment(layout_.state_offset(0), n1);
  model_->phase(0).FirstIntegrals(x1, &H_, dr ? &dH_ : nullptr, nullptr);
  const int row = layout_.first_integral_row();
  if (r) {
    (*r)(row) = H_(0) - u(layout_.H_index());
    for (int j = 1; j < k; ++j) (*r)(row + j) = H_(j) - fixed_levels_(j - 1);
  }
  if (dr) {
    dr->Add(row, layout_.state_offset(0), dH_);
    dr->Add(row, layout_.H_index(), -1.0);
    for (int p = 0; p < q; ++p) {
      model_->phase(0).ParameterDerivatives(x1, layout_.parameter_model_index(p), nullptr, &dp_H_, nullptr, nullptr);
      dr->Add(row, layout_.parameter_index(p), dp_H_);
    }
  }
}

}  // namespace hybridcont
