// A hybrid model whose phase functions are compiled expressions (expression.h), as a model file gives them.
//
//   ExpressionModelSpec spec;                 // filled by the model-file reader (model_file.h)
//   HybridModel model = BuildExpressionModel(std::move(spec));
//
// Each phase is an AutoDiffPhase (internal/autodiff_phase.h) over functions that run an ExpressionProgram, so its
// derivatives are the same forward-mode automatic differentiation as a built-in model's: df, dH, ∇²H, de
// and dΔ are exact, never finite differences. Two ways to run a program:
//   - interpreted: ExpressionProgram::Evaluate<T>, one instruction at a time over the scalar type T;
//   - compiled: straight-line C++ generated from the same instructions (model_codegen.h), compiled by the
//     system compiler and loaded; CompiledPrograms holds its entry points. It computes the same operations
//     in the same order, so both give the same numbers (second derivatives: equal to rounding, the
//     interpreter runs them over nested jets, see InterpretAsBoundedDynamic).
#ifndef HYBRIDCONT_EXPRESSION_MODEL_H_
#define HYBRIDCONT_EXPRESSION_MODEL_H_

#include <algorithm>
#include <array>
#include <memory>
#include <string>
#include <type_traits>
#include <vector>

#include "hybridcont/expression.h"
#include "hybridcont/internal/autodiff_phase.h"
#include "hybridcont/model.h"

