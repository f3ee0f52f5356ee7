// A conservative hybrid dynamical system: a cyclic sequence of m >= 1 phases (paper §2.1).
//
// Phase i has a state x_i of its own dimension n_i, a vector field f_i, first integrals H_i (energy; one
// or more), an event function e_i whose *downward* zero crossing ends the phase (guard: e_i = 0 with
// de_i·f_i < 0) and a reset map Delta_i: x_i^- -> x_{i+1}^+ into the next phase (cyclic: m+1 = 1).
// Phase 1 carries the anchor a, whose downward zero crossing defines the Poincaré section.
//
// Users write the phase functions once, as templates over the scalar type, and assemble a model with
// ModelBuilder (model_builder.h), which differentiates them by forward-mode automatic differentiation;
// a model file (model_file.h) gives the same without C++. A user who wants analytic derivatives
// implements the `Phase` interface below directly.
//
// A model may declare symmetries (ModelBuilder::Symmetry): involutions that map orbits onto orbits, each a
// sign change of every phase's state, possibly with time reversal (durations and ξ change sign). The
// exploration then maps a half-branch that is the image of a traced one instead of tracing it
// (exploration.h, "Symmetries"); `hybridcont check` verifies each declaration on sample points.
#ifndef HYBRIDCONT_MODEL_H_
#define HYBRIDCONT_MODEL_H_

#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "hybridcont/hybrid_automaton.h"
#include "hybridcont/invariant.h"
#include "hybridcont/model_setup.h"
#include "hybridcont/observable.h"
#include "hybridcont/types.h"

namespace hybridcont {

// Largest state dimension of a phase written with automatic differentiation. The derivative part of the
// AD scalars is stack storage of this capacity (no heap allocation in the integrator's inner loop, in the
// spirit of Ceres' fixed-size Jets). 16 states = 8 degrees of freedom per phase; the nested scalars used
// for Hessians of H grow with its square and must stay below Eigen's 128 KiB stack-object limit.
inline constexpr int kMaxPhaseDim = 16;

// The vector type user model functions take and return, for a scalar type T (double or an AD scalar).
template <class T>
using StateVector = Eigen::Matrix<T, Eigen::Dynamic, 1, 0, kMaxPhaseDim, 1>;

// One phase of a hybrid system, type-erased. All derivative outputs are optional (nullptr: not wanted).
// Implementations must be thread-safe for concurrent const calls.
class Phase {
 public:
  Phase(std::string name, std::vector<std::string> state_names, int next_dim, int num_first_integrals,
        Vector typical_state);
  virtual ~Phase() = default;

  const std::string& name() const { return name_; }
  int dim() const { return static_cast<int>(state_names_.size()); }
  // Dimension of the phase the reset map leads into.
  int next_dim() const { return next_dim_; }
  const std::vector<std::string>& state_names() const { return state_names_; }
  int num_first_integrals() const { return num_first_integrals_; }
  // A state where the model functions are well defined; used to sample derivative checks.
  const Vector& typical_state() const { return typical_state_; }

  // f(x) and df/dx.
  virtual void VectorField(const Eigen::Ref<const Vector>& x, Vector* f, Matrix* df) const = 0;
  // H_j(x), j = 1..k; dH: k x n with row j = dH_j; d2H: k Hessians n x n.
  virtual void FirstIntegrals(const Eigen::Ref<const Vector>& x, Vector* H, Matrix* dH,
                              std::vector<Matrix>* d2H) const = 0;
  // e(x) and de/dx (row).
  virtual double Event(const Eigen::Ref<const Vector>& x, RowVector* de) const = 0;
  // Delta(x) into the next phase and D = dDelta/dx (next_dim x n).
  virtual void Reset(const Eigen::Ref<const Vector>& x, Vector* x_next, Matrix* D) const = 0;

