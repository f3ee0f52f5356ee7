// The answer of a run on one screen: what a researcher asks first of a diagram. Per physical family (named as
// the model names it, its mirror images folded into it): where its orbits are physical and where stable in
// the continued coordinate, with how each range ends; its located special points (type, coordinate, period,
// precision) with their restart labels; and the families it connects to. The rest of the diagram (branches
// without a physical orbit, every special point, the branch switches, the work) is counted in one line and
// kept in the full report (`--verbose`, summary.json's "report"). The command line ends a run with it; the
// Python package's Study prints it.
//
//   std::cout << OneScreenAnswer(study, seconds);
#ifndef HYBRIDCONT_STUDY_ANSWER_H_
#define HYBRIDCONT_STUDY_ANSWER_H_

#include <string>

#include "hybridcont/study.h"

namespace hybridcont {

// `seconds`: the wall time of the computation, its last line.
std::string OneScreenAnswer(const StudyResult& study, double seconds);

// How a range's end is known, as the answer and the report say it: a special point's label ("PD4", with ", not
// located" where it was only bracketed), else the end's own words ("end of the branch, bound-reached").
std::string RangeEndText(const RangeEnd& end, const std::vector<StudySpecialPoint>& special_points);

}  // namespace hybridcont

#endif  // HYBRIDCONT_STUDY_ANSWER_H_