namespace hybridcont {

// The programs of one phase. Inputs of every program: the phase's states, in order.
struct ExpressionPhaseSpec {
  std::string name;
  std::vector<std::string> state_names;
  Vector typical_state;
  ExpressionProgram vector_field;  // n outputs
  ExpressionProgram integrals;     // k outputs (the first integrals H_1..H_k)
  ExpressionProgram event;         // 1 output
  ExpressionProgram reset;         // outputs: the next phase's states
  // A phase given by its mechanics (mechanics.h): its mass matrix M(q) (n × n outputs, row-major) and the
  // states holding q, so that a non-finite vector field where M is not positive definite is explained.
  // Empty otherwise.
  ExpressionProgram mass_matrix;
  std::vector<int> coordinates;
};

// A model file's hybrid automaton ([[modes]] and [[transitions]], hybrid_automaton.h): transition k is
// catalogue phase k, its source mode's programs with its guard as the event and its reset.
struct ExpressionAutomatonSpec {
  std::vector<AutomatonMode> modes;
  std::vector<AutomatonTransition> transitions;  // guards: the event programs as functions
  int anchor_mode = 0;
  Word word;                                     // the file's word: the run's start is an orbit of it
  std::vector<ExpressionPhaseSpec> phases;       // the catalogue, one per transition
  std::vector<ModelSymmetry> symmetries;         // signs per catalogue phase
  std::vector<Observable> observables;           // functions per catalogue phase
  ModelSetup setup;                              // the file's, for its word
};

struct ExpressionModelSpec {
  std::string name;
  std::string description;
  std::vector<ParameterInfo> parameters;  // values start at the defaults
  std::vector<ExpressionPhaseSpec> phases;
  ExpressionProgram anchor;  // over the first phase's states
  std::vector<ModelSymmetry> symmetries;
  std::vector<Observable> observables;  // and admissibility constraints (observable.h)
  ModelSetup setup;
  // Set for an automaton: the fields above are those of its word (ExpressionWordSpec).
  std::shared_ptr<const ExpressionAutomatonSpec> automaton;
};

// The cyclic model spec of one word of spec.automaton: phase i is catalogue phase word[i], symmetries and
// observables mapped along. Words other than the file's keep the run's bounds and drawing but not what names
// the file word's unknowns (starts, families, quantities, figures, value observables).
ExpressionModelSpec ExpressionWordSpec(const ExpressionModelSpec& spec, const Word& word);
// The catalogue as one spec (phases per transition, the anchor after them), what a model file compiles.
ExpressionModelSpec ExpressionCatalogueSpec(const ExpressionModelSpec& spec);

// The programs of a model, in the order phase 0 (vector field, integrals, event, reset), phase 1, ...,
// then the anchor.
enum class ProgramKind { kVectorField = 0, kIntegrals = 1, kEvent = 2, kReset = 3, kAnchor = 4 };

// Scalar types a program runs over: double, the fixed-size first-order jet of the phase's dimension,
// the fixed-size second-order jet (HessianJet), and the bounded-dynamic jets used above kMaxFixedJetDim.
// kValueJacobian and kValueHessian are no scalar types but entries of phases above kMaxPhaseDim (the
// dynamic-size path, which has no jets of a fixed capacity to pass), all doubles: fn(x, p, out) with x the n
// states and out the k outputs followed by their k x n Jacobian, row-major, and for kValueHessian then the k
// Hessians, n x n each, row-major. Generated code evaluates them over jets of the phase's exact dimension on
// the stack (the Hessian row by row: a one-direction jet over the n-direction one).
enum class ScalarKind {
  kDouble = 0,
  kFixedJet = 1,
  kHessianJet = 2,
  kDynamicJet = 3,
  kDynamicJet2 = 4,
  kValueJacobian = 5,
  kValueHessian = 6
};
inline constexpr int kNumScalarKinds = 7;

namespace internal {
template <class T> struct IsHessianJet : std::false_type {};
template <int N> struct IsHessianJet<HessianJet<N>> : std::true_type {};

template <class T>
constexpr ScalarKind KindOf() {
  if constexpr (std::is_same_v<T, double>) return ScalarKind::kDouble;
  else if constexpr (IsHessianJet<T>::value) return ScalarKind::kHessianJet;
  else if constexpr (std::is_same_v<T, Jet>) return ScalarKind::kDynamicJet;
  else if constexpr (std::is_same_v<T, Jet2>) return ScalarKind::kDynamicJet2;
  else return ScalarKind::kFixedJet;
}
}  // namespace internal

// Entry points of compiled programs: fn(x, p, out) with x, out arrays of the scalar type. A null entry
// runs the interpreter.
using CompiledProgramFn = void (*)(const void* x, const double* p, void* out);
// Entry points with the parameters as ParamJets too (derivatives in one model parameter, on the runs in a
// parameter): fn(x, p, out), x, p and out arrays of ParamJet. Null: interpreted.
using CompiledParamJetFn = void (*)(const void* x, const void* p, void* out);
struct CompiledPrograms {
  // [phase * 5 + ProgramKind][ScalarKind]; the anchor at [num_phases * 5 + kAnchor].
  std::vector<std::array<CompiledProgramFn, kNumScalarKinds>> entries;
  // [phase * 5 + ProgramKind], like entries.
  std::vector<CompiledParamJetFn> param_jet_entries;
  std::shared_ptr<void> library;  // keeps the loaded code alive
};

namespace internal {

// The interpreter over the bounded-dynamic jets, out of line (expression_model.cc): a flattened caller
// (AutoDiffPhase's unfolded field) must not inline it once per dimension.
void InterpretJets(const ExpressionProgram& program, const double* p, const Jet* x, Jet* out);
void InterpretJets(const ExpressionProgram& program, const double* p, const Jet2* x, Jet2* out);

// The interpreter over a fixed-size jet runs over the bounded-dynamic jet of the same order: inputs copied
// in, outputs copied out, the same derivatives (first order: the same operations, the same bits; second
// order: nested jets, equal to rounding). One instantiation of the interpreter serves every dimension and
// order, which keeps the library's compile time down (bench/README.md, "Build time"); the interpreter is
// the path without a compiler, where speed is not the point.
template <int N>
void InterpretAsBoundedDynamic(const ExpressionProgram& program, const double* p,
                               const Eigen::AutoDiffScalar<Eigen::Matrix<double, N, 1>>* x,
                               Eigen::AutoDiffScalar<Eigen::Matrix<double, N, 1>>* out) {
  thread_local std::vector<Jet> xd, od;
  xd.resize(program.num_inputs());
  od.resize(program.num_outputs());
  for (int i = 0; i < program.num_inputs(); ++i) xd[i] = Jet(x[i].value(), x[i].derivatives());
  InterpretJets(program, p, xd.data(), od.data());
  for (int i = 0; i < program.num_outputs(); ++i) {
    out[i].value() = od[i].value();
    if (od[i].derivatives().size() == N) {
      out[i].derivatives() = od[i].derivatives();
    } else {  // a constant output: no derivatives
      out[i].derivatives().setZero();
    }
  }
}

template <int N>
void InterpretAsBoundedDynamic(const ExpressionProgram& program, const double* p, const HessianJet<N>* x,
                               HessianJet<N>* out) {
  thread_local std::vector<Jet2> xd, od;
  xd.resize(program.num_inputs());
  od.resize(program.num_outputs());
  for (int i = 0; i < program.num_inputs(); ++i) {
    Jet2& v = xd[i];
    v.value() = Jet(x[i].value, Eigen::Map<const Eigen::Matrix<double, N, 1>>(x[i].gradient.data()));
    v.derivatives().resize(N);
    for (int j = 0; j < N; ++j) {
      DerivativeVector row(N);
      for (int l = 0; l < N; ++l) row(l) = x[i].hessian[HessianJet<N>::Packed(std::min(j, l), std::max(j, l))];
      v.derivatives()(j) = Jet(x[i].gradient[j], row);
    }
  }
  InterpretJets(program, p, xd.data(), od.data());
  for (int i = 0; i < program.num_outputs(); ++i) {
    const Jet2& v = od[i];
    HessianJet<N>& o = out[i];
    o = HessianJet<N>(v.value().value());
    // Sizes below N are constants of the nested jets (no derivatives).
    for (int j = 0; j < N && j < v.value().derivatives().size(); ++j) o.gradient[j] = v.value().derivatives()(j);
    for (int j = 0; j < N && j < v.derivatives().size(); ++j) {
      const DerivativeVector& row = v.derivatives()(j).derivatives();
      for (int l = j; l < N && l < row.size(); ++l) o.hessian[HessianJet<N>::Packed(j, l)] = row(l);
    }
  }
}

// What one phase's functions read: its programs, the parameter values, the compiled entry points.
struct ExpressionPhaseData {
  const ExpressionProgram* programs[5] = {};
  const ExpressionPhaseSpec* phase = nullptr;  // null for the anchor
  const double* parameters = nullptr;
  const std::array<CompiledProgramFn, kNumScalarKinds>* compiled[5] = {};
  CompiledParamJetFn compiled_param_jets[5] = {};