  // The dissipative unfolding of eq. `hybridDynamicsNum`: f~(x, xi) = f(x) + sum_j xi_j dH_j(x)^T,
  // with A = df~/dx = df + sum_j xi_j d2H_j and B = df~/dxi = dH^T (n x k). Hessians are evaluated only
  // when some xi_j != 0 (their term vanishes exactly otherwise) and include_hessian_term is true; a
  // caller may drop the term when it is provably below its accuracy (see PhaseFlow).
  void UnfoldedVectorField(const Eigen::Ref<const Vector>& x, const Eigen::Ref<const Vector>& xi,
                           Vector* f_tilde, Matrix* A, Matrix* B, bool include_hessian_term = true) const {
    ComputeUnfoldedVectorField(x, xi, f_tilde, A, B, include_hessian_term);
  }

  // Derivatives with respect to a model parameter p (index into HybridModel::parameters()), for
  // continuation in p (shooting_layout.h, "Free parameters"). A phase that provides them says so here;
  // AutoDiffPhase does when the model's parameter struct is a template over the scalar type
  // (model_builder.h), and model-file phases always do.
  virtual bool has_parameter_derivatives() const { return false; }
  // At x: ∂f/∂p (n), ∂H_j/∂p (k), ∂e/∂p and ∂Δ/∂p (next_dim). Each output optional (nullptr: not wanted).
  virtual void ParameterDerivatives(const Eigen::Ref<const Vector>& x, int parameter, Vector* field,
                                    Vector* integrals, double* event, Vector* reset) const;
  // ∂f~/∂p = ∂f/∂p + Σ_j ξ_j ∂(∇H_j)/∂p (n) of the unfolded field at (x, ξ): the inhomogeneity of the
  // parameter's sensitivity equation (flow.h). The mixed term is left out when include_mixed_term is
  // false (it vanishes on every orbit, where ξ = 0; see TimeBasedShooting::kXiHessianTolerance).
  virtual void UnfoldedFieldParameterDerivative(const Eigen::Ref<const Vector>& x,
                                                const Eigen::Ref<const Vector>& xi, int parameter,
                                                Vector* dfdp, bool include_mixed_term = true) const;

  // Whether the event function bounds the state during the phase (a gap, like a height above the ground,
  // that a physical orbit never makes negative), as events do; false for an event that only marks a time
  // (the cut at the Poincaré section of a repeated model), which only its downward crossing matters for.
  virtual bool event_bounds_state() const { return true; }

  // Why the vector field is not finite at x, in words ("the mass matrix is not positive definite at ..."),
  // for the integrator's message; "" when the phase cannot tell (the default).
  virtual std::string ExplainNonFinite(const Eigen::Ref<const Vector>& x) const {
    (void)x;
    return "";
  }

  // The same phase reading its parameters from `parameters`, a copy of the block it was made with
  // (HybridModel::Clone). nullptr, the default: the phase cannot be rebound (a hand-written phase that
  // keeps its own parameters), and its model cannot be cloned.
  virtual std::unique_ptr<Phase> CloneWith(const class ParameterBlock& parameters) const {
    (void)parameters;
    return nullptr;
  }

 protected:
  // UnfoldedVectorField from the four functions above. A phase may override it to compute the same in one
  // pass (AutoDiffPhase does): it runs once per right-hand-side evaluation of the integrator.
  virtual void ComputeUnfoldedVectorField(const Eigen::Ref<const Vector>& x, const Eigen::Ref<const Vector>& xi,
                                          Vector* f_tilde, Matrix* A, Matrix* B, bool include_hessian_term) const;

