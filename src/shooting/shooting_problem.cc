#include "hybridcont/shooting_problem.h"

#include "hybridcont/invariant.h"

namespace hybridcont {

std::unique_ptr<ZeroProblem> ShootingProblem::Clone() const {
  std::unique_ptr<ShootingProblem> clone = CopyWithTolerances(1.0);
  clone->set_jacobian_tolerance(jacobian_tolerance());  // the same zero set and the same accuracy
  return clone;
}

std::unique_ptr<ZeroProblem> ShootingProblem::Refined(double factor) const { return CopyWithTolerances(factor); }

void ShootingProblem::AddWorkOf(const ZeroProblem& clone) {
  const auto* other = dynamic_cast<const ShootingProblem*>(&clone);
  HYBRIDCONT_DEMAND(other != nullptr);
  counters_ += other->counters_;
  num_evaluations_ += other->num_evaluations_;
}

}  // namespace hybridcont
