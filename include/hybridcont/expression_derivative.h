// Symbolic derivatives of parsed expressions (expression.h), and the algebra that builds them.
//
// A model written from its mechanics (mechanics.h) needs derivatives of its energies as new expressions:
// the mass matrix M = ∂²T/∂q̇², the forces ∂T/∂q − ∂V/∂q, the contact Jacobian ∂g/∂q. They are formed here
// by the chain rule over the expression tree, exactly: the result is again an expression, which the
// expression compiler shares and evaluates like any other, so its own derivatives (df, dΔ, and in a
// parameter) are the same forward-mode automatic differentiation as everywhere else. Nested automatic
// differentiation would give the same numbers at a higher cost in every evaluation; finite differences
// never enter.
//
// The constructors below simplify as they build (constants folded, 0 and 1 absorbed, x − x = 0 for one
// node), so that a derivative that vanishes is the constant 0 and the derivative of a quadratic form in
// the velocities is free of them: tests on the structure (IsZero, DependsOnInput) rely on that.
#ifndef HYBRIDCONT_EXPRESSION_DERIVATIVE_H_
#define HYBRIDCONT_EXPRESSION_DERIVATIVE_H_

#include <functional>
#include <vector>

#include "hybridcont/expression.h"

namespace hybridcont {

// Simplifying constructors.
ExprPtr Add(const ExprPtr& a, const ExprPtr& b);
ExprPtr Sub(const ExprPtr& a, const ExprPtr& b);
ExprPtr Mul(const ExprPtr& a, const ExprPtr& b);
ExprPtr Div(const ExprPtr& a, const ExprPtr& b);
ExprPtr Neg(const ExprPtr& a);
ExprPtr Sqrt(const ExprPtr& a);
// Σ_k a_k b_k (null entries are zero).
ExprPtr Dot(const std::vector<ExprPtr>& a, const std::vector<ExprPtr>& b);

// True if e is the constant `value`.
bool IsConstant(const ExprPtr& e, double value);
// True if e is the constant 0.
inline bool IsZero(const ExprPtr& e) { return IsConstant(e, 0.0); }
// True if the tree reads input `index`.
bool DependsOnInput(const ExprPtr& e, int index);

// ∂e/∂x_input, simplified. Throws ModelInputError at `where` where e uses an operation without a
// derivative (comparisons, logic, min, max).
ExprPtr Differentiate(const ExprPtr& e, int input, const SourceLocation& where);

// e with each input k replaced by replace(k) where that is non-null (the tree rebuilt with the simplifying
// constructors, so that a factor that becomes 0 drops out; shared nodes stay shared).
ExprPtr SubstituteInputs(const ExprPtr& e, const std::function<ExprPtr(int input)>& replace);

// x = A⁻¹ b for a symmetric positive definite A (n × n, rows of expressions; only the lower triangle is
// read) by the Cholesky factorization A = L Lᵀ written out as expressions: O(n³) nodes, shared by the
// compiler. At a state where A is not positive definite a diagonal entry of L is the square root of a
// negative number, so the result is NaN, never a wrong finite value; the integrator reports it (and
// Phase::ExplainNonFinite says why).
std::vector<ExprPtr> CholeskySolve(const std::vector<std::vector<ExprPtr>>& A, const std::vector<ExprPtr>& b);

}  // namespace hybridcont

#endif  // HYBRIDCONT_EXPRESSION_DERIVATIVE_H_
