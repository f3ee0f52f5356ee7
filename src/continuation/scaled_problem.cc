#include "hybridcont/scaled_problem.h"

#include <cmath>
#include <stdexcept>

#include "hybridcont/invariant.h"

namespace hybridcont {

ScaledProblem::ScaledProblem(ZeroProblem* problem, Vector scales) : problem_(problem), scales_(std::move(scales)) {
  HYBRIDCONT_DEMAND(problem_ != nullptr && scales_.size() == problem_->num_unknowns());
  const auto names = problem_->unknown_names();
  for (int k = 0; k < scales_.size(); ++k) {
    if (!(scales_(k) > 0.0) || !std::isfinite(scales_(k))) {
      throw std::invalid_argument("ScaledProblem: scale of '" + names[k] + "' = " + std::to_string(scales_(k)) +
                                  " must be finite and > 0");
    }
  }
}

std::unique_ptr<ZeroProblem> ScaledProblem::Wrap(std::unique_ptr<ZeroProblem> inner) const {
  if (inner == nullptr) return nullptr;
  auto wrapped = std::make_unique<ScaledProblem>(inner.get(), scales_);
  wrapped->owned_ = std::move(inner);
  return wrapped;
}

std::unique_ptr<ZeroProblem> ScaledProblem::Clone() const { return Wrap(problem_->Clone()); }
std::unique_ptr<ZeroProblem> ScaledProblem::Refined(double factor) const { return Wrap(problem_->Refined(factor)); }

void ScaledProblem::AddWorkOf(const ZeroProblem& clone) {
  const auto* scaled = dynamic_cast<const ScaledProblem*>(&clone);
  HYBRIDCONT_DEMAND(scaled != nullptr);  // a clone or refined copy of this scaling
  problem_->AddWorkOf(*scaled->problem_);
}

EvaluationStatus ScaledProblem::Evaluate(const Vector& v, Vector* r, Matrix* dr) {
  u_ = FromScaled(v);
  const EvaluationStatus status = problem_->Evaluate(u_, r, dr);
  if (status.ok && dr) *dr = *dr * scales_.asDiagonal();  // dr/dv = dr/du diag(s)
  return status;
}

EvaluationStatus ScaledProblem::EvaluateSparse(const Vector& v, Vector* r, SparseMatrix* dr) {
  u_ = FromScaled(v);
  const EvaluationStatus status = problem_->EvaluateSparse(u_, r, dr);
  if (status.ok && dr) *dr = *dr * scales_.asDiagonal();
  return status;
}

}  // namespace hybridcont
