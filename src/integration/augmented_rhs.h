// Internal: the augmented right-hand side of eqs. `diffState`, `diffParam` as an odeint system.
//
// z = [x; vec(Phi); vec(Psi)] (column-major), dz = [f~; A Phi; A Psi + [B  B_p]] with A = df~/dx,
// B = df~/dxi and, for free model parameters p (PhaseFlow::set_free_parameters), B_p = df~/dp: Psi then
// has k + q columns, dphi/dxi followed by dphi/dp.
// The functor is a cheap handle (odeint copies systems by value); its scratch space lives in
// AugmentedRhsWorkspace, made once per integrator (conventions §6). A non-finite model value sets
// the workspace's flag and time and returns dz = 0, so that the stepper's arithmetic stays finite and
// the driving loop reports the failure with phase and time.
#ifndef HYBRIDCONT_SRC_INTEGRATION_AUGMENTED_RHS_H_
#define HYBRIDCONT_SRC_INTEGRATION_AUGMENTED_RHS_H_

#include <cmath>
#include <vector>

#include "hybridcont/internal/autodiff_phase.h"
#include "hybridcont/model.h"

namespace hybridcont::internal {

struct AugmentedRhsWorkspace {
  const Phase* phase = nullptr;
  Vector xi;
  int n = 0;
  int k = 0;
  // Free model parameters (indices into the model's parameters) and their number q.
  std::vector<int> parameters;
  int q = 0;
  bool sensitivities = false;
  // Include the xi·d2H term in A (see PhaseFlow::Integrate for when it may be dropped).
  bool hessian_term = true;
  long rhs_evaluations = 0;
  bool nonfinite = false;
  double nonfinite_time = 0.0;
  std::string nonfinite_reason;  // the phase's explanation at the first non-finite evaluation, if any
  Vector f;
  Matrix A, B, Bp;
  Vector dfdp;

  // Prepares an integration; returns the size of z.
  int Start(const Phase& p, const Eigen::Ref<const Vector>& xi_in, bool with_sensitivities) {
    phase = &p;
    xi = xi_in;
    n = p.dim();
    k = p.num_first_integrals();
    q = static_cast<int>(parameters.size());
    sensitivities = with_sensitivities;
    hessian_term = true;
    rhs_evaluations = 0;
    nonfinite = false;
    nonfinite_time = 0.0;
    nonfinite_reason.clear();
    return sensitivities ? n + n * n + n * (k + q) : n;
  }
  // z at t = 0: [x0; I; 0].
  void InitialState(const Eigen::Ref<const Vector>& x0, Vector* z) const {
    z->resize(sensitivities ? n + n * n + n * (k + q) : n);
    z->head(n) = x0;
    if (!sensitivities) return;
    Eigen::Map<Matrix>(z->data() + n, n, n).setIdentity();
    Eigen::Map<Matrix>(z->data() + n + n * n, n, k + q).setZero();
  }
  Eigen::Map<const Matrix> Phi(const Vector& z) const { return Eigen::Map<const Matrix>(z.data() + n, n, n); }
  Eigen::Map<const Matrix> Psi(const Vector& z) const {
    return Eigen::Map<const Matrix>(z.data() + n + n * n, n, k + q);
  }

  void Evaluate(const Vector& z, Vector& dz, double t) {
    ++rhs_evaluations;
    dz.resize(z.size());
    phase->UnfoldedVectorField(z.head(n), xi, &f, sensitivities ? &A : nullptr, sensitivities ? &B : nullptr,
                               hessian_term);
    // Vectorized sums instead of element-wise tests of f, A and B (those were ~7% of a SLIP exploration):
    // a NaN or Inf in f, A or B reaches its sum or dz (A Phi, A Psi + B; 0 * Inf is NaN) and then dz's sum.
    // A sum that overflows from finite entries (~1e308) also counts as non-finite: the integration has
    // blown up. f first, so that A and B are not read when f already failed (a model may not fill them).
    bool finite = std::isfinite(f.sum());
    if (finite && sensitivities && q > 0) {
      if (Bp.rows() != n || Bp.cols() != q) Bp.resize(n, q);
      for (int i = 0; i < q; ++i) {
        phase->UnfoldedFieldParameterDerivative(z.head(n), xi, parameters[i], &dfdp, hessian_term);
        Bp.col(i) = dfdp;
      }
      finite = std::isfinite(Bp.sum());
    }
    if (finite) {
      dz.head(n) = f;
      if (sensitivities) DispatchOnDimension(n, [&](auto N) { Propagate<decltype(N)::value>(z, dz); });
      finite = std::isfinite(dz.sum());
    }
    if (!finite) {
      if (!nonfinite) {
        nonfinite_time = t;
        nonfinite_reason = phase->ExplainNonFinite(z.head(n));
      }
      nonfinite = true;
      dz.setZero();
    }
  }

  // dPhi = A Phi, dPsi = A Psi + B with the phase dimension N fixed at compile time where it is small: the
  // products unroll (the dynamic-size ones were ~18% of a SLIP r + dr evaluation).
  template <int N>
  void Propagate(const Vector& z, Vector& dz) const {
    using Square = Eigen::Matrix<double, N, N>;
    using Tall = Eigen::Matrix<double, N, Eigen::Dynamic>;
    const Eigen::Map<const Square> A_n(A.data(), n, n);
    Eigen::Map<Square>(dz.data() + n, n, n).noalias() = A_n * Eigen::Map<const Square>(z.data() + n, n, n);
    Eigen::Map<Tall> dPsi(dz.data() + n + n * n, n, k + q);
    dPsi.noalias() = A_n * Eigen::Map<const Tall>(z.data() + n + n * n, n, k + q);
    dPsi.leftCols(k) += Eigen::Map<const Tall>(B.data(), n, k);
    if (q > 0) dPsi.rightCols(q) += Eigen::Map<const Tall>(Bp.data(), n, q);
  }
};

// The odeint system: a handle on a workspace.
struct AugmentedRhs {
  AugmentedRhsWorkspace* w;
  void operator()(const Vector& z, Vector& dz, double t) const { w->Evaluate(z, dz, t); }
};

}  // namespace hybridcont::internal

#endif  // HYBRIDCONT_SRC_INTEGRATION_AUGMENTED_RHS_H_
