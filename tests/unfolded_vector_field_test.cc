// The unfolded vector field (eq. `hybridDynamicsNum`), which AutoDiffPhase computes in one pass, equals its
// definition from the phase's own functions: f~ = f + dH^T xi, A = df + sum_j xi_j d2H_j, B = dH^T.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "hybridcont/models.h"

namespace hybridcont {
namespace {

void ExpectClose(const Matrix& got, const Matrix& want, const std::string& what) {
  ASSERT_EQ(got.rows(), want.rows()) << what;
  ASSERT_EQ(got.cols(), want.cols()) << what;
  EXPECT_LE((got - want).cwiseAbs().maxCoeff(), 1e-14 * std::max(1.0, want.cwiseAbs().maxCoeff())) << what;
}

TEST(UnfoldedVectorField, EqualsItsDefinitionInEveryBuiltinPhase) {
  std::vector<HybridModel> models;
  for (const std::string& name : BuiltinModelNames()) models.push_back(MakeBuiltinModel(name));
  models.push_back(MakeBallChain(3));
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

}  // namespace
}  // namespace hybridcont