  template <class T>
  void Run(ProgramKind kind, const T* x, T* out) const {
    const int k = static_cast<int>(kind);
    if (compiled[k] != nullptr) {
      if (CompiledProgramFn fn = (*compiled[k])[static_cast<int>(KindOf<T>())]) {
        fn(x, parameters, out);
        return;
      }
    }
    if constexpr (KindOf<T>() == ScalarKind::kFixedJet || KindOf<T>() == ScalarKind::kHessianJet) {
      InterpretAsBoundedDynamic(*programs[k], parameters, x, out);
    } else {
      programs[k]->Evaluate(x, parameters, out);
    }
  }
};

// A phase's data with the parameters as jets S (derivatives with respect to one parameter): the same
// programs, interpreted over S.
template <class S>
struct ExpressionJetData {
  const ExpressionPhaseData* base = nullptr;
  const S* parameters = nullptr;  // per-thread storage of the seeding block, valid until its next seeding
  void Run(ProgramKind kind, const S* x, S* out) const {
    if constexpr (std::is_same_v<S, ParamJet>) {
      if (CompiledParamJetFn fn = base->compiled_param_jets[static_cast<int>(kind)]) {
        fn(x, parameters, out);
        return;
      }
    }
    base->programs[static_cast<int>(kind)]->EvaluateWithParameterJets(x, parameters, out);
  }
};

// The functor AutoDiffPhase instantiates (model.h's interface, with the data as its "parameters"):
// D is ExpressionPhaseData, or ExpressionJetData for derivatives in a parameter.
struct ExpressionFunctions {
  template <class T, class D>
  static StateVector<T> VectorField(const StateVector<T>& x, const D& d) {
    return Outputs(ProgramKind::kVectorField, x, d);
  }
  template <class T, class D>
  static StateVector<T> FirstIntegrals(const StateVector<T>& x, const D& d) {
    return Outputs(ProgramKind::kIntegrals, x, d);
  }
  template <class T, class D>
  static T Event(const StateVector<T>& x, const D& d) {
    return Outputs(ProgramKind::kEvent, x, d)(0);
  }
  template <class T, class D>
  static StateVector<T> Reset(const StateVector<T>& x, const D& d) {
    return Outputs(ProgramKind::kReset, x, d);
  }
  template <class T, class D>
  static T Anchor(const StateVector<T>& x, const D& d) {
    return Outputs(ProgramKind::kAnchor, x, d)(0);
  }
  // A mechanical phase's vector field is NaN where its mass matrix is not positive definite: says so.
  static std::string ExplainNonFinite(const Vector& x, const ExpressionPhaseData& d);

 private:
  static const ExpressionPhaseData& Base(const ExpressionPhaseData& d) { return d; }
  template <class S>
  static const ExpressionPhaseData& Base(const ExpressionJetData<S>& d) {
    return *d.base;
  }
  template <class T, class D>
  static StateVector<T> Outputs(ProgramKind kind, const StateVector<T>& x, const D& d) {
    StateVector<T> out(Base(d).programs[static_cast<int>(kind)]->num_outputs());
    d.Run(kind, x.data(), out.data());
    return out;
  }
};

// Expression models differentiate in every parameter.
template <class S>
struct ParametersAs<ExpressionPhaseData, S> {
  using type = ExpressionJetData<S>;
};

}  // namespace internal

// Builds the model; compiled (may be null) supplies compiled entry points for the spec's programs (for an
// automaton: for ExpressionCatalogueSpec(spec)'s, and the model is the automaton's model of its word).
// Throws std::invalid_argument for inconsistent sizes (ValidatePhaseSizes' messages).
HybridModel BuildExpressionModel(ExpressionModelSpec spec, std::shared_ptr<const CompiledPrograms> compiled = nullptr);

}  // namespace hybridcont

#endif  // HYBRIDCONT_EXPRESSION_MODEL_H_
