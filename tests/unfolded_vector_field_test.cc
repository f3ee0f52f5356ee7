// The unfolded vector field (eq. `hybridDynamicsNum`), which AutoDiffPhase computes in one pass, equals its
// definition from the phase's own functions: f~ = f + dH^T xi, A = df + sum_j xi_j d2H_j, B = dH^T; for
// fixed-size and bounded-dynamic jets alike.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "hybridcont/derivative_check.h"
#include "hybridcont/model_builder.h"
#include "hybridcont/models.h"

namespace hybridcont {
namespace {

// A phase above kMaxFixedJetDim (bounded-dynamic jets): five coupled pendula, x = [q; p].
struct PendulaParameters {
  double coupling = 0.3;
};
struct Pendula {
  static constexpr int kDof = 5;
  static constexpr int kDimension = 2 * kDof;  // above kMaxFixedJetDim: the bounded-dynamic jets only
  template <class T>
  static StateVector<T> VectorField(const StateVector<T>& x, const PendulaParameters& c) {
    using std::sin;
    StateVector<T> f(2 * kDof);
    for (int i = 0; i < kDof; ++i) {
      f(i) = x(kDof + i);
      f(kDof + i) = -sin(x(i));
      if (i > 0) f(kDof + i) -= c.coupling * (x(i) - x(i - 1));
      if (i + 1 < kDof) f(kDof + i) -= c.coupling * (x(i) - x(i + 1));
    }
    return f;
  }
  template <class T>
  static T FirstIntegral(const StateVector<T>& x, const PendulaParameters& c) {
    using std::cos;
    T h = T(0.0);
    for (int i = 0; i < kDof; ++i) h += 0.5 * x(kDof + i) * x(kDof + i) - cos(x(i));
    for (int i = 0; i + 1 < kDof; ++i) h += 0.5 * c.coupling * (x(i) - x(i + 1)) * (x(i) - x(i + 1));
    return h;
  }
  template <class T>
  static T Event(const StateVector<T>& x, const PendulaParameters&) {
    return x(0);
  }
  template <class T>
  static StateVector<T> Reset(const StateVector<T>& x, const PendulaParameters&) {
    return x;
  }
};
struct PendulaAnchor {
  static constexpr int kDimension = 2 * Pendula::kDof;
  template <class T>
  static T Anchor(const StateVector<T>& x, const PendulaParameters&) {
    return x(Pendula::kDof);
  }
};

HybridModel MakePendula() {
  ModelBuilder<PendulaParameters> b("pendula", "five coupled pendula (a 10-dimensional phase)");
  b.Parameter("c", &PendulaParameters::coupling, "coupling");
  std::vector<std::string> names;
  Vector typical(2 * Pendula::kDof);
  for (int i = 0; i < 2 * Pendula::kDof; ++i) {
    names.push_back("x" + std::to_string(i));
    typical(i) = 0.1 * (i + 1) * (i % 2 == 0 ? 1.0 : -1.0);
  }
  b.AddPhase<Pendula>("swing", names, typical);
  b.SetAnchor<PendulaAnchor>();
  return b.Build();
}

void ExpectClose(const Matrix& got, const Matrix& want, const std::string& what) {
  ASSERT_EQ(got.rows(), want.rows()) << what;
  ASSERT_EQ(got.cols(), want.cols()) << what;
  EXPECT_LE((got - want).cwiseAbs().maxCoeff(), 1e-14 * std::max(1.0, want.cwiseAbs().maxCoeff())) << what;
}

TEST(UnfoldedVectorField, EqualsItsDefinitionInEveryBuiltinPhase) {
  std::vector<HybridModel> models;
  for (const std::string& name : BuiltinModelNames()) models.push_back(MakeBuiltinModel(name));
  models.push_back(MakeBallChain(3));
  models.push_back(MakePendula());
  for (const HybridModel& model : models) {
    const std::string& name = model.name();
    for (int i = 0; i < model.num_phases(); ++i) {
      const Phase& phase = model.phase(i);
      const Vector& x = phase.typical_state();
      const int k = phase.num_first_integrals();
      Vector f, H;
      Matrix df, dH;
      std::vector<Matrix> d2H;
      phase.VectorField(x, &f, &df);
      phase.FirstIntegrals(x, &H, &dH, &d2H);
      for (const double level : {0.0, 0.3}) {
        const Vector xi = Vector::LinSpaced(k, level, 2.0 * level);
        Vector f_tilde_want = f + dH.transpose() * xi;
        Matrix A_want = df;
        for (int j = 0; j < k; ++j) A_want += xi(j) * d2H[j];
        const std::string where = name + " phase " + phase.name() + " xi " + std::to_string(level);

        Vector f_tilde;
        Matrix A, B;
        phase.UnfoldedVectorField(x, xi, &f_tilde, &A, &B);
        ExpectClose(f_tilde, f_tilde_want, where + ": f~");
        ExpectClose(A, A_want, where + ": A");
        ExpectClose(B, dH.transpose(), where + ": B");

        phase.UnfoldedVectorField(x, xi, &f_tilde, &A, nullptr, /*include_hessian_term=*/false);
        ExpectClose(f_tilde, f_tilde_want, where + ": f~ without the Hessian term");
        ExpectClose(A, df, where + ": A without the Hessian term");

        phase.UnfoldedVectorField(x, xi, &f_tilde, nullptr, nullptr);
        ExpectClose(f_tilde, f_tilde_want, where + ": f~ alone");
      }
    }
  }
}

// The bounded-dynamic path end to end: Jacobians, Hessians and the flow's Phi, Psi against differences.
TEST(UnfoldedVectorField, BoundedDynamicPhasePassesDerivativeChecks) {
  const HybridModel pendula = MakePendula();
  const DerivativeCheckReport report = CheckDerivatives(pendula, DerivativeCheckOptions{});
  EXPECT_TRUE(report.passed()) << report.Table();
}

}  // namespace
}  // namespace hybridcont
