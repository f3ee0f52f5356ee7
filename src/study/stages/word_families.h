// `hybridcont run` on a hybrid automaton (hybrid_automaton.h): after the run's own word, the families of the
// neighbouring words its physical families lead into (word_change.h), followed like the run's own.
//
// Where a physical family of a word has a phase duration through 0 (between two accepted points, located by
// the corrector with that duration held at 0) or a located CB point of a competing transition's guard, the
// neighbouring words are built and checked; an accepted change is explored in its word from the orbit (both
// directions: RunFromStarts), unless the orbit lies on a branch already traced in that word, which is then
// recorded as the connection and not traced again. The new word's families are scanned in turn, up to
// kMaxWords words. Branch and special-point ids continue the run's; each branch's summary entry says its
// "word" (ResultsWriter), each explored family "handed_over_from" (the change's index), and the record
// (StudyResult::word_changes, summary.json's "word_changes") lists every change considered: where, the rule, accepted or refused with the reason, the
// new word's orbit compared with the old (state at the section and period), and the branches it leads to.
//   std::string report = ExploreWordChanges(model, setup, diagram, &special_points, &record, writer, hooks);
#ifndef HYBRIDCONT_STUDY_WORD_FAMILIES_H_
#define HYBRIDCONT_STUDY_WORD_FAMILIES_H_

#include <ostream>
#include <string>
#include <vector>

#include "hybridcont/exploration.h"
#include "hybridcont/model.h"
#include "study/io/results_writer.h"
#include "study/engine/run_setup.h"

namespace hybridcont::study {

// Most words one run explores (the run's own included): an automaton's words are unbounded in number, a
// diagram's hand-overs are few.
inline constexpr int kMaxWords = 8;

// What the stage records of the words (study.h): the words explored and every change of word considered.
struct WordRecord {
  std::vector<StudyWord> words;
  std::vector<StudyWordChange> changes;
};

// Why a study of `model` with `setup` cannot follow its automaton's other words ("" where it can, or where the
// model has no automaton): a family in a free parameter, or an observable that bounds or ends the run.
std::string WordsNotFollowed(const HybridModel& model, const RunSetup& setup);

// `diagram` and `special_points` are the run's (time-based layout of `model`, a word of an automaton).
// Appends the new families' special points to special_points, the words and changes to `record`, writes their
// branches through `writer` and annotates summary.json; returns the report section ("" for a model without an
// automaton).
std::string ExploreWordChanges(const HybridModel& model, const RunSetup& setup, const BifurcationDiagram& diagram,
                               std::vector<StudySpecialPoint>* special_points, WordRecord* record,
                               ResultsWriter& writer, const StudyHooks& hooks);

}  // namespace hybridcont::study

#endif  // HYBRIDCONT_STUDY_WORD_FAMILIES_H_
