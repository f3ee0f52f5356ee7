#include "hybridcont/corrector.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "continuation/bordered_solver.h"
#include "continuation/jacobian_tolerance_scope.h"
#include "hybridcont/internal/enum_names.h"
#include "hybridcont/internal/options_check.h"
#include "hybridcont/invariant.h"

namespace hybridcont {

namespace {

constexpr internal::EnumName<CorrectorStatus> kCorrectorStatusNames[] = {
    {CorrectorStatus::kConverged, "converged"},
    {CorrectorStatus::kMaxIterations, "max-iterations"},
    {CorrectorStatus::kDiverged, "diverged"},
    {CorrectorStatus::kSingular, "singular"},
    {CorrectorStatus::kEvaluationFailed, "evaluation-failed"},
};

constexpr internal::EnumName<CorrectorType> kCorrectorTypeNames[] = {
    {CorrectorType::kPseudoArclength, "pseudo-arclength"},
    {CorrectorType::kMoorePenrose, "moore-penrose"},
};

}  // namespace

std::string ToString(CorrectorStatus status) { return internal::EnumToString(kCorrectorStatusNames, status); }

std::string ToString(CorrectorType type) { return internal::EnumToString(kCorrectorTypeNames, type); }

bool FromString(const std::string& text, CorrectorType* type) {
  return internal::EnumFromString(kCorrectorTypeNames, text, type);
}

std::string CorrectorOptions::Validate() const {
  return internal::OptionsCheck("CorrectorOptions")
      .AtLeast("max_iterations", max_iterations, 1)
      .Require(residual_tolerance > 0, "residual_tolerance", residual_tolerance, "must be > 0")
      .Require(step_tolerance > 0, "step_tolerance", step_tolerance, "must be > 0")
      .Require(max_contraction > 0, "max_contraction", max_contraction, "must be > 0")
      .Require(max_distance > 0, "max_distance", max_distance, "must be > 0")
      .Require(predictor_jacobian_tolerance >= 0 && predictor_jacobian_tolerance < 1, "predictor_jacobian_tolerance",
               predictor_jacobian_tolerance, "must be in [0, 1)")
      .Require(max_jacobian_distance >= 0, "max_jacobian_distance", max_jacobian_distance, "must be >= 0")
      .message();
}

std::string CorrectorResult::BriefReport() const {
  std::ostringstream out;
  out << "Corrector: " << ToString(status) << ", " << iterations << " iterations, |F| = " << residual_norm
      << ", |du| = " << step_norm << ", kappa = " << contraction;
  if (!message.empty()) out << " (" << message << ")";
  return out.str();
}

using internal::JacobianToleranceScope;

// Scratch space sized once per problem (conventions §6): the Newton loop allocates nothing after the
// first call.
struct Corrector::Workspace {
  Vector r, F, delta, kernel, unit_last, border, correction;
  Vector evaluated;  // the iterate r and dr are at
  Matrix dr;
  // Sparse channel (ZeroProblem::prefers_sparse_jacobian): dr is evaluated and factorized sparse, and
  // the dense copy is made only when jacobian() is asked for.
  bool sparse = false;
  bool dense_stale = false;
  SparseMatrix dr_sparse;
  internal::BorderedSolver solver;
};

Corrector::Corrector(ZeroProblem* problem, const CorrectorOptions& options)
    : problem_(problem), options_(options), workspace_(std::make_unique<Workspace>()) {
  HYBRIDCONT_DEMAND(problem_ != nullptr);
  const std::string error = options_.Validate();
  if (!error.empty()) throw std::invalid_argument(error);
  const int n = problem_->num_unknowns();
  workspace_->F.resize(n);
  workspace_->delta.resize(n);
  workspace_->kernel.resize(n);
  workspace_->unit_last = Vector::Unit(n, n - 1);
}

Corrector::~Corrector() = default;
Corrector::Corrector(Corrector&&) noexcept = default;
Corrector& Corrector::operator=(Corrector&&) noexcept = default;

const Vector& Corrector::residual() const { return workspace_->r; }
const Vector& Corrector::evaluated_point() const { return workspace_->evaluated; }
const Matrix& Corrector::jacobian() const {
  Workspace& w = *workspace_;
  if (w.sparse && w.dense_stale) {
    w.dr = Matrix(w.dr_sparse);
    w.dense_stale = false;
  }
  return w.dr;
}
const SparseMatrix& Corrector::sparse_jacobian() const {
  Workspace& w = *workspace_;
  if (!w.sparse) w.dr_sparse = w.dr.sparseView(1.0, 0.0);
  return w.dr_sparse;
}

CorrectorResult Corrector::CorrectPseudoArclength(const Vector& u_pred, const Vector& tau, Vector* u) {
  return Run(Border::kArclength, u_pred, tau, 0.0, u);
}
CorrectorResult Corrector::CorrectMoorePenrose(const Vector& u_pred, const Vector& tau, Vector* u) {
  return Run(Border::kMoorePenrose, u_pred, tau, 0.0, u);
}
CorrectorResult Corrector::CorrectWithConstraint(const Vector& u_pred, const Vector& c, double value,
                                                 Vector* u) {
  return Run(Border::kConstraint, u_pred, c, value, u);
}
CorrectorResult Corrector::CorrectFixedComponent(const Vector& u_pred, int index, double target, Vector* u) {
  HYBRIDCONT_DEMAND(index >= 0 && index < problem_->num_unknowns());
  return Run(Border::kConstraint, u_pred, Vector::Unit(problem_->num_unknowns(), index), target, u);
}
CorrectorResult Corrector::Correct(CorrectorType type, const Vector& u_pred, const Vector& tau, Vector* u) {
  return type == CorrectorType::kMoorePenrose ? CorrectMoorePenrose(u_pred, tau, u)
                                              : CorrectPseudoArclength(u_pred, tau, u);
}

// The linear equation of a constraint border holds after a Newton step up to the rounding of u + Δ;
// projected so that it holds exactly (a stop at H = 2 lands on H = 2.0, not on 1.9999999999999998).
void Corrector::ProjectOnConstraint(Border border, double value, Vector* u) const {
  if (border != Border::kConstraint) return;
  const Vector& c = workspace_->border;
  *u += ((value - c.dot(*u)) / c.squaredNorm()) * c;
}

bool Corrector::AcceptNewtonStep(double before_previous_step, double previous_step, double last_step,
                                 const Vector& u) const {
  if (!(previous_step > 0)) return false;
  // From k = 2 on, the contraction must be established over two steps: after a first step that overshot
  // along a nearly singular direction of B and a second that took it back, |Δ₂|/|Δ₁| is small although
  // Newton is not yet in its quadratic regime (docs/design/continuation.md, "Corrector: acceptance on
  // error estimates").
  if (before_previous_step > 0 && previous_step > kMaxAcceptedContraction * before_previous_step) return false;
  const double theta = last_step / previous_step;
  const double scale = 1.0 + u.norm();
  return theta <= kMaxAcceptedContraction && theta / (1 - theta) * last_step <= options_.step_tolerance * scale &&
         last_step <= options_.max_jacobian_distance * scale;
}

// The state of one Run: its border and predictor, and the norms of the last Newton steps.
struct Corrector::Newton {
  Border border;
  const Vector& u_pred;
  double value;
  bool exact_at_predictor;  // dr at the predictor as exact as the later ones (CorrectorOptions::kOnCurveStep)
  double last_step = 0, previous_step = 0, before_previous_step = 0, previous_residual = 0;
};

CorrectorResult Corrector::Run(Border border, const Vector& u_pred, const Vector& b, double value,
                               Vector* u_out) {
  const int n = problem_->num_unknowns();
  if (u_pred.size() != n || b.size() != n) {
    throw std::invalid_argument("Corrector: u_pred has size " + std::to_string(u_pred.size()) +
                                " and the border vector " + std::to_string(b.size()) + ", expected " +
                                std::to_string(n) + " (= num_unknowns())");
  }
  Workspace& w = *workspace_;
  Vector& u = *u_out;
  u = u_pred;
  w.border = b;
  if (border != Border::kConstraint) w.border.normalize();

  CorrectorResult result;
  Newton newton{border, u_pred, value, false};
  w.sparse = problem_->prefers_sparse_jacobian();
  newton.exact_at_predictor = !(options_.predictor_jacobian_tolerance > problem_->jacobian_tolerance());
  for (int k = 0;; ++k) {
    if (!EvaluateAt(newton, k, u, &result)) return result;
    if (k > 0 && result.residual_norm <= options_.residual_tolerance && ConvergedAt(newton, k, &u, &result)) {
      return result;
    }
    if (Stalled(&newton, k, &result) || !TakeNewtonStep(&newton, k, &u, &result)) return result;
    if (AcceptedAfterStep(newton, k, &u, &result)) return result;
  }
}

bool Corrector::EvaluateAt(const Newton& newton, int k, const Vector& u, CorrectorResult* result) {
  Workspace& w = *workspace_;
  const int n = problem_->num_unknowns();
  const EvaluationStatus evaluation = [&] {
    // The predictor's dr only steers the first step (CorrectorOptions::predictor_jacobian_tolerance);
    // the problem's own tolerance is restored however Evaluate returns, an exception included.
    const JacobianToleranceScope scope(problem_, k == 0 ? options_.predictor_jacobian_tolerance : -1.0);
    return w.sparse ? problem_->EvaluateSparse(u, &w.r, &w.dr_sparse) : problem_->Evaluate(u, &w.r, &w.dr);
  }();
  w.dense_stale = w.sparse;
  w.evaluated = u;
  ++result->evaluations;
  if (!evaluation.ok) {
    result->status = CorrectorStatus::kEvaluationFailed;
    result->message = evaluation.message;
    return false;
  }
  w.F.head(n - 1) = w.r;
  switch (newton.border) {
    case Border::kArclength: w.F(n - 1) = w.border.dot(u - newton.u_pred); break;
    case Border::kConstraint: w.F(n - 1) = w.border.dot(u) - newton.value; break;
    case Border::kMoorePenrose: w.F(n - 1) = 0; break;
  }
  result->residual_norm = w.F.norm();
  result->distance = (u - newton.u_pred).norm();
  if (k == 0) result->predictor_residual_norm = result->residual_norm;
  if (k == 1 && result->predictor_residual_norm > 0) {
    result->residual_contraction = result->residual_norm / result->predictor_residual_norm;
  }
  const bool jacobian_finite = w.sparse ? Eigen::Map<const Vector>(w.dr_sparse.valuePtr(), w.dr_sparse.nonZeros()).allFinite()
                                        : w.dr.allFinite();
  if (!std::isfinite(result->residual_norm) || !jacobian_finite) {
    result->status = CorrectorStatus::kDiverged;
    result->message = "non-finite residual or Jacobian";
    return false;
  }
  return true;
}

bool Corrector::ConvergedAt(const Newton& newton, int k, Vector* u, CorrectorResult* result) {
  Workspace& w = *workspace_;
  // Deuflhard's termination (NLEQ-ERR): the simplified Newton correction Δ̄ = −B_{k−1}⁻¹F(u_k), from
  // the factorization already at hand, estimates the error left in u_k; when it is small, u_k + Δ̄
  // (error ~κ·|Δ̄|, at the rounding level) is the solution. This saves the last Newton step and its
  // r+dr evaluation on most points; dr (jacobian()) is then the one at u_k, |Δ̄| <= step_tolerance away.
  // Only from the second step on: the estimate is trusted once Newton has shown its contraction
  // (a first step from the predictor may sit next to a singular point, where the residual is
  // quadratic in the distance and a small residual says little about the error).
  const double tolerance = options_.step_tolerance * (1.0 + u->norm());
  if (options_.accept_on_error_estimate && k >= 2) {
    w.delta = -w.F;
    w.solver.Solve(w.delta, &w.correction);
  }
  if (options_.accept_on_error_estimate && k >= 2 && newton.last_step > tolerance && w.correction.norm() <= tolerance) {
    *u += w.correction;
    result->step_norm = w.correction.norm();
    result->distance = (*u - newton.u_pred).norm();
    ProjectOnConstraint(newton.border, newton.value, u);
    result->status = CorrectorStatus::kConverged;
    return true;
  }
  // At the rounding floor the steps stop contracting; the residual test decides there.
  const bool at_floor = k >= 2 && newton.last_step >= 0.5 * newton.previous_step;
  if (newton.last_step <= tolerance || at_floor) {
    ProjectOnConstraint(newton.border, newton.value, u);
    result->status = CorrectorStatus::kConverged;
    return true;
  }
  return false;
}

bool Corrector::Stalled(Newton* newton, int k, CorrectorResult* result) const {
  // Growing steps alone are not divergence: a first step that overshoots along a nearly singular
  // direction of B is taken back by the second one (|Δ₁| ≈ |Δ₀|) while the residual drops.
  if (k >= 2 && newton->last_step > options_.max_contraction * newton->previous_step &&
      result->residual_norm >= newton->previous_residual) {
    result->status = CorrectorStatus::kDiverged;
    result->message = "Newton steps and residual grow: |du| " + std::to_string(newton->previous_step) + " -> " +
                      std::to_string(newton->last_step) + ", |F| " + std::to_string(newton->previous_residual) +
                      " -> " + std::to_string(result->residual_norm);
    return true;
  }
  newton->previous_residual = result->residual_norm;
  if (k == options_.max_iterations) {
    result->status = CorrectorStatus::kMaxIterations;
    result->message = "|F| = " + std::to_string(result->residual_norm) + " after " + std::to_string(k) +
                      " iterations";
    return true;
  }
  return false;
}

bool Corrector::TakeNewtonStep(Newton* newton, int k, Vector* u, CorrectorResult* result) {
  Workspace& w = *workspace_;
  if (!(w.sparse ? w.solver.Factorize(w.dr_sparse, w.border) : w.solver.Factorize(w.dr, w.border))) {
    result->status = CorrectorStatus::kSingular;
    result->message = "bordered matrix [dr; b^T] singular at iteration " + std::to_string(k);
    return false;
  }
  w.F = -w.F;
  w.solver.Solve(w.F, &w.delta);
  if (newton->border == Border::kMoorePenrose) {
    // Kernel update (Allgower–Georg): the new border is the tangent induced by dr(u_k), oriented like
    // the old one (its last equation is τ_kᵀ v = 1 > 0).
    w.solver.Solve(w.unit_last, &w.kernel);
    w.border = w.kernel / w.kernel.norm();
  }
  newton->before_previous_step = newton->previous_step;
  newton->previous_step = newton->last_step;
  newton->last_step = w.delta.norm();
  result->step_norm = newton->last_step;
  if (k == 1) result->contraction = newton->previous_step > 0 ? newton->last_step / newton->previous_step : 0.0;
  *u += w.delta;
  result->iterations = k + 1;
  if ((*u - newton->u_pred).norm() > options_.max_distance) {
    result->status = CorrectorStatus::kDiverged;
    result->message = "iterate left the ball of radius max_distance = " + std::to_string(options_.max_distance) +
                      " around the predictor";
    return false;
  }
  return true;
}

bool Corrector::AcceptedAfterStep(const Newton& newton, int k, Vector* u, CorrectorResult* result) const {
  const bool on_curve = k == 0 && newton.exact_at_predictor && result->residual_norm <= options_.residual_tolerance &&
                        newton.last_step <= std::min(CorrectorOptions::kOnCurveStep, options_.max_jacobian_distance) *
                                                (1.0 + u->norm());
  if (on_curve || (options_.accept_on_error_estimate && k >= 1 &&
                   AcceptNewtonStep(newton.before_previous_step, newton.previous_step, newton.last_step, *u))) {
    // u_{k+1} = u_k + Δ_k is returned without evaluating r there: its error is estimated by θ_k·|Δ_k|
    // (AcceptNewtonStep). jacobian() stays the one at u_k, |Δ_k| away.
    result->distance = (*u - newton.u_pred).norm();
    ProjectOnConstraint(newton.border, newton.value, u);
    result->status = CorrectorStatus::kConverged;
    return true;
  }
  return false;
}

}  // namespace hybridcont
