#include "hybridcont/mechanics.h"

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

EquationsOfMotion DeriveEquationsOfMotion(const MechanicalSystem& s) {
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

std::vector<ExprPtr> ImpactVelocities(const MechanicalSystem& s, const EquationsOfMotion& eq, const ExprPtr& g,
                                      const ExprPtr& restitution, const SourceLocation& where) {
  const int n = static_cast<int>(s.coordinates.size());
  for (int v : s.velocities) {
    if (DependsOnInput(g, v)) throw ModelInputError(where, "the contact constraint g(q) depends on a velocity");
  }
  std::vector<ExprPtr> G(n), dq(n);
  bool depends = false;
  for (int i = 0; i < n; ++i) {
    G[i] = Differentiate(g, s.coordinates[i], where);
    dq[i] = MakeInput(s.velocities[i]);
    depends = depends || !IsZero(G[i]);
  }
  if (!depends) throw ModelInputError(where, "the contact constraint g(q) does not depend on the coordinates");
  const std::vector<ExprPtr> w = CholeskySolve(eq.mass_matrix, G);  // M⁻¹ Gᵀ
  // The impulse factor (1 + e) (G q̇) / (G M⁻¹ Gᵀ).
  const ExprPtr factor = Div(Mul(Add(MakeConstant(1.0), restitution), Dot(G, dq)), Dot(G, w));
  std::vector<ExprPtr> after(n);
  for (int i = 0; i < n; ++i) after[i] = Sub(dq[i], Mul(w[i], factor));
  return after;
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
