// The dynamic-size path of expression models (private to src/model): a phase, or the anchor, whose state
// has more than kMaxPhaseDim components. The fixed-capacity jets of AutoDiffPhase (internal/autodiff_phase.h)
// keep small phases free of heap allocation; above their capacity the same programs are evaluated over
// Eigen's AutoDiffScalar with heap-allocated derivative vectors (VectorXd), nested for ∇²H, and with a
// one-direction jet for derivatives in a parameter (∂²H/∂x∂p from HessianJet<2> per state, as
// AutoDiffPhase does). The numbers are those of the same forward-mode differentiation; only the storage
// differs. A compiled model file (model_compiler.h) gives them generated code for values and Jacobians
// (ScalarKind::kValueJacobian: jets of the phase's exact dimension on the stack), for ∇²H
// (ScalarKind::kValueHessian) and for the parameter jets.
#ifndef HYBRIDCONT_SRC_MODEL_LARGE_EXPRESSION_PHASE_H_
#define HYBRIDCONT_SRC_MODEL_LARGE_EXPRESSION_PHASE_H_

#include <memory>
#include <string>
#include <vector>

#include "hybridcont/expression_model.h"

namespace hybridcont::internal {

class LargeExpressionPhase : public Phase {
 public:
  // Reads its programs and parameters from block->BindingFor(slot) (an ExpressionPhaseData).
  LargeExpressionPhase(std::string name, std::vector<std::string> state_names, int next_dim, int num_integrals,
                       Vector typical_state, const ParameterBlock* block, int slot);

  void VectorField(const Eigen::Ref<const Vector>& x, Vector* f, Matrix* df) const override;
  void FirstIntegrals(const Eigen::Ref<const Vector>& x, Vector* H, Matrix* dH, std::vector<Matrix>* d2H) const override;
  double Event(const Eigen::Ref<const Vector>& x, RowVector* de) const override;
  void Reset(const Eigen::Ref<const Vector>& x, Vector* x_next, Matrix* D) const override;
  bool has_parameter_derivatives() const override { return true; }
  void ParameterDerivatives(const Eigen::Ref<const Vector>& x, int parameter, Vector* field, Vector* integrals,
                            double* event, Vector* reset) const override;
  void UnfoldedFieldParameterDerivative(const Eigen::Ref<const Vector>& x, const Eigen::Ref<const Vector>& xi,
                                        int parameter, Vector* dfdp, bool include_mixed_term) const override;
  std::unique_ptr<Phase> CloneWith(const ParameterBlock& parameters) const override;

 private:
  const ExpressionPhaseData* data_;
  int slot_;
  int num_integrals_;
  int num_parameters_;
};

class LargeExpressionAnchor : public Anchor {
 public:
  LargeExpressionAnchor(const ParameterBlock* block, int slot);
  double Evaluate(const Eigen::Ref<const Vector>& x, RowVector* da) const override;
  bool has_parameter_derivatives() const override { return true; }
  double ParameterDerivative(const Eigen::Ref<const Vector>& x, int parameter) const override;
  std::unique_ptr<Anchor> CloneWith(const ParameterBlock& parameters) const override;

 private:
  const ExpressionPhaseData* data_;
  int slot_;
  int num_parameters_;
};

}  // namespace hybridcont::internal

#endif  // HYBRIDCONT_SRC_MODEL_LARGE_EXPRESSION_PHASE_H_
