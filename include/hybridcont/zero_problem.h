// A zero problem: a smooth map r: R^{N+1} -> R^N with its Jacobian dr (N x (N+1)).
//
// Its zero set S = r^{-1}(0) is, near regular points, a curve; the continuation engine traces it. The
// engine knows nothing about hybrid systems: the time-based shooting map (timebased_shooting.h), the
// state-based map, and the algebraic test curves (a circle, a pitchfork) are all ZeroProblems.
//
//   class Circle : public hybridcont::ZeroProblem {
//    public:
//     int num_equations() const override { return 1; }
//     std::vector<std::string> unknown_names() const override { return {"x", "y"}; }
//     EvaluationStatus Evaluate(const Vector& u, Vector* r, Matrix* dr) override {
//       if (r) *r = Vector::Constant(1, u.squaredNorm() - 1.0);
//       if (dr) *dr = 2.0 * u.transpose();
//       return {};
//     }
//   };
//
// Evaluate is non-const: implementations keep their scratch space (integrator state, sensitivities) in
// members so that repeated evaluations allocate nothing. A numerical failure during an evaluation (the
// integrator's step fell below its minimum, a model function returned NaN) is reported through the
// returned status, never by an exception: the caller decides (e.g. the corrector halves its step).
//
// Because of that scratch space one instance evaluates on one thread at a time. A caller that wants to
// evaluate concurrently (the exploration traces half-branches on several threads, exploration.h) asks
// for independent copies with Clone() and, when done, hands their work counters back with AddWorkOf():
//
//   std::unique_ptr<ZeroProblem> copy = problem.Clone();   // nullptr: this problem stays serial
//   std::thread worker([&] { copy->Evaluate(u, &r, &dr); });
//   worker.join();
//   problem.AddWorkOf(*copy);                              // totals count both threads' work
#ifndef HYBRIDCONT_ZERO_PROBLEM_H_
#define HYBRIDCONT_ZERO_PROBLEM_H_

#include <memory>
#include <string>
#include <vector>

#include "hybridcont/types.h"

namespace hybridcont {

// Outcome of one evaluation of r / dr.
struct EvaluationStatus {
  bool ok = true;
  std::string message;  // empty when ok; otherwise what failed, where (phase, time) and why
  static EvaluationStatus Failure(std::string why) { return {false, std::move(why)}; }
};

class ZeroProblem {
 public:
  virtual ~ZeroProblem() = default;

  // N, the number of equations. The number of unknowns is N + 1.
  virtual int num_equations() const = 0;
  int num_unknowns() const { return num_equations() + 1; }

  // Names of the N+1 unknowns, in the order of u (used to label outputs and to address components,
  // e.g. "H" for the level set of the first integral or "xi" for the unfolding parameter).
  virtual std::vector<std::string> unknown_names() const = 0;

  // Evaluates r(u) into *r (if r != nullptr) and dr(u) into *dr (if dr != nullptr), resizing them.
  // Both outputs are computed from the same internal state when both are requested.
  virtual EvaluationStatus Evaluate(const Vector& u, Vector* r, Matrix* dr) = 0;

  // Sparse channel. A problem whose dr has O(N) nonzeros (time-based multiple shooting: a block-cyclic
  // pattern of 2(m+1) blocks) says so here, and the corrector then evaluates and factorizes dr as a sparse
  // matrix: a Newton step costs O(m) instead of the O(m²) of merely storing N x (N+1) doubles. The
  // pattern must not depend on u (explicit zeros are stored), so that its analysis can be reused.
  virtual bool prefers_sparse_jacobian() const { return false; }
  // r and dr as a sparse N x (N+1) matrix. The default converts the dense Evaluate.
  virtual EvaluationStatus EvaluateSparse(const Vector& u, Vector* r, SparseMatrix* dr) {
    if (dr == nullptr) return Evaluate(u, r, nullptr);
    Matrix dense;
    const EvaluationStatus status = Evaluate(u, r, &dense);
    if (status.ok) *dr = dense.sparseView(1.0, 0.0);
    return status;
  }

  // An independent problem with the same zero set (same model, options and fixed values): its own scratch
  // space, caches and zeroed work counters, so that it can evaluate on one thread while this one (or
  // another clone) evaluates on another. A clone is meant for a caller that is already concurrent: it
  // starts no threads of its own. nullptr, the default, says the problem cannot be copied; callers then
  // stay serial.
  virtual std::unique_ptr<ZeroProblem> Clone() const { return nullptr; }
  // Adds the work counters of `clone` (made by this problem's Clone()) to this problem's, so that totals
  // cover every thread's evaluations. Default: nothing is counted.
  virtual void AddWorkOf(const ZeroProblem& clone) { (void)clone; }

  // How exact the next evaluations' dr must be: terms of dr whose relative size is below `tolerance` may
  // be left out (0, the default: dr exact to the problem's own accuracy). The corrector raises it for the
  // Jacobian at the predictor, which only steers the first Newton step: a relative error ε there adds
  // ε·|u_0 − u*| to the error of u_1, next to Newton's own C·|u_0 − u*|², and the Jacobians that tangents,
  // test functions and monodromies are taken from are evaluated exactly. The time-based map then leaves
  // out the ξ·∇²H term of df~/dx where it is below the tolerance (its Hessians were ~20% of a SLIP
  // exploration). Default: ignored.
  virtual void set_jacobian_tolerance(double tolerance) { (void)tolerance; }
  // The tolerance in effect (0 for problems that ignore it).
  virtual double jacobian_tolerance() const { return 0.0; }

  // Index of the named unknown, or -1.
  int UnknownIndex(const std::string& name) const {
    const std::vector<std::string> names = unknown_names();
    for (int i = 0; i < static_cast<int>(names.size()); ++i) {
      if (names[i] == name) return i;
    }
    return -1;
  }
};

}  // namespace hybridcont

#endif  // HYBRIDCONT_ZERO_PROBLEM_H_
