// The layout of u and r for the time-based multiple-shooting map (paper eq. `timebased`).
//
// With m phases, phase m+1 is phase 1 again (the return to the Poincaré section), and k first integrals:
//
//   u = [ t_{m+1}, x̄_{m+1} | t_m, x̄_m | ... | t_1, x̄_1 | xi_1..xi_k | H̄ ]          (N + 1 unknowns)
//   r = [ block m+1 | block m | ... | block 1 | H_1(x̄_1) - H̄, H_j(x̄_1) - H̄_j (j >= 2) ]   (N equations)
//
// where block i has n_{i+1} + 1 rows: [Delta_i(phi_i) - x̄_{i+1}; e_i(phi_i)] for i <= m and
// [phi_1 - x̄_1; a(phi_1)] for i = m+1, so N = sum_{i=1}^{m+1} n_i + m + 1 + k (= the paper's N for k = 1).
// Levels H̄_j, j >= 2, of further first integrals are fixed values, not unknowns: the continuation stays
// one-dimensional (paper's remark on N_H > 1).
//
// Names (used as CSV column headers and to address components): "t1".."t<m+1>", "x<i>_<state>" (e.g.
// "x2_dx"), "xi" (or "xi1".."xik"), "H".
//
//   ShootingLayout layout(model);
//   double H = u(layout.H_index());
//   auto x2 = u.segment(layout.state_offset(1), layout.dim(1));   // 0-based: phase 2
#ifndef HYBRIDCONT_SHOOTING_LAYOUT_H_
#define HYBRIDCONT_SHOOTING_LAYOUT_H_

#include <string>
#include <vector>

#include "hybridcont/invariant.h"
#include "hybridcont/model.h"

namespace hybridcont {

class ShootingLayout {
 public:
  explicit ShootingLayout(const HybridModel& model);

  // Number of shooting segments, m + 1.
  int num_segments() const { return static_cast<int>(dims_.size()); }
  // State dimension of segment i (0-based; segment m is phase 1 again).
  int dim(int i) const { return dims_[CheckedSegment(i)]; }
  int num_first_integrals() const { return k_; }
  int num_unknowns() const { return num_unknowns_; }
  int num_equations() const { return num_unknowns_ - 1; }

  // Index of t_{i+1} in u (0-based segment i).
  int time_index(int i) const { return time_index_[CheckedSegment(i)]; }
  // Index of the first entry of x̄_{i+1} in u.
  int state_offset(int i) const { return time_index(i) + 1; }
  int xi_index(int j = 0) const { return xi_index_ + j; }
  int H_index() const { return num_unknowns_ - 1; }

  // First row of block i of r (segment i's shooting/periodicity rows followed by its event/anchor row).
  int block_row(int i) const { return block_row_[CheckedSegment(i)]; }
  int first_integral_row() const { return num_equations() - k_; }

  const std::vector<std::string>& unknown_names() const { return names_; }

  // Total period T = sum of the m+1 durations.
  double Period(const Vector& u) const;

 private:
  int CheckedSegment(int i) const {
    HYBRIDCONT_DEMAND(i >= 0 && i < num_segments());
    return i;
  }

  std::vector<int> dims_;
  int k_;
  std::vector<int> time_index_;
  std::vector<int> block_row_;
  int xi_index_;
  int num_unknowns_;
  std::vector<std::string> names_;
};

}  // namespace hybridcont

#endif  // HYBRIDCONT_SHOOTING_LAYOUT_H_
