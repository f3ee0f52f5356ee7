#include "continuation/bordered_solver.h"

#include <algorithm>
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
  triplets_.clear();
  for (Eigen::Index j = 0; j < n; ++j) {
    for (Eigen::Index i = 0; i < n; ++i) {
      if (B_(i, j) != 0.0) triplets_.emplace_back(static_cast<int>(i), static_cast<int>(j), B_(i, j));
    }
  }
  sparse_B_.resize(n, n);
  sparse_B_.setFromTriplets(triplets_.begin(), triplets_.end());
  analyzed_rows_ = -1;  // the pattern of a dense matrix's nonzeros may change from call to call
  return FactorizeSparseB();
}

bool BorderedSolver::Factorize(const SparseMatrix& A, const Vector& b) {
  const Eigen::Index n = A.cols();
  sparse_ = true;
  if (!b.allFinite() || !Eigen::Map<const Vector>(A.valuePtr(), A.nonZeros()).allFinite()) return false;
  // B = [A; bᵀ], column by column (A is column-major): A's column j, then b_j in the last row.
  triplets_.clear();
  triplets_.reserve(static_cast<size_t>(A.nonZeros() + n));
  for (Eigen::Index j = 0; j < n; ++j) {
    for (SparseMatrix::InnerIterator it(A, j); it; ++it) {
      triplets_.emplace_back(static_cast<int>(it.row()), static_cast<int>(j), it.value());
    }
    triplets_.emplace_back(static_cast<int>(n - 1), static_cast<int>(j), b(j));
  }
  sparse_B_.resize(n, n);
  sparse_B_.setFromTriplets(triplets_.begin(), triplets_.end());
  return FactorizeSparseB();
}

bool BorderedSolver::FactorizeSparseB() {
  const Eigen::Index n = sparse_B_.rows();
  sparse_B_.makeCompressed();
  const bool same_pattern =
      analyzed_rows_ == n && analyzed_nonzeros_ == sparse_B_.nonZeros() &&
      std::equal(analyzed_outer_.begin(), analyzed_outer_.end(), sparse_B_.outerIndexPtr()) &&
      std::equal(sparse_B_.innerIndexPtr(), sparse_B_.innerIndexPtr() + sparse_B_.nonZeros(), analyzed_inner_.begin());
  if (!same_pattern) {
    sparse_lu_.analyzePattern(sparse_B_);
    analyzed_rows_ = n;
    analyzed_nonzeros_ = sparse_B_.nonZeros();
    analyzed_outer_.assign(sparse_B_.outerIndexPtr(), sparse_B_.outerIndexPtr() + n + 1);
    analyzed_inner_.assign(sparse_B_.innerIndexPtr(), sparse_B_.innerIndexPtr() + sparse_B_.nonZeros());
  }
  sparse_lu_.factorize(sparse_B_);
  if (sparse_lu_.info() != Eigen::Success) return false;
  sparse_log_det_ = sparse_lu_.logAbsDeterminant();
  sparse_sign_ = sparse_lu_.signDeterminant() < 0 ? -1 : 1;
  const Vector e = Vector::Ones(n);
  const Vector x = sparse_lu_.solve(e);
  if (!x.allFinite()) return false;
  // |B|_inf: largest absolute row sum
  Vector row_sums = Vector::Zero(n);
  for (Eigen::Index j = 0; j < n; ++j) {
    for (SparseMatrix::InnerIterator it(sparse_B_, j); it; ++it) row_sums(it.row()) += std::abs(it.value());
  }
  return row_sums.maxCoeff() * x.cwiseAbs().maxCoeff() < 1.0 / kSingularPivotRatio;
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
