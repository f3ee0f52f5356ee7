#include "hybridcont/shooting_layout.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace hybridcont {

ShootingLayout::ShootingLayout(const HybridModel& model, const FreeParameters& free)
    : k_(model.num_first_integrals()) {
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
  segment_rows_ = row;
  xi_index_ = col;
  if (k_ > 0) {
    for (int j = 0; j < k_; ++j) names_.push_back(k_ == 1 ? "xi" : "xi" + std::to_string(j + 1));
    names_.push_back("H");
    H_index_ = col + k_;
    num_unknowns_ = col + k_ + 1;
  } else {  // no first integral: no unfolding, no level; a free parameter carries the family
    H_index_ = -1;
    num_unknowns_ = col;
  }
  parameter_start_ = num_unknowns_;
  for (const std::string& name : free.parameters) {
    const int index = model.FindParameter(name);
    if (index < 0) {
      std::string known;
      for (const ParameterInfo& p : model.parameters()) known += (known.empty() ? "" : ", ") + p.name;
      throw std::invalid_argument("free parameter '" + name + "': model '" + model.name() +
                                  "' has no such parameter (parameters: " + known + ")");
    }
    if (std::find(names_.begin(), names_.end(), name) != names_.end()) {
      throw std::invalid_argument("free parameter '" + name + "': " +
                                  (std::find(parameter_model_index_.begin(), parameter_model_index_.end(), index) !=
                                           parameter_model_index_.end()
                                       ? std::string("named twice")
                                       : std::string("has the name of another unknown")));
    }
    parameter_model_index_.push_back(index);
    names_.push_back(name);
    ++num_unknowns_;
  }
  observable_start_ = num_unknowns_;
  for (const std::string& name : free.observables) {
    const int index = model.FindObservable(name);
    if (index < 0) {
      std::string known;
      for (const Observable& o : model.observables()) known += (known.empty() ? "" : ", ") + o.name;
      throw std::invalid_argument("observable '" + name + "': model '" + model.name() + "' has no such observable" +
                                  (known.empty() ? std::string(" (it declares none)") : " (observables: " + known + ")"));
    }
    if (std::find(names_.begin(), names_.end(), name) != names_.end()) {
      throw std::invalid_argument("observable '" + name + "': named twice");
    }
    observable_model_index_.push_back(index);
    names_.push_back(name);
    ++num_unknowns_;
  }
  for (const auto& [name, value] : free.fixed) {
    const auto it = std::find(names_.begin(), names_.end(), name);
    if (it == names_.end()) {
      throw std::invalid_argument("fixed unknown '" + name + "' is not an unknown of the problem (unknowns: " +
                                  std::string(k_ > 0 ? "H, xi, " : "") +
                                  "t1..t" + std::to_string(m + 1) + ", x<i>_<state>, the free parameters, the observables)");
    }
    const int index = static_cast<int>(it - names_.begin());
    if (std::find(fixed_index_.begin(), fixed_index_.end(), index) != fixed_index_.end()) {
      throw std::invalid_argument("fixed unknown '" + name + "': fixed twice");
    }
    if (!std::isfinite(value)) throw std::invalid_argument("fixed unknown '" + name + "': value must be finite");
    fixed_index_.push_back(index);
    fixed_value_.push_back(value);
  }
  // Without H̄, one free parameter carries the family; with none free, the layout is the square system of an
  // orbit at fixed parameters (the base layout of such a model: Newton at fixed parameters, replay, files).
  const std::size_t carried = k_ > 0 || parameter_model_index_.empty() ? 0 : 1;
  if (fixed_index_.size() + carried != parameter_model_index_.size()) {
    throw std::invalid_argument(
        std::to_string(parameter_model_index_.size()) + " free parameter(s) and " + std::to_string(fixed_index_.size()) +
        " fixed unknown(s): " +
        (k_ > 0 ? "each free parameter needs one fixed unknown (e.g. --free k --fix H=1.5)"
                : "a model without first integral is continued in one free parameter (e.g. --free gamma), each "
                  "further one needs a fixed unknown") +
        " so that the solutions form a curve");
  }
}

int ShootingLayout::num_equations() const {
  // the blocks, the first integrals, the fixing rows, the observables' equations
  return segment_rows_ + k_ + num_fixed() + num_observables();
}

int ShootingLayout::UnknownIndex(const std::string& name) const {
  const auto it = std::find(names_.begin(), names_.end(), name);
  return it == names_.end() ? -1 : static_cast<int>(it - names_.begin());
}

double ShootingLayout::Period(const Vector& u) const {
  double T = 0.0;
  for (int i = 0; i < num_segments(); ++i) T += u(time_index_[i]);
  return T;
}

}  // namespace hybridcont
