#include "hybridcont/mechanics.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "hybridcont/expression_derivative.h"

namespace hybridcont {
namespace {

// The name of input `index` for messages: "state 3" when no names are given.
std::string InputName(const std::vector<std::string>& names, int index) {
  return index < static_cast<int>(names.size()) ? names[index] : "state " + std::to_string(index);
}

std::string FormatState(const std::vector<std::string>& names, const Vector& x) {
  std::ostringstream os;
  os.precision(6);
  os << "(";
  for (int k = 0; k < x.size(); ++k) os << (k ? ", " : "") << InputName(names, k) << " = " << x(k);
  os << ")";
  return os.str();
}

}  // namespace

MechanicalSystem PinnedAtRest(const MechanicalSystem& system) {
  if (system.pinned_coordinates.empty()) return system;
  if (!system.kinetic) {
    throw ModelInputError(system.mass_matrix_where,
                          "pinned coordinates need the Lagrangian form (kinetic): the impact's mass matrix in the "
                          "extended coordinates is derived from T");
  }
  std::vector<int> pinned = system.pinned_coordinates;
  pinned.insert(pinned.end(), system.pinned_velocities.begin(), system.pinned_velocities.end());
  const auto at_rest = [&](int input) {
    return std::find(pinned.begin(), pinned.end(), input) != pinned.end() ? MakeConstant(0.0) : nullptr;
  };
  MechanicalSystem s = system;
  s.pinned_coordinates.clear();
  s.pinned_velocities.clear();
  s.kinetic = SubstituteInputs(system.kinetic, at_rest);
  if (system.potential) s.potential = SubstituteInputs(system.potential, at_rest);
  for (ExprPtr& f : s.forces) {
    if (f) f = SubstituteInputs(f, at_rest);
  }
  return s;
}

EquationsOfMotion DeriveEquationsOfMotion(const MechanicalSystem& system) {
  const MechanicalSystem s = PinnedAtRest(system);
  const int n = static_cast<int>(s.coordinates.size());
  if (static_cast<int>(s.velocities.size()) != n) {
    throw ModelInputError(s.kinetic_where, "as many velocities as coordinates are needed");
  }
  EquationsOfMotion eq;
  eq.mass_matrix.assign(n, std::vector<ExprPtr>(n));
  eq.forces.assign(n, MakeConstant(0.0));
  const auto force = [&](int i) { return i < static_cast<int>(s.forces.size()) && s.forces[i] ? s.forces[i] : MakeConstant(0.0); };
  const auto velocity_free = [&](const ExprPtr& e, const SourceLocation& where, const std::string& what) {
    for (int v : s.velocities) {
      if (DependsOnInput(e, v)) throw ModelInputError(where, what + " depends on a velocity");
    }
  };
  ExprPtr potential = s.potential ? s.potential : MakeConstant(0.0);
  if (s.potential) velocity_free(s.potential, s.potential_where, "the potential energy V(q)");
  if (s.kinetic) {
    if (HasNonSmoothOperation(s.kinetic)) {
      throw ModelInputError(s.kinetic_where, "comparisons, logic, min and max have no derivative and cannot be used in T");
    }
    // ∂T/∂q̇_i, then M_ij = ∂²T/∂q̇_i∂q̇_j (lower triangle, mirrored).
    std::vector<ExprPtr> p(n);
    for (int i = 0; i < n; ++i) p[i] = Differentiate(s.kinetic, s.velocities[i], s.kinetic_where);
    for (int i = 0; i < n; ++i) {
      for (int j = 0; j <= i; ++j) {
        ExprPtr mij = Differentiate(p[i], s.velocities[j], s.kinetic_where);
        for (int v : s.velocities) {
          if (DependsOnInput(mij, v)) {
            throw ModelInputError(s.kinetic_where,
                                  "the kinetic energy is not quadratic in the velocities: its second derivative in "
                                  "the velocities (the mass matrix) depends on a velocity");
          }
        }
        eq.mass_matrix[i][j] = eq.mass_matrix[j][i] = mij;
      }
    }
    // h_i = ∂T/∂q_i − Σ_k ∂²T/∂q̇_i∂q_k q̇_k − ∂V/∂q_i + Q_i.
    for (int i = 0; i < n; ++i) {
      ExprPtr h = Differentiate(s.kinetic, s.coordinates[i], s.kinetic_where);
      for (int k = 0; k < n; ++k) {
        h = Sub(h, Mul(Differentiate(p[i], s.coordinates[k], s.kinetic_where), MakeInput(s.velocities[k])));
      }
      h = Sub(h, Differentiate(potential, s.coordinates[i], s.potential_where));
      eq.forces[i] = Add(h, force(i));
    }
    eq.energy = Add(s.kinetic, potential);
  } else {
    if (static_cast<int>(s.mass_matrix.size()) != n) {
      throw ModelInputError(s.mass_matrix_where, "the mass matrix has " + std::to_string(s.mass_matrix.size()) +
                                                     " rows for " + std::to_string(n) + " coordinates");
    }
    for (int i = 0; i < n; ++i) {
      if (static_cast<int>(s.mass_matrix[i].size()) != n) {
        throw ModelInputError(s.mass_matrix_where, "row " + std::to_string(i + 1) + " of the mass matrix has " +
                                                       std::to_string(s.mass_matrix[i].size()) + " entries for " +
                                                       std::to_string(n) + " coordinates");
      }
      for (int j = 0; j < n; ++j) {
        if (!s.mass_matrix[i][j]) throw ModelInputError(s.mass_matrix_where, "missing mass-matrix entry");
        velocity_free(s.mass_matrix[i][j], s.mass_matrix_where,
                      "mass-matrix entry (" + std::to_string(i + 1) + ", " + std::to_string(j + 1) + ")");
      }
    }
    eq.mass_matrix = s.mass_matrix;
    ExprPtr kinetic = MakeConstant(0.0);
    for (int i = 0; i < n; ++i) {
      eq.forces[i] = Sub(force(i), Differentiate(potential, s.coordinates[i], s.potential_where));
      for (int j = 0; j < n; ++j) {
        kinetic = Add(kinetic, Mul(Mul(MakeInput(s.velocities[i]), s.mass_matrix[i][j]), MakeInput(s.velocities[j])));
      }
    }
    eq.energy = Add(Mul(MakeConstant(0.5), kinetic), potential);
  }
  eq.accelerations = CholeskySolve(eq.mass_matrix, eq.forces);
  return eq;
}

void CheckMechanics(const MechanicalSystem& s, const EquationsOfMotion& eq, int num_states,
                    const std::vector<Vector>& states, const std::vector<double>& p,
                    const std::vector<std::string>& state_names) {
  const int n = static_cast<int>(s.coordinates.size());
  // Outputs: T, ½ q̇ᵀ M q̇, then M row-major.
  std::vector<ExprPtr> outputs;
  ExprPtr quadratic = MakeConstant(0.0);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      quadratic = Add(quadratic, Mul(Mul(MakeInput(s.velocities[i]), eq.mass_matrix[i][j]), MakeInput(s.velocities[j])));
    }
  }
  outputs.push_back(s.kinetic ? s.kinetic : MakeConstant(0.0));
  outputs.push_back(Mul(MakeConstant(0.5), quadratic));
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) outputs.push_back(eq.mass_matrix[i][j]);
  }
  const ExpressionProgram program(outputs, num_states, false, {});
  for (const Vector& x : states) {
    const auto value = [&](int k) { return program.EvaluateScalar(x.data(), p.data(), k); };
    if (s.kinetic) {
      const double t = value(0), q = value(1);
      // Rounding of a sum of n² products of size |q|: a few ulps of it.
      if (!(std::abs(t - q) <= 1e-12 * (std::abs(t) + std::abs(q)) + 1e-300)) {
        std::ostringstream os;
        os.precision(10);
        os << "the kinetic energy is not a quadratic form in the velocities: T = " << t << " but ½ q̇ᵀ M q̇ = " << q
           << " at " << FormatState(state_names, x) << " (T may have no terms of order 0 or 1 in the velocities)";
        throw ModelInputError(s.kinetic_where, os.str());
      }
    } else {
      for (int i = 0; i < n; ++i) {
        for (int j = 0; j < i; ++j) {
          const double a = value(2 + i * n + j), b = value(2 + j * n + i);
          if (!(std::abs(a - b) <= 1e-12 * (std::abs(a) + std::abs(b)) + 1e-300)) {
            std::ostringstream os;
            os.precision(10);
            os << "the mass matrix is not symmetric: entry (" << i + 1 << ", " << j + 1 << ") = " << a << " but ("
               << j + 1 << ", " << i + 1 << ") = " << b << " at " << FormatState(state_names, x);
            throw ModelInputError(s.mass_matrix_where, os.str());
          }
        }
      }
    }
  }
}

