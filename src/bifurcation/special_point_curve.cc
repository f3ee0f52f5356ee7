// Minimally augmented defining systems of fold, branch-point and test-function curves, and the driver that
// traces them in both directions and locates codimension-two points (special_point_curve.h).
#include "hybridcont/special_point_curve.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include <Eigen/LU>
#include <Eigen/SVD>

#include "continuation/bordered_solver.h"
#include "continuation/branch_geometry.h"
#include "hybridcont/internal/enum_names.h"
#include "hybridcont/internal/options_check.h"
#include "hybridcont/invariant.h"

namespace hybridcont {
namespace {

constexpr internal::EnumName<CurveKind> kCurveKindNames[] = {
    {CurveKind::kFold, "fold"},
    {CurveKind::kBranchPoint, "branch-point"},
    {CurveKind::kTestFunction, "test-function"},
};
constexpr internal::EnumName<CodimTwoType> kCodimTwoNames[] = {
    {CodimTwoType::kTurning, "turning"},
    {CodimTwoType::kCusp, "cusp"},
    {CodimTwoType::kFoldOnBranchPoint, "fold-on-branch-point"},
    {CodimTwoType::kBetaZero, "beta-zero"},
    {CodimTwoType::kMonitor, "monitor"},
    {CodimTwoType::kCrossing, "crossing"},
};
constexpr internal::EnumName<CurveStatus> kCurveStatusNames[] = {
    {CurveStatus::kTraced, "traced"},
    {CurveStatus::kStartFailed, "start-failed"},
};

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Columns of the fixing row other than its largest count as zero below this fraction of it.
constexpr double kFixingRowTolerance = 1e-14;

// Hadamard-normalized determinant of [A; bᵀ] (det over the product of its row norms, in [−1, 1]) through
// the engine's bordered solver (log|pivots| and a sign: units mix, a product would over- or underflow).
// 0 where the matrix is numerically singular.
double NormalizedDeterminant(const Matrix& a, const Vector& b) {
  internal::BorderedSolver solver;
  if (!solver.Factorize(a, b) || b.norm() == 0.0) return 0.0;
  return solver.DeterminantSign() *
         std::exp(solver.LogAbsDeterminant() - internal::LogRowScale(a) - std::log(b.norm()));
}

// Orthonormal columns spanning those of a (n x 2), Gram–Schmidt in column order: the frame keeps the
// orientation of a (the triangular factor has a positive diagonal).
Matrix OrthonormalFrame(const Matrix& a) {
  Matrix q = a;
  q.col(0).normalize();
  q.col(1) -= q.col(0).dot(q.col(1)) * q.col(0);
  q.col(1).normalize();
  return q;
}

}  // namespace

std::string ToString(CurveKind kind) { return internal::EnumToString(kCurveKindNames, kind); }
bool FromString(const std::string& text, CurveKind* kind) {
  return internal::EnumFromString(kCurveKindNames, text, kind);
}
std::string ToString(CodimTwoType type) { return internal::EnumToString(kCodimTwoNames, type); }
std::string ToString(CurveStatus status) { return internal::EnumToString(kCurveStatusNames, status); }

std::string SpecialPointCurveOptions::Validate() const {
  return internal::OptionsCheck("SpecialPointCurveOptions")
      .Nested("continuation", continuation.Validate())
      .Positive("second_derivative_step", second_derivative_step)
      .Positive("location.sigma_tolerance", location.sigma_tolerance)
      .AtLeast("location.max_iterations", location.max_iterations, 1)
      .Require(std::all_of(monitors.begin(), monitors.end(),
                           [](const ScalarTest& t) { return !t.name.empty() && t.value != nullptr; }),
               "monitors: every monitor needs a name and a value function")
      .message();
}

// ---------------------------------------------------------------------------------------------------------
// The curve problem.

struct SpecialPointCurveProblem::Impl {
  ZeroProblem* base = nullptr;
  CurveDefinition definition;
  SpecialPointCurveOptions options;
  int n = 0;                  // N: equations of R
  int a = -1, b = -1;         // the two parameters among the base unknowns
  std::vector<int> rows;      // base rows other than the fixing row
  std::vector<int> x_columns; // base unknowns other than a and b
  std::vector<int> m_columns; // base unknowns other than b
  // Fold borders of R_x (fold curves; on branch-point curves for the fold-on-BP test).
  Vector fold_b, fold_c;
  // Branch-point borders of M = [R_x R_a] and the regularization vector.
  Vector bp_border;  // ψ̃, N
  Matrix bp_frame;   // V, (N+1) x 2
  Vector psi;        // ψ, N
  // Scratch of the base evaluations.
  Vector base_r;
  Matrix base_dr;

