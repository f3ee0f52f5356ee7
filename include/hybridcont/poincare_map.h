// The Poincaré map P~(x0, xi) of the unfolded hybrid system and its exact Jacobian (paper §2.4, §3.2).
//
// From x0 in phase 1, every phase i = 1..m is integrated event-driven (event_flow.h) until its event e_i
// crosses zero downward; the reset Delta_i carries the state on; back in phase 1 the flow runs until the
// anchor a crosses zero downward:
//
//     x̄_1 = x0,   x̄_{i+1} = Delta_i(phi_i(t_i^E(x̄_i), x̄_i; xi)),   P~(x0, xi) = phi_1(t^A_{m+1}, x̄_{m+1}; xi).
//
// Jacobian (eqs. `fundamentalMatrixHybrid`, `PoincareJacobian`). With Phi_i, Psi_i the phase
// sensitivities at the event, S_i the saltation matrices (saltation.h), Pi = I - f da / (da f) the
// section projection at the return:
//
//     Phi̅_1 = I,   Phi̅_{i+1} = S_i Phi_i Phi̅_i                      (eq. `recursionPhi`)
//     Psi̅_1 = 0,   Psi̅_{i+1} = S_i (Phi_i Psi̅_i + Psi_i)
//     dP~/dx0 = Pi Phi(t^A, x0),     Phi(t^A, x0) = Phi_{m+1} Phi̅_{m+1}
//     dP~/dxi = Pi (Phi_{m+1} Psi̅_{m+1} + Psi_{m+1})
//
// Why the xi-chain has this form: Phi̅_i and Psi̅_i are the derivatives of the state at a *fixed global
// time* during phase i. A variation dxi moves the state at the event by v = Phi_i Phi̅_i dx0 + (Phi_i
// Psi̅_i + Psi_i) dxi and the event time by dt = -de v / (de f^-) (implicit function theorem on
// e_i = 0, eq. `nablaT`); after the reset, the fixed-time variation is D (f^- dt + v) - f^+ dt = S_i v.
// The xi-sensitivity of the event times thus enters exactly like the x0-sensitivity. At the return,
// Pi removes the anchor-time shift the same way.
//
// Appendix B: with PoincareSection::kLastEvent the section is the last event itself (a := e_m); the map
// stops right after Delta_m, P~ = x̄_{m+1}, and the last saltation is S~_m = D_m (I - f^- de / (de f^-))
// (eq. `LastSaltation`) with no projection. x0 then lies on Delta_m(E_m) (e.g. the ball just after
// impact); the model's anchor is not used.
//
// At a fixed point (xi = 0), Phi(t^A, x0) is the monodromy matrix Phi_T, and dH_1(x0) is a left
// eigenvector of dP~/dx0 with eigenvalue 1 (Thm 2.1, eq. `leftEigen`).
//
//   PoincareMap map(model, PoincareOptions{});
//   PoincareResult res;
//   if (map.Evaluate(x0, xi, /*with_jacobian=*/true, &res) == PoincareStatus::kSuccess) res.x, res.dP_dx0 ...
#ifndef HYBRIDCONT_POINCARE_MAP_H_
#define HYBRIDCONT_POINCARE_MAP_H_

#include <string>
#include <vector>

#include "hybridcont/event_flow.h"
#include "hybridcont/model.h"
#include "hybridcont/saltation.h"

namespace hybridcont {

enum class PoincareSection {
  kAnchor,     // the model's anchor a in phase 1 (paper §2.4; Remark `eventanchor`)
  kLastEvent,  // the last event e_m (Appendix B; the anchor of Grizzle/Westervelt)
};
std::string ToString(PoincareSection section);
bool FromString(const std::string& name, PoincareSection* section);  // "anchor" / "last-event"

struct PoincareOptions {
  // Integration, event location and grazing tolerances of every phase (event_flow.h).
  EventFlowOptions event;
  PoincareSection section = PoincareSection::kAnchor;

  std::string Validate() const { return event.Validate(); }
};

enum class PoincareStatus {
  kSuccess,
  kEventFailed,  // a phase did not end in a transversal event: see event_status, failed_phase, message
  kNonFinite,    // a reset map, event or anchor returned NaN/Inf
};
std::string ToString(PoincareStatus status);

struct PoincareResult {
  PoincareStatus status = PoincareStatus::kSuccess;
  std::string message;  // empty on success; otherwise names the phase, the guard, the time and the reason
  // On kEventFailed: what the event-driven flow of the failed phase reported, and that phase's index
  // (0-based; m for the return to the anchor).
  EventFlowStatus event_status = EventFlowStatus::kEventReached;
  int failed_phase = -1;

  Vector x;        // P~(x0, xi), in phase 1
  Matrix dP_dx0;   // n1 x n1 (with_jacobian)
  Matrix dP_dxi;   // n1 x k  (with_jacobian)
  Matrix Phi;      // hybrid fundamental matrix Phi(t^A, x0) before the section projection (kAnchor)
  // Per phase i = 0..m-1 (and m: the return to the section, kAnchor only):
  std::vector<double> durations;           // t_i^E, then t^A_{m+1}
  std::vector<Vector> starts;              // x̄_1 = x0, x̄_2, ..., x̄_{m+1}
  std::vector<double> transversalities;    // |de f^-| / (|de||f^-|) of every crossing (anchor last)
  std::vector<Matrix> saltations;          // S_1..S_m (S~_m for kLastEvent) (with_jacobian)
  double period = 0.0;                     // t^A: sum of the durations
  FlowCounters counters;

  bool ok() const { return status == PoincareStatus::kSuccess; }
  std::string BriefReport() const;
};

class PoincareMap {
 public:
  // Keeps a reference to model (it must outlive this object). Throws std::invalid_argument if the
  // options are invalid or kLastEvent is asked of a model whose phase m does not lead into phase 1's
  // dimension (it always does for a cyclic model; checked for clarity).
  PoincareMap(const HybridModel& model, PoincareOptions options);

  // Evaluates P~(x0, xi) and, with with_jacobian, dP~/dx0 and dP~/dxi. Returns result->status; never
  // throws for numerical outcomes.
  PoincareStatus Evaluate(const Eigen::Ref<const Vector>& x0, const Eigen::Ref<const Vector>& xi, bool with_jacobian,
                          PoincareResult* result);

  const HybridModel& model() const { return *model_; }
  const PoincareOptions& options() const { return options_; }

 private:
  const HybridModel* model_;
  PoincareOptions options_;
  std::vector<EventFlow> flows_;  // phases 1..m, then phase 1 again for the return
  EventFlowResult phase_result_;
  Vector x_next_, f_plus_;
  Matrix D_, S_, Pi_;
};

}  // namespace hybridcont

#endif  // HYBRIDCONT_POINCARE_MAP_H_
