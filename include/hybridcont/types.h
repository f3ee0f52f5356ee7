// Basic linear-algebra aliases shared by every hybridcont header.
//
//   hybridcont::Vector x(4);      // a state of a phase, a residual, u
//   hybridcont::Matrix Phi(4, 4); // a fundamental matrix, a Jacobian
//
// Dynamic sizes throughout the public API: phases of one model have different dimensions (SLIP: stance 4,
// flight 5), so the sizes are run-time values. Hot loops use workspaces sized once (conventions §6).
#ifndef HYBRIDCONT_TYPES_H_
#define HYBRIDCONT_TYPES_H_

#include <Eigen/Core>
#include <Eigen/SparseCore>

namespace hybridcont {

using Vector = Eigen::VectorXd;
using RowVector = Eigen::RowVectorXd;
using Matrix = Eigen::MatrixXd;
// Jacobians with O(N) nonzeros (multiple shooting with many phases: block-cyclic), column-major.
using SparseMatrix = Eigen::SparseMatrix<double>;

}  // namespace hybridcont

#endif  // HYBRIDCONT_TYPES_H_