  int base_unknowns() const { return n + 2; }

  // R (and dR) at the base unknowns u: the base problem without its fixing row.
  EvaluationStatus EvaluateR(const Vector& u, Vector* r, Matrix* dr) {
    EvaluationStatus status = base->Evaluate(u, r ? &base_r : nullptr, dr ? &base_dr : nullptr);
    if (!status.ok) return status;
    if (r) *r = base_r(rows);
    if (dr) *dr = base_dr(rows, Eigen::all);
    return status;
  }

  // Solves [A β; cᵀ 0][v; g] = [0; 1] and its adjoint [Aᵀ c; βᵀ 0][w; h] = [0; 1] (A = R_x).
  bool FoldSolve(const Matrix& dr, Vector* v, Vector* w, double* g) const {
    Matrix k = Matrix::Zero(n + 1, n + 1);
    k.topLeftCorner(n, n) = dr(Eigen::all, x_columns);
    k.topRightCorner(n, 1) = fold_b;
    k.bottomLeftCorner(1, n) = fold_c.transpose();
    const Eigen::PartialPivLU<Matrix> lu(k);
    Vector rhs = Vector::Zero(n + 1);
    rhs(n) = 1;
    const Vector s = lu.solve(rhs), t = lu.transpose().solve(rhs);
    if (!s.allFinite() || !t.allFinite()) return false;
    *v = s.head(n);
    *g = s(n);
    *w = t.head(n);
    return true;
  }

  // Solves [M ψ̃; Vᵀ 0][Φ; g] = [0; I₂] and [Mᵀ V; ψ̃ᵀ 0][w; h] = [0; 1] (M = [R_x R_a]).
  bool BranchPointSolve(const Matrix& dr, Matrix* phi, Vector* w, Vector* g) const {
    Matrix k = Matrix::Zero(n + 2, n + 2);
    k.topLeftCorner(n, n + 1) = dr(Eigen::all, m_columns);
    k.topRightCorner(n, 1) = bp_border;
    k.bottomLeftCorner(2, n + 1) = bp_frame.transpose();
    const Eigen::PartialPivLU<Matrix> lu(k);
    Matrix rhs = Matrix::Zero(n + 2, 2);
    rhs.bottomRows(2).setIdentity();
    const Matrix s = lu.solve(rhs);
    Vector e = Vector::Zero(n + 2);
    e(n + 1) = 1;
    const Vector t = lu.transpose().solve(e);
    if (!s.allFinite() || !t.allFinite()) return false;
    *phi = s.topRows(n + 1);
    *g = s.row(n + 1).transpose();
    *w = t.head(n);
    return true;
  }

  // v on x (or on the m columns) padded with zeros to a base direction.
  Vector Pad(const Vector& v, const std::vector<int>& columns) const {
    Vector d = Vector::Zero(base_unknowns());
    for (int i = 0; i < static_cast<int>(columns.size()); ++i) d(columns[i]) = v(i);
    return d;
  }

