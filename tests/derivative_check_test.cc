// Every derivative of every built-in model agrees with central finite differences.
#include <gtest/gtest.h>

#include "hybridcont/derivative_check.h"
#include "hybridcont/model_builder.h"
#include "hybridcont/models.h"

namespace hybridcont {
namespace {

class BuiltinModelDerivatives : public ::testing::TestWithParam<std::string> {};

TEST_P(BuiltinModelDerivatives, AgreeWithFiniteDifferences) {
  const HybridModel model = MakeBuiltinModel(GetParam());
  const DerivativeCheckReport report = CheckDerivatives(model, DerivativeCheckOptions{});
  // Every derivative kind is covered: per phase 7 (f, e, Delta, dH, d2H, Phi, Psi), anchor, shooting map,
  // the symmetry group of the shooting map (the SLIP: mirror, time reversal and their product), and the map's
  // column of every model parameter.
  const int symmetries = GetParam() == "slip" ? 3 : 1;
  const int parameters = static_cast<int>(model.parameters().size());
  EXPECT_EQ(static_cast<int>(report.entries.size()), 7 * model.num_phases() + 2 + symmetries + parameters);
  for (const auto& e : report.entries) {
    EXPECT_TRUE(e.passed()) << e.what << ": " << e.worst_error << " > " << e.tolerance << " " << e.note;
  }
  EXPECT_TRUE(report.passed()) << report.Table();
}

INSTANTIATE_TEST_SUITE_P(AllModels, BuiltinModelDerivatives,
                         ::testing::Values("bouncing-ball", "rocking-block", "bouncing-rod", "slip"),
                         [](const auto& info) {
                           std::string s = info.param;
                           for (char& c : s) c = (c == '-') ? '_' : c;
                           return s;
                         });

// A deliberately wrong Jacobian must be caught: the checker is itself tested.
struct WrongParameters {};
struct WrongPhase {
  template <class T>
  static StateVector<T> VectorField(const StateVector<T>& x, const WrongParameters&) {
    StateVector<T> f(2);
    f << x(1), -x(0);
    return f;
  }
  template <class T>
  static T FirstIntegral(const StateVector<T>& x, const WrongParameters&) {
    return 0.5 * (x(0) * x(0) + x(1) * x(1));
  }
  template <class T>
  static T Event(const StateVector<T>& x, const WrongParameters&) {
    return x(0);
  }
  template <class T>
  static StateVector<T> Reset(const StateVector<T>& x, const WrongParameters&) {
    StateVector<T> y(2);
    y << x(0), -x(1);
    return y;
  }
};
struct WrongAnchor {
  template <class T>
  static T Anchor(const StateVector<T>& x, const WrongParameters&) {
    return x(1);
  }
};

// Hand-written phase whose df/dx has a sign error.
class HandWrittenWrong final : public Phase {
 public:
  HandWrittenWrong() : Phase("wrong", {"q", "p"}, 2, 1, Vector::Constant(2, 0.5)) {}
  void VectorField(const Eigen::Ref<const Vector>& x, Vector* f, Matrix* df) const override {
    *f = Vector(2);
    (*f) << x(1), -x(0);
    if (df) {
      df->resize(2, 2);
      *df << 0, 1, 1, 0;  // wrong: should be [0 1; -1 0]
    }
  }
  void FirstIntegrals(const Eigen::Ref<const Vector>& x, Vector* H, Matrix* dH, std::vector<Matrix>* d2H) const override {
    *H = Vector::Constant(1, 0.5 * x.squaredNorm());
    if (dH) *dH = x.transpose();
    if (d2H) *d2H = {Matrix::Identity(2, 2)};
  }
  double Event(const Eigen::Ref<const Vector>& x, RowVector* de) const override {
    if (de) *de = RowVector::Unit(2, 0);
    return x(0);
  }
  void Reset(const Eigen::Ref<const Vector>& x, Vector* y, Matrix* D) const override {
    *y = Vector(2);
    (*y) << x(0), -x(1);
    if (D) *D = Vector2d(1, -1).asDiagonal();
  }
  using Vector2d = Eigen::Vector2d;
};

// A mirror declared without the forward speed's sign: the check names it.
TEST(DerivativeCheck, CatchesAWrongSymmetryDeclaration) {
  HybridModel slip = MakeSlip();
  Vector stance(4), flight(5);
  stance << -1, 1, -1, 1;
  flight << 1, -1, 1, 1, -1;  // dx should flip
  slip.AddSymmetry({"bad-mirror", {stance, flight}, false});
  const DerivativeCheckReport report = CheckDerivatives(slip, DerivativeCheckOptions{});
  bool found = false;
  for (const auto& e : report.entries) {
    if (e.what.find("'bad-mirror'") == std::string::npos) continue;
    found = true;
    EXPECT_GT(e.worst_error, 1e-2) << e.what;  // O(1), not noise
    EXPECT_FALSE(e.passed());
  }
  EXPECT_TRUE(found) << report.Table();
  EXPECT_FALSE(report.passed());
}

TEST(DerivativeCheck, SymmetryDeclarationsAreValidated) {
  HybridModel slip = MakeSlip();
  const auto message = [&](ModelSymmetry s) {
    try {
      slip.AddSymmetry(std::move(s));
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  Vector four = Vector::Ones(4), five = Vector::Ones(5), two = Vector::Ones(2);
  EXPECT_EQ(message({"a", {four}, true}), "model 'slip', symmetry 'a': 1 sign vectors for 2 phases");
  EXPECT_EQ(message({"a", {four, two}, true}), "model 'slip', symmetry 'a', phase 'flight': 2 signs for 5 states");
  Vector half = four;
  half(2) = 0.5;
  EXPECT_EQ(message({"a", {half, five}, true}),
            "model 'slip', symmetry 'a', phase 'stance': sign of state 'dalpha' is 0.500000, must be +1 or -1");
  EXPECT_EQ(message({"a", {four, five}, false}), "model 'slip', symmetry 'a': is the identity");
  EXPECT_EQ(message({"mirror", {four, five}, true}), "model 'slip', symmetry 'mirror': declared twice");
  EXPECT_EQ(message({"", {four, five}, true}), "model 'slip': a symmetry needs a name");
  EXPECT_EQ(slip.symmetries().size(), 2u);
}

TEST(DerivativeCheck, CatchesAWrongHandWrittenJacobian) {
  ModelBuilder<WrongParameters> b("wrong", "oscillator with a wrong Jacobian");
  b.AddPhase(std::make_unique<HandWrittenWrong>());
  b.SetAnchor<WrongAnchor>();
  const HybridModel model = b.Build();
  const DerivativeCheckReport report = CheckDerivatives(model, DerivativeCheckOptions{});
  EXPECT_FALSE(report.passed());
  bool df_failed = false;
  for (const auto& e : report.entries) {
    if (e.what == "phase 'wrong': df/dx") df_failed = !e.passed() && e.worst_error > 0.5;
  }
  EXPECT_TRUE(df_failed) << report.Table();
}

TEST(DerivativeCheck, AutoDiffOscillatorPasses) {
  ModelBuilder<WrongParameters> b("oscillator", "harmonic oscillator");
  b.AddPhase<WrongPhase>("free", {"q", "p"}, Vector::Constant(2, 0.5));
  b.SetAnchor<WrongAnchor>();
  const HybridModel model = b.Build();
  EXPECT_TRUE(CheckDerivatives(model, DerivativeCheckOptions{}).passed());
}

// A functor that declares its state dimension (kDimension) has its derivatives compiled for that dimension
// only: the same numbers as the dispatch over every dimension, and a phase whose state names disagree with
// the declaration is refused with the phase named.
struct DeclaredPhase : WrongPhase {
  static constexpr int kDimension = 2;
};
struct DeclaredAnchor : WrongAnchor {
  static constexpr int kDimension = 2;
};
struct MisdeclaredPhase : WrongPhase {
  static constexpr int kDimension = 3;
};

TEST(DerivativeCheck, DeclaredDimensionGivesTheSameDerivatives) {
  const auto build = [](auto phase, auto anchor) {
    ModelBuilder<WrongParameters> b("oscillator", "harmonic oscillator");
    b.AddPhase<decltype(phase)>("free", {"q", "p"}, Vector::Constant(2, 0.5));
    b.SetAnchor<decltype(anchor)>();
    return b.Build();
  };
  const HybridModel dispatched = build(WrongPhase{}, WrongAnchor{});
  const HybridModel declared = build(DeclaredPhase{}, DeclaredAnchor{});
  const Vector x = Eigen::Vector2d(0.3, -0.7);
  Vector f1, f2, H1, H2, y1, y2;
  Matrix df1, df2, dH1, dH2, D1, D2;
  std::vector<Matrix> d2H1, d2H2;
  RowVector de1, de2, da1, da2;
  dispatched.phase(0).VectorField(x, &f1, &df1);
  declared.phase(0).VectorField(x, &f2, &df2);
  dispatched.phase(0).FirstIntegrals(x, &H1, &dH1, &d2H1);
  declared.phase(0).FirstIntegrals(x, &H2, &dH2, &d2H2);
  EXPECT_EQ(dispatched.phase(0).Event(x, &de1), declared.phase(0).Event(x, &de2));
  dispatched.phase(0).Reset(x, &y1, &D1);
  declared.phase(0).Reset(x, &y2, &D2);
  EXPECT_EQ(dispatched.anchor().Evaluate(x, &da1), declared.anchor().Evaluate(x, &da2));
  EXPECT_EQ(f1, f2);
  EXPECT_EQ(df1, df2);
  EXPECT_EQ(df2, (Matrix(2, 2) << 0, 1, -1, 0).finished());
  EXPECT_EQ(H1, H2);
  EXPECT_EQ(dH1, dH2);
  ASSERT_EQ(d2H2.size(), 1u);
  EXPECT_EQ(d2H1[0], d2H2[0]);
  EXPECT_EQ(d2H2[0], Matrix::Identity(2, 2));
  EXPECT_EQ(de1, de2);
  EXPECT_EQ(y1, y2);
  EXPECT_EQ(D1, D2);
  EXPECT_EQ(da1, da2);
  EXPECT_TRUE(CheckDerivatives(declared, DerivativeCheckOptions{}).passed());

  ModelBuilder<WrongParameters> b("oscillator", "harmonic oscillator");
  b.AddPhase<MisdeclaredPhase>("free", {"q", "p"}, Vector::Constant(2, 0.5));
  b.SetAnchor<WrongAnchor>();
  try {
    b.Build();
    ADD_FAILURE() << "a phase of 2 states whose functions declare kDimension = 3 was built";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("phase 'free': its functions declare kDimension = 3, but 2 state names"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace hybridcont
