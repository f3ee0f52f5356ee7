// Lyapunov–Schmidt reduction at singular points (branch_switching.h).
#include "hybridcont/branch_switching.h"

#include "continuation/jacobian_tolerance_scope.h"
#include "hybridcont/internal/enum_names.h"
#include "hybridcont/internal/options_check.h"
#include "hybridcont/invariant.h"

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace hybridcont {
namespace {

std::string FormatNumber(double value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

// Forms (A_j)_pq = ψ_jᵀ d²r[φ_p, φ_q] by central differences of dr along each φ_q with step eps,
// symmetrized. False (and *message) where an evaluation at u ± eps·φ_q fails.
bool DifferencedForms(ZeroProblem* problem, const Vector& u, const Matrix& kernel, const Matrix& cokernel,
                      double eps, std::vector<Matrix>* forms, std::string* message) {
  const Eigen::Index k = kernel.cols(), m = cokernel.cols();
  forms->assign(m, Matrix::Zero(k, k));
  Matrix dr_plus, dr_minus;
  for (Eigen::Index q = 0; q < k; ++q) {
    const EvaluationStatus plus = problem->Evaluate(u + eps * kernel.col(q), nullptr, &dr_plus);
    const EvaluationStatus minus = problem->Evaluate(u - eps * kernel.col(q), nullptr, &dr_minus);
    if (!plus.ok || !minus.ok) {
      *message = plus.ok ? minus.message : plus.message;
      return false;
    }
    const Matrix second = cokernel.transpose() * ((dr_plus - dr_minus) / (2 * eps)) * kernel;  // m x k: [j, p]
    for (Eigen::Index j = 0; j < m; ++j) (*forms)[j].col(q) = second.row(j).transpose();
  }
  for (Matrix& form : *forms) form = 0.5 * (form + form.transpose()).eval();
  return true;
}

// ||a - b|| / max(||a||, ||b||) over all forms (Frobenius).
double FormsDistance(const std::vector<Matrix>& a, const std::vector<Matrix>& b) {
  double difference = 0, size = 0;
  for (size_t j = 0; j < a.size(); ++j) {
    difference += (a[j] - b[j]).squaredNorm();
    size += std::max(a[j].squaredNorm(), b[j].squaredNorm());
  }
  return size > 0 ? std::sqrt(difference / size) : 0.0;
}

// The forms by differences with step eps, confirmed by the differences with step eps/10 (branch_switching.h,
// "Second derivatives"). Where the two disagree by more than kFormAgreement, or an evaluation fails, the
// step shrinks tenfold, down to eps·kMinStepFactor. The forms of the coarsest confirmed step are kept
// (less rounding noise than the finer one), so a problem confirmed at once gets exactly the forms of eps.
// *message notes a shrunken step; false with the history where no step is confirmed.
bool QuadraticForms(ZeroProblem* problem, const Vector& u, const Matrix& kernel, const Matrix& cokernel,
                    double eps, std::vector<Matrix>* forms, std::string* message) {
  // 1 %: far above the agreement of a quadratic-enough map (truncation O(eps^2) plus integration noise
  // over eps, ~1e-5 relative at eps = 1e-5) and far below what steers a switch to the wrong branch.
  constexpr double kFormAgreement = 1e-2;
  // Six decades: below ~1e-10 integration noise in dr (~1e-10 relative) outweighs any second derivative.
  constexpr double kMinStepFactor = 1e-6;
  std::vector<Matrix> coarse, fine;
  std::string why;
  bool have_coarse = DifferencedForms(problem, u, kernel, cokernel, eps, &coarse, &why);
  std::ostringstream history;
  for (double step = eps; step / 10 >= eps * kMinStepFactor; step /= 10) {
    std::string fine_why;
    const bool have_fine = DifferencedForms(problem, u, kernel, cokernel, step / 10, &fine, &fine_why);
    const double distance = have_coarse && have_fine ? FormsDistance(coarse, fine) : -1;
    if (distance >= 0 && distance <= kFormAgreement) {
      *forms = std::move(coarse);
      if (step != eps) {
        *message = "second derivatives by differences with step " + FormatNumber(step) + " (" + history.str() +
                   "the map is far from quadratic over larger steps)";
      }
      return true;
    }
    history << "step " << FormatNumber(step) << ": "
            << (!have_coarse ? why
                : !have_fine ? "the step ten times smaller failed: " + fine_why
                             : "differs from the step ten times smaller by " + FormatNumber(distance))
            << "; ";
    coarse = std::move(fine);
    have_coarse = have_fine;
    why = fine_why;
  }
  *message = "finite-difference evaluation failed: no step from " + FormatNumber(eps) + " down to " +
             FormatNumber(eps * kMinStepFactor) + " gives second derivatives that the step ten times smaller confirms (" +
             history.str() + "end)";
  return false;
}

constexpr internal::EnumName<BranchSwitchStatus> kBranchSwitchStatusNames[] = {
    {BranchSwitchStatus::kOk, "ok"},
    {BranchSwitchStatus::kFallback, "fallback"},
    {BranchSwitchStatus::kRegular, "regular"},
    {BranchSwitchStatus::kUnderdetermined, "underdetermined"},
    {BranchSwitchStatus::kNoRoots, "no-roots"},
    {BranchSwitchStatus::kEvaluationFailed, "evaluation-failed"},
};

enum class Roots { kTwo, kDouble, kNone };

// Real roots (unit vectors in R²) of α A α = a α₁² + 2b α₁α₂ + c α₂² = 0. A discriminant within
// ±degeneracy_tolerance·(a² + b² + c²) of zero is a double root (one direction), below that no real root.
Roots QuadraticRoots(const Matrix& A, double degeneracy_tolerance, std::vector<Eigen::Vector2d>* roots) {
  const double a = A(0, 0), b = A(0, 1), c = A(1, 1);
  const double scale = a * a + b * b + c * c;
  const double disc = b * b - a * c;
  roots->clear();
  if (!(scale > 0) || disc < -degeneracy_tolerance * scale) return Roots::kNone;
  // Homogeneous roots (α₁, α₂) of a α₁² + 2b α₁α₂ + c α₂²: t = α₁/α₂ ∈ {q/a, c/q} gives the directions
  // (q, a) and (c, q) without any division, valid also for a = 0 or c = 0 (e.g. Q = −2α₁α₂).
  if (disc <= degeneracy_tolerance * scale) {
    const Eigen::Vector2d first(-b, a), second(c, -b);
    roots->push_back((first.norm() >= second.norm() ? first : second).normalized());
    return Roots::kDouble;
  }
  const double q = -(b + std::copysign(std::sqrt(disc), b));  // |q| >= sqrt(disc) > 0: no cancellation
  roots->push_back(Eigen::Vector2d(q, a).normalized());
  roots->push_back(Eigen::Vector2d(c, q).normalized());
  return Roots::kTwo;
}

}  // namespace

Vector CanonicalLine(Vector v) {
  v.normalize();
  Eigen::Index i;
  v.cwiseAbs().maxCoeff(&i);
  return v(i) < 0 ? Vector(-v) : v;
}

namespace {

// The conditions as rows c_i of C (C v = 0), on the unknowns named by their coefficients.
Matrix ConditionMatrix(const ZeroProblem& problem, const std::vector<LinearCondition>& conditions) {
  Matrix C(static_cast<Eigen::Index>(conditions.size()), problem.num_unknowns());
  C.setZero();
  for (size_t i = 0; i < conditions.size(); ++i) {
    for (const auto& [name, coefficient] : conditions[i].coefficients) {
      const int index = problem.UnknownIndex(name);
      if (index < 0) throw std::invalid_argument("StartOptions::conditions: \"" + name + "\" is not an unknown");
      C(static_cast<Eigen::Index>(i), index) += coefficient;
    }
  }
  return C;
}

// Singular values, kernel and cokernel of dr(u0) (rank decided relative to max(1, σ_max)); false when
// the evaluation failed (out says why).
bool AnalyzeKernel(ZeroProblem* problem, const Vector& u0, double rank_tolerance, BranchDirections* out) {
  Matrix dr;
  if (const EvaluationStatus status = problem->Evaluate(u0, nullptr, &dr); !status.ok) {
    out->status = BranchSwitchStatus::kEvaluationFailed;
    out->message = status.message;
    return false;
  }
  const int n = problem->num_unknowns();
  Eigen::JacobiSVD<Matrix> svd(dr, Eigen::ComputeFullU | Eigen::ComputeFullV);
  out->singular_values = svd.singularValues();
  const double threshold = rank_tolerance * std::max(1.0, out->singular_values.maxCoeff());
  int rank = 0;
  while (rank < out->singular_values.size() && out->singular_values(rank) > threshold) ++rank;
  out->kernel_dimension = n - rank;
  out->cokernel_dimension = static_cast<int>(dr.rows()) - rank;
  out->kernel = svd.matrixV().rightCols(out->kernel_dimension);
  out->cokernel = svd.matrixU().rightCols(out->cokernel_dimension);
  return true;
}

// Z spanning the null space of C Φ: the kernel Φ restricted by the conditions is Φ Z.
Matrix RestrictedKernel(const Matrix& C, const Matrix& kernel, double rank_tolerance) {
  const Eigen::Index k = kernel.cols();
  if (C.rows() == 0) return Matrix::Identity(k, k);
  const Matrix CPhi = C * kernel;
  Eigen::JacobiSVD<Matrix> csvd(CPhi, Eigen::ComputeFullV);
  const double cmax = std::max(1.0, csvd.singularValues().size() ? csvd.singularValues().maxCoeff() : 0.0);
  int crank = 0;
  while (crank < csvd.singularValues().size() && csvd.singularValues()(crank) > rank_tolerance * cmax) ++crank;
  return csvd.matrixV().rightCols(k - crank);
}

// The branch lines Φ Z α of a 2-dim restricted kernel: roots α of the dominant form that make every
// other form vanish too (out->status, directions and message).
void CommonRoots(const std::vector<Matrix>& forms, const Matrix& basis, const BranchSwitchOptions& options,
                 BranchDirections* out) {
  HYBRIDCONT_DEMAND(!forms.empty());
  size_t dominant = 0;
  for (size_t j = 1; j < forms.size(); ++j) {
    if (forms[j].norm() > forms[dominant].norm()) dominant = j;
  }
  std::vector<Eigen::Vector2d> roots;
  const Roots kind = QuadraticRoots(forms[dominant], options.degeneracy_tolerance, &roots);
  if (kind == Roots::kNone) {
    out->status = BranchSwitchStatus::kNoRoots;
    out->message = "the algebraic bifurcation equation has no real roots (or vanishes identically)";
    return;
  }
  // A double root is one branch line: with a 2-dim kernel a degenerate (non-simple) point, after
  // restriction by conditions the usual case (the other branches lie outside the restricted plane).
  if (kind == Roots::kDouble) out->message = "double root of the algebraic bifurcation equation";
  for (const Eigen::Vector2d& root : roots) {
    bool common = true;
    for (const Matrix& form : forms) {
      if (std::abs(root.dot(form * root)) > options.abe_tolerance * std::max(form.norm(), 1e-300) &&
          form.norm() > options.abe_tolerance * forms[dominant].norm()) {
        common = false;
      }
    }
    if (common) out->directions.push_back(CanonicalLine(basis * root));
  }
  out->status = out->directions.empty() ? BranchSwitchStatus::kNoRoots : BranchSwitchStatus::kOk;
  if (out->directions.empty()) out->message = "the roots of the dominant form do not solve the other forms";
  if (out->directions.size() == 2 && std::abs(out->directions[0].dot(out->directions[1])) > 1 - 1e-12) {
    out->directions.pop_back();
  }
}

}  // namespace

std::string ToString(BranchSwitchStatus status) { return internal::EnumToString(kBranchSwitchStatusNames, status); }

std::string BranchSwitchOptions::Validate() const {
  return internal::OptionsCheck("BranchSwitchOptions")
      .Between("rank_tolerance", rank_tolerance, 0, 1)
      .Require(fd_step > 0, "fd_step", fd_step, "must be > 0")
      .Require(degeneracy_tolerance >= 0, "degeneracy_tolerance", degeneracy_tolerance, "must be >= 0")
      .Require(abe_tolerance > 0, "abe_tolerance", abe_tolerance, "must be > 0")
      .message();
}

std::string StartOptions::Validate() const {
  internal::OptionsCheck check("StartOptions");
  check.Nested("switching", switching.Validate());
  for (size_t i = 0; i < conditions.size(); ++i) {
    check.Require(!conditions[i].coefficients.empty(), "conditions[" + std::to_string(i) + "] has no coefficients");
  }
  return check.message();
}

std::string BranchDirections::BriefReport() const {
  std::ostringstream out;
  out << "Singular point: " << ToString(status) << ", kernel dimension " << kernel_dimension << ", "
      << directions.size() << " branch directions";
  if (!message.empty()) out << " (" << message << ")";
  return out.str();
}

std::string BranchSwitch::BriefReport() const {
  std::ostringstream out;
  out << "Branch switch: " << ToString(status) << ", ABE (" << a << ", " << b << ", " << c
      << "), incoming root angle " << incoming_root_angle << ", sigma_min/max(1, sigma_max) " << sigma_ratio;
  if (!message.empty()) out << " (" << message << ")";
  return out.str();
}

BranchDirections AnalyzeSingularPoint(ZeroProblem* problem, const Vector& u0, const StartOptions& options) {
  if (const std::string error = options.Validate(); !error.empty()) throw std::invalid_argument(error);
  // Kernels and second derivatives (finite differences of dr) from the exact Jacobian.
  const internal::JacobianToleranceScope exact(problem, 0.0, internal::JacobianToleranceScope::Mode::kExactly);
  const int n = problem->num_unknowns();
  if (u0.size() != n) {
    throw std::invalid_argument("AnalyzeSingularPoint: u0 has size " + std::to_string(u0.size()) +
                                ", expected " + std::to_string(n));
  }
  const Matrix C = ConditionMatrix(*problem, options.conditions);

  BranchDirections out;
  if (!AnalyzeKernel(problem, u0, options.switching.rank_tolerance, &out)) return out;
  if (out.kernel_dimension == 1) {
    out.status = BranchSwitchStatus::kRegular;
    out.directions.push_back(CanonicalLine(out.kernel.col(0)));
    return out;
  }
  const Matrix basis = out.kernel * RestrictedKernel(C, out.kernel, options.switching.rank_tolerance);
  if (basis.cols() == 0) {
    out.status = BranchSwitchStatus::kNoRoots;
    out.message = "the linear conditions exclude every kernel direction";
    return out;
  }
  if (basis.cols() == 1) {
    out.status = BranchSwitchStatus::kOk;
    out.message = "direction selected by the linear conditions alone";
    out.directions.push_back(CanonicalLine(basis.col(0)));
    return out;
  }
  if (basis.cols() > 2) {
    // ξ = 0 on every periodic orbit of a conservative model: where the ξ axis lies in the restricted kernel
    // (it leads into the rest states of the dissipative unfolding, not into a family of orbits), the
    // condition direction[ξ] = 0 is added and the analysis repeated.
    const int xi = problem->UnknownIndex("xi");
    const bool has_xi_condition = std::any_of(options.conditions.begin(), options.conditions.end(), [](const auto& c) {
      return c.coefficients.size() == 1 && c.coefficients.front().first == "xi";
    });
    if (xi >= 0 && !has_xi_condition && (basis.transpose().col(xi)).norm() >= 1 - 1e-8) {
      StartOptions with_xi = options;
      with_xi.conditions.push_back(LinearCondition{{{"xi", 1.0}}});
      BranchDirections again = AnalyzeSingularPoint(problem, u0, with_xi);
      again.message = "the condition direction[xi] = 0 added (the xi axis leads into rest states, not orbits)" +
                      (again.message.empty() ? std::string() : "; " + again.message);
      return again;
    }
    out.status = BranchSwitchStatus::kUnderdetermined;
    out.message = "kernel dimension " + std::to_string(out.kernel_dimension) + " restricted to " +
                  std::to_string(basis.cols()) + " by the conditions; give " + std::to_string(basis.cols() - 2) +
                  " more linear condition(s)";
    return out;
  }
  std::vector<Matrix> forms;
  if (!QuadraticForms(problem, u0, basis, out.cokernel, options.switching.fd_step, &forms, &out.message)) {
    out.status = BranchSwitchStatus::kEvaluationFailed;
    return out;
  }
  CommonRoots(forms, basis, options.switching, &out);
  return out;
}

std::vector<Vector> BranchDirectionsAt(ZeroProblem& problem, const Vector& u0, const StartOptions& options) {
  return AnalyzeSingularPoint(&problem, u0, options).directions;
}

BranchSwitch SwitchDirectionAt(ZeroProblem* problem, const SpecialPoint& sb, const BranchSwitchOptions& options) {
  if (const std::string error = options.Validate(); !error.empty()) throw std::invalid_argument(error);
  // Kernel and second derivatives (finite differences of dr) from the exact Jacobian.
  const internal::JacobianToleranceScope exact(problem, 0.0, internal::JacobianToleranceScope::Mode::kExactly);
  BranchSwitch out;
  Matrix dr;
  if (const EvaluationStatus status = problem->Evaluate(sb.u, nullptr, &dr); !status.ok) {
    out.status = BranchSwitchStatus::kEvaluationFailed;
    out.message = status.message;
    return out;
  }
  const Eigen::Index n = dr.cols(), rows = dr.rows();
  Eigen::JacobiSVD<Matrix> svd(dr, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Vector& sigma = svd.singularValues();
  out.sigma_ratio = sigma(rows - 1) / std::max(sigma(0), 1.0);
  const Matrix kernel = svd.matrixV().rightCols(2);
  const Matrix cokernel = svd.matrixU().rightCols(1);
  // Basis φ₁ ∥ (incoming tangent projected on the kernel), φ₂ ⟂ φ₁ in the kernel.
  // The tangent at the located point (special_point.h: never the meaningless induced tangent next to the
  // SB), else the last one before it.
  const Vector incoming = sb.tangent.size() == n && sb.tangent.allFinite() ? sb.tangent : sb.tangent_before;
  Eigen::Vector2d c1 = kernel.transpose() * incoming;
  if (!(c1.norm() > 0)) c1 = Eigen::Vector2d(1, 0);
  c1.normalize();
  Matrix basis(n, 2);
  basis.col(0) = kernel * c1;
  basis.col(1) = kernel * Eigen::Vector2d(-c1(1), c1(0));

  std::vector<Matrix> forms;
  if (!QuadraticForms(problem, sb.u, basis, cokernel, options.fd_step, &forms, &out.message)) {
    out.status = BranchSwitchStatus::kEvaluationFailed;
    return out;
  }
  out.a = forms[0](0, 0);
  out.b = forms[0](0, 1);
  out.c = forms[0](1, 1);
  std::vector<Eigen::Vector2d> roots;
  if (QuadraticRoots(forms[0], options.degeneracy_tolerance, &roots) != Roots::kTwo) {
    out.status = BranchSwitchStatus::kFallback;
    out.message = "degenerate algebraic bifurcation equation (discriminant b^2 - ac = " +
                  std::to_string(out.b * out.b - out.a * out.c) +
                  "): using the kernel direction orthogonal to the incoming tangent";
    out.direction = CanonicalLine(basis.col(1));
    out.incoming_direction = basis.col(0);
    return out;
  }
  // Transverse root: smallest |α₁| (least aligned with the incoming tangent).
  const bool first_transverse = std::abs(roots[0](0)) < std::abs(roots[1](0));
  const Eigen::Vector2d transverse = first_transverse ? roots[0] : roots[1];
  const Eigen::Vector2d along = first_transverse ? roots[1] : roots[0];
  out.direction = CanonicalLine(basis * transverse);
  out.incoming_direction = (basis * along).normalized();
  if (out.incoming_direction.dot(incoming) < 0) out.incoming_direction = -out.incoming_direction;
  out.incoming_root_angle = std::acos(std::clamp(std::abs(along(0)), 0.0, 1.0));
  out.status = BranchSwitchStatus::kOk;
  return out;
}

std::vector<Branch> TraceSwitchedBranches(ZeroProblem* problem, const SpecialPoint& sb,
                                          const BranchSwitch& branch_switch, const ContinuationOptions& options) {
  std::vector<Branch> branches;
  for (const int d : {+1, -1}) {
    ContinuationStepper stepper(problem, options, static_cast<int>(branches.size()));
    StepStatus status = stepper.StartAtSingularPoint(sb.u, d * branch_switch.direction);
    while (status == StepStatus::kContinuing) status = stepper.Step();
    Branch branch = stepper.TakeBranch();
    branch.direction = d;
    branch.parent_special_point = sb.id;
    branches.push_back(std::move(branch));
  }
  return branches;
}

}  // namespace hybridcont
