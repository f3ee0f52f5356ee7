// Changes of the phase sequence: where a family of one word of a hybrid automaton (hybrid_automaton.h)
// continues as a family of a neighbouring word.
//
// The map r of a word encodes one cyclic phase sequence, so a physical family ends where the sequence
// degenerates, although the orbit goes on as an orbit of another word (the paper's concluding remark):
//
//   a phase's duration passes through 0   phase j (1 <= j < m) has zero duration: the orbit enters mode
//                                         M_j by word[j−1] and leaves it at once by word[j]. In the word
//                                         without phase j, a transition τ from M_{j−1} to M_{j+1} takes
//                                         their place; the orbit is one of that word when τ's guard is 0
//                                         where word[j−1]'s is (the same instant), τ's reset is the
//                                         composition Δ_j ∘ Δ_{j−1} there, and the first integrals agree
//                                         (they do: both words keep them).
//   a competing guard is touched          the guard of a transition τ out of M_s that the word does not
//                                         take there reaches 0 during segment s at t* (tangentially, its
//                                         interior minimum; or at the segment's end, with the phase's own
//                                         guard). Inserting τ at t* (and, when τ leads into another mode J,
//                                         a phase of zero duration in J and a transition σ back) gives a
//                                         word whose orbit is the same; at the end of the segment τ
//                                         (with σ) replaces the phase's own transition.
//
// Each candidate is built as the new word's time-based unknowns from the orbit's (durations split or
// dropped, the states after inserted transitions from the flow and the resets) and checked by the new map
// itself: its residual there is what the conditions above say, blockwise — the guard rows of the replaced
// transitions, their reset rows, the first integrals — so a refused change names the one that fails
// (`reason`). An accepted one is then corrected in the new word (Moore–Penrose: a point where the new
// family turns in H̄, as at a grazing, is regular too), and the orbit compared: state at the section and
// period, which agree to the correction's accuracy when the two words describe the same motion.
//
//   std::vector<WordChange> c = WordsWithoutPhase(model, u, /*segment=*/1, integrator);
//   if (c[0].accepted) explore model.automaton()->ModelForWord(c[0].word) from c[0].u
#ifndef HYBRIDCONT_WORD_CHANGE_H_
#define HYBRIDCONT_WORD_CHANGE_H_

#include <string>
#include <vector>

#include "hybridcont/flow.h"
#include "hybridcont/model.h"

namespace hybridcont {

struct WordChange {
  Word word;            // the neighbouring word
  std::string rule;     // "phase 2 (flight) removed: liftoff > landing replaced by apex"
  bool accepted = false;
  // The orbit is a singular point of the new word's map (a branch point, where its families cross): u is the
  // mapped orbit, not corrected; a family of the new word is then not started from it.
  bool singular = false;
  std::string reason;   // why it was refused
  Vector u_mapped;      // the orbit in the new word's time-based layout, as mapped
  Vector u;             // the same, corrected by the new word's map (accepted only)
  double residual = 0;  // |r_new(u_mapped)|
  // After the correction: |x̄_1 (new) − x̄_1 (old)| at the section, and the periods' difference.
  double state_difference = 0;
  double period_difference = 0;
};

// Residual below which a mapped orbit is one of the new word: the orbit is a located point (precision
// ~1e-10 relative) and the map integrates to 1e-12; a mismatch of a guard or a reset is O(1) unless the
// words really meet.
inline constexpr double kWordChangeResidual = 1e-7;

// The words without phase `segment` (1 <= segment < m) of model's word, at an orbit u (time-based layout
// of `model`, no free parameters) whose duration t_segment is 0: one candidate per transition that could
// take the removed phase's place; empty when there is none (then `why` says so).
std::vector<WordChange> WordsWithoutPhase(const HybridModel& model, const Vector& u, int segment,
                                          const IntegratorOptions& integrator, std::string* why);

// The words with transition `transition` inserted at time t (0 < |t| <= |t_s|) of segment `segment` of
// model's word, at an orbit u where that transition's guard is 0 there.
std::vector<WordChange> WordsWithTransition(const HybridModel& model, const Vector& u, int transition, int segment,
                                            double t, const IntegratorOptions& integrator, std::string* why);

}  // namespace hybridcont

#endif  // HYBRIDCONT_WORD_CHANGE_H_
