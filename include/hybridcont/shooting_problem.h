// ShootingProblem: the part the two shooting maps share as zero problems (zero_problem.h). The
// time-based map (timebased_shooting.h, eq. `timebased`) and the state-based map (statebased_shooting.h,
// eq. `statebased`) both integrate flows to evaluate r, so both
//   - count the work of those integrations (right-hand sides, steps, evaluations of r), and
//   - copy themselves: a clone (same model, options and fixed levels) that evaluates on another thread,
//     and a refined copy whose integrators' rtol and atol are scaled by a factor < 1, for a-posteriori
//     estimates of the integration error (special_point.h).
// A map implements one function, CopyWithTolerances; Clone, Refined and AddWorkOf follow from it.
//
//   TimeBasedShooting map(model, IntegratorOptions{});
//   std::unique_ptr<ZeroProblem> worker = map.Clone();   // evaluate on another thread, then
//   map.AddWorkOf(*worker);                               // count its work in map.counters()
#ifndef HYBRIDCONT_SHOOTING_PROBLEM_H_
#define HYBRIDCONT_SHOOTING_PROBLEM_H_

#include <memory>

#include "hybridcont/flow.h"
#include "hybridcont/zero_problem.h"

namespace hybridcont {

class ShootingProblem : public ZeroProblem {
 public:
  // A copy with the same zero set and the same Jacobian accuracy (jacobian_tolerance), one thread, its
  // counters zero.
  std::unique_ptr<ZeroProblem> Clone() const final;
  // A copy whose integrators' rtol and atol are `factor` times this problem's (event tolerances
  // unchanged); its Jacobians are exact.
  std::unique_ptr<ZeroProblem> Refined(double factor) const final;
  // Adds the work counted by `clone`, a ShootingProblem made by Clone or Refined (anything else is a
  // programming error and trips the invariant check).
  void AddWorkOf(const ZeroProblem& clone) final;

  // Work of all evaluations so far, and of the copies added with AddWorkOf.
  const FlowCounters& counters() const { return counters_; }
  // Evaluations that integrated (an evaluation answered from the cache of the last point is not counted).
  long num_evaluations() const { return num_evaluations_; }
  void ResetCounters() {
    counters_ = FlowCounters();
    num_evaluations_ = 0;
  }

 protected:
  // The one function a map implements: a single-threaded copy with the same model, options and fixed
  // levels, its integrators' rtol and atol times `tolerance_factor`, its counters zero.
  virtual std::unique_ptr<ShootingProblem> CopyWithTolerances(double tolerance_factor) const = 0;

  void CountEvaluation() { ++num_evaluations_; }
  void CountWork(const FlowCounters& work) { counters_ += work; }

 private:
  FlowCounters counters_;
  long num_evaluations_ = 0;
};

}  // namespace hybridcont

#endif  // HYBRIDCONT_SHOOTING_PROBLEM_H_
