// Words of a hybrid automaton chosen for the transitions they take, and the cyclic model of a word at a
// model's parameter values (hybrid_automaton.h).
//
// A run starts on the file's word (and the words of its other starts) and reaches further words only through
// changes of the phase sequence (word_change.h): the modes and transitions of those words must be checked
// before anything runs (conservation of the first integrals, derivatives), not when a hand-over first takes
// them. WordsThroughEveryTransition gives words that together take every transition.
#ifndef HYBRIDCONT_AUTOMATON_WORDS_H_
#define HYBRIDCONT_AUTOMATON_WORDS_H_

#include <vector>

#include "hybridcont/hybrid_automaton.h"
#include "hybridcont/model.h"

namespace hybridcont {

// The cyclic model of `word` (HybridAutomaton::ModelForWord of model.automaton(), which must be set) with
// model's current parameter values.
HybridModel WordModelAt(const HybridModel& model, const Word& word);

// The transitions that `word` takes, in its order, each once.
std::vector<int> TransitionsOf(const Word& word);

// Words that, with `given`, take every transition of `automaton`: for each transition that no word so far
// takes, in declaration order, the shortest cycle through it from the anchor mode (a shortest path of
// transitions from the anchor mode to its source, the transition, a shortest path from its target back; cuts
// are never used on the paths). The given words are not repeated. A transition on no cycle through the
// anchor mode (no periodic orbit can take it) goes to *untaken when untaken is not null.
std::vector<Word> WordsThroughEveryTransition(const HybridAutomaton& automaton, const std::vector<Word>& given,
                                              std::vector<int>* untaken = nullptr);

}  // namespace hybridcont

#endif  // HYBRIDCONT_AUTOMATON_WORDS_H_
