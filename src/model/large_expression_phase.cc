#include "large_expression_phase.h"

#include <vector>

#include <unsupported/Eigen/AutoDiff>

#include "hybridcont/invariant.h"

namespace hybridcont::internal {

namespace {

using DynJet = Eigen::AutoDiffScalar<Eigen::VectorXd>;
using DynJet2 = Eigen::AutoDiffScalar<Eigen::Matrix<DynJet, Eigen::Dynamic, 1>>;

const ExpressionPhaseData* DataOf(const ParameterBlock* block, int slot) {
  const auto* data = static_cast<const ExpressionPhaseData*>(block->BindingFor(slot));
  HYBRIDCONT_DEMAND(data != nullptr);
  return data;
}

const ExpressionProgram& Program(const ExpressionPhaseData& d, ProgramKind kind) {
  return *d.programs[static_cast<int>(kind)];
}

// The compiled entry of program `kind` for scalar kind `scalar`, or null (interpreted).
CompiledProgramFn CompiledEntry(const ExpressionPhaseData& d, ProgramKind kind, ScalarKind scalar) {
  const auto* entries = d.compiled[static_cast<int>(kind)];
  return entries != nullptr ? (*entries)[static_cast<int>(scalar)] : nullptr;
}

// Values of program `kind` at x, and with J != nullptr its Jacobian (outputs × n), by one evaluation over
// jets with n directions: generated code's (ScalarKind::kValueJacobian, jets of the exact dimension on the
// stack) where the model was compiled, else the interpreter's over heap-allocated jets.
void ValueAndJacobian(const ExpressionPhaseData& d, ProgramKind kind, const Eigen::Ref<const Vector>& x, Vector* values,
                      Matrix* J) {
  const ExpressionProgram& program = Program(d, kind);
  const int n = static_cast<int>(x.size()), k = program.num_outputs();
  values->resize(k);
  if (J == nullptr) {
    if (CompiledProgramFn fn = CompiledEntry(d, kind, ScalarKind::kDouble)) {
      fn(x.data(), d.parameters, values->data());
    } else {
      program.Evaluate<double>(x.data(), d.parameters, values->data());
    }
    return;
  }
  if (CompiledProgramFn fn = CompiledEntry(d, kind, ScalarKind::kValueJacobian)) {
    thread_local std::vector<double> out;
    out.resize(static_cast<std::size_t>(k) * (n + 1));
    fn(x.data(), d.parameters, out.data());
    *values = Eigen::Map<const Vector>(out.data(), k);
    *J = Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(out.data() + k, k, n);
    return;
  }
  std::vector<DynJet> xs(n), out(k);
  for (int i = 0; i < n; ++i) xs[i] = DynJet(x(i), Eigen::VectorXd::Unit(n, i));
  program.Evaluate<DynJet>(xs.data(), d.parameters, out.data());
  J->resize(k, n);
  for (int j = 0; j < k; ++j) {
    (*values)(j) = out[j].value();
    if (out[j].derivatives().size() == n) J->row(j) = out[j].derivatives().transpose();
    else J->row(j).setZero();  // a constant output carries no derivative vector
  }
}

// ∂(outputs of program `kind`)/∂p at x for model parameter `parameter` (num_parameters of them), by one
// evaluation with the parameters as one-direction jets.
Vector ParameterColumn(const ExpressionPhaseData& d, ProgramKind kind, const Eigen::Ref<const Vector>& x, int parameter,
                       int num_parameters) {
  const ExpressionProgram& program = Program(d, kind);
  std::vector<ParamJet> xs(x.size()), p(num_parameters), out(program.num_outputs());
  for (int i = 0; i < x.size(); ++i) xs[i] = ParamJet(x(i), Eigen::Matrix<double, 1, 1>::Zero());
  for (int j = 0; j < num_parameters; ++j) {
    p[j] = ParamJet(d.parameters[j], Eigen::Matrix<double, 1, 1>::Constant(j == parameter ? 1.0 : 0.0));
  }
  if (CompiledParamJetFn fn = d.compiled_param_jets[static_cast<int>(kind)]) {
    fn(xs.data(), p.data(), out.data());
  } else {
    program.EvaluateWithParameterJets<ParamJet>(xs.data(), p.data(), out.data());
  }
  Vector column(program.num_outputs());
  for (int j = 0; j < column.size(); ++j) column(j) = out[j].derivatives().size() ? out[j].derivatives()(0) : 0.0;
  return column;
}

}  // namespace

LargeExpressionPhase::LargeExpressionPhase(std::string name, std::vector<std::string> state_names, int next_dim,
                                           int num_integrals, Vector typical_state, const ParameterBlock* block,
                                           int slot)
    : Phase(std::move(name), std::move(state_names), next_dim, num_integrals, std::move(typical_state)),
      data_(DataOf(block, slot)),
      slot_(slot),
      num_integrals_(num_integrals),
      num_parameters_(static_cast<int>(block->infos().size())) {}

void LargeExpressionPhase::VectorField(const Eigen::Ref<const Vector>& x, Vector* f, Matrix* df) const {
  ValueAndJacobian(*data_, ProgramKind::kVectorField, x, f, df);
}

void LargeExpressionPhase::FirstIntegrals(const Eigen::Ref<const Vector>& x, Vector* H, Matrix* dH,
                                          std::vector<Matrix>* d2H) const {
  if (d2H == nullptr) return ValueAndJacobian(*data_, ProgramKind::kIntegrals, x, H, dH);
  const ExpressionProgram& program = Program(*data_, ProgramKind::kIntegrals);
  const int n = static_cast<int>(x.size()), k = program.num_outputs();
  if (CompiledProgramFn fn = CompiledEntry(*data_, ProgramKind::kIntegrals, ScalarKind::kValueHessian)) {
    thread_local std::vector<double> out;
    out.resize(static_cast<std::size_t>(k) * (1 + n + n * n));
    fn(x.data(), data_->parameters, out.data());
    *H = Eigen::Map<const Vector>(out.data(), k);
    using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
    if (dH) *dH = Eigen::Map<const RowMajor>(out.data() + k, k, n);
    d2H->resize(k);
    for (int j = 0; j < k; ++j) (*d2H)[j] = Eigen::Map<const RowMajor>(out.data() + k * (1 + n) + j * n * n, n, n);
    return;
  }
  // Interpreted, second order: jets of jets, outer and inner over the n states.
  std::vector<DynJet2> xs(n), out(k);
  for (int i = 0; i < n; ++i) {
    Eigen::Matrix<DynJet, Eigen::Dynamic, 1> outer(n);
    for (int j = 0; j < n; ++j) outer(j) = DynJet(i == j ? 1.0 : 0.0, Eigen::VectorXd::Zero(n));
    xs[i] = DynJet2(DynJet(x(i), Eigen::VectorXd::Unit(n, i)), outer);
  }
  program.Evaluate<DynJet2>(xs.data(), data_->parameters, out.data());
  H->resize(k);
  if (dH) dH->setZero(k, n);
  d2H->assign(k, Matrix::Zero(n, n));
  for (int j = 0; j < k; ++j) {
    (*H)(j) = out[j].value().value();
    if (out[j].derivatives().size() != n) continue;
    for (int a = 0; a < n; ++a) {
      const DynJet& da = out[j].derivatives()(a);
      if (dH) (*dH)(j, a) = da.value();
      if (da.derivatives().size() == n) (*d2H)[j].row(a) = da.derivatives().transpose();
    }
  }
}

double LargeExpressionPhase::Event(const Eigen::Ref<const Vector>& x, RowVector* de) const {
  Vector value;
  Matrix J;
  ValueAndJacobian(*data_, ProgramKind::kEvent, x, &value, de ? &J : nullptr);
  if (de) *de = J.row(0);
  return value(0);
}

void LargeExpressionPhase::Reset(const Eigen::Ref<const Vector>& x, Vector* x_next, Matrix* D) const {
  ValueAndJacobian(*data_, ProgramKind::kReset, x, x_next, D);
}

void LargeExpressionPhase::ParameterDerivatives(const Eigen::Ref<const Vector>& x, int parameter, Vector* field,
                                                Vector* integrals, double* event, Vector* reset) const {
  if (field) *field = ParameterColumn(*data_, ProgramKind::kVectorField, x, parameter, num_parameters_);
  if (integrals) *integrals = ParameterColumn(*data_, ProgramKind::kIntegrals, x, parameter, num_parameters_);
  if (event) *event = ParameterColumn(*data_, ProgramKind::kEvent, x, parameter, num_parameters_)(0);
  if (reset) *reset = ParameterColumn(*data_, ProgramKind::kReset, x, parameter, num_parameters_);
}

void LargeExpressionPhase::UnfoldedFieldParameterDerivative(const Eigen::Ref<const Vector>& x,
                                                            const Eigen::Ref<const Vector>& xi, int parameter,
                                                            Vector* dfdp, bool include_mixed_term) const {
  *dfdp = ParameterColumn(*data_, ProgramKind::kVectorField, x, parameter, num_parameters_);
  if (!include_mixed_term || (xi.array() == 0.0).all()) return;
  // Σ_j ξ_j ∂²H_j/∂x_i∂p, state by state: x_i variable 0, p variable 1 of a second-order jet.
  const ExpressionProgram& program = Program(*data_, ProgramKind::kIntegrals);
  const int n = static_cast<int>(x.size());
  std::vector<MixedJet> xs(n), p(num_parameters_), out(program.num_outputs());
  for (int j = 0; j < num_parameters_; ++j) {
    p[j] = j == parameter ? MixedJet::Variable(data_->parameters[j], 1) : MixedJet(data_->parameters[j]);
  }
  for (int i = 0; i < n; ++i) {
    for (int a = 0; a < n; ++a) xs[a] = a == i ? MixedJet::Variable(x(a), 0) : MixedJet(x(a));
    program.EvaluateWithParameterJets<MixedJet>(xs.data(), p.data(), out.data());
    for (int j = 0; j < num_integrals_; ++j) (*dfdp)(i) += xi(j) * out[j].hessian[MixedJet::Packed(0, 1)];
  }
}

std::unique_ptr<Phase> LargeExpressionPhase::CloneWith(const ParameterBlock& parameters) const {
  return std::make_unique<LargeExpressionPhase>(name(), state_names(), next_dim(), num_integrals_, typical_state(),
                                                &parameters, slot_);
}

LargeExpressionAnchor::LargeExpressionAnchor(const ParameterBlock* block, int slot)
    : data_(DataOf(block, slot)), slot_(slot), num_parameters_(static_cast<int>(block->infos().size())) {}

double LargeExpressionAnchor::Evaluate(const Eigen::Ref<const Vector>& x, RowVector* da) const {
  Vector value;
  Matrix J;
  ValueAndJacobian(*data_, ProgramKind::kAnchor, x, &value, da ? &J : nullptr);
  if (da) *da = J.row(0);
  return value(0);
}

double LargeExpressionAnchor::ParameterDerivative(const Eigen::Ref<const Vector>& x, int parameter) const {
  return ParameterColumn(*data_, ProgramKind::kAnchor, x, parameter, num_parameters_)(0);
}

std::unique_ptr<Anchor> LargeExpressionAnchor::CloneWith(const ParameterBlock& parameters) const {
  return std::make_unique<LargeExpressionAnchor>(&parameters, slot_);
}

}  // namespace hybridcont::internal
