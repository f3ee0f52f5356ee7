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
// Free parameters. Continuation in model parameters p_1..p_q (e.g. the SLIP's leg stiffness k) appends them
// to u, and as many fixing rows u_j − c_j (e.g. H̄ held at 1.5) to r, so that the zero set is again a curve:
//
//   u = [ ... | xi_1..xi_k | H̄ | p_1..p_q ]      r = [ ... | first integrals | u_{j_1} − c_1 .. u_{j_q} − c_q ]
//
// The Jacobian columns of p come from the flows' parameter sensitivities (flow.h) and the parameter
// derivatives of resets, events, anchor and first integrals (Phase::ParameterDerivatives): exact, like the
// others. A parameter is named as in the model ("k"); any unknown may be fixed ("H", "t2", "x1_l", "xi").
// Without free parameters the layout is the paper's.
//
// Observables (observable.h). A model's observables named in FreeParameters::observables join the problem as
// COCO joins monitor functions: each adds an unknown o_j, after the free parameters, and an equation
// o_j − g_j(v, p) = 0, after the fixing rows, so that it can be held fixed (a fixing row on o_j: `--fix
// speed=1 --free k`), bounded or reached like any unknown; its Jacobian row is g_j's exact gradient
// (orbit_observables.h). Unnamed observables cost nothing; they are evaluated at branch points for outputs.
//
//   u = [ ... | p_1..p_q | o_1..o_s ]      r = [ ... | fixing rows | o_1 − g_1 .. o_s − g_s ]
//
// Models without a first integral (k = 0: dissipative or forced systems, a passive walker) have no
// unfolding and no level: u = [ segments | p_1..p_q ], r = [ blocks | fixing rows ], and the first free
// parameter carries the family (q = number of fixed unknowns + 1). H_index() is then -1; level_index() is
// the coordinate a family is followed in, H̄ or that parameter. With no parameter free, such a layout is
// square (an isolated orbit at fixed parameters) and has no level_index().
//
// Names (used as CSV column headers and to address components): "t1".."t<m+1>", "x<i>_<state>" (e.g.
// "x2_dx"), "xi" (or "xi1".."xik"), "H", then the free parameters' and the observables' names.
//
//   ShootingLayout layout(model);
//   double H = u(layout.H_index());
//   auto x2 = u.segment(layout.state_offset(1), layout.dim(1));   // 0-based: phase 2
#ifndef HYBRIDCONT_SHOOTING_LAYOUT_H_
#define HYBRIDCONT_SHOOTING_LAYOUT_H_

#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "hybridcont/invariant.h"
#include "hybridcont/model.h"

namespace hybridcont {

// Which model parameters are free unknowns and which unknowns are held fixed (equally many).
struct FreeParameters {
  std::vector<std::string> parameters;                  // model parameter names, appended to u in order
  std::vector<std::pair<std::string, double>> fixed;    // unknown name and the value it is held at
  std::vector<std::string> observables;                 // model observables joining the unknowns, in order
  // No parameter free and nothing fixed (observables may still join).
  bool empty() const { return parameters.empty() && fixed.empty(); }
};

class ShootingLayout {
 public:
  // Throws std::invalid_argument naming the offending entry when a parameter is unknown to the model,
  // named twice or named like another unknown, a fixed name is no unknown, or the counts differ.
  explicit ShootingLayout(const HybridModel& model, const FreeParameters& free = {});

  // Number of shooting segments, m + 1.
  int num_segments() const { return static_cast<int>(dims_.size()); }
  // State dimension of segment i (0-based; segment m is phase 1 again).
  int dim(int i) const { return dims_[CheckedSegment(i)]; }
  int num_first_integrals() const { return k_; }
  int num_unknowns() const { return num_unknowns_; }
  // num_unknowns() − 1, except for the base layout of a model without first integral (no free parameter):
  // num_unknowns(), the square system of an orbit at fixed parameters.
  int num_equations() const;