std::vector<ExprPtr> ImpactVelocities(const MechanicalSystem& s, const EquationsOfMotion& eq,
                                      const std::vector<ExprPtr>& constraints, const ExprPtr& restitution,
                                      const SourceLocation& where,
                                      std::vector<std::vector<ExprPtr>>* impact_mass_matrix) {
  const int n = static_cast<int>(s.coordinates.size());
  const int k = static_cast<int>(constraints.size());
  // The extended coordinates (q, p), their velocities (q̇, ṗ) with ṗ⁻ = 0, and M_e.
  std::vector<int> coordinates = s.coordinates, velocities = s.velocities;
  coordinates.insert(coordinates.end(), s.pinned_coordinates.begin(), s.pinned_coordinates.end());
  velocities.insert(velocities.end(), s.pinned_velocities.begin(), s.pinned_velocities.end());
  const int ne = static_cast<int>(coordinates.size());
  const auto pinned_at_rest = [&](const ExprPtr& e) {
    if (s.pinned_coordinates.empty()) return e;
    return SubstituteInputs(e, [&](int input) -> ExprPtr {
      for (int j = n; j < ne; ++j) {
        if (input == coordinates[j] || input == velocities[j]) return MakeConstant(0.0);
      }
      return nullptr;
    });
  };
  std::vector<std::vector<ExprPtr>> M = eq.mass_matrix;
  if (ne > n) {
    M.assign(ne, std::vector<ExprPtr>(ne));
    for (int i = 0; i < ne; ++i) {
      const ExprPtr p = Differentiate(s.kinetic, velocities[i], s.kinetic_where);
      for (int j = 0; j <= i; ++j) {
        const ExprPtr mij = Differentiate(p, velocities[j], s.kinetic_where);
        for (int v : velocities) {
          if (DependsOnInput(mij, v)) {
            throw ModelInputError(s.kinetic_where, "the kinetic energy is not quadratic in the velocities of the "
                                                   "coordinates and the pinned coordinates");
          }
        }
        M[i][j] = M[j][i] = pinned_at_rest(mij);
      }
    }
  }
  if (impact_mass_matrix != nullptr) *impact_mass_matrix = M;
  std::vector<ExprPtr> dq(ne);
  for (int i = 0; i < ne; ++i) dq[i] = i < n ? MakeInput(velocities[i]) : MakeConstant(0.0);
  // G (k × ne) and W = M_e⁻¹ Gᵀ (its columns).
  std::vector<std::vector<ExprPtr>> G(k), W(k);
  for (int r = 0; r < k; ++r) {
    for (int v : velocities) {
      if (DependsOnInput(constraints[r], v)) {
        throw ModelInputError(where, "the contact constraint g(q) depends on a velocity");
      }
    }
    bool depends = false;
    for (int i = 0; i < ne; ++i) {
      G[r].push_back(pinned_at_rest(Differentiate(constraints[r], coordinates[i], where)));
      depends = depends || !IsZero(G[r][i]);
    }
    if (!depends) {
      throw ModelInputError(where, "the contact constraint g(q)" + (k > 1 ? " (row " + std::to_string(r + 1) + ")" : std::string()) +
                                       " does not depend on the coordinates");
    }
    W[r] = CholeskySolve(M, G[r]);
  }
  const ExprPtr one_plus_e = Add(MakeConstant(1.0), restitution);
  std::vector<ExprPtr> after(n);
  if (k == 1) {
    // The impulse factor (1 + e) (G q̇) / (G M⁻¹ Gᵀ).
    const ExprPtr factor = Div(Mul(one_plus_e, Dot(G[0], dq)), Dot(G[0], W[0]));
    for (int i = 0; i < n; ++i) after[i] = Sub(dq[i], Mul(W[0][i], factor));
    return after;
  }
  // λ = (G M⁻¹ Gᵀ)⁻¹ (1 + e) G q̇, symmetric positive definite where the rows are independent.
  std::vector<std::vector<ExprPtr>> A(k, std::vector<ExprPtr>(k));
  std::vector<ExprPtr> b(k);
  for (int r = 0; r < k; ++r) {
    for (int c = 0; c < k; ++c) A[r][c] = Dot(G[r], W[c]);
    b[r] = Mul(one_plus_e, Dot(G[r], dq));
  }
  const std::vector<ExprPtr> lambda = CholeskySolve(A, b);
  for (int i = 0; i < n; ++i) {
    ExprPtr impulse = MakeConstant(0.0);
    for (int r = 0; r < k; ++r) impulse = Add(impulse, Mul(W[r][i], lambda[r]));
    after[i] = Sub(dq[i], impulse);
  }
  return after;
}

