#include "continuation/bordered_solver.h"

#include <cmath>

namespace hybridcont::internal {

bool BorderedSolver::Factorize(const Matrix& A, const Vector& b) {
  const Eigen::Index n = A.cols();
  if (B_.rows() != n || B_.cols() != n) B_.resize(n, n);
  B_.topRows(n - 1) = A;
  B_.row(n - 1) = b.transpose();
  if (!B_.allFinite()) return false;
  lu_.compute(B_);
  const auto diagonal = lu_.matrixLU().diagonal().cwiseAbs();
  const double largest = diagonal.maxCoeff();
  return largest > 0 && std::isfinite(largest) && diagonal.minCoeff() > kSingularPivotRatio * largest;
}

void BorderedSolver::Solve(const Vector& rhs, Vector* x) const {
  if (x->size() != rhs.size()) x->resize(rhs.size());
  *x = lu_.solve(rhs);
}

double BorderedSolver::LogAbsDeterminant() const {
  return lu_.matrixLU().diagonal().cwiseAbs().array().log().sum();
}

int BorderedSolver::DeterminantSign() const {
  double sign = lu_.permutationP().determinant();
  const auto diagonal = lu_.matrixLU().diagonal();
  for (Eigen::Index i = 0; i < diagonal.size(); ++i) {
    if (diagonal(i) < 0) sign = -sign;
  }
  return sign < 0 ? -1 : 1;
}

}  // namespace hybridcont::internal
