// Newton correctors: bring a predicted point back onto the solution curve S = r^{-1}(0).
//
// Paper §3.1, eq. (corrector): u^{i+1} ≈ argmin_{u ∈ S} ||u − u_pred||. Every corrector here is Newton's
// method on r(u) = 0 bordered by one extra scalar equation, so that the (N+1) x (N+1) matrix
//
//        [ dr(u) ]   N rows      (the Jacobian of the zero problem, N x (N+1))
//    B = [-------]
//        [  bᵀ   ]   1 row       (the border: what pins u down along the curve)
//
// is square and, at a regular point, invertible. The three borders:
//
//   pseudo-arclength   F = [r(u); τᵀ(u − u_pred)], b = τ: u stays on the hyperplane ⟂ τ through u_pred
//                      (Keller).
//   Moore–Penrose      Δ_k = −[dr(u_k); τ_kᵀ]⁻¹[r(u_k); 0], τ_{k+1} = [dr(u_k); τ_kᵀ]⁻¹e_{N+1} / ||·||: the
//                      minimum-norm step, τ_k following the kernel of dr, so u converges to the point of S
//                      nearest to u_pred, eq. (corrector) (Allgower–Georg §3.3).
//   linear constraint  F = [r(u); cᵀu − value], b = c: e.g. c = e_k, the point of S with u_k = value
//                      exactly (stops, targets).
//
// Tiny example (the unit circle x² + y² = 1, predictor off the curve):
//
//   Circle circle;                                  // a ZeroProblem, see zero_problem.h
//   hybridcont::Corrector corrector(&circle);
//   Vector u;
//   CorrectorResult result = corrector.CorrectPseudoArclength(Vector2d(1.1, 0.2), Vector2d(0, 1), &u);
//   // result.status == CorrectorStatus::kConverged, u ≈ (0.979796, 0.2)
//
// Convergence: ||F(u_k)||₂ <= residual_tolerance and a last Newton step ||Δ|| <= step_tolerance·(1 + ||u||),
// or Deuflhard's error estimate below the step tolerance (CorrectorOptions::accept_on_error_estimate). At
// least one Newton step is always taken. Numerical outcomes are statuses (CorrectorResult), never
// exceptions or prints; vectors of the wrong size are a programming error (std::invalid_argument).
// Design decisions: docs/design/continuation.md, "Corrector: ...".
#ifndef HYBRIDCONT_CORRECTOR_H_
#define HYBRIDCONT_CORRECTOR_H_

#include <limits>
#include <memory>
#include <string>

#include "hybridcont/types.h"
#include "hybridcont/zero_problem.h"

