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

// A parameter block that reads through to a parent model (the repeated model's). A copy of such a block
// holds a copy of the parent, and the views below clone themselves onto that copy's phases: so a model of
// views can be copied (HybridModel::Clone) and its parameters made free like any other's.
class ParentModelAccess {
 public:
  virtual ~ParentModelAccess() = default;
  virtual const HybridModel& parent() const = 0;
};

// `target` again, under its own name and states (it must outlive the view).
class PhaseView : public Phase {
 public:
  // `target` is phase `index` of its model (CloneWith finds it there in the copy).
  PhaseView(const Phase& target, int index) : PhaseView(target, index, target.next_dim()) {}

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
  std::string ExplainNonFinite(const Eigen::Ref<const Vector>& x) const override { return target_.ExplainNonFinite(x); }
  bool event_bounds_state() const override { return target_.event_bounds_state(); }
  std::unique_ptr<Phase> CloneWith(const ParameterBlock& parameters) const override {
    const auto* access = dynamic_cast<const ParentModelAccess*>(&parameters);
    if (access == nullptr) return nullptr;
    return std::make_unique<PhaseView>(access->parent().phase(index_), index_);
  }

 protected:
  PhaseView(const Phase& target, int index, int next_dim)
      : Phase(target.name(), target.state_names(), next_dim, target.num_first_integrals(), target.typical_state()),
        target_(target),
        index_(index) {}

  void ComputeUnfoldedVectorField(const Eigen::Ref<const Vector>& x, const Eigen::Ref<const Vector>& xi,
                                  Vector* f_tilde, Matrix* A, Matrix* B, bool include_hessian_term) const override {
    target_.UnfoldedVectorField(x, xi, f_tilde, A, B, include_hessian_term);
  }

 private:
  const Phase& target_;
  int index_;
};

// Phase 1 ended at the Poincaré section: phase 1's flow and first integrals, the anchor a as its event
// (downward crossing, as for the section itself) and the identity as its reset into phase 1. Its
// saltation matrix is the identity (same vector field on both sides), so a cycle cut there has the
// parent's monodromy.
class SectionPhaseView : public PhaseView {
 public:
  SectionPhaseView(const Phase& phase1, const Anchor& anchor) : PhaseView(phase1, 0, phase1.dim()), anchor_(anchor) {}

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
  std::unique_ptr<Phase> CloneWith(const ParameterBlock& parameters) const override {
    const auto* access = dynamic_cast<const ParentModelAccess*>(&parameters);
    if (access == nullptr) return nullptr;
    return std::make_unique<SectionPhaseView>(access->parent().phase(0), access->parent().anchor());
  }
  bool event_bounds_state() const override { return false; }  // the section marks a time, as the anchor does

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
  std::unique_ptr<Anchor> CloneWith(const ParameterBlock& parameters) const override {
    const auto* access = dynamic_cast<const ParentModelAccess*>(&parameters);
    if (access == nullptr) return nullptr;
    return std::make_unique<AnchorView>(access->parent().anchor());
  }

 private:
  const Anchor& target_;
};

}  // namespace hybridcont::internal

#endif  // HYBRIDCONT_MODEL_PHASE_VIEW_H_
