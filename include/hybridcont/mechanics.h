// A phase given by its mechanics: the equations of motion, the energy and impact laws derived from a
// Lagrangian or a mass-matrix form, as expressions (expression.h) over the phase's states.
//
// Two forms, over generalized coordinates q (n of them) and their velocities q̇ (both are states):
//   - Lagrangian: kinetic energy T(q, q̇) = ½ q̇ᵀ M(q) q̇ (a quadratic form in q̇), potential V(q) and
//     optional generalized forces Q(q, q̇). Euler–Lagrange, d/dt ∂T/∂q̇ − ∂T/∂q + ∂V/∂q = Q, gives
//         M(q) q̈ = h(q, q̇),  M = ∂²T/∂q̇²,  h = ∂T/∂q − (∂²T/∂q̇∂q) q̇ − ∂V/∂q + Q,
//     and the energy H = T + V, which Q conserves when it does no work (Q·q̇ = 0).
//   - Mass-matrix: M(q) and h(q, q̇) given; with a potential V declared, −∂V/∂q is added to h and
//     H = ½ q̇ᵀ M q̇ + V.
// q̈ = M⁻¹ h is solved by the tool (CholeskySolve, expression_derivative.h): exact derivatives through it,
// NaN (reported by the integrator, explained by ExplainMassMatrix) where M is not positive definite.
//
// Impact at a contact constraint g(q) = 0 with Newton's law of restitution e (the paper's resets of the
// rod, eq. jumpLeft and jumpRight, are the case e = 1): with G = ∂g/∂q (a row) and the impulse along
// M⁻¹Gᵀ,
//         q⁺ = q,   q̇⁺ = q̇ − (1 + e) M⁻¹Gᵀ (G q̇) / (G M⁻¹ Gᵀ),
// so that G q̇⁺ = −e G q̇ and, for e = 1, T(q, q̇⁺) = T(q, q̇).
//
// A contact of several constraints g(q) ∈ R^k (a point foot that neither slips nor rebounds: k = 2) takes
// the impulse Gᵀλ with G = ∂g/∂q (k × n) and λ from the k × k system (G M⁻¹ Gᵀ) λ = (1 + e) G q̇:
//         q̇⁺ = q̇ − M⁻¹Gᵀ λ,  G q̇⁺ = −e G q̇.
// Walking models add pinned coordinates p (the stance foot's position): at rest while the phase lasts (the
// equations of motion are those of T and V with p = 0, ṗ = 0, the constraint substituted into the
// Lagrangian), but free in the impact, which acts in the extended coordinates (q, p) with the mass matrix
// M_e = ∂²T/∂(q̇, ṗ)² and ṗ⁻ = 0. The plastic heel strike (e = 0 on the new foot's position, k = 2) then
// conserves the angular momentum about the new contact point, which is how the literature states it
// (Garcia et al. 1998, eq. 4; Goswami et al. 1998), and the new stance foot is at rest afterwards, while the
// old one leaves the ground without an impulse. A relabelling q' = S(q) (the legs exchange their roles)
// carries the velocities by its Jacobian, q̇' = (∂S/∂q) q̇⁺.
#ifndef HYBRIDCONT_MECHANICS_H_
#define HYBRIDCONT_MECHANICS_H_

#include <cmath>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "hybridcont/expression.h"
#include "hybridcont/model.h"
#include "hybridcont/types.h"