  // wᵀ R_uu[d, ·] = d/dε wᵀ dR(u + εd), the central difference of two Jacobians along d/|d|.
  EvaluationStatus DirectionalGradient(const Vector& u, const Vector& w, const Vector& d, RowVector* out) {
    const double length = d.norm(), eps = options.second_derivative_step;
    out->setZero(base_unknowns());
    if (length == 0.0) return {};
    Matrix plus, minus;
    EvaluationStatus status = EvaluateR(u + (eps / length) * d, nullptr, &plus);
    if (!status.ok) return status;
    status = EvaluateR(u - (eps / length) * d, nullptr, &minus);
    if (!status.ok) return status;
    *out = w.transpose() * (plus - minus) * (length / (2 * eps));
    return {};
  }

  // The caller's scalar test and its gradient (the caller's, or central differences of its value).
  EvaluationStatus TestGradient(const ScalarTest& test, const Vector& u, RowVector* gradient) const {
    if (test.gradient) {
      if (!test.gradient(u, gradient) || gradient->size() != base_unknowns() || !gradient->allFinite()) {
        return EvaluationStatus::Failure("test function '" + test.name + "': no gradient at this point");
      }
      return {};
    }
    const double h = options.second_derivative_step;
    gradient->resize(base_unknowns());
    for (int k = 0; k < base_unknowns(); ++k) {
      Vector up = u, down = u;
      up(k) += h;
      down(k) -= h;
      (*gradient)(k) = (test.value(up) - test.value(down)) / (2 * h);
    }
    if (!gradient->allFinite()) {
      return EvaluationStatus::Failure("test function '" + test.name + "': not finite next to this point");
    }
    return {};
  }
};

SpecialPointCurveProblem::SpecialPointCurveProblem(ZeroProblem* base, const CurveDefinition& definition,
                                                   const Vector& u0, const SpecialPointCurveOptions& options)
    : impl_(std::make_unique<Impl>()) {
  if (base == nullptr) throw std::invalid_argument("SpecialPointCurveProblem: base problem is null");
  const std::string message = options.Validate();
  if (!message.empty()) throw std::invalid_argument(message);
  Impl& m = *impl_;
  m.base = base;
  m.definition = definition;
  m.options = options;
  m.n = base->num_equations() - 1;
  if (m.n < 1) throw std::invalid_argument("SpecialPointCurveProblem: the base problem needs at least 2 equations");
  if (definition.fix_row < 0 || definition.fix_row > m.n) {
    throw std::invalid_argument("CurveDefinition::fix_row = " + std::to_string(definition.fix_row) +
                                " must index one of the base problem's " + std::to_string(m.n + 1) + " rows");
  }
  m.a = base->UnknownIndex(definition.family_parameter);
  if (m.a < 0) {
    throw std::invalid_argument("CurveDefinition::family_parameter = '" + definition.family_parameter +
                                "' is not an unknown of the base problem");
  }
  if (definition.kind == CurveKind::kTestFunction && !definition.test.value) {
    throw std::invalid_argument("CurveDefinition::test: a test-function curve needs a value function");
  }
  if (u0.size() != m.base_unknowns() && u0.size() != num_unknowns()) {
    throw std::invalid_argument("SpecialPointCurveProblem: u0 has " + std::to_string(u0.size()) +
                                " entries, expected " + std::to_string(m.base_unknowns()));
  }
  const Vector u_base = u0.head(m.base_unknowns());
  const EvaluationStatus status = base->Evaluate(u_base, nullptr, &m.base_dr);
  if (!status.ok) throw std::invalid_argument("SpecialPointCurveProblem: base Jacobian at u0: " + status.message);
  const RowVector fixing = m.base_dr.row(definition.fix_row);
  Eigen::Index b = 0;
  const double largest = fixing.cwiseAbs().maxCoeff(&b);
  if (!(largest > 0) || (fixing.cwiseAbs().sum() - largest) > kFixingRowTolerance * largest) {
    throw std::invalid_argument("CurveDefinition::fix_row = " + std::to_string(definition.fix_row) +
                                " is not a fixing row u_b - c = 0 (one nonzero Jacobian entry)");
  }
  m.b = static_cast<int>(b);
  if (m.b == m.a) {
    throw std::invalid_argument("CurveDefinition::family_parameter = '" + definition.family_parameter +
                                "' is the unknown the fixing row holds fixed");
  }
  for (int i = 0; i <= m.n; ++i) {
    if (i != definition.fix_row) m.rows.push_back(i);
  }
  for (int j = 0; j < m.base_unknowns(); ++j) {
    if (j != m.a && j != m.b) m.x_columns.push_back(j);
    if (j != m.b) m.m_columns.push_back(j);
  }
  const EvaluationStatus borders = InitializeBorders(u0);
  if (!borders.ok) throw std::invalid_argument("SpecialPointCurveProblem: borders at u0: " + borders.message);
}

SpecialPointCurveProblem::~SpecialPointCurveProblem() = default;

CurveKind SpecialPointCurveProblem::kind() const { return impl_->definition.kind; }
int SpecialPointCurveProblem::family_index() const { return impl_->a; }
int SpecialPointCurveProblem::second_index() const { return impl_->b; }
int SpecialPointCurveProblem::base_unknowns() const { return impl_->base_unknowns(); }

int SpecialPointCurveProblem::num_equations() const {
  return impl_->n + (impl_->definition.kind == CurveKind::kBranchPoint ? 2 : 1);
}

std::vector<std::string> SpecialPointCurveProblem::unknown_names() const {
  std::vector<std::string> names = impl_->base->unknown_names();
  if (impl_->definition.kind == CurveKind::kBranchPoint) names.push_back("beta");
  return names;
}

EvaluationStatus SpecialPointCurveProblem::InitializeBorders(const Vector& u) {
  Impl& m = *impl_;
  Matrix dr;
  const EvaluationStatus status = m.EvaluateR(u.head(m.base_unknowns()), nullptr, &dr);
  if (!status.ok) return status;
  if (m.definition.kind == CurveKind::kTestFunction) return {};
  const Eigen::JacobiSVD<Matrix> fold(dr(Eigen::all, m.x_columns), Eigen::ComputeFullU | Eigen::ComputeFullV);
  m.fold_b = fold.matrixU().col(m.n - 1);
  m.fold_c = fold.matrixV().col(m.n - 1);
  if (m.definition.kind == CurveKind::kBranchPoint) {
    const Eigen::JacobiSVD<Matrix> bp(dr(Eigen::all, m.m_columns), Eigen::ComputeFullU | Eigen::ComputeFullV);
    m.bp_border = bp.matrixU().col(m.n - 1);
    m.psi = m.bp_border;
    m.bp_frame = bp.matrixV().rightCols(2);
  }
  return {};
}

EvaluationStatus SpecialPointCurveProblem::UpdateBorders(const Vector& u) {
  Impl& m = *impl_;
  if (m.definition.kind == CurveKind::kTestFunction) return {};
  Matrix dr;
  const EvaluationStatus status = m.EvaluateR(u.head(m.base_unknowns()), nullptr, &dr);
  if (!status.ok) return status;
  Vector v, w;
  double g = 0;
  if (m.FoldSolve(dr, &v, &w, &g) && v.norm() > 0 && w.norm() > 0) {
    m.fold_c = v.normalized();
    m.fold_b = w.normalized();
  }
  if (m.definition.kind == CurveKind::kBranchPoint) {
    Matrix phi;
    Vector gg;
    if (!m.BranchPointSolve(dr, &phi, &w, &gg) || w.norm() == 0) {
      return EvaluationStatus::Failure("branch-point borders: singular bordered matrix");
    }
    m.bp_frame = OrthonormalFrame(phi);
    m.bp_border = w.normalized();
  }
  return {};
}

EvaluationStatus SpecialPointCurveProblem::DefiningValues(const Vector& u, Vector* g) {
  Impl& m = *impl_;
  const Vector u_base = u.head(m.base_unknowns());
  if (m.definition.kind == CurveKind::kTestFunction) {
    const double value = m.definition.test.value(u_base);
    if (!std::isfinite(value)) return EvaluationStatus::Failure("test function '" + m.definition.test.name + "' not finite");
    *g = Vector::Constant(1, value);
    return {};
  }
  Matrix dr;
  const EvaluationStatus status = m.EvaluateR(u_base, nullptr, &dr);
  if (!status.ok) return status;
  Vector v, w;
  if (m.definition.kind == CurveKind::kFold) {
    double value = 0;
    if (!m.FoldSolve(dr, &v, &w, &value)) return EvaluationStatus::Failure("fold: singular bordered matrix");
    *g = Vector::Constant(1, value);
    return {};
  }
  Matrix phi;
  if (!m.BranchPointSolve(dr, &phi, &w, g)) return EvaluationStatus::Failure("branch point: singular bordered matrix");
  return {};
}

EvaluationStatus SpecialPointCurveProblem::Evaluate(const Vector& u, Vector* r, Matrix* dr) {
  Impl& m = *impl_;
  HYBRIDCONT_DEMAND(u.size() == num_unknowns());
  const int n = m.n, nb = m.base_unknowns();
  const Vector u_base = u.head(nb);
  Vector big_r;
  Matrix big_dr;
  EvaluationStatus status = m.EvaluateR(u_base, &big_r, &big_dr);
  if (!status.ok) return status;
  if (m.definition.kind == CurveKind::kTestFunction) {
    const double value = m.definition.test.value(u_base);
    if (!std::isfinite(value)) return EvaluationStatus::Failure("test function '" + m.definition.test.name + "' not finite");
    if (r) {
      r->resize(n + 1);
      *r << big_r, value;
    }
    if (dr) {
      RowVector gradient;
      status = m.TestGradient(m.definition.test, u_base, &gradient);
      if (!status.ok) return status;
      dr->resize(n + 1, nb);
      *dr << big_dr, gradient;
    }
    return {};
  }
  if (m.definition.kind == CurveKind::kFold) {
    Vector v, w;
    double g = 0;
    if (!m.FoldSolve(big_dr, &v, &w, &g)) return EvaluationStatus::Failure("fold: singular bordered matrix");
    if (r) {
      r->resize(n + 1);
      *r << big_r, g;
    }
    if (dr) {
      RowVector gradient;
      status = m.DirectionalGradient(u_base, w, m.Pad(v, m.x_columns), &gradient);
      if (!status.ok) return status;
      dr->resize(n + 1, nb);
      *dr << big_dr, -gradient;
    }
    return {};
  }
  // Branch point: unknowns (u, β).
  const double beta = u(nb);
  Matrix phi;
  Vector w, g;
  if (!m.BranchPointSolve(big_dr, &phi, &w, &g)) return EvaluationStatus::Failure("branch point: singular bordered matrix");
  if (r) {
    r->resize(n + 2);
    *r << big_r + beta * m.psi, g;
  }
  if (dr) {
    dr->setZero(n + 2, nb + 1);
    dr->topLeftCorner(n, nb) = big_dr;
    dr->topRightCorner(n, 1) = m.psi;
    for (int i = 0; i < 2; ++i) {
      RowVector gradient;
      status = m.DirectionalGradient(u_base, w, m.Pad(phi.col(i), m.m_columns), &gradient);
      if (!status.ok) return status;
      dr->block(n + i, 0, 1, nb) = -gradient;
    }
  }
  return {};
}

std::vector<std::string> SpecialPointCurveProblem::codim_two_names() const {
  switch (impl_->definition.kind) {
    case CurveKind::kFold: return {"cusp"};
    case CurveKind::kBranchPoint: return {"fold-on-branch-point", "beta"};
    case CurveKind::kTestFunction: return {};
  }
  HYBRIDCONT_UNREACHABLE();
}

std::vector<double> SpecialPointCurveProblem::CodimTwoTests(const Vector& u) {
  Impl& m = *impl_;
  const Vector u_base = u.head(m.base_unknowns());
  if (m.definition.kind == CurveKind::kTestFunction) return {};
  Matrix dr;
  if (!m.EvaluateR(u_base, nullptr, &dr).ok) return std::vector<double>(codim_two_names().size(), kNaN);
  if (m.definition.kind == CurveKind::kFold) {
    Vector v, w;
    double g = 0;
    if (!m.FoldSolve(dr, &v, &w, &g) || v.norm() == 0 || w.norm() == 0) return {kNaN};
    const Vector d = m.Pad(v.normalized(), m.x_columns);
    RowVector gradient;
    if (!m.DirectionalGradient(u_base, w.normalized(), d, &gradient).ok) return {kNaN};
    return {gradient.dot(d)};
  }
  Matrix a(m.n, m.n + 1);  // [R_x β_f; c_fᵀ 0] = [a; bᵀ]
  a << dr(Eigen::all, m.x_columns), m.fold_b;
  Vector b = Vector::Zero(m.n + 1);
  b.head(m.n) = m.fold_c;
  return {NormalizedDeterminant(a, b), u(m.base_unknowns())};
}

// ---------------------------------------------------------------------------------------------------------
// Reports.

std::string CodimTwoPoint::BriefReport(const std::vector<std::string>& names) const {
  std::ostringstream out;
  out.precision(12);
  out << ToString(type);
  if (!name.empty() && name != ToString(type)) out << " " << name;
  out << " (" << ToString(status) << ") after curve point " << index << ", u = (";
  for (Eigen::Index i = 0; i < u.size(); ++i) {
    if (i > 0) out << ", ";
    if (i < static_cast<Eigen::Index>(names.size())) out << names[i] << "=";
    out << u(i);
  }
  out.precision(3);
  out << "), precision " << precision;
  if (!message.empty()) out << " [" << message << "]";
  return out.str();
}

Vector SpecialPointCurve::Column(const std::string& name) const {
  const auto it = std::find(unknown_names.begin(), unknown_names.end(), name);
  if (it == unknown_names.end()) throw std::invalid_argument("SpecialPointCurve::Column: unknown '" + name + "'");
  const Eigen::Index k = it - unknown_names.begin();
  Vector column(points.size());
  for (size_t i = 0; i < points.size(); ++i) column(i) = points[i](k);
  return column;
}

std::string SpecialPointCurve::BriefReport() const {
  std::ostringstream out;
  out << ToString(kind) << " curve: " << ToString(status) << ", " << points.size() << " points, "
      << codim_two_points.size() << " codimension-two points, forward " << ToString(forward_termination)
      << ", backward " << ToString(backward_termination) << ", " << newton_iterations << " Newton iterations";
  if (!message.empty()) out << " [" << message << "]";
  return out.str();
}

std::string SpecialPointCurve::FullReport() const {
  std::ostringstream out;
  out << BriefReport() << "\n";
  if (!forward_message.empty()) out << "  forward: " << forward_message << "\n";
  if (!backward_message.empty()) out << "  backward: " << backward_message << "\n";
  for (const CodimTwoPoint& point : codim_two_points) out << "  " << point.BriefReport(unknown_names) << "\n";
  return out.str();
}

// ---------------------------------------------------------------------------------------------------------
// The driver.

namespace {

// One direction of the curve: its points, test values and codimension-two points (indices within it).
struct HalfCurve {
  std::vector<Vector> points;
  std::vector<double> arclength;
  std::vector<Vector> tests;
  std::vector<CodimTwoPoint> codim_two;
  TerminationReason termination = TerminationReason::kNotFinished;
  std::string message;
  int newton_iterations = 0;
};

struct TestSet {
  SpecialPointCurveProblem* problem;
  const std::vector<ScalarTest>* monitors;
  int builtin;  // number of built-in tests (first in the list)

