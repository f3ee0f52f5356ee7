// Internal: sets a problem's Jacobian tolerance (ZeroProblem::set_jacobian_tolerance) for a scope and
// restores the previous value when the scope ends, also by an exception.
#ifndef HYBRIDCONT_SRC_CONTINUATION_JACOBIAN_TOLERANCE_SCOPE_H_
#define HYBRIDCONT_SRC_CONTINUATION_JACOBIAN_TOLERANCE_SCOPE_H_

#include <algorithm>

#include "hybridcont/zero_problem.h"

namespace hybridcont::internal {

class JacobianToleranceScope {
 public:
  enum class Mode {
    kAtLeast,  // raise to `tolerance` (never below the problem's own): a Jacobian that only steers
    kExactly,  // set to `tolerance`, e.g. 0 for the exact Jacobian of SB test functions
  };
  // A negative tolerance leaves the problem alone.
  JacobianToleranceScope(ZeroProblem* problem, double tolerance, Mode mode = Mode::kAtLeast)
      : problem_(tolerance >= 0 ? problem : nullptr), previous_(problem->jacobian_tolerance()) {
    if (problem_ != nullptr) {
      problem_->set_jacobian_tolerance(mode == Mode::kAtLeast ? std::max(tolerance, previous_) : tolerance);
    }
  }
  ~JacobianToleranceScope() {
    if (problem_ != nullptr) problem_->set_jacobian_tolerance(previous_);
  }
  JacobianToleranceScope(const JacobianToleranceScope&) = delete;
  JacobianToleranceScope& operator=(const JacobianToleranceScope&) = delete;

 private:
  ZeroProblem* problem_;
  double previous_;
};

}  // namespace hybridcont::internal

#endif  // HYBRIDCONT_SRC_CONTINUATION_JACOBIAN_TOLERANCE_SCOPE_H_
