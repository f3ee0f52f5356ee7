#include "hybridcont/shooting_layout.h"

namespace hybridcont {

ShootingLayout::ShootingLayout(const HybridModel& model) : k_(model.num_first_integrals()) {
  const int m = model.num_phases();
  dims_.resize(m + 1);
  for (int i = 0; i <= m; ++i) dims_[i] = model.phase(i).dim();
  time_index_.resize(m + 1);
  block_row_.resize(m + 1);
  names_.clear();
  // u lists segments from m+1 down to 1 (the paper's order); r lists their blocks in the same order.
  int col = 0;
  int row = 0;
  for (int i = m; i >= 0; --i) {
    time_index_[i] = col;
    // std::string(...).append: GCC 12 warns (-Wrestrict, a false positive) on "literal" + std::string&&.
    names_.push_back(std::string("t").append(std::to_string(i + 1)));
    for (const std::string& s : model.phase(i).state_names()) {
      names_.push_back(std::string("x").append(std::to_string(i + 1)).append("_").append(s));
    }
    col += 1 + dims_[i];
    block_row_[i] = row;
    row += dims_[(i + 1) % (m + 1)] + 1;
  }
  xi_index_ = col;
  for (int j = 0; j < k_; ++j) names_.push_back(k_ == 1 ? "xi" : "xi" + std::to_string(j + 1));
  names_.push_back("H");
  num_unknowns_ = col + k_ + 1;
}

double ShootingLayout::Period(const Vector& u) const {
  double T = 0.0;
  for (int i = 0; i < num_segments(); ++i) T += u(time_index_[i]);
  return T;
}

}  // namespace hybridcont