namespace hybridcont {

// The mechanics of a phase. Indices are inputs of the phase's expressions (its states).
struct MechanicalSystem {
  // q: n input indices; -1 for an ignorable (cyclic) coordinate that is not a state: nothing depends on
  // it, only its velocity is a state.
  std::vector<int> coordinates;
  std::vector<int> velocities;   // q̇: n input indices, velocities[i] the rate of coordinates[i]
  // Lagrangian form: kinetic (non-null) and potential (null: V = 0).
  ExprPtr kinetic;
  ExprPtr potential;
  // Mass-matrix form (when kinetic is null): n × n, symmetric.
  std::vector<std::vector<ExprPtr>> mass_matrix;
  // Q (Lagrangian) or h (mass-matrix form); n entries, null entries zero.
  std::vector<ExprPtr> forces;
  // Pinned coordinates p and their velocities ṗ (Lagrangian form only): inputs numbered from the phase's
  // state dimension on (they are not states), 0 while the phase lasts, free in an impact.
  std::vector<int> pinned_coordinates, pinned_velocities;
  // Where each field came from, for messages: kinetic, potential, mass_matrix, forces.
  SourceLocation kinetic_where, potential_where, mass_matrix_where, forces_where;
};

// The derived equations: M (n × n, symmetric), h (n), q̈ = M⁻¹h (n) and the energy.
struct EquationsOfMotion {
  std::vector<std::vector<ExprPtr>> mass_matrix;
  std::vector<ExprPtr> forces;
  std::vector<ExprPtr> accelerations;
  ExprPtr energy;
};

// The system while its pinned coordinates are at rest: p = 0 and ṗ = 0 substituted into T, V and Q, no
// pinned coordinates left. The system itself when it has none.
MechanicalSystem PinnedAtRest(const MechanicalSystem& system);

// Derives the equations (of PinnedAtRest(system)). Throws ModelInputError (at the field concerned) for bad mechanics that shows in
// the structure: T or M depending on a velocity, V depending on a velocity, a non-smooth operation, a mass
// matrix of the wrong size. CheckMechanics finds what only shows in values.
EquationsOfMotion DeriveEquationsOfMotion(const MechanicalSystem& system);

// Checks at `states` (each a full state of the phase) with parameter values p: T equals ½ q̇ᵀ M q̇ (no
// terms of order 0, 1 or above 2 in q̇), M is symmetric (mass-matrix form). Throws ModelInputError naming
// the field, the state and the values.
void CheckMechanics(const MechanicalSystem& system, const EquationsOfMotion& equations, int num_states,
                    const std::vector<Vector>& states, const std::vector<double>& p,
                    const std::vector<std::string>& state_names);

// The post-impact velocities q̇⁺ (n, the coordinates that are not pinned) at the contact g = 0, one
// expression of q (and p) per constraint row; throws ModelInputError at `where` if a row does not depend on
// the coordinates or depends on a velocity. The restitution e is an expression of the parameters (a
// number, or a parameter to continue in).
// The impact's mass matrix (in the coordinates and the pinned coordinates, those at rest) goes to
// *impact_mass_matrix where it is given: a caller checks it at values (ExplainMassMatrix), since a pinned
// coordinate the kinetic energy gives no mass makes it singular and the impulse undefined.
std::vector<ExprPtr> ImpactVelocities(const MechanicalSystem& system, const EquationsOfMotion& equations,
                                      const std::vector<ExprPtr>& constraints, const ExprPtr& restitution,
                                      const SourceLocation& where,
                                      std::vector<std::vector<ExprPtr>>* impact_mass_matrix = nullptr);

// The velocities after the relabelling q' = S(q): relabel[i] is S_i (null: q'_i = q_i), an expression of
// the coordinates; the result is q̇'_i = Σ_j ∂S_i/∂q_j · velocities[j]. Throws ModelInputError at `where`
// if some S_i depends on a velocity.
std::vector<ExprPtr> RelabelVelocities(const MechanicalSystem& system, const std::vector<ExprPtr>& relabel,
                                       const std::vector<ExprPtr>& velocities, const SourceLocation& where);

// Why M is not positive definite at a state, from its entries there (n × n, row-major): "" if it is.
// Names the coordinates (names[i] for q_i) and the values: "the mass matrix is not positive definite at
// (y = 0.3, alpha = 0.1): pivot 2 of its Cholesky factorization is -0.25".
std::string ExplainMassMatrix(const std::vector<double>& entries, const std::vector<std::string>& names,
                              const std::vector<double>& coordinates);

// ---- The same mechanics in a C++ model (model_builder.h): phase functions are templates over the scalar
// type T (double and the jets of automatic differentiation), so these are too. A phase in the mass-matrix
// form writes
//     MassMatrix<T> M(2, 2);  M << ...;   StateVector<T> h(2);  h << ...;
//     const StateVector<T> acc = SolveMassMatrix(M, h);              // q̈ = M⁻¹ h
// and an impact reset
//     const StateVector<T> after = ImpactVelocities(M, G, qdot, 1.0);  // G = ∂g/∂q at the contact
// Derivatives flow through both exactly (they are loops of +, −, ×, ÷ and √ over T).

template <class T>
using MassMatrix = Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxPhaseDim, kMaxPhaseDim>;

namespace internal {

// x = A⁻¹ b by the Cholesky factorization A = L Lᵀ of a symmetric positive definite A (only its lower
// triangle is read: a(i, j) for j <= i), over any scalar type with −, ×, ÷ and sqrt: numbers and jets
// (SolveMassMatrix) and expression trees (CholeskySolve, expression_derivative.h). Where A is not positive
// definite a pivot is negative and its square root NaN, never a wrong finite value.
template <class T, class A, class B, class X>
void CholeskySolveInto(int n, const A& a, const B& b, X&& x) {
  using std::sqrt;
  thread_local std::vector<T> L, y;  // per thread: no allocation once warm
  L.assign(static_cast<std::size_t>(n) * n, T(a(0, 0)));
  y.assign(n, T(b(0)));
  const auto l = [&](int i, int j) -> T& { return L[static_cast<std::size_t>(i) * n + j]; };
  for (int j = 0; j < n; ++j) {
    for (int i = j; i < n; ++i) {
      T s = a(i, j);
      for (int k = 0; k < j; ++k) s = s - l(i, k) * l(j, k);
      l(i, j) = i == j ? T(sqrt(s)) : T(s / l(j, j));
    }
  }
  for (int i = 0; i < n; ++i) {
    T s = b(i);
    for (int k = 0; k < i; ++k) s = s - l(i, k) * y[k];
    y[i] = s / l(i, i);
  }
  for (int i = n - 1; i >= 0; --i) {
    T s = y[i];
    for (int k = i + 1; k < n; ++k) s = s - l(k, i) * x(k);
    x(i) = s / l(i, i);
  }
}

}  // namespace internal

// x = M⁻¹ b (M symmetric positive definite): internal::CholeskySolveInto over the phase's scalar type.
template <class T>
StateVector<T> SolveMassMatrix(const MassMatrix<T>& M, const StateVector<T>& b) {
  StateVector<T> x(b.size());
  internal::CholeskySolveInto<T>(
      static_cast<int>(b.size()), [&](int i, int j) -> const T& { return M(i, j); },
      [&](int i) -> const T& { return b(i); }, [&](int i) -> T& { return x(i); });
  return x;
}

// Newton's law of restitution e at a contact with Jacobian G = ∂g/∂q (as a column): the post-impact
// velocities q̇ − (1 + e) M⁻¹Gᵀ (G q̇) / (G M⁻¹ Gᵀ).
template <class T>
StateVector<T> ImpactVelocities(const MassMatrix<T>& M, const StateVector<T>& G, const StateVector<T>& qdot,
                                double restitution) {
  const StateVector<T> w = SolveMassMatrix(M, G);
  T gq = G(0) * qdot(0), gw = G(0) * w(0);
  for (int i = 1; i < G.size(); ++i) {
    gq = gq + G(i) * qdot(i);
    gw = gw + G(i) * w(i);
  }
  const T factor = (1.0 + restitution) * gq / gw;
  StateVector<T> after(qdot.size());
  for (int i = 0; i < qdot.size(); ++i) after(i) = qdot(i) - w(i) * factor;
  return after;
}

}  // namespace hybridcont

#endif  // HYBRIDCONT_MECHANICS_H_
