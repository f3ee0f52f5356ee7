// Where a branch's orbits are physical and where they are stable, in the coordinate the family is followed in,
// each end taken from the special point located there.
//
// A run classifies every accepted point (classification.h) and the Floquet multipliers of the physical ones
// (floquet.h). A class changes between two points; what a person needs is where, to the precision the tool
// can give: the special point the exploration located between those two points that explains the change —
// a grazing point (GR), a constraint boundary (CB) or a turning point (TP) for an end of the physical
// stretch, a multiplier crossing (BP, PD, NS, KC) or a turning point or SB point for a change of stability.
// Without such a point the end is said to lie between the two points, not located.
//
//   std::vector<bool> physical = ..., stable = ...;   // per point of branch b
//   BranchRanges r = RangesOnBranch(b, physical, stable, layout.continued_index());
//   for (const Range& p : r.physical) p.from.value, p.from.how ("GR #3, located to 1.8e-10"), p.to ...
#ifndef HYBRIDCONT_FAMILY_RANGES_H_
#define HYBRIDCONT_FAMILY_RANGES_H_

#include <string>
#include <vector>

#include "hybridcont/continuation.h"

namespace hybridcont {

struct RangeEnd {
  double value = 0;        // the coordinate at the end
  bool located = false;    // a located special point, or a point of the branch (its first or last)
  double precision = 0;    // of the special point in the coordinate (0 at a branch point); NaN unknown
  int special_point = -1;  // its id, −1 for none
  // "GR #3, located to 1.8e-10", "start of the branch", "end of the branch, bound-reached", "point 0,
  // zero duration", "between points 4 and 5, not located".
  std::string how;
};

struct Range {
  RangeEnd from, to;       // in the order of the branch's points
  int first_point = 0, last_point = 0;
  // The family the stretch belongs to, named by the model's family rules at its middle point (a stretch's ends
  // may be shared with another family's). Set by a study; empty from RangesOnBranch.
  std::string family;
};

struct BranchRanges {
  int branch = -1;
  // Maximal runs of physical points, split at the turning points of the coordinate (folds) inside them:
  // each runs one way in the coordinate, from its `from` to its `to`.
  std::vector<Range> physical;
  std::vector<Range> stable;    // the same of the stable physical points
};

// The ranges of branch b (special points from b.special_points). physical[i] and stable[i] are the classes
// of b.points[i] (stable only counts where physical); boundary[i] marks a point that is not physical only
// because it lies on the boundary of the physical orbits (a phase of zero duration, a tangential event): a
// physical or stable stretch next to it ends at it, exactly. `coordinate` indexes u. A stable stretch of the
// branch's start point alone, where the branch leaves a special point (the bifurcation itself, neutral
// there), is no stretch and is left out; a physical one, with no special point before the next point, is the
// family's only physical orbit and ends where it starts. unresolved[i] (empty: none) marks a point the
// integration does not resolve (OrbitAnalysis::resolved: its multipliers and class are not to be trusted,
// e.g. orbits passing ever nearer an equilibrium as the period grows without bound): it belongs to no
// stretch, and a stretch next to it ends at its own last point ("point 185, the last orbit the integration
// resolves"). undetermined[i] (empty: none) marks a physical point whose multipliers cannot tell its
// stability (StabilityClass::undetermined): it belongs to no stable stretch, and one next to it ends at its own
// point ("point 40, the last orbit whose multipliers tell its stability"), not between the two.
BranchRanges RangesOnBranch(const Branch& b, const std::vector<bool>& physical, const std::vector<bool>& stable,
                            const std::vector<bool>& boundary, int coordinate,
                            const std::vector<bool>& unresolved = {}, const std::vector<bool>& undetermined = {});

// "1.2467401100 (BP #1, located, precision 1.8e-10)" for a report line.
std::string ToString(const RangeEnd& end);

}  // namespace hybridcont

#endif  // HYBRIDCONT_FAMILY_RANGES_H_