namespace hybridcont {

enum class CorrectorStatus {
  kConverged,         // residual and step tests met
  kMaxIterations,     // still iterating after max_iterations Newton steps
  kDiverged,          // steps and residual grew, the iterate left max_distance, or a value became NaN/Inf
  kSingular,          // the bordered matrix [dr; bᵀ] is numerically singular
  kEvaluationFailed,  // ZeroProblem::Evaluate reported a failure (message copied)
};
std::string ToString(CorrectorStatus status);

enum class CorrectorType {
  kPseudoArclength,  // hyperplane ⟂ predictor direction; cheapest, the default
  kMoorePenrose,     // minimum-norm steps with a kernel update per iteration (Allgower–Georg)
};
std::string ToString(CorrectorType type);
// Parses "pseudo-arclength" / "moore-penrose"; returns false for anything else.
bool FromString(const std::string& text, CorrectorType* type);

struct CorrectorOptions {
  // Newton converges quadratically from a good predictor; needing more than a dozen steps means the
  // step was too long, and halving it is cheaper than iterating on.
  int max_iterations = 12;
  // ||F(u)||₂ at acceptance. 1e-10 leaves room for integrator round-off in shooting maps, and is far below
  // the 1e-10 precision asked of located special points only in combination with step_tolerance.
  double residual_tolerance = 1e-10;
  // Last Newton step ||Δ||₂ / (1 + ||u||₂). With quadratic convergence the error after a step of 1e-10 is
  // ~1e-20, so accepted points are accurate to the rounding level.
  double step_tolerance = 1e-10;
  // Also accept u_k (k >= 2) when the simplified Newton correction Δ̄ = −B_{k−1}⁻¹F(u_k) (Deuflhard's
  // error estimate, from the factorization at hand) is below step_tolerance·(1 + ||u||), returning
  // u_k + Δ̄ (NLEQ-ERR's termination): one r+dr evaluation fewer per point at the same accuracy
  // (docs/design/continuation.md, "Corrector: acceptance on error estimates").
  bool accept_on_error_estimate = true;
  // With accept_on_error_estimate, a full Newton step Δ_k (k >= 1) whose estimated error θ_k|Δ_k| is below
  // step_tolerance is taken without evaluating r at its end (see Corrector::AcceptNewtonStep), when
  // |Δ_k| <= max_jacobian_distance·(1 + ||u||): jacobian() is then the one at u_k, |Δ_k| away from the
  // returned point, so this bounds how far the Jacobian the stepper takes tangents from may lie. It is
  // also the safeguard of the estimate: θ_k is only a lower bound of Newton's contraction (a first step
  // may land close by chance on a strongly curved map), and whatever the contraction, the error after a
  // step of at most 1e-8 is ω|Δ_k|²/2 <= ω·5e-17 (ω the Lipschitz constant of B⁻¹dr): below the step
  // tolerance unless ω > 2e6 in the scaled unknowns (docs/design/continuation.md,
  // "Corrector: max_jacobian_distance").
  double max_jacobian_distance = 1e-8;
  // ZeroProblem::set_jacobian_tolerance for the evaluation at the predictor, whose dr only steers the
  // first Newton step (a relative error ε adds ε·|u_0 − u*| to the error of u_1); every later evaluation
  // is exact (0). A cheaper predictor Jacobian for a negligible loss (docs/design/continuation.md,
  // "Corrector: predictor Jacobian tolerance").
  double predictor_jacobian_tolerance = 1e-2;
  // A predictor already on the curve: when the evaluation at it is exact (predictor_jacobian_tolerance
  // does not loosen the problem's own Jacobian tolerance), its residual is below residual_tolerance and
  // the first Newton step is at the rounding level of u (||Δ₀|| <= kOnCurveStep·(1 + ||u||), and within
  // max_jacobian_distance), u_0 + Δ₀ is returned with the Jacobian at u_0: the second evaluation would
  // only confirm it. The root finders' trial points are often interpolated onto the curve to ~1e-15 once
  // their bracket is small.
  static constexpr double kOnCurveStep = 1e-13;
  // A step ratio ||Δ_{k+1}|| / ||Δ_k|| above this, with a residual that did not decrease either, is
  // divergence: Newton inside its basin contracts. (Steps alone may grow once: a first step overshooting
  // along a nearly singular direction of the bordered matrix, e.g. next to an SB point, is taken back by
  // the second while the residual drops; max_iterations still bounds that case.)
  double max_contraction = 1.0;
  // ||u − u_pred||₂ above this is divergence: keeps the corrector from jumping to another branch.
  // The stepper sets it per step (a multiple of the step length); infinite for a bare corrector.
  double max_distance = std::numeric_limits<double>::infinity();

  // Empty if valid; otherwise names the field, its value and the violated constraint.
  std::string Validate() const;
};

struct CorrectorResult {
  CorrectorStatus status = CorrectorStatus::kMaxIterations;
  std::string message;        // empty when converged; otherwise why not (evaluation message included)
  int iterations = 0;         // Newton steps taken (each costs one factorization)
  // Calls of ZeroProblem::Evaluate: iterations + 1 when converged on the tests, iterations when accepted
  // on an error estimate after the last step (the returned u is then not evaluated).
  int evaluations = 0;
  // ||F||₂ at the last evaluated iterate: the returned u, or for a point accepted after a full Newton
  // step the iterate before that step (the returned point's residual is then smaller, ~ω|Δ_k|²/2).
  double residual_norm = 0;
  double step_norm = 0;       // ||Δ||₂ of the last Newton step
  // Allgower–Georg contraction estimate κ = ||Δ₁|| / ||Δ₀|| (0 when Newton stopped after one step): the
  // step controller's main signal.
  double contraction = 0;
  // The same in the residual: ||F(u₁)|| / ||F(u₀)|| (affine contravariant, Deuflhard §2.2; 0 when Newton
  // stopped at u₀). Unlike κ it does not see a first step that overshoots along a nearly singular
  // direction of the bordered matrix and the second step that takes the overshoot back (|Δ₁| ≈ |Δ₀|
  // although Newton converges): the residual of that overshoot is small.
  double residual_contraction = 0;
  double predictor_residual_norm = 0;  // ||F(u₀)||₂ at the predictor
  double distance = 0;        // ||u − u_pred||₂ at the returned u

