// Phases and an anchor that forward to another model's objects without owning or copying them: the
// building blocks of the repeated model (period_doubling.h), whose phases are the user's phases again.
//
// Every virtual of `Phase` and `Anchor` is forwarded here and nowhere else, one line each, so that a
// virtual added to `Phase` is forwarded by adding its line below.
//
//   PhaseView copy(model.phase(0));                        // phase 1 again
//   SectionPhaseView to_section(model.phase(0), model.anchor());  // phase 1 up to the Poincaré section
#ifndef HYBRIDCONT_MODEL_PHASE_VIEW_H_
#define HYBRIDCONT_MODEL_PHASE_VIEW_H_

#include "hybridcont/model.h"

namespace hybridcont::internal {

// `target` again, under its own name and states (it must outlive the view).
class PhaseView : public Phase {
 public:
  explicit PhaseView(const Phase& target) : PhaseView(target, target.next_dim()) {}

  void VectorField(const Eigen::Ref<const Vector>& x, Vector* f, Matrix* df) const override {
    target_.VectorField(x, f, df);
  }
  void FirstIntegrals(const Eigen::Ref<const Vector>& x, Vector* H, Matrix* dH,
                      std::vector<Matrix>* d2H) const override {
    target_.FirstIntegrals(x, H, dH, d2H);
  }
  double Event(const Eigen::Ref<const Vector>& x, RowVector* de) const override { return target_.Event(x, de); }
  void Reset(const Eigen::Ref<const Vector>& x, Vector* x_next, Matrix* D) const override {
    target_.Reset(x, x_next, D);
  }
  bool has_parameter_derivatives() const override { return target_.has_parameter_derivatives(); }
  void ParameterDerivatives(const Eigen::Ref<const Vector>& x, int parameter, Vector* field, Vector* integrals,
                            double* event, Vector* reset) const override {
    target_.ParameterDerivatives(x, parameter, field, integrals, event, reset);
  }
  void UnfoldedFieldParameterDerivative(const Eigen::Ref<const Vector>& x, const Eigen::Ref<const Vector>& xi,
                                        int parameter, Vector* dfdp, bool include_mixed_term) const override {
    target_.UnfoldedFieldParameterDerivative(x, xi, parameter, dfdp, include_mixed_term);
  }

 protected:
  PhaseView(const Phase& target, int next_dim)
      : Phase(target.name(), target.state_names(), next_dim, target.num_first_integrals(), target.typical_state()),
        target_(target) {}

  void ComputeUnfoldedVectorField(const Eigen::Ref<const Vector>& x, const Eigen::Ref<const Vector>& xi,
                                  Vector* f_tilde, Matrix* A, Matrix* B, bool include_hessian_term) const override {
    target_.UnfoldedVectorField(x, xi, f_tilde, A, B, include_hessian_term);
  }

 private:
  const Phase& target_;
};

// Phase 1 ended at the Poincaré section: phase 1's flow and first integrals, the anchor a as its event
// (downward crossing, as for the section itself) and the identity as its reset into phase 1. Its
// saltation matrix is the identity (same vector field on both sides), so a cycle cut there has the
// parent's monodromy.
class SectionPhaseView : public PhaseView {
 public:
  SectionPhaseView(const Phase& phase1, const Anchor& anchor) : PhaseView(phase1, phase1.dim()), anchor_(anchor) {}

  double Event(const Eigen::Ref<const Vector>& x, RowVector* de) const override { return anchor_.Evaluate(x, de); }
  void Reset(const Eigen::Ref<const Vector>& x, Vector* x_next, Matrix* D) const override {
    if (x_next != nullptr) *x_next = x;
    if (D != nullptr) D->setIdentity(x.size(), x.size());
  }
  bool has_parameter_derivatives() const override {
    return PhaseView::has_parameter_derivatives() && anchor_.has_parameter_derivatives();
  }
  void ParameterDerivatives(const Eigen::Ref<const Vector>& x, int parameter, Vector* field, Vector* integrals,
                            double* event, Vector* reset) const override {
    PhaseView::ParameterDerivatives(x, parameter, field, integrals, nullptr, nullptr);
    if (event != nullptr) *event = anchor_.ParameterDerivative(x, parameter);
    if (reset != nullptr) reset->setZero(x.size());
  }

 private:
  const Anchor& anchor_;
};

// `target` again (it must outlive the view).
class AnchorView : public Anchor {
 public:
  explicit AnchorView(const Anchor& target) : target_(target) {}
  double Evaluate(const Eigen::Ref<const Vector>& x, RowVector* da) const override { return target_.Evaluate(x, da); }
  bool has_parameter_derivatives() const override { return target_.has_parameter_derivatives(); }
  double ParameterDerivative(const Eigen::Ref<const Vector>& x, int parameter) const override {
    return target_.ParameterDerivative(x, parameter);
  }

 private:
  const Anchor& target_;
};

}  // namespace hybridcont::internal

#endif  // HYBRIDCONT_MODEL_PHASE_VIEW_H_
