// Internal: the one place where bordered systems are factorized and solved.
//
//        [ A  ]  N rows        A = dr(u), N x (N+1)
//    B = [----]                                         B x = rhs,   B is (N+1) x (N+1)
//        [ bᵀ ]  1 row         b = tangent, c of a constraint, or a reference direction
//
// Every Newton step, every tangent and every determinant test function of the continuation engine goes
// through this class, so a block-bordered or sparse solver (multiple shooting with many phases, linear
// cost in the number of phases) can replace the dense LU here without touching the algorithms.
#ifndef HYBRIDCONT_SRC_CONTINUATION_BORDERED_SOLVER_H_
#define HYBRIDCONT_SRC_CONTINUATION_BORDERED_SOLVER_H_

#include <Eigen/LU>
#include <Eigen/SparseCore>
#include <Eigen/SparseLU>
#include <vector>

#include "hybridcont/types.h"

namespace hybridcont::internal {

class BorderedSolver {
 public:
  // Factorizes [A; bᵀ]. Returns false if the matrix is not finite or numerically singular (smallest pivot
  // of the LU below kSingularPivotRatio times the largest). Storage is reused between calls of equal size.
  bool Factorize(const Matrix& A, const Vector& b);
  // The same for a sparse A (always the sparse LU). The symbolic analysis (COLAMD ordering, elimination
  // tree) is reused while the pattern of A stays the same: only the numeric factorization is redone.
  bool Factorize(const SparseMatrix& A, const Vector& b);
  // x = B⁻¹ rhs for the last successful factorization; x is resized only when its size differs.
  void Solve(const Vector& rhs, Vector* x) const;
  // log|det B| and sign(det B) of the last factorization (never formed as a product: it over/underflows
  // for hundreds of unknowns).
  double LogAbsDeterminant() const;
  int DeterminantSign() const;

  // Pivot ratio below which B counts as singular: ~ the unit round-off times a small safety factor. Kept
  // this small on purpose: points within ~1e-12 of a bifurcation point must still be solvable while the
  // location of that point is refined (their Newton systems are ill-conditioned but consistent).
  static constexpr double kSingularPivotRatio = 1e-15;

  // From this size on, B is factorized as a sparse matrix (SuperLU-style supernodal LU with COLAMD
  // ordering). Multiple-shooting Jacobians are block-cyclic with O(m) nonzero blocks: the sparse LU costs
  // O(m) where the dense one costs O(m^3) (measured with bench BM_ScalingNewtonStep: dense LU of N = 3000
  // takes seconds, sparse milliseconds). Below it, dense partial-pivoting LU is faster.
  static constexpr Eigen::Index kSparseThreshold = 150;
  // Sparse path: Eigen's SparseLU does not expose its pivots, so "numerically singular" is judged by a
  // condition estimate |B|_inf |x|_inf / |e|_inf for B x = e (e = ones), against 1 / kSingularPivotRatio.

 private:
  bool FactorizeSparse();
  bool FactorizeSparseB();
  // Pattern of the last analyzed sparse B (sizes and column starts), to reuse analyzePattern.
  Eigen::Index analyzed_rows_ = -1, analyzed_nonzeros_ = -1;
  std::vector<int> analyzed_outer_, analyzed_inner_;
  std::vector<Eigen::Triplet<double>> triplets_;

  Matrix B_;
  Eigen::PartialPivLU<Matrix> lu_;
  bool sparse_ = false;
  SparseMatrix sparse_B_;
  Eigen::SparseLU<Eigen::SparseMatrix<double>, Eigen::COLAMDOrdering<int>> sparse_lu_;
  double sparse_log_det_ = 0.0;
  int sparse_sign_ = 1;
};

}  // namespace hybridcont::internal

#endif  // HYBRIDCONT_SRC_CONTINUATION_BORDERED_SOLVER_H_
