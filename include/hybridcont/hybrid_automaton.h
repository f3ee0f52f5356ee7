// A hybrid automaton: modes and the transitions between them; a periodic orbit's cyclic word of transitions.
//
// A cyclic model (model.h) fixes one phase sequence: phase i ends at its event and resets into phase i+1.
// An automaton lets a mode have several outgoing transitions (a flight ends when either leg touches down; a
// ball meets the floor or, above some energy, the ceiling), each with its guard g (the transition fires at
// g's downward zero crossing) and its reset into the target mode. A periodic orbit then carries its *word*:
// the cyclic sequence of transitions it takes. For each word the automaton gives an ordinary cyclic model
// (ModelForWord), whose phase i is the source mode of word[i] with that transition's guard as its event and
// its reset, so that every shooting map, continuation and analysis of a cyclic model applies unchanged.
//
// Words start at the anchor mode: word[0] leaves the one mode that carries the anchor (the Poincaré
// section), so that the time-based layout of every word has the same section.
//
// Competing transitions. An orbit of a word is an orbit of the automaton only if no other transition fires
// first: while phase i runs in mode M towards word[i], the guard of every other transition τ out of M stays
// >= 0. ModelForWord declares that as one admissibility constraint per competing transition (observable.h,
// named "<τ>_guard", a minimum over the phases where τ competes), so the classification names a violated
// guard and a family where τ's guard is touched (tangentially, or at the same time as the phase's own) has a
// located CB point there: where the orbit may continue in a word with τ inserted (word_change.h). A *cut* (a
// transition into its own mode with the identity reset: the apex of a stance, a mark in time) never
// competes: taking it or not is the same motion.
//
//   HybridAutomaton::Create(name, modes, transitions, anchor_mode, factory)   // factory: word -> cyclic model
//   std::shared_ptr<const HybridAutomaton> a = model.automaton();            // a model file's [[modes]]
//   HybridModel stance_only = a->ModelForWord(a->WordOf({"stance"}));
#ifndef HYBRIDCONT_HYBRID_AUTOMATON_H_
#define HYBRIDCONT_HYBRID_AUTOMATON_H_

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "hybridcont/observable.h"

namespace hybridcont {

class HybridModel;

struct AutomatonMode {
  std::string name;
  std::vector<std::string> state_names;
};

struct AutomatonTransition {
  std::string name;  // an identifier: it names the transition's guard constraint "<name>_guard"
  int from = -1;     // source and target modes
  int to = -1;
  // g(x, p) over the source mode's states and the model's parameters.
  std::shared_ptr<const SmoothFunction> guard;
  // Into its own mode with the identity reset: a mark in time that never competes (see above).
  bool cut = false;
};

// The cyclic sequence of transitions an orbit takes; word[0] leaves the anchor mode.
using Word = std::vector<int>;

class HybridAutomaton : public std::enable_shared_from_this<HybridAutomaton> {
 public:
  // The cyclic model of a checked word, phases named after their modes (observables, symmetries and
  // drawings keyed by mode). ModelForWord adds the guard constraints and the automaton itself.
  using WordModelFactory = std::function<HybridModel(const Word& word)>;

  // Throws std::invalid_argument naming the mode or transition when names are empty or repeated, a
  // transition's modes are out of range, a guard is missing, or a mode has no outgoing transition.
  static std::shared_ptr<HybridAutomaton> Create(std::string name, std::vector<AutomatonMode> modes,
                                                 std::vector<AutomatonTransition> transitions, int anchor_mode,
                                                 WordModelFactory factory);
  // The same names and connections without dynamics (guards may be null, no factory): for reading and
  // checking words (WordOf, CheckWord, WordName) before the guards exist; ModelForWord is not available.
  static std::shared_ptr<HybridAutomaton> Graph(std::string name, std::vector<AutomatonMode> modes,
                                                std::vector<AutomatonTransition> transitions, int anchor_mode);

  const std::string& name() const { return name_; }
  const std::vector<AutomatonMode>& modes() const { return modes_; }
  const std::vector<AutomatonTransition>& transitions() const { return transitions_; }
  int anchor_mode() const { return anchor_mode_; }
  // Index of the named transition or mode, or -1.
  int FindTransition(const std::string& name) const;
  int FindMode(const std::string& name) const;
  // Transitions out of `mode`, in declaration order.
  std::vector<int> TransitionsFrom(int mode) const;

  // Throws std::invalid_argument saying why `word` is not a word of this automaton (empty, a transition out
  // of range, consecutive transitions that do not connect, not starting at the anchor mode).
  void CheckWord(const Word& word) const;
  // The word through the given modes (cyclic: the last one leads back to the first), each step taking the
  // one transition between consecutive modes; an entry may name a transition instead (its source mode, left
  // by that transition), where two modes are joined by several. Throws std::invalid_argument when a name is
  // neither, a step has no transition or more than one (naming them), or the word does not start at the
  // anchor mode.
  Word WordOf(const std::vector<std::string>& names) const;
  std::vector<std::string> ModeNames(const Word& word) const;
  // "stance > flight" (modes), with a transition named where two modes are joined by more than one.
  std::string WordName(const Word& word) const;

  // The cyclic model of `word` (checked), with a constraint "<τ>_guard" per competing transition τ and
  // model.automaton(), model.word() set.
  HybridModel ModelForWord(const Word& word) const;
  // The transition whose guard constraint is named `constraint`, or -1.
  int GuardConstraintTransition(const std::string& constraint) const;
  static std::string GuardConstraintName(const AutomatonTransition& t) { return t.name + "_guard"; }

 private:
  HybridAutomaton() = default;

  std::string name_;
  std::vector<AutomatonMode> modes_;
  std::vector<AutomatonTransition> transitions_;
  int anchor_mode_ = 0;
  WordModelFactory factory_;
};

}  // namespace hybridcont

#endif  // HYBRIDCONT_HYBRID_AUTOMATON_H_