 private:
  std::string name_;
  std::vector<std::string> state_names_;
  int next_dim_;
  int num_first_integrals_;
  Vector typical_state_;
};

// The anchor a: X_1 -> R of the Poincaré section (its downward zero crossing).
class Anchor {
 public:
  virtual ~Anchor() = default;
  virtual double Evaluate(const Eigen::Ref<const Vector>& x, RowVector* da) const = 0;
  // ∂a/∂p for model parameter `parameter` (Phase::has_parameter_derivatives). Default: unavailable.
  virtual bool has_parameter_derivatives() const { return false; }
  virtual double ParameterDerivative(const Eigen::Ref<const Vector>& x, int parameter) const;
  // Phase::CloneWith's twin.
  virtual std::unique_ptr<Anchor> CloneWith(const class ParameterBlock& parameters) const {
    (void)parameters;
    return nullptr;
  }
};

// The values a parameter may take: an interval with open or closed ends (default: every finite value).
// A value outside is refused by HybridModel::SetParameter with a message naming the parameter, the value
// and the interval, so that `--set k=-40` says that k must be positive instead of failing deep inside a run.
struct ParameterRange {
  double lower = -std::numeric_limits<double>::infinity();
  double upper = std::numeric_limits<double>::infinity();
  bool lower_closed = false;
  bool upper_closed = false;
  bool Contains(double v) const {
    return (lower_closed ? v >= lower : v > lower) && (upper_closed ? v <= upper : v < upper);
  }
  // "(0, inf)", "[0, 1]", "(-inf, inf)".
  std::string ToString() const;
  static ParameterRange Positive() { return {0.0, std::numeric_limits<double>::infinity(), false, false}; }
  static ParameterRange NonNegative() { return {0.0, std::numeric_limits<double>::infinity(), true, false}; }
  static ParameterRange Open(double lower, double upper) { return {lower, upper, false, false}; }
  static ParameterRange Closed(double lower, double upper) { return {lower, upper, true, true}; }
};

struct ParameterInfo {
  std::string name;
  double default_value;
  std::string description;
  ParameterRange range;
};

// Named real parameters of a model; the values live in a user struct P (see ModelBuilder).
class ParameterBlock {
 public:
  virtual ~ParameterBlock() = default;
  virtual const std::vector<ParameterInfo>& infos() const = 0;
  virtual double Get(int index) const = 0;
  virtual void Set(int index, double value) = 0;
  // An independent copy with the same values (HybridModel::Clone); nullptr: the block cannot be copied.
  virtual std::unique_ptr<ParameterBlock> Clone() const { return nullptr; }
  // What phase or anchor `slot` (phase index; the anchor is slot num_phases) reads its parameters from:
  // the typed storage that Phase::CloneWith binds a rebound phase to. Internal to the model builders.
  virtual const void* BindingFor(int slot) const {
    (void)slot;
    return nullptr;
  }
};

// An involution x_i -> S_i x_i (S_i = diag(state_signs[i]), entries ±1) of every phase that maps orbits of
// the model onto orbits. In both cases it must commute with the resets (Δ_i(S_i x) = S_{i+1} Δ_i(x)),
// leave the first integrals invariant (H(S x) = H(x)) and the events and the anchor invariant up to sign
// (e(S x) = ±e(x); the state-based map, which follows downward crossings, needs +). Without time
// reversal it commutes with the flows (f_i(S x) = S f_i(x)). With time reversal (mechanical
// reversibility: velocities flip) f_i(S x) = −S f_i(x) instead, so x(t) -> S x(−t); then durations and
// ξ change sign in the time-based map (the dissipative unfolding f + ξ∇H reverses with ξ). `hybridcont
// check` tests the time-based map's equivariance.
// Example, the SLIP: mirror x -> −x flips (α, α̇) in stance and (α, ẋ, α̇) in flight; time reversal
// flips the velocities (α̇, l̇) and (ẋ, ẏ, α̇).
struct ModelSymmetry {
  std::string name;
  std::vector<Vector> state_signs;  // one per phase, of the phase's dimension
  bool reverses_time = false;
};

// Whether `name` is, or could be, an unknown of the time-based layout (shooting_layout.h): t<digits>,
// x<digits>_<state>, xi, xi<digits>, H; or T, the period every observable expression knows. Observables
// (and the guard constraints "<transition>_guard" of an automaton) may not be named so.
bool IsLayoutName(const std::string& name);

// A hybrid model: phases, anchor and parameters. Move-only (phases refer to the parameter block it owns).
class HybridModel {
 public:
  HybridModel(std::string name, std::string description, std::unique_ptr<ParameterBlock> parameters,
              std::vector<std::unique_ptr<Phase>> phases, std::unique_ptr<Anchor> anchor);
  HybridModel(HybridModel&&) noexcept = default;
  HybridModel& operator=(HybridModel&&) noexcept = default;

