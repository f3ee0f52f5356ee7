// Completing a self-symmetric closed loop by reflection (docs/design/exploration.md, "Loops completed by
// reflection").
//
// A half-branch leaving a point p0 with g(p0) = p0 along τ0 with g(τ0) = −τ0 may be a loop that the
// symmetry g maps onto itself with its orientation reversed: its second half is the mirror image of the
// first, traversed backwards. Its midpoint M is g-fixed with g(τ_M) = −τ_M; where M is a located special
// point (there the loop meets the g-fixed family again, at an SB point), the trace stops and the loop is
// completed: after P_0..P_j (M between P_j and P_j+1) come g(P_j), ..., g(P_1) and the start point again,
// with tangents −g(τ), arclength 2 s_M − s, the special points before M mirrored likewise. It ends as the
// trace would: kClosedLoop at its start.
//
//   Reflection reflection;
//   if (FindReflection(problem, stepper.branch(), m, g, options, &reflection)) { /* stop tracing */ }
//   ...
//   CompleteByReflection(reflection, &branch);
#ifndef HYBRIDCONT_BIFURCATION_LOOP_REFLECTION_H_
#define HYBRIDCONT_BIFURCATION_LOOP_REFLECTION_H_

#include <vector>

#include "hybridcont/continuation.h"
#include "hybridcont/exploration.h"
#include "hybridcont/types.h"
#include "hybridcont/zero_problem.h"

namespace hybridcont::internal {

struct Reflection {
  const Symmetry* g = nullptr;  // null: none found
  int midpoint = -1;            // index of the special point M in the traced branch
  double sb_sign = 1;           // sign of the SB test function at g(P) relative to P
};

// g(u) = u and g(τ) = −τ within same_point_tolerance and known_branch_angle.
bool IsFixed(const Symmetry& g, const Vector& u, const Vector& tangent, const ExplorationOptions& options);

// Whether special point `m` of the branch traced so far is the midpoint of a loop reflected by g, checked
// by one evaluation at g(P_j), the first reflected point (residual, induced tangent, and the SB test's
// sign there).
bool FindReflection(ZeroProblem* problem, const Branch& branch, int m, const Symmetry& g,
                    const ExplorationOptions& options, Reflection* out);

// Replaces the points and special points past M by the images of those before it; ends the branch with
// kClosedLoop (Branch::reflected_from, Branch::symmetry).
void CompleteByReflection(const Reflection& reflection, Branch* branch);

// The progress reports of the reflected points (those past P_j) replace the buffered ones past P_j.
void ReportReflectedPoints(const Branch& branch, const std::vector<int>& progress_indices,
                           std::vector<ProgressInfo>* progress);

}  // namespace hybridcont::internal

#endif  // HYBRIDCONT_BIFURCATION_LOOP_REFLECTION_H_