std::vector<ExprPtr> RelabelVelocities(const MechanicalSystem& s, const std::vector<ExprPtr>& relabel,
                                       const std::vector<ExprPtr>& velocities, const SourceLocation& where) {
  const int n = static_cast<int>(s.coordinates.size());
  std::vector<ExprPtr> out = velocities;
  for (int i = 0; i < n; ++i) {
    if (!relabel[i]) continue;
    for (int v : s.velocities) {
      if (DependsOnInput(relabel[i], v)) throw ModelInputError(where, "the relabelling depends on a velocity");
    }
    ExprPtr sum = MakeConstant(0.0);
    for (int j = 0; j < n; ++j) sum = Add(sum, Mul(Differentiate(relabel[i], s.coordinates[j], where), velocities[j]));
    out[i] = sum;
  }
  return out;
}

std::string ExplainMassMatrix(const std::vector<double>& entries, const std::vector<std::string>& names,
                              const std::vector<double>& coordinates) {
  const int n = static_cast<int>(coordinates.size());
  // The same Cholesky factorization as CholeskySolve, in double precision.
  std::vector<double> L(n * n, 0.0);
  for (int j = 0; j < n; ++j) {
    for (int i = j; i < n; ++i) {
      double s = entries[i * n + j];
      for (int k = 0; k < j; ++k) s -= L[i * n + k] * L[j * n + k];
      if (i == j) {
        if (!(s > 0.0) || !std::isfinite(s)) {
          std::ostringstream os;
          os.precision(6);
          os << "the mass matrix is not positive definite at (";
          for (int k = 0; k < n; ++k) os << (k ? ", " : "") << InputName(names, k) << " = " << coordinates[k];
          os << "): pivot " << j + 1 << " of its Cholesky factorization is " << s;
          return os.str();
        }
        L[j * n + j] = std::sqrt(s);
      } else {
        L[i * n + j] = s / L[j * n + j];
      }
    }
  }
  return "";
}

}  // namespace hybridcont
