// Event-driven simulation of a hybrid automaton (hybrid_automaton.h) from an orbit's section state: in
// each mode the flow runs until the *first* guard of any transition out of the mode crosses zero downwards,
// that transition is taken (its reset applied), and so on until the orbit is back at the section after as
// many transitions as its word has. It checks what a word's map assumes: that the automaton itself, choosing
// transitions by the first guard crossed, takes the word's transitions and returns to the orbit.
//
//   AutomatonReplayResult r = ReplayAutomaton(word_model, u, integrator);   // u: time-based layout
//   r.same_word, r.return_error, r.taken
#ifndef HYBRIDCONT_AUTOMATON_REPLAY_H_
#define HYBRIDCONT_AUTOMATON_REPLAY_H_

#include <string>

#include "hybridcont/flow.h"
#include "hybridcont/model.h"

namespace hybridcont {

struct AutomatonReplayResult {
  bool ok = false;          // the simulation ran to the section (else message says where it stopped)
  std::string message;
  Word taken;               // the transitions taken, in order
  bool same_word = false;   // taken == the model's word
  double return_error = 0;  // |x − x̄_1| at the section after the last transition (ok and same_word)
};

// `model` is a word of an automaton (model.automaton() set); u an orbit of it (time-based layout, no free
// parameters). A transition the word does not contain ends the simulation there (taken names it).
AutomatonReplayResult ReplayAutomaton(const HybridModel& model, const Vector& u, const IntegratorOptions& integrator);

}  // namespace hybridcont

#endif  // HYBRIDCONT_AUTOMATON_REPLAY_H_
