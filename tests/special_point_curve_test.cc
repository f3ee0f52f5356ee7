// Two-parameter curves of special points on algebraic problems with closed-form curves: the cusp's fold
// curves, a persistent (symmetric) and a regularized (imperfect) branch-point curve, a test-function
// curve, and every defining system's Jacobian against central differences.
#include "hybridcont/special_point_curve.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <stdexcept>

namespace hybridcont {
namespace {

// A base problem: the rows `equations(u)` followed by the fixing row u_b − value (row n).
class AlgebraicFamily : public ZeroProblem {
 public:
  using Residual = std::function<Vector(const Vector&)>;
  AlgebraicFamily(std::vector<std::string> names, Residual residual, int fixed, double value)
      : names_(std::move(names)), residual_(std::move(residual)), fixed_(fixed), value_(value) {}
  int num_equations() const override { return static_cast<int>(names_.size()) - 1; }
  std::vector<std::string> unknown_names() const override { return names_; }
  // dr: the families' own Jacobians (jacobian_) and the fixing row.
  EvaluationStatus Evaluate(const Vector& u, Vector* r, Matrix* dr) override {
    const Vector rows = residual_(u);
    if (r) {
      r->resize(num_equations());
      *r << rows, u(fixed_) - value_;
    }
    if (dr) {
      dr->setZero(num_equations(), num_unknowns());
      dr->topRows(num_equations() - 1) = jacobian_(u);
      (*dr)(num_equations() - 1, fixed_) = 1;
    }
    return {};
  }
  std::function<Matrix(const Vector&)> jacobian_;