  // Index of t_{i+1} in u (0-based segment i).
  int time_index(int i) const { return time_index_[CheckedSegment(i)]; }
  // Index of the first entry of x̄_{i+1} in u.
  int state_offset(int i) const { return time_index(i) + 1; }
  int xi_index(int j = 0) const { return xi_index_ + j; }
  // Index of H̄ in u; -1 for a model without first integral.
  int H_index() const { return H_index_; }
  bool has_level() const { return H_index_ >= 0; }
  // The coordinate a family is followed in: H̄, or (no first integral) the first free parameter.
  int level_index() const { return H_index_ >= 0 ? H_index_ : parameter_index(0); }
  const std::string& level_name() const { return names_[level_index()]; }
  // The coordinate the continuation follows the family in: the first free parameter when there is one (`--free
  // k --fix H=1.5` follows k at fixed H̄), else level_index(). Reports name a point by it.
  int continued_index() const { return num_free_parameters() > 0 ? parameter_index(0) : level_index(); }
  const std::string& continued_name() const { return names_[continued_index()]; }

  // Free parameters: their number q, the index in u of the i-th and its index among the model's parameters.
  int num_free_parameters() const { return static_cast<int>(parameter_model_index_.size()); }
  int parameter_index(int i = 0) const { return parameter_start_ + i; }
  int parameter_model_index(int i) const { return parameter_model_index_.at(i); }
  // Observables joining the unknowns: their number s, the index in u of the j-th, its index among the model's
  // observables and its equation's row.
  int num_observables() const { return static_cast<int>(observable_model_index_.size()); }
  int observable_index(int j) const { return observable_start_ + j; }
  int observable_model_index(int j) const { return observable_model_index_.at(j); }
  int observable_row(int j) const { return fixed_row(0) + num_fixed() + j; }
  // Unknowns of the orbit without free parameters and observables: v of observable.h.
  int num_orbit_unknowns() const { return parameter_start_; }
  // Fixing rows: the i-th holds unknown fixed_index(i) at fixed_value(i), in row fixed_row(i).
  int num_fixed() const { return static_cast<int>(fixed_index_.size()); }
  int fixed_index(int i) const { return fixed_index_.at(i); }
  double fixed_value(int i) const { return fixed_value_.at(i); }
  void set_fixed_value(int i, double value) { fixed_value_.at(i) = value; }
  int fixed_row(int i) const { return first_integral_row() + k_ + i; }

  // First row of block i of r (segment i's shooting/periodicity rows followed by its event/anchor row).
  int block_row(int i) const { return block_row_[CheckedSegment(i)]; }
  int first_integral_row() const { return num_equations() - k_ - num_fixed() - num_observables(); }

  const std::vector<std::string>& unknown_names() const { return names_; }
  // Index of the named unknown, or -1.
  int UnknownIndex(const std::string& name) const;

  // Total period T = sum of the m+1 durations.
  double Period(const Vector& u) const;

 private:
  // A segment index the caller gave: out of range is the caller's error, an exception (never an abort).
  int CheckedSegment(int i) const {
    if (i < 0 || i >= num_segments()) {
      throw std::out_of_range("ShootingLayout: segment " + std::to_string(i) + " outside [0, " +
                              std::to_string(num_segments()) + ")");
    }
    return i;
  }

  std::vector<int> dims_;
  int k_;
  std::vector<int> time_index_;
  std::vector<int> block_row_;
  int segment_rows_;
  int xi_index_;
  int H_index_;
  int parameter_start_;
  int num_unknowns_;
  std::vector<int> parameter_model_index_;
  int observable_start_;
  std::vector<int> observable_model_index_;
  std::vector<int> fixed_index_;
  std::vector<double> fixed_value_;
  std::vector<std::string> names_;
};

}  // namespace hybridcont

#endif  // HYBRIDCONT_SHOOTING_LAYOUT_H_
