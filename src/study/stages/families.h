// The families of a study, decided in one place. Every branch the study traces — from the model's start, a
// branch switch, a restart, a period doubling, another word of an automaton — gets its family name and the
// ranges where its orbits are physical and stable here, from the typed analysis of its points
// (orbit_analysis.h): physical is the classification's verdict, stable the Floquet class of a physical orbit,
// and a point that is not physical only because it lies on the boundary (a zero duration, a grazing event)
// ends a stretch exactly there (family_ranges.h). The one-screen answer, the report, the results folder,
// Python's tables and a sweep's table all read what is decided here (StudyBranch::family, ranges;
// StudyResult::families).
//
//   const std::string lines = AssignBranchFamily(branch, layout, scenario.describe, writer);  // "" without physical orbits
//   result.families = FoldFamilies(result);   // per family: its branches, the union of their ranges
#ifndef HYBRIDCONT_STUDY_FAMILIES_H_
#define HYBRIDCONT_STUDY_FAMILIES_H_

#include <functional>
#include <string>
#include <vector>

#include "hybridcont/continuation.h"
#include "hybridcont/family_ranges.h"
#include "hybridcont/shooting_layout.h"
#include "hybridcont/study.h"

namespace hybridcont::study {

class ResultsWriter;

// The name of the family an orbit u belongs to (the model's family rules, model_setup.h).
using FamilyNamer = std::function<std::string(const Vector& u)>;

// Branch b's family and ranges from its analysed points (points[i] is b.points[i], analysed), in the
// coordinate u(coordinate); each stretch named by `name_of` at its middle point, the branch by its first
// physical stretch. No family (empty name and ranges) where b has no physical orbit or not every point was
// analysed.
struct BranchFamily {
  std::string family;
  BranchRanges ranges;
};
BranchFamily FamilyOfBranch(const Branch& b, const std::vector<StudyPoint>& points, int coordinate,
                            const FamilyNamer& name_of);

// FamilyOfBranch of a branch the writer recorded (its points as analysed there), recorded as the branch's
// family and ranges; returns the report's lines for it ("" without physical orbits).
std::string AssignBranchFamily(const Branch& b, const ShootingLayout& layout, const FamilyNamer& name_of,
                               ResultsWriter& writer);

// Where the linear stability of a branch's physical orbits flips, between points after_point and after_point + 1
// (a period-doubled family's "stability_changes" in summary.json): at the special point located there — the
// end of a stable stretch (family_ranges.h), its value and how it is known — else at the later point's value,
// not located. From the branch's analysed points and stable ranges; empty without them.
struct StabilityChange {
  int after_point = 0;
  double value = 0;      // of the branch's continued coordinate
  bool stable = false;   // after the change
  bool located = false;
  int special_point = -1;
  std::string how;       // the end's text (RangeEnd::how) where it is a special point's
};
std::vector<StabilityChange> StabilityChanges(const StudyBranch& b);

// The family names of a period-doubled family's orbits u_2 = [c_1 | c_2 | ξ | H̄ ...] (period_doubling.h), from
// the parent model's rules (`parent_name_of`, on parent orbits of `parent`'s layout) applied to each cycle
// [c_j | ξ | H̄ ...]: "period-doubled " and the cycles' names, distinct and in alphabetical order, joined by
// " / " — "period-doubled forward hopping", "period-doubled backward hopping / forward hopping" (hopping
// forward and back in turn; both halves of the family get the one name). Never the parent's own name.
FamilyNamer PeriodDoubledNamer(FamilyNamer parent_name_of, const ShootingLayout& parent, const ShootingLayout& doubled);

}  // namespace hybridcont::study

#endif  // HYBRIDCONT_STUDY_FAMILIES_H_
