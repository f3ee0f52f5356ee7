// The state-based zero problem of paper eq. `statebased`: single shooting through the Poincaré map.
//
//     u = [ x0 (n1) | xi_1..xi_k | H̄ ]                                   (N + 1 = n1 + k + 1 unknowns)
//     r = [ P~(x0, xi) - x0 (n1) | H_1(x0) - H̄ | H_j(x0) - H̄_j, j = 2..k ]   (N = n1 + k equations)
//
//          x0              xi           H̄
//   dr = [ dP~/dx0 - I     dP~/dxi      0 ]      (Jacobian of eq. `druAppendix`; dP~ from
//        [ dH(x0)          0           -e1]       poincare_map.h, with its saltation chain)
//
// For k = 1 this is the paper's N = n1 + 1. For k > 1 the convention is the time-based one
// (shooting_layout.h): all xi_j are unknowns, the levels H̄_j, j >= 2, are fixed values. Unknown names are
// those of the time-based layout for the same quantities ("x1_<state>", "xi" or "xi1".., "H"), so branch
// outputs of the two formulations can be compared column by column.
//
// Where the state-based map does not exist it says so (paper §3.4, Table `stateVStime`): a grazing
// crossing, a phase of zero duration, a guard that is never reached all make Evaluate return
// EvaluationStatus::Failure with the phase, the guard, the time and the reason. The SLIP start point
// (zero flight time, lift-off exactly tangent) is such a point; the time-based map evaluates there.
//
// A state-based run can start from a point of a time-based branch (FromTimeBased: take x̄_1, xi, H̄),
// and a state-based point can be expanded into the time-based layout (ToTimeBased: one event-driven pass
// fills the durations t_i and the phase starts x̄_i).
//
//   StateBasedShooting sb(model, PoincareOptions{});
//   Vector u = sb.FromTimeBased(u_timebased);
//   Vector r; Matrix dr;
//   EvaluationStatus s = sb.Evaluate(u, &r, &dr);
#ifndef HYBRIDCONT_STATEBASED_SHOOTING_H_
#define HYBRIDCONT_STATEBASED_SHOOTING_H_

#include <memory>
#include <string>
#include <vector>

#include "hybridcont/poincare_map.h"
#include "hybridcont/shooting_layout.h"
#include "hybridcont/shooting_problem.h"

namespace hybridcont {

class StateBasedShooting : public ShootingProblem {
 public:
  // Keeps a reference to model (it must outlive this object). Throws std::invalid_argument if the
  // options are invalid.
  StateBasedShooting(const HybridModel& model, PoincareOptions options);

  int num_equations() const override { return n1_ + k_; }
  std::vector<std::string> unknown_names() const override { return names_; }
  // The model's symmetries without time reversal (and their products): phase 1's signs on x0. A time
  // reversal runs the phases backwards, which the event-driven map, integrating forward through downward
  // crossings, does not.
  std::vector<Symmetry> symmetries() const override;
  EvaluationStatus Evaluate(const Vector& u, Vector* r, Matrix* dr) override;

  // Layout of u.
  int x0_offset() const { return 0; }
  int xi_index(int j = 0) const { return n1_ + j; }
  int H_index() const { return n1_ + k_; }

  // Fixed levels H̄_j of first integrals j = 2..k (size k-1); zero by default.
  void SetFixedLevels(const Vector& levels);

  // u_state = [x̄_1; xi; H̄] from a time-based u (shooting_layout.h). Throws std::invalid_argument on a
  // size mismatch.
  Vector FromTimeBased(const Vector& u_time) const;
  // A time-based u from a state-based one: one event-driven pass (no Jacobian) gives t_1..t_{m+1} and
  // x̄_2..x̄_{m+1}; x̄_1 = x0, xi and H̄ are copied. Fails (status, no exception) where P~ does.
  EvaluationStatus ToTimeBased(const Vector& u_state, Vector* u_time);

  // The Poincaré map evaluation at the last evaluated u (durations, saltations, Phi(t^A, x0): at a
  // fixed point with xi = 0 this is the monodromy matrix).
  const PoincareResult& last_map() const { return map_result_; }
  const PoincareMap& map() const { return map_; }
  const HybridModel& model() const { return *model_; }

  // Clone, Refined, AddWorkOf, counters(): shooting_problem.h.

 protected:
  std::unique_ptr<ShootingProblem> CopyWithTolerances(double tolerance_factor) const override;

 private:
  const HybridModel* model_;
  PoincareMap map_;
  ShootingLayout layout_;
  int n1_;
  int k_;
  std::vector<std::string> names_;
  Vector fixed_levels_;
  PoincareResult map_result_;
  // cache of the last evaluated point (one integration per point, conventions §8)
  Vector cached_u_;
  bool cached_jacobian_ = false;
  bool cache_valid_ = false;
  Vector H_;
  Matrix dH_;
};

}  // namespace hybridcont

#endif  // HYBRIDCONT_STATEBASED_SHOOTING_H_