 private:
  std::vector<std::string> names_;
  Residual residual_;
  int fixed_;
  double value_;
};

// f(x; a, b) = a + b x − x³ at b fixed: folds where b = 3x², a = −2x³, i.e. a = ∓2 (b/3)^{3/2}, meeting at
// the cusp (0, 0).
AlgebraicFamily Cusp(double b) {
  AlgebraicFamily family({"x", "a", "b"}, [](const Vector& u) {
    return Vector::Constant(1, u(1) + u(2) * u(0) - std::pow(u(0), 3)); }, 2, b);
  family.jacobian_ = [](const Vector& u) {
    Matrix j(1, 3);
    j << u(2) - 3 * u(0) * u(0), 1, u(0);
    return j;
  };
  return family;
}

// R1 = x (y − μ − x²), R2 = y² − λ at μ fixed: the symmetric family x = 0, y² = λ and the asymmetric one
// x² = y − μ cross at the branch point (0, μ, μ²) for every μ (the symmetry x → −x); the symmetric family's
// fold y = 0 meets it at μ = 0, where the curve λ = μ² also turns in λ.
AlgebraicFamily SymmetricPitchfork(double mu) {
  AlgebraicFamily family({"x", "y", "lambda", "mu"}, [](const Vector& u) {
    Vector r(2);
    r << u(0) * (u(1) - u(3) - u(0) * u(0)), u(1) * u(1) - u(2);
    return r; }, 3, mu);
  family.jacobian_ = [](const Vector& u) {
    Matrix j(2, 4);
    j << u(1) - u(3) - 3 * u(0) * u(0), u(0), 0, -u(0),
         0, 2 * u(1), -1, 0;
    return j;
  };
  return family;
}

// x (λ − x) + μ at μ fixed: a transcritical branch point only at μ = 0; the regularized curve is
// (x, λ, μ, β) = (0, 0, t, −t).
AlgebraicFamily ImperfectTranscritical(double mu) {
  AlgebraicFamily family({"x", "lambda", "mu"}, [](const Vector& u) {
    return Vector::Constant(1, u(0) * (u(1) - u(0)) + u(2)); }, 2, mu);
  family.jacobian_ = [](const Vector& u) {
    Matrix j(1, 3);
    j << u(1) - 2 * u(0), u(0), 1;
    return j;
  };
  return family;
}

// A non-polynomial family (third derivatives nonzero) for the Jacobian checks: unknowns (x1, x2, a, b).
AlgebraicFamily Transcendental(double b) {
  AlgebraicFamily family({"x1", "x2", "a", "b"}, [](const Vector& u) {
    Vector r(2);
    r << std::sin(u(0)) + u(2) * u(1) - u(3) * u(0) * u(0), u(0) * u(1) + std::cos(u(2) * u(1)) - u(3);
    return r; }, 3, b);
  family.jacobian_ = [](const Vector& u) {
    Matrix j(2, 4);
    const double s = std::sin(u(2) * u(1));
    j << std::cos(u(0)) - 2 * u(3) * u(0), u(2), u(1), -u(0) * u(0),
         u(1), u(0) - u(2) * s, -u(1) * s, -1;
    return j;
  };
  return family;
}

// Largest difference between dr and central differences of r (step h), relative to max(1, |dr|).
double JacobianError(ZeroProblem* problem, const Vector& u, double h) {
  Vector r;
  Matrix dr;
  EXPECT_TRUE(problem->Evaluate(u, &r, &dr).ok);
  Matrix fd(dr.rows(), dr.cols());
  for (Eigen::Index k = 0; k < u.size(); ++k) {
    Vector up = u, down = u, r_up, r_down;
    up(k) += h;
    down(k) -= h;
    problem->Evaluate(up, &r_up, nullptr);
    problem->Evaluate(down, &r_down, nullptr);
    fd.col(k) = (r_up - r_down) / (2 * h);
  }
  return (dr - fd).cwiseAbs().maxCoeff() / std::max(1.0, dr.cwiseAbs().maxCoeff());
}

// A measured error as the test's XML/JSON output records it.
std::string Scientific(double value) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.2e", value);
  return text;
}

SpecialPointCurveOptions CurveOptions() {
  SpecialPointCurveOptions options;
  options.continuation.max_step = 0.1;
  options.continuation.max_points = 400;
  return options;
}

TEST(SpecialPointCurve, CuspFoldCurvesMatchTheClosedFormAndMeetAtTheCusp) {
  AlgebraicFamily cusp = Cusp(3.0);
  SpecialPointCurveOptions options = CurveOptions();
  options.continuation.bounds = {{"x", -1.2, 1.2}};
  options.monitors = {{"b=1", [](const Vector& u) { return u(2) - 1.0; }, nullptr}};
  const CurveDefinition fold{CurveKind::kFold, 1, "a", {}};
  const SpecialPointCurve curve = TraceSpecialPointCurve(&cusp, fold, Eigen::Vector3d(1, -2, 3), options);
  SCOPED_TRACE(curve.FullReport());
  ASSERT_EQ(curve.status, CurveStatus::kTraced);
  EXPECT_EQ(curve.forward_termination, TerminationReason::kBoundReached);
  EXPECT_EQ(curve.backward_termination, TerminationReason::kBoundReached);
  double worst = 0;
  int positive = 0, negative = 0;
  for (const Vector& u : curve.points) {
    const double x = u(0), a = u(1), b = u(2);
    ASSERT_GE(b, 0.0);
    const double closed_a = (x > 0 ? -2 : 2) * std::pow(b / 3, 1.5);  // a = ∓2 (b/3)^{3/2}
    worst = std::max({worst, std::abs(a - closed_a), std::abs(b - 3 * x * x)});
    if (x > 0.1) ++positive;
    if (x < -0.1) ++negative;
  }
  EXPECT_LT(worst, 1e-10);
  RecordProperty("fold_curve_error", Scientific(worst));
  EXPECT_GT(positive, 5);  // both fold curves
  EXPECT_GT(negative, 5);
  EXPECT_NEAR(curve.points.front()(0), -curve.points.back()(0), 1e-12);  // both ends on |x| = 1.2
  EXPECT_NEAR(std::abs(curve.points.back()(0)), 1.2, 1e-12);

  int cusps = 0, turns_in_b = 0, monitors = 0;
  for (const CodimTwoPoint& point : curve.codim_two_points) {
    if (point.type == CodimTwoType::kCusp) {
      ++cusps;
      EXPECT_EQ(point.status, LocationStatus::kLocated);
      EXPECT_LT(point.u.cwiseAbs().maxCoeff(), 1e-10) << point.BriefReport(curve.unknown_names);
      RecordProperty("cusp_error", Scientific(point.u.cwiseAbs().maxCoeff()));
    }
    if (point.type == CodimTwoType::kTurning && point.name == "b") {
      ++turns_in_b;  // the projection's cusp: b = 3x² has its minimum there
      EXPECT_LT(point.u.cwiseAbs().maxCoeff(), 1e-10) << point.BriefReport(curve.unknown_names);
    }
    if (point.type == CodimTwoType::kMonitor) {
      ++monitors;  // b = 1 at x = ±1/√3, a = ∓2/(3√3)
      EXPECT_NEAR(std::abs(point.u(0)), 1 / std::sqrt(3.0), 1e-10);
      EXPECT_NEAR(point.u(1), -2 * point.u(0) / 3, 1e-10);
      RecordProperty("monitor_error_" + std::to_string(monitors),
                     Scientific(std::abs(std::abs(point.u(0)) - 1 / std::sqrt(3.0))));
    }
  }
  EXPECT_EQ(cusps, 1);
  EXPECT_EQ(turns_in_b, 1);
  EXPECT_EQ(monitors, 2);
}

// f(x; a, b) = a + b x − (x − 0.3)³ + 0.1 sin x: fold curves b(x) = 3(x − 0.3)² − 0.1 cos x,
// a(x) = −b(x) x + (x − 0.3)³ − 0.1 sin x, the cusp where f_xx = −6(x − 0.3) − 0.1 sin x = 0. Its fourth
// derivative is nonzero, so the directional differences of Jacobians are not exact here.
TEST(SpecialPointCurve, CuspOfANonPolynomialFamily) {
  AlgebraicFamily family({"x", "a", "b"}, [](const Vector& u) {
    return Vector::Constant(1, u(1) + u(2) * u(0) - std::pow(u(0) - 0.3, 3) + 0.1 * std::sin(u(0))); }, 2, 1.0);
  family.jacobian_ = [](const Vector& u) {
    Matrix j(1, 3);
    j << u(2) - 3 * std::pow(u(0) - 0.3, 2) + 0.1 * std::cos(u(0)), 1, u(0);
    return j;
  };
  auto b_of = [](double x) { return 3 * std::pow(x - 0.3, 2) - 0.1 * std::cos(x); };
  auto a_of = [&](double x) { return -b_of(x) * x + std::pow(x - 0.3, 3) - 0.1 * std::sin(x); };
  double cusp_x = 0.3;  // Newton on f_xx = 0
  for (int k = 0; k < 50; ++k) cusp_x -= (-6 * (cusp_x - 0.3) - 0.1 * std::sin(cusp_x)) / (-6 - 0.1 * std::cos(cusp_x));
  const double x0 = 1.0;
  SpecialPointCurveOptions options = CurveOptions();
  options.continuation.bounds = {{"x", -0.6, 1.2}};
  const CurveDefinition fold{CurveKind::kFold, 1, "a", {}};
  const SpecialPointCurve curve =
      TraceSpecialPointCurve(&family, fold, Eigen::Vector3d(x0, a_of(x0), b_of(x0)), options);
  SCOPED_TRACE(curve.FullReport());
  ASSERT_EQ(curve.status, CurveStatus::kTraced);
  double worst = 0;
  for (const Vector& u : curve.points) {
    worst = std::max({worst, std::abs(u(1) - a_of(u(0))), std::abs(u(2) - b_of(u(0)))});
  }
  EXPECT_LT(worst, 1e-10);
  RecordProperty("nonpolynomial_fold_curve_error", Scientific(worst));
  int cusps = 0;
  for (const CodimTwoPoint& point : curve.codim_two_points) {
    if (point.type != CodimTwoType::kCusp) continue;
    ++cusps;
    EXPECT_EQ(point.status, LocationStatus::kLocated);
    EXPECT_NEAR(point.u(0), cusp_x, 1e-9);
    EXPECT_NEAR(point.u(2), b_of(cusp_x), 1e-9);
    RecordProperty("nonpolynomial_cusp_error", Scientific(std::abs(point.u(0) - cusp_x)));
  }
  EXPECT_EQ(cusps, 1);
}

TEST(SpecialPointCurve, FoldCurveFromALocatedTurningPoint) {
  // The one-parameter family at b = 2, traced in a: turning points at x = ±√(2/3).
  AlgebraicFamily cusp = Cusp(2.0);
  ContinuationOptions family_options;
  family_options.turning_point_components = {"a"};
  family_options.bounds = {{"x", -2, 2}};
  const Branch branch = TraceBranch(&cusp, Eigen::Vector3d(0, 0, 2), family_options);
  ASSERT_FALSE(branch.special_points.empty());
  const SpecialPoint& turn = branch.special_points.front();
  ASSERT_EQ(turn.type, SpecialPointType::kTurningPoint);
  SpecialPointCurveOptions options = CurveOptions();
  options.continuation.bounds = {{"b", -1, 3}};
  const SpecialPointCurve curve = TraceSpecialPointCurve(&cusp, turn, 1, "a", options);
  SCOPED_TRACE(curve.FullReport());
  ASSERT_EQ(curve.status, CurveStatus::kTraced);
  EXPECT_NEAR(curve.points[curve.start_index](2), 2.0, 1e-12);
  for (const Vector& u : curve.points) EXPECT_NEAR(u(2), 3 * u(0) * u(0), 1e-10);
}

TEST(SpecialPointCurve, SymmetricBranchPointPersistsWithBetaZero) {
  AlgebraicFamily pitchfork = SymmetricPitchfork(0.5);
  SpecialPointCurveOptions options = CurveOptions();
  options.continuation.bounds = {{"mu", -1, 1}};
  const CurveDefinition bp{CurveKind::kBranchPoint, 2, "lambda", {}};
  const SpecialPointCurve curve = TraceSpecialPointCurve(&pitchfork, bp, Eigen::Vector4d(0, 0.5, 0.25, 0.5), options);
  SCOPED_TRACE(curve.FullReport());
  ASSERT_EQ(curve.status, CurveStatus::kTraced);
  ASSERT_EQ(curve.unknown_names.back(), "beta");
  double worst = 0;
  for (const Vector& u : curve.points) {
    worst = std::max({worst, std::abs(u(0)), std::abs(u(1) - u(3)), std::abs(u(2) - u(3) * u(3)), std::abs(u(4))});
  }
  EXPECT_LT(worst, 1e-10);
  RecordProperty("branch_point_curve_error", Scientific(worst));
  EXPECT_NEAR(curve.Column("mu").minCoeff(), -1, 1e-12);
  EXPECT_NEAR(curve.Column("mu").maxCoeff(), 1, 1e-12);
  int folds = 0, turns = 0;
  for (const CodimTwoPoint& point : curve.codim_two_points) {
    if (point.type == CodimTwoType::kFoldOnBranchPoint) {
      ++folds;  // the symmetric family's fold meets the branch point at μ = 0
      EXPECT_EQ(point.status, LocationStatus::kLocated);
      EXPECT_LT(point.u.cwiseAbs().maxCoeff(), 1e-10) << point.BriefReport(curve.unknown_names);
      RecordProperty("fold_on_branch_point_error", Scientific(point.u.cwiseAbs().maxCoeff()));
    }
    if (point.type == CodimTwoType::kTurning && point.name == "lambda") {
      ++turns;
      EXPECT_LT(point.u.cwiseAbs().maxCoeff(), 1e-10) << point.BriefReport(curve.unknown_names);
    }
    EXPECT_NE(point.type, CodimTwoType::kBetaZero);
  }
  EXPECT_EQ(folds, 1);
  EXPECT_EQ(turns, 1);
}

TEST(SpecialPointCurve, ImperfectBranchPointIsWhereBetaVanishes) {
  AlgebraicFamily transcritical = ImperfectTranscritical(0.3);
  SpecialPointCurveOptions options = CurveOptions();
  options.continuation.bounds = {{"mu", -0.5, 0.5}};
  const CurveDefinition bp{CurveKind::kBranchPoint, 1, "lambda", {}};
  const SpecialPointCurve curve = TraceSpecialPointCurve(&transcritical, bp, Eigen::Vector3d(0, 0, 0.3), options);
  SCOPED_TRACE(curve.FullReport());
  ASSERT_EQ(curve.status, CurveStatus::kTraced);
  double worst = 0;
  for (const Vector& u : curve.points) {
    worst = std::max({worst, std::abs(u(0)), std::abs(u(1)), std::abs(u(2) + u(3))});
  }
  int zeros = 0;
  for (const CodimTwoPoint& point : curve.codim_two_points) {
    if (point.type != CodimTwoType::kBetaZero) continue;
    ++zeros;
    EXPECT_EQ(point.status, LocationStatus::kLocated);
    EXPECT_LT(point.u.cwiseAbs().maxCoeff(), 1e-10) << point.BriefReport(curve.unknown_names);
    RecordProperty("beta_zero_error", Scientific(point.u.cwiseAbs().maxCoeff()));
  }
  EXPECT_LT(worst, 1e-10);
  RecordProperty("regularized_curve_error", Scientific(worst));
  EXPECT_EQ(zeros, 1);
}

// The family x = sin a + b at b fixed, and g = x² + a² − 1: the curve is closed, x = ±√(1 − a²),
// b = x − sin a, turning in a at a = ±1 (x = 0, b = −sin a).
TEST(SpecialPointCurve, CurveOfAScalarTestFunctionWithAndWithoutItsGradient) {
  for (const bool analytic : {true, false}) {
    SCOPED_TRACE(analytic ? "analytic gradient" : "central differences");
    AlgebraicFamily family({"x", "a", "b"}, [](const Vector& u) {
      return Vector::Constant(1, u(0) - std::sin(u(1)) - u(2)); }, 2, 1.0);
    family.jacobian_ = [](const Vector& u) {
      Matrix j(1, 3);
      j << 1, -std::cos(u(1)), -1;
      return j;
    };
    ScalarTest test{"circle", [](const Vector& u) { return u(0) * u(0) + u(1) * u(1) - 1; }, nullptr};
    if (analytic) {
      test.gradient = [](const Vector& u, RowVector* g) {
        *g = RowVector::Zero(3);
        (*g)(0) = 2 * u(0);
        (*g)(1) = 2 * u(1);
        return true;
      };
    }
    const CurveDefinition definition{CurveKind::kTestFunction, 1, "a", test};
    const SpecialPointCurve curve =
        TraceSpecialPointCurve(&family, definition, Eigen::Vector3d(1, 0, 1), CurveOptions());
    SCOPED_TRACE(curve.FullReport());
    ASSERT_EQ(curve.status, CurveStatus::kTraced);
    EXPECT_EQ(curve.forward_termination, TerminationReason::kClosedLoop);
    double worst = 0;
    for (const Vector& u : curve.points) {
      worst = std::max({worst, std::abs(u(0) * u(0) + u(1) * u(1) - 1), std::abs(u(0) - std::sin(u(1)) - u(2))});
    }
    EXPECT_LT(worst, 1e-10);
    RecordProperty(std::string(analytic ? "analytic" : "differenced") + "_curve_error", Scientific(worst));
    int turns = 0;
    for (const CodimTwoPoint& point : curve.codim_two_points) {
      if (point.type != CodimTwoType::kTurning || point.name != "a") continue;
      ++turns;
      EXPECT_NEAR(std::abs(point.u(1)), 1, 1e-10);
      EXPECT_NEAR(point.u(2), -std::sin(point.u(1)), 1e-10);
      RecordProperty(std::string(analytic ? "analytic" : "differenced") + "_turning_error_" + std::to_string(turns),
                     Scientific(std::abs(std::abs(point.u(1)) - 1)));
    }
    EXPECT_EQ(turns, 2);
  }
}

// Every defining system's dr (directional differences of Jacobians, ε = 1e-4) against central differences
// of its residual (h = 1e-6), at points off the curve on a family with nonzero third derivatives.
TEST(SpecialPointCurve, JacobiansMatchFiniteDifferences) {
  AlgebraicFamily family = Transcendental(0.7);
  const Eigen::Vector4d u0(0.4, -0.3, 1.1, 0.7);
  for (const CurveKind kind : {CurveKind::kFold, CurveKind::kBranchPoint, CurveKind::kTestFunction}) {
    SCOPED_TRACE(ToString(kind));
    CurveDefinition definition{kind, 2, "a", {}};
    definition.test = {"g", [](const Vector& u) { return std::sin(u(0) * u(2)) + u(1) * u(3); }, nullptr};
    SpecialPointCurveProblem problem(&family, definition, u0);
    Vector u = Vector::Zero(problem.num_unknowns());
    u.head(4) = u0 + Eigen::Vector4d(0.05, -0.02, 0.03, 0.01);
    if (kind == CurveKind::kBranchPoint) u(4) = 0.2;
    const double error = JacobianError(&problem, u, 1e-6);
    EXPECT_LT(error, 1e-7);
    RecordProperty(ToString(kind) + "_jacobian_error", Scientific(error));
  }
}

TEST(SpecialPointCurve, RejectsBadDefinitions) {
  AlgebraicFamily cusp = Cusp(3.0);
  const Eigen::Vector3d u0(1, -2, 3);
  EXPECT_THROW(SpecialPointCurveProblem(&cusp, {CurveKind::kFold, 0, "a", {}}, u0), std::invalid_argument);
  EXPECT_THROW(SpecialPointCurveProblem(&cusp, {CurveKind::kFold, 1, "q", {}}, u0), std::invalid_argument);
  EXPECT_THROW(SpecialPointCurveProblem(&cusp, {CurveKind::kFold, 1, "b", {}}, u0), std::invalid_argument);
  EXPECT_THROW(SpecialPointCurveProblem(&cusp, {CurveKind::kTestFunction, 1, "a", {}}, u0), std::invalid_argument);
  SpecialPointCurveOptions options;
  options.second_derivative_step = 0;
  EXPECT_NE(options.Validate(), "");
  EXPECT_THROW(SpecialPointCurveProblem(&cusp, {CurveKind::kFold, 1, "a", {}}, u0, options), std::invalid_argument);
}

}  // namespace
}  // namespace hybridcont
