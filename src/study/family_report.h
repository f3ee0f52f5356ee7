// The answer per family, in words and in summary.json: where a branch's orbits are physical and where stable,
// in the continued coordinate, each end the special point located there (family_ranges.h), from the points the
// results writer classified.
//
//   report += BranchRangesReport(branch, layout, describe, writer);   // "" for a branch without physical orbits
#ifndef HYBRIDCONT_STUDY_FAMILY_REPORT_H_
#define HYBRIDCONT_STUDY_FAMILY_REPORT_H_

#include <functional>
#include <string>

#include "hybridcont/continuation.h"
#include "hybridcont/shooting_layout.h"
#include "results_writer.h"

namespace hybridcont::study {

// Branch b's stretches (its points as the writer classified them; b's special points) in the coordinate
// layout.continued_index(), each stretch named by `describe` at its middle point: annotated into b's
// summary.json entry (`family`, `physical_ranges`, `stable_ranges`) and returned as report lines. "" where
// b has no physical orbit or not every point was classified.
std::string BranchRangesReport(const Branch& b, const ShootingLayout& layout,
                               const std::function<std::string(const Vector& u)>& describe, ResultsWriter& writer);

}  // namespace hybridcont::study

#endif  // HYBRIDCONT_STUDY_FAMILY_REPORT_H_