  bool converged() const { return status == CorrectorStatus::kConverged; }
  std::string BriefReport() const;
};

class Corrector {
 public:
  // problem must outlive the corrector. Throws std::invalid_argument if options are invalid.
  explicit Corrector(ZeroProblem* problem, const CorrectorOptions& options = CorrectorOptions());
  ~Corrector();
  Corrector(Corrector&&) noexcept;
  Corrector& operator=(Corrector&&) noexcept;

  // Pseudo-arclength: solves [r(u); τᵀ(u − u_pred)] = 0 starting from u_pred. τ need not be normalized.
  CorrectorResult CorrectPseudoArclength(const Vector& u_pred, const Vector& tau, Vector* u);
  // Moore–Penrose: minimum-norm Newton steps, τ (an approximate tangent) updated to the kernel of dr.
  CorrectorResult CorrectMoorePenrose(const Vector& u_pred, const Vector& tau, Vector* u);
  // Linear constraint: solves [r(u); cᵀu − value] = 0 starting from u_pred.
  CorrectorResult CorrectWithConstraint(const Vector& u_pred, const Vector& c, double value, Vector* u);
  // Component `index` of u fixed to `target` (c = e_index): stop exactly at e.g. H = 2.
  CorrectorResult CorrectFixedComponent(const Vector& u_pred, int index, double target, Vector* u);
  // Dispatches on type (pseudo-arclength or Moore–Penrose) with τ as hyperplane normal / tangent guess.
  CorrectorResult Correct(CorrectorType type, const Vector& u_pred, const Vector& tau, Vector* u);

  // r and dr of the last call's last evaluation, at evaluated_point(): the returned u itself, or, for a point
  // accepted after a full Newton step or on an error estimate, the iterate before it, at most
  // max_jacobian_distance·(1 + ||u||) away (CorrectorOptions). The stepper takes the tangent from this dr and
  // the test functions their values (test_function.h), so a converged point costs no extra evaluation.
  const Vector& residual() const;
  const Vector& evaluated_point() const;
  const Matrix& jacobian() const;
  // The same as a sparse matrix (no dense copy for problems that prefer sparse Jacobians).
  const SparseMatrix& sparse_jacobian() const;

  const CorrectorOptions& options() const { return options_; }
  void set_max_distance(double max_distance) { options_.max_distance = max_distance; }
  void set_accept_on_error_estimate(bool accept) { options_.accept_on_error_estimate = accept; }
  void set_predictor_jacobian_tolerance(double tolerance) { options_.predictor_jacobian_tolerance = tolerance; }

 private:
  struct Workspace;
  enum class Border { kArclength, kMoorePenrose, kConstraint };
  CorrectorResult Run(Border border, const Vector& u_pred, const Vector& b, double value, Vector* u);
  // The steps of Run, on its state (border, predictor, norms of the last steps); each returns whether
  // Run goes on (EvaluateAt, TakeNewtonStep) or ends with *result (ConvergedAt, Stalled, AcceptedAfterStep).
  struct Newton;
  bool EvaluateAt(const Newton& newton, int k, const Vector& u, CorrectorResult* result);
  bool ConvergedAt(const Newton& newton, int k, Vector* u, CorrectorResult* result);
  bool Stalled(Newton* newton, int k, CorrectorResult* result) const;
  bool TakeNewtonStep(Newton* newton, int k, Vector* u, CorrectorResult* result);
  bool AcceptedAfterStep(const Newton& newton, int k, Vector* u, CorrectorResult* result) const;
  // Deuflhard's a-posteriori estimate after a full Newton step Δ_k (k >= 1): with the contraction
  // θ_k = |Δ_k| / |Δ_{k−1}|, the error of u_k + Δ_k is about θ_k / (1 − θ_k) · |Δ_k| (an over-estimate by
  // the factor θ_k under quadratic convergence). Accepted when that is below step_tolerance·(1 + ||u||),
  // θ_k <= kMaxAcceptedContraction (the contraction is established, not a stagnating iteration) and
  // |Δ_k| <= max_jacobian_distance·(1 + ||u||).
  // From k = 2 on also θ_{k−1} <= kMaxAcceptedContraction (before_previous_step = |Δ_{k−2}|, 0 for k = 1).
  bool AcceptNewtonStep(double before_previous_step, double previous_step, double last_step,
                        const Vector& u) const;
  static constexpr double kMaxAcceptedContraction = 0.25;
  void ProjectOnConstraint(Border border, double value, Vector* u) const;

  ZeroProblem* problem_;
  CorrectorOptions options_;
  std::unique_ptr<Workspace> workspace_;
};

}  // namespace hybridcont

#endif  // HYBRIDCONT_CORRECTOR_H_
