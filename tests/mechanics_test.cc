// Models given by their mechanics (mechanics.h, expression_derivative.h): symbolic derivatives against
// automatic differentiation, the expression Cholesky solve against Eigen's, the derived equations of
// motion and impact law of the bouncing pendulum against the ones derived by hand, and a mass matrix that
// is not positive definite explained by the integrator.
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <unsupported/Eigen/AutoDiff>
#include <cmath>
#include <filesystem>
#include <random>

#include "hybridcont/expression_derivative.h"
#include "hybridcont/expression_model.h"
#include "hybridcont/flow.h"
#include "hybridcont/mechanics.h"
#include "hybridcont/model_file.h"

namespace hybridcont {
namespace {

using Jet2d = Eigen::AutoDiffScalar<Eigen::Vector2d>;

// Inputs x (0) and y (1), parameter a (0).
ExprPtr Parse(const std::string& text) {
  return ParseExpression(text,
                         [](const std::string& s) -> ExprPtr {
                           if (s == "x") return MakeInput(0);
                           if (s == "y") return MakeInput(1);
                           if (s == "a") return MakeParameter(0);
                           return nullptr;
                         },
                         {});
}

// Every function of the grammar, composed, with shared subexpressions and powers of every kind.
TEST(ExpressionDerivative, AgreesWithAutomaticDifferentiation) {
  const std::vector<std::string> cases = {
      "x*y + a*x^3 - y/x",
      "sin(x*y) + cos(a*x) - tan(0.3*y)",
      "asin(0.3*x) + acos(0.2*y) + atan(x - y)",
      "sinh(x) + cosh(y*x) + tanh(x/y)",
      "exp(-x^2) * log(1 + y^2) + sqrt(1 + x*x*y)",
      "abs(x - 2*y) + atan2(y, x) + atan2(0.5, x)",
      "x^y + pow(y, 2.5) + 2^x + x^-2 + (-x)^3",
      "(x + y)^2 / (1 + (x + y)^2) - -x",
      "a*a",
  };
  for (const std::string& text : cases) {
    const ExprPtr e = Parse(text);
    const std::vector<ExprPtr> outputs = {e, Differentiate(e, 0, {}), Differentiate(e, 1, {})};
    const ExpressionProgram program(outputs, 2, true, {});
    const ExpressionProgram original({e}, 2, true, {});
    for (const auto& [x, y] : {std::pair{0.7, 1.3}, std::pair{1.9, 0.4}, std::pair{0.35, 2.2}}) {
      const double p[] = {0.8};
      const double in[] = {x, y};
      double out[3];
      program.Evaluate(in, p, out);
      Jet2d jx[] = {Jet2d(x, Eigen::Vector2d(1, 0)), Jet2d(y, Eigen::Vector2d(0, 1))};
      Jet2d jet;
      original.Evaluate(jx, p, &jet);
      EXPECT_NEAR(out[0], jet.value(), 1e-15 * (1 + std::abs(jet.value()))) << text;
      for (int k = 0; k < 2; ++k) {
        const double ad = jet.derivatives()(k);
        EXPECT_NEAR(out[1 + k], ad, 1e-13 * (1 + std::abs(ad))) << text << " d/d" << (k ? "y" : "x") << " at (" << x
                                                                << ", " << y << ")";
      }
    }
  }
}

TEST(ExpressionDerivative, SimplifiesWhatVanishes) {
  // A quadratic form in y: its second derivative in y is free of y, its third is the constant 0.
  const ExprPtr T = Parse("0.5*a*(x^2 + 1)*y^2 + a*sin(x)*y*x");
  const ExprPtr d2 = Differentiate(Differentiate(T, 1, {}), 1, {});
  EXPECT_FALSE(DependsOnInput(d2, 1));
  EXPECT_TRUE(IsZero(Differentiate(d2, 1, {})));
  EXPECT_TRUE(IsZero(Differentiate(Parse("a*x^2"), 1, {})));
  EXPECT_THROW(Differentiate(Parse("min(x, y)"), 0, {}), ModelInputError);
}

TEST(CholeskySolve, AgreesWithEigenAndIsNanWhereNotPositiveDefinite) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> d(-1.0, 1.0);
  for (int n = 1; n <= 6; ++n) {
    Matrix B(n, n);
    for (int i = 0; i < n; ++i) {
      for (int j = 0; j < n; ++j) B(i, j) = d(rng);
    }
    const Matrix A = B * B.transpose() + 0.5 * Matrix::Identity(n, n);
    Vector b(n);
    for (int i = 0; i < n; ++i) b(i) = d(rng);
    std::vector<std::vector<ExprPtr>> a(n, std::vector<ExprPtr>(n));
    std::vector<ExprPtr> rhs(n);
    for (int i = 0; i < n; ++i) {
      rhs[i] = MakeConstant(b(i));
      for (int j = 0; j < n; ++j) a[i][j] = MakeConstant(A(i, j));
    }
    // The matrix as inputs, so that the solve runs at evaluation time.
    std::vector<std::vector<ExprPtr>> a_in(n, std::vector<ExprPtr>(n));
    Vector entries(n * n);
    for (int i = 0; i < n; ++i) {
      for (int j = 0; j < n; ++j) {
        a_in[i][j] = MakeInput(i * n + j);
        entries(i * n + j) = A(i, j);
      }
    }
    const ExpressionProgram program(CholeskySolve(a_in, rhs), n * n, true, {});
    Vector x(n);
    program.Evaluate(entries.data(), nullptr, x.data());
    const Vector expected = A.llt().solve(b);
    EXPECT_LE((x - expected).norm(), 1e-13 * expected.norm()) << "n = " << n;
    // Folded at build time when the matrix is constant.
    const std::vector<ExprPtr> folded = CholeskySolve(a, rhs);
    const ExpressionProgram constant(folded, 0, true, {});
    Vector y(n);
    constant.Evaluate<double>(nullptr, nullptr, y.data());
    EXPECT_LE((y - expected).norm(), 1e-13 * expected.norm()) << "n = " << n;
    // An indefinite matrix: NaN, and the explanation names the failing pivot.
    if (n >= 2) {
      Vector bad = entries;
      bad(n * n - 1) = -5.0;
      program.Evaluate(bad.data(), nullptr, x.data());
      EXPECT_TRUE(x.array().isNaN().any());
      std::vector<std::string> names;
      std::vector<double> q(n, 0.1);
      for (int i = 0; i < n; ++i) names.push_back("q" + std::to_string(i + 1));
      const std::string why = ExplainMassMatrix(std::vector<double>(bad.data(), bad.data() + n * n), names, q);
      EXPECT_NE(why.find("not positive definite"), std::string::npos) << why;
      EXPECT_NE(why.find("pivot " + std::to_string(n)), std::string::npos) << why;
      EXPECT_EQ(ExplainMassMatrix(std::vector<double>(entries.data(), entries.data() + n * n), names, q), "");
    }
  }
}

HybridModel LoadModel(const std::string& name) {
  ModelFileOptions options;
  options.compile = false;
  return LoadModelFile(std::filesystem::path(HYBRIDCONT_SOURCE_DIR) / "models" / (name + ".toml"), options);
}

// The bouncing pendulum (models/bouncing-pendulum.toml), derived by hand: with s = sin(theta),
// c = cos(theta), M = m1 + m2,
//   [ M          m2 l s ] [ y''     ]   [ -m2 l c theta'^2 - M g ]
//   [ m2 l s     m2 l^2 ] [ theta'' ] = [ -m2 g l s              ],
// and at the stop y' -> -y', theta' -> theta' + 2 y' s / l.
TEST(Mechanics, BouncingPendulumEquationsAndImpactAsDerivedByHand) {
  const HybridModel model = LoadModel("bouncing-pendulum");
  const Phase& phase = model.phase(0);
  const double m1 = 1.0, m2 = 1.0, l = 1.0, g = 1.0, M = m1 + m2;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> d(-2.0, 2.0);
  for (int trial = 0; trial < 20; ++trial) {
    const Vector x = (Vector(4) << d(rng), d(rng), d(rng), d(rng)).finished();
    const double s = std::sin(x(1)), c = std::cos(x(1));
    Eigen::Matrix2d A;
    A << M, m2 * l * s, m2 * l * s, m2 * l * l;
    const Eigen::Vector2d h(-m2 * l * c * x(3) * x(3) - M * g, -m2 * g * l * s);
    const Eigen::Vector2d acc = A.ldlt().solve(h);
    Vector f;
    phase.VectorField(x, &f, nullptr);
    EXPECT_NEAR(f(0), x(2), 1e-15);
    EXPECT_NEAR(f(1), x(3), 1e-15);
    EXPECT_NEAR(f(2), acc(0), 1e-13 * (1 + acc.norm()));
    EXPECT_NEAR(f(3), acc(1), 1e-13 * (1 + acc.norm()));
    Vector H;
    phase.FirstIntegrals(x, &H, nullptr, nullptr);
    const double T = 0.5 * M * x(2) * x(2) + m2 * l * s * x(2) * x(3) + 0.5 * m2 * l * l * x(3) * x(3);
    EXPECT_NEAR(H(0), T + M * g * x(0) + m2 * g * l * (1 - c), 1e-13 * (1 + std::abs(H(0))));
    // The impact (at any y: the law does not depend on it).
    Vector after;
    phase.Reset(x, &after, nullptr);
    EXPECT_NEAR(after(0), x(0), 1e-15);
    EXPECT_NEAR(after(1), x(1), 1e-15);
    EXPECT_NEAR(after(2), -x(2), 1e-13 * (1 + std::abs(x(2))));
    EXPECT_NEAR(after(3), x(3) + 2 * x(2) * s / l, 1e-13 * (1 + std::abs(x(3))));
    Vector H_after;
    phase.FirstIntegrals(after, &H_after, nullptr, nullptr);
    EXPECT_NEAR(H_after(0), H(0), 1e-13 * (1 + std::abs(H(0))));  // the elastic law keeps T
  }
}

// A mass matrix that stops being positive definite along a flow: a non-finite status whose message names
// the phase, the mass matrix and the coordinates there.
TEST(Mechanics, MassMatrixNotPositiveDefiniteIsExplained) {
  const char* text = R"toml(hybridcont = 1
name = "degenerate"
[parameters]
g = { value = 1.0 }
[[phases]]
name = "fall"
coordinates = ["y", "z"]
typical = [0.5, 0.5, 0.1, 0.1]
mass_matrix = [["1", "0"], ["0", "y"]]
potential = "g*y + 0.5*z^2"
event = "y + 1"
anchor = "dy"
reset = { y = "y", z = "z", dy = "-dy", dz = "dz" }
[start]
kind = "guess"
)toml";
  const HybridModel model = BuildExpressionModel(ParseModelText(text, "degenerate.toml"));
  PhaseFlow flow(model.phase(0), IntegratorOptions{});
  PhaseFlowResult result;
  // y falls from 0.5 through 0: M = diag(1, y) is singular at y = 0 and indefinite below; z feels a
  // spring, so its acceleration -z/y is not finite there.
  const Vector x0 = (Vector(4) << 0.5, 0.1, 0.0, 0.0).finished();
  flow.Integrate(x0, Vector::Zero(1), 2.0, false, &result);
  EXPECT_EQ(result.status, FlowStatus::kNonFinite) << result.message;
  EXPECT_NE(result.message.find("phase 'fall'"), std::string::npos) << result.message;
  EXPECT_NE(result.message.find("the mass matrix is not positive definite at (y = "), std::string::npos)
      << result.message;
  EXPECT_NE(result.message.find("pivot 2"), std::string::npos) << result.message;
}

}  // namespace
}  // namespace hybridcont
