#include "continuation/bordered_solver.h"

#include <cmath>
#include <vector>

namespace hybridcont::internal {

bool BorderedSolver::Factorize(const Matrix& A, const Vector& b) {
  const Eigen::Index n = A.cols();
  if (B_.rows() != n || B_.cols() != n) B_.resize(n, n);
  B_.topRows(n - 1) = A;
  B_.row(n - 1) = b.transpose();
  if (!B_.allFinite()) return false;
  sparse_ = n >= kSparseThreshold;
  if (sparse_) return FactorizeSparse();
  lu_.compute(B_);
  const auto diagonal = lu_.matrixLU().diagonal().cwiseAbs();
  const double largest = diagonal.maxCoeff();
  return largest > 0 && std::isfinite(largest) && diagonal.minCoeff() > kSingularPivotRatio * largest;
}

bool BorderedSolver::FactorizeSparse() {
  const Eigen::Index n = B_.rows();
  std::vector<Eigen::Triplet<double>> triplets;
  for (Eigen::Index j = 0; j < n; ++j) {
    for (Eigen::Index i = 0; i < n; ++i) {
      if (B_(i, j) != 0.0) triplets.emplace_back(static_cast<int>(i), static_cast<int>(j), B_(i, j));
    }
  }
  sparse_B_.resize(n, n);
  sparse_B_.setFromTriplets(triplets.begin(), triplets.end());
  sparse_lu_.analyzePattern(sparse_B_);
  sparse_lu_.factorize(sparse_B_);
  if (sparse_lu_.info() != Eigen::Success) return false;
  sparse_log_det_ = sparse_lu_.logAbsDeterminant();
  sparse_sign_ = sparse_lu_.signDeterminant() < 0 ? -1 : 1;
  const Vector e = Vector::Ones(n);
  const Vector x = sparse_lu_.solve(e);
  if (!x.allFinite()) return false;
  const double norm_B = B_.cwiseAbs().rowwise().sum().maxCoeff();
  return norm_B * x.cwiseAbs().maxCoeff() < 1.0 / kSingularPivotRatio;
}

void BorderedSolver::Solve(const Vector& rhs, Vector* x) const {
  if (x->size() != rhs.size()) x->resize(rhs.size());
  if (sparse_) {
    *x = sparse_lu_.solve(rhs);
    return;
  }
  *x = lu_.solve(rhs);
}

double BorderedSolver::LogAbsDeterminant() const {
  if (sparse_) return sparse_log_det_;
  return lu_.matrixLU().diagonal().cwiseAbs().array().log().sum();
}

int BorderedSolver::DeterminantSign() const {
  if (sparse_) return sparse_sign_;
  double sign = lu_.permutationP().determinant();
  const auto diagonal = lu_.matrixLU().diagonal();
  for (Eigen::Index i = 0; i < diagonal.size(); ++i) {
    if (diagonal(i) < 0) sign = -sign;
  }
  return sign < 0 ? -1 : 1;
}

}  // namespace hybridcont::internal