  const std::string& name() const { return name_; }
  const std::string& description() const { return description_; }
  // m, the number of phases in one cycle.
  int num_phases() const { return static_cast<int>(phases_.size()); }
  // Phase i, 0-based and cyclic: phase(m) is phase(0) (shooting segment m). i >= 0.
  const Phase& phase(int i) const {
    HYBRIDCONT_DEMAND(i >= 0);
    return *phases_[i % phases_.size()];
  }
  int num_first_integrals() const { return phases_.front()->num_first_integrals(); }
  const Anchor& anchor() const { return *anchor_; }

  const std::vector<ParameterInfo>& parameters() const { return parameters_->infos(); }
  // Value of the named parameter; throws std::invalid_argument naming the parameter if unknown.
  double parameter(const std::string& name) const;
  // Index of the named parameter in parameters(), or -1.
  int FindParameter(const std::string& name) const;
  // Value of parameter `index`; sets it without the name lookup (the range is still enforced).
  double parameter_value(int index) const { return parameters_->Get(index); }
  void SetParameterValue(int index, double value);
  // Sets a parameter; throws std::invalid_argument if the name is unknown, the value is not finite or it
  // lies outside the parameter's range (the message names the parameter, the value and the range).
  void SetParameter(const std::string& name, double value);

  // The model's default run and presentation (model_setup.h).
  const ModelSetup& setup() const { return setup_; }
  void SetSetup(ModelSetup setup) { setup_ = std::move(setup); }

  // Every phase and the anchor differentiate with respect to parameters (Phase::ParameterDerivatives), so
  // a parameter can be a free unknown of the shooting maps.
  bool has_parameter_derivatives() const;
  // An independent model with the same phases, anchor, parameter values, symmetries and set-up, its
  // parameters its own: a shooting map whose parameter is an unknown sets it on its own copy, so that
  // copies evaluating on several threads never share a parameter. Only when is_cloneable().
  bool is_cloneable() const;
  HybridModel Clone() const;

  // Declared symmetries (generators; see ModelSymmetry).
  const std::vector<ModelSymmetry>& symmetries() const { return symmetries_; }
  // Adds one; throws std::invalid_argument naming the symmetry, phase and entry when the sign vectors do
  // not match the phases (count, dimension, entries ±1) or the name is empty or taken.
  void AddSymmetry(ModelSymmetry symmetry);

  // Declared observables and admissibility constraints (observable.h), in declaration order.
  const std::vector<Observable>& observables() const { return observables_; }
  // Index of the named observable, or -1.
  int FindObservable(const std::string& name) const;
  // Adds one; throws std::invalid_argument naming it when the name is empty, taken (by an observable, a
  // parameter or an unknown of the time-based layout), the function of its kind is missing, or a
  // constraint is not a minimum.
  void AddObservable(Observable observable);

  // The hybrid automaton this model is the word `word()` of (hybrid_automaton.h), or null: a cyclic model is
  // the automaton of its one cycle. Set by HybridAutomaton::ModelForWord; kept by Clone.
  const std::shared_ptr<const HybridAutomaton>& automaton() const { return automaton_; }
  const Word& word() const { return word_; }
  void SetAutomaton(std::shared_ptr<const HybridAutomaton> automaton, Word word) {
    automaton_ = std::move(automaton);
    word_ = std::move(word);
  }
  // The modes of the phases: the automaton's mode names along word(), else the phases' names.
  std::vector<std::string> WordModeNames() const;

 private:
  int ParameterIndex(const std::string& name) const;

  std::string name_;
  std::string description_;
  std::unique_ptr<ParameterBlock> parameters_;
  std::vector<std::unique_ptr<Phase>> phases_;
  std::unique_ptr<Anchor> anchor_;
  std::vector<ModelSymmetry> symmetries_;
  std::vector<Observable> observables_;
  ModelSetup setup_;
  std::shared_ptr<const HybridAutomaton> automaton_;
  Word word_;
};

}  // namespace hybridcont

#endif  // HYBRIDCONT_MODEL_H_
