// Unknown scaling for continuation: trace r(u) = 0 in the coordinates ũ = u ./ s.
//
// Arclength steps, tangent angles, corrector distances and "same point / same branch" tolerances all use
// the Euclidean norm of u. When components have very different typical magnitudes (an angular velocity
// ~100 next to durations ~0.01), that norm sees only the large ones: the curve crawls in the small ones
// and directions that break a symmetry become invisible. Dividing each component by its typical
// magnitude s_k makes all of them O(1), the "weights" of AUTO and COCO.
//
//   ScaledProblem scaled(&shooting, scales);                 // scales(k) > 0
//   BifurcationDiagram d = Explore(&scaled, scaled.ToScaled(u0), options);
//   Vector u = scaled.FromScaled(d.branches[0].points[5].u);
#ifndef HYBRIDCONT_SCALED_PROBLEM_H_
#define HYBRIDCONT_SCALED_PROBLEM_H_

#include <memory>

#include "hybridcont/zero_problem.h"

namespace hybridcont {

class ScaledProblem : public ZeroProblem {
 public:
  // problem must outlive this object and scales has one entry per unknown (invariants); each scale must
  // be positive and finite (std::invalid_argument).
  ScaledProblem(ZeroProblem* problem, Vector scales);

  int num_equations() const override { return problem_->num_equations(); }
  std::vector<std::string> unknown_names() const override { return problem_->unknown_names(); }
  EvaluationStatus Evaluate(const Vector& v, Vector* r, Matrix* dr) override;
  bool prefers_sparse_jacobian() const override { return problem_->prefers_sparse_jacobian(); }
  EvaluationStatus EvaluateSparse(const Vector& v, Vector* r, SparseMatrix* dr) override;

  // A scaled clone of the wrapped problem (nullptr if that has none), which the clone owns.
  // Diagonal scaling commutes with sign changes: the same signs act on v.
  std::vector<Symmetry> symmetries() const override { return problem_->symmetries(); }
  // Forwarded: scaling renames nothing, so the family is followed in the wrapped problem's parameter (a free
  // model parameter has turning points in it, folds, like H̄).
  std::string family_parameter() const override { return problem_->family_parameter(); }
  std::unique_ptr<ZeroProblem> Clone() const override;
  // A scaled refined copy of the wrapped problem (nullptr if that has none), which the copy owns.
  std::unique_ptr<ZeroProblem> Refined(double factor) const override;
  // Forwards the work of the clone's wrapped problem to this one's.
  void AddWorkOf(const ZeroProblem& clone) override;
  // Forwarded: the column scaling leaves every entry's relative error as it is.
  void set_jacobian_tolerance(double tolerance) override { problem_->set_jacobian_tolerance(tolerance); }
  double jacobian_tolerance() const override { return problem_->jacobian_tolerance(); }

  Vector ToScaled(const Vector& u) const { return u.cwiseQuotient(scales_); }
  Vector FromScaled(const Vector& v) const { return v.cwiseProduct(scales_); }
  const Vector& scales() const { return scales_; }
  // The problem in model units this scaling wraps.
  ZeroProblem* wrapped() const { return problem_; }

 private:
  // This scaling around `inner` (owned); nullptr for a null inner.
  std::unique_ptr<ZeroProblem> Wrap(std::unique_ptr<ZeroProblem> inner) const;

  ZeroProblem* problem_;
  std::unique_ptr<ZeroProblem> owned_;  // problem_ of a clone
  Vector scales_;
  Vector u_;
};

}  // namespace hybridcont

#endif  // HYBRIDCONT_SCALED_PROBLEM_H_
