// Conservation checks: the first integrals H_j a model declares are kept by its flows and its resets.
//
// The method rests on it (paper §3: families of periodic orbits exist because H is conserved), so a model
// whose energy is not conserved (a sign error in a force, a reset that forgets an impulse) must be refused
// before anything runs, with the phase or reset that breaks it. Checked at given states of each phase:
//   - along the flow:    ∇H_j(x) · f(x) = 0, measured as |∇H_j · f| / (|∇H_j| |f|) (the cosine of the
//                        angle between them, 0 for a conserved H; exact in the model's arithmetic, so the
//                        tolerance is far below any integration tolerance and far above rounding);
//   - across the reset:  H_j(Δ(x)) = H_j(x) at states x on the guard e(x) = 0 (each given state is moved
//                        there along ∇e by Newton's method; off the guard a reset need not conserve H:
//                        the SLIP's touch-down maps the leg to its natural length only there), measured as
//                        |ΔH_j| / (|H_j(x)| + |∇H_j(x)| |x|).
#ifndef HYBRIDCONT_CONSERVATION_CHECK_H_
#define HYBRIDCONT_CONSERVATION_CHECK_H_

#include <string>
#include <vector>

#include "hybridcont/model.h"

namespace hybridcont {

struct ConservationEntry {
  std::string what;          // "phase 'stance': H kept by the flow", "reset 'stance' -> 'flight': H kept"
  double worst = 0.0;        // worst measure over the states (see the header comment)
  std::string worst_state;   // where: "(alpha = 0.1, l = 0.9, ...)"
  int num_states = 0;        // states the entry was evaluated at
  bool passed(double tolerance) const { return worst <= tolerance; }
};

struct ConservationReport {
  // A violation is a modelling error, not round-off: relative measures of 1e-9 and above never come from
  // rounding of expressions (1e-15) and stay below every physical error (a missing term: O(1)).
  static constexpr double kTolerance = 1e-9;
  std::vector<ConservationEntry> entries;  // per phase: the flow, then the reset into the next phase
  bool passed() const;
  // The first failing entry in words, "" if all pass: "phase 'stance': H is not kept by the flow:
  // |∇H·f| / (|∇H| |f|) = 0.31 at (alpha = 0.1, ...)".
  std::string FirstFailure() const;
};

// states[i]: states of phase i to check at (none: the phase's typical state).
ConservationReport CheckConservation(const HybridModel& model, const std::vector<std::vector<Vector>>& states);

}  // namespace hybridcont

#endif  // HYBRIDCONT_CONSERVATION_CHECK_H_
