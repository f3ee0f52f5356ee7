// A study's analysed points as one table, column by column: what a branch file holds (docs/results-format.md),
// over every branch, built from the typed study (study.h) — the study in memory or read back by LoadStudy —
// so that a table a front end shows (Python's Study.points) says what the record says.
//
//   for (const StudyColumn& c : StudyPointColumns(study)) ... c.name, c.text ? c.texts : c.numbers
//
// Columns, in order: branch, family (its branch's), index, H, T, every unknown but H by name (the branches'
// layouts, in the order first met; NaN where a branch has no such unknown), physical (1 or 0), classification,
// stability, residual, newton_iterations, step, dT_d<c> (the period's slope in each continued coordinate c),
// replay_error, stable, normal, num_unit (NaN without multipliers), max_multiplier, bp_test, pd_test,
// mu<j>_re and mu<j>_im (the nontrivial multipliers, as many as the most any point has), automaton_replay_error
// (an automaton's), the model's quantities and its observables. One row per point, branches in id order.
#ifndef HYBRIDCONT_STUDY_TABLE_H_
#define HYBRIDCONT_STUDY_TABLE_H_

#include <string>
#include <vector>

#include "hybridcont/study.h"

namespace hybridcont {

struct StudyColumn {
  std::string name;
  bool text = false;               // texts, else numbers (NaN where a row has no value)
  std::vector<double> numbers;
  std::vector<std::string> texts;
};

std::vector<StudyColumn> StudyPointColumns(const StudyResult& study);

}  // namespace hybridcont

#endif  // HYBRIDCONT_STUDY_TABLE_H_