  Vector All(const Vector& u) const {
    const std::vector<double> codim = problem->CodimTwoTests(u);
    Vector values(builtin + monitors->size());
    for (int i = 0; i < builtin; ++i) values(i) = codim[i];
    for (size_t i = 0; i < monitors->size(); ++i) {
      values(builtin + i) = (*monitors)[i].value(u.head(problem->base_unknowns()));
    }
    return values;
  }
  double One(const Vector& u, int k) const {
    if (k < builtin) return problem->CodimTwoTests(u)[k];
    return (*monitors)[k - builtin].value(u.head(problem->base_unknowns()));
  }
  CodimTwoType Type(int k) const {
    if (k >= builtin) return CodimTwoType::kMonitor;
    if (problem->kind() == CurveKind::kFold) return CodimTwoType::kCusp;
    return k == 0 ? CodimTwoType::kFoldOnBranchPoint : CodimTwoType::kBetaZero;
  }
};

HalfCurve TraceHalf(SpecialPointCurveProblem* problem, const Vector& u0, ContinuationOptions options,
                    int direction, const TestSet& tests, const SpecialPointCurveOptions& curve_options) {
  HalfCurve half;
  options.direction = direction;
  problem->InitializeBorders(u0);
  ContinuationStepper stepper(problem, options);
  stepper.Start(u0);
  size_t seen = 0;
  auto record = [&]() {
    const Branch& branch = stepper.branch();
    while (seen < branch.points.size()) {
      const ContinuationPoint& point = branch.points[seen];
      half.points.push_back(point.u);
      half.arclength.push_back(point.arclength);
      half.tests.push_back(tests.All(point.u));
      if (seen > 0) {
        const Vector& before = half.tests[seen - 1];
        const Vector& after = half.tests[seen];
        for (Eigen::Index k = 0; k < before.size(); ++k) {
          if (!(before(k) * after(k) < 0)) continue;
          // β at the corrector's residual level is zero: a persistent branch point, rounding flips its sign.
          const double noise = options.corrector.residual_tolerance;
          if (tests.Type(static_cast<int>(k)) == CodimTwoType::kBetaZero &&
              std::max(std::abs(before(k)), std::abs(after(k))) <= noise) {
            continue;
          }
          const TestFunctionRoot root = LocateTestFunctionRoot(
              problem, half.points[seen - 1], half.points[seen],
              [&](const Vector& u) { return tests.One(u, static_cast<int>(k)); }, curve_options.location);
          CodimTwoPoint found;
          found.type = tests.Type(static_cast<int>(k));
          found.name = k < tests.builtin ? ToString(found.type) : (*tests.monitors)[k - tests.builtin].name;
          found.status = root.located ? LocationStatus::kLocated : LocationStatus::kBracketed;
          found.index = static_cast<int>(seen) - 1;
          found.u = root.u;
          found.precision = root.precision;
          found.message = root.message;
          half.codim_two.push_back(found);
        }
      }
      if (curve_options.update_borders) problem->UpdateBorders(point.u);
      ++seen;
    }
  };
  record();
  while (!stepper.finished()) {
    stepper.Step();
    record();
  }
  const Branch& branch = stepper.branch();
  for (const SpecialPoint& point : branch.special_points) {
    CodimTwoPoint found;
    found.type = point.type == SpecialPointType::kTurningPoint ? CodimTwoType::kTurning : CodimTwoType::kCrossing;
    found.name = point.type == SpecialPointType::kTurningPoint ? point.component : ToString(found.type);
    found.status = point.status;
    found.index = point.index;
    found.u = point.u;
    found.precision = point.precision();
    found.message = point.message;
    half.codim_two.push_back(found);
  }
  half.termination = branch.termination;
  half.message = branch.message;
  half.newton_iterations = branch.newton_iterations;
  return half;
}

}  // namespace

SpecialPointCurve TraceSpecialPointCurve(ZeroProblem* base, const CurveDefinition& definition, const Vector& u0,
                                         const SpecialPointCurveOptions& options) {
  SpecialPointCurveProblem problem(base, definition, u0, options);
  SpecialPointCurve curve;
  curve.kind = definition.kind;
  curve.unknown_names = problem.unknown_names();
  ContinuationOptions continuation = options.continuation;
  if (continuation.turning_point_components.empty()) {
    continuation.turning_point_components = {curve.unknown_names[problem.family_index()],
                                             curve.unknown_names[problem.second_index()]};
  }
  const std::string invalid = continuation.ValidateFor(curve.unknown_names);
  if (!invalid.empty()) throw std::invalid_argument("SpecialPointCurveOptions::continuation: " + invalid);
  Vector start = Vector::Zero(problem.num_unknowns());
  start.head(u0.size()) = u0;

  const int builtin = options.detect_codim_two ? static_cast<int>(problem.codim_two_names().size()) : 0;
  if (builtin > 0) curve.test_names = problem.codim_two_names();
  for (const ScalarTest& monitor : options.monitors) curve.test_names.push_back(monitor.name);
  const TestSet tests{&problem, &options.monitors, builtin};

  HalfCurve forward = TraceHalf(&problem, start, continuation, +1, tests, options);
  curve.forward_termination = forward.termination;
  curve.forward_message = forward.message;
  curve.newton_iterations = forward.newton_iterations;
  if (forward.termination == TerminationReason::kStartFailed || forward.points.empty()) {
    curve.status = CurveStatus::kStartFailed;
    curve.message = forward.message;
    return curve;
  }
  HalfCurve backward;
  if (forward.termination != TerminationReason::kClosedLoop) {
    backward = TraceHalf(&problem, start, continuation, -1, tests, options);
    curve.newton_iterations += backward.newton_iterations;
  }
  curve.backward_termination = backward.termination;
  curve.backward_message = backward.message;
  curve.status = CurveStatus::kTraced;

  // Backward points reversed (without its start, the forward's), then the forward points.
  const int k = std::max(0, static_cast<int>(backward.points.size()) - 1);
  for (int i = k; i >= 1; --i) {
    curve.points.push_back(backward.points[i]);
    curve.arclength.push_back(-backward.arclength[i]);
    curve.tests.push_back(backward.tests[i]);
  }
  curve.start_index = k;
  for (size_t j = 0; j < forward.points.size(); ++j) {
    curve.points.push_back(forward.points[j]);
    curve.arclength.push_back(forward.arclength[j]);
    curve.tests.push_back(forward.tests[j]);
  }
  for (CodimTwoPoint point : backward.codim_two) {
    point.index = k - point.index - 1;
    curve.codim_two_points.push_back(point);
  }
  for (CodimTwoPoint point : forward.codim_two) {
    point.index += k;
    curve.codim_two_points.push_back(point);
  }
  std::stable_sort(curve.codim_two_points.begin(), curve.codim_two_points.end(),
                   [](const CodimTwoPoint& x, const CodimTwoPoint& y) { return x.index < y.index; });
  return curve;
}

SpecialPointCurve TraceSpecialPointCurve(ZeroProblem* base, const SpecialPoint& point, int fix_row,
                                         const std::string& family_parameter,
                                         const SpecialPointCurveOptions& options) {
  CurveDefinition definition;
  definition.fix_row = fix_row;
  if (point.type == SpecialPointType::kTurningPoint) {
    definition.kind = CurveKind::kFold;
    definition.family_parameter = point.component;
  } else if (point.type == SpecialPointType::kSimpleBifurcation) {
    definition.kind = CurveKind::kBranchPoint;
    definition.family_parameter = family_parameter;
  } else {
    throw std::invalid_argument("TraceSpecialPointCurve: a " + ToString(point.type) +
                                " point has no curve (turning or simple-bifurcation points only)");
  }
  return TraceSpecialPointCurve(base, definition, point.u, options);
}

}  // namespace hybridcont
