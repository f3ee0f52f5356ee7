// Automatic exploration: from one start point, trace every branch reachable by switching at simple
// bifurcation points, and return the bifurcation diagram as a graph.
//
//   nodes: special points (SB points, turning points, a singular start), each stored once
//   edges: half-branches, each leaving a start point or an SB point in one direction (Branch::direction,
//          Branch::parent_special_point) and ending for a TerminationReason
//
// Algorithm (breadth first over SB points):
//   1. Start. Regular u0 (kernel of dr of dimension 1): trace d = +1 and d = −1 (eq. IVP); the second is
//      skipped when the first closes a loop. Singular u0 (kernel dimension >= 2, e.g. an equilibrium with
//      zero phase durations): the branch lines from the algebraic bifurcation equations
//      (branch_switching.h, with ExplorationOptions::start_conditions for kernels of dimension > 2), each
//      traced as two half-branches ±v from u0.
//   2. Every SB point located on a traced branch is compared with the known ones (distance in u below
//      same_point_tolerance·(1 + ||u||)): a new one is queued, a known one only records the branch.
//   3. For a queued SB point within max_depth: the transverse ABE root v (SwitchDirectionAt) gives the two
//      half-branches ±v, each traced unless a branch already leaves the point in that direction.
//   4. Never twice: a "ray" (point, direction) is recorded for every branch leaving, passing through or
//      returning to a special point; a new half-branch whose ray matches one (cos >= same_direction_cosine,
//      or within half the smallest angle between the point's branch lines when the ABE roots are closer
//      than that) is not traced. Independently, the first known_branch_check_points points of every new
//      branch are compared with all traced branches (distance to a chord within the chord sag, tangent
//      within known_branch_angle of the interpolated one); a match ends the new branch with kKnownBranch.
//
// Symmetries (ZeroProblem::symmetries(), e.g. the SLIP's mirror and time reversal): a half-branch
// leaving point p along v is not traced when a merged branch starts at q along w with S q = p and
// S w ∥ v (same_point_tolerance; directions within known_branch_angle) for a symmetry S: it is that
// branch mapped point by point (u -> S u, τ -> S τ, special points likewise; Branch::image_of,
// Branch::symmetry). Switching directions are computed at every SB point, images too: a mapped one could
// only be checked by the second derivatives the computation needs anyway (N = 1: dr vanishes at an SB
// point), and their canonical sign (CanonicalLine) makes the images' half-branches come in the order of
// the traced diagram's. What
// the serial trace would decide is decided on the image too: its first points are checked against the
// merged branches (kKnownBranch), its special points are registered and queued. Guards: a symmetry is
// used only when it maps every stop onto itself (bounds and sum bounds symmetric where it flips signs,
// targets at 0 there; none with a stop_predicate, which cannot be checked); the first mapped point is
// evaluated, and a residual above 1e-6·(1 + ||u||) or a tangent off by more than known_branch_angle drops
// the symmetry for the rest of the run (BifurcationDiagram::warnings) and the half-branch is traced (the
// last mapped point is checked as well). An image's termination message names the mapped stop. The
// sign of the SB test function along an image is taken from that evaluation (det([dr; τᵀ]) may change
// sign under S). Sources whose own end depended on the order of tracing (kKnownBranch) are not mapped.
// Mapped branches are exact images (the time-based map is equivariant to the last bit on the built-in
// models: durations, states and ξ change sign in exact arithmetic), so the diagram is the traced one
// up to the tracing's own noise; the SLIP's complete diagram costs about half.
// A half-branch leaving a g-fixed point p0 along τ0 with g τ0 = −τ0 may be a loop that g maps onto itself
// reversed (the SLIP's closed loop from an SB point of hopping in place). When a special point M located
// on it is g-fixed with g τ_M = −τ_M (the loop meets the g-fixed family again there), the trace stops
// and the loop is completed by reflection: g(P_j), ..., g(P_1), then p0, with tangents −g τ, arclength
// 2 s_M − s, the special points before M mirrored (Branch::reflected_from). One evaluation at g(P_j)
// checks it as for images; the loop ends kClosedLoop at p0, as the trace would.
//
// Tiny example (pitchfork x³ − λx from a regular point of the trivial branch):
//
//   ExplorationOptions options;
//   options.continuation.bounds = {{"lambda", -1, 1}};
//   BifurcationDiagram diagram = Explore(&pitchfork, Vector2d(0, -0.5), options);
//   // 4 half-branches: x = 0 (λ up, λ down) and λ = x² (x > 0, x < 0); one SB point at (0, 0), located.
//
// Threads (ExplorationOptions::threads > 1 and ZeroProblem::Clone() available): the diagram is the serial
// one to the last bit — same branches, points, special points, ids and order. The serial run is a
// sequence of groups of half-branches (the start, then one group per queued SB point, steps 1 and 3);
// each group is launched as soon as it is known, its switching direction computed at once and its
// half-branches traced ahead by workers, each on its own clone of the problem, in the serial order.
// Earlier still: an SB point a worker has located starts its group while the exploring thread waits and
// no half-branch waits for a worker (speculatively: the merge that queues the point adopts the group, a
// merge that does not drops it).
// The exploring thread merges the groups in that order and replays every serial decision on the
// results: a ray known by then skips a half-branch (its trace is dropped); the closed-loop and
// max_branches rules likewise; the known-branch check, already made while tracing against the branches
// merged before the launch, is repeated on the kept copies of the first points against the branches
// merged since, and ends the branch there. Special point ids are given at the merge, branch ids too
// (a half-branch traced under another id is relabeled). Consequences:
//  - ContinuationOptions::progress is called on the exploring thread, branch by branch in the serial
//    order, with the serial values: a branch's points are reported when it is merged.
//  - ContinuationOptions::stop_predicate is called on the workers, concurrently, also for points of
//    half-branches the serial run would not trace: it must be safe to call from several threads and
//    depend on u only (otherwise set threads = 1).
//  - The problem's work counters include the clones' (ZeroProblem::AddWorkOf): all work done, also
//    that of traces the merge drops (few: half-branches are handed to workers only while they can still
//    become branches within max_branches).
// Why a replay and not locks: the decisions depend on the order in which branches become known; any
// other order changes the diagram (another branch would be the one found "already traced").
//
// The library never prints: ContinuationOptions::progress receives every accepted point (with the
// branch id), and BriefReport()/FullReport() summarize the result.
#ifndef HYBRIDCONT_EXPLORATION_H_
#define HYBRIDCONT_EXPLORATION_H_

#include <algorithm>
#include <string>
#include <thread>
#include <vector>

#include "hybridcont/branch_switching.h"
#include "hybridcont/continuation.h"
#include "hybridcont/special_point.h"
#include "hybridcont/types.h"
#include "hybridcont/zero_problem.h"

namespace hybridcont {

struct ExplorationOptions {
  // Per half-branch: bounds, targets, max_points (the limit per branch), step sizes, progress callback.
  ContinuationOptions continuation;
  // Kernel, cokernel and ABE at SB points and at a singular start.
  BranchSwitchOptions switching;
  // Linear conditions on the direction at a singular start whose kernel has dimension > 2 (the rod).
  std::vector<LinearCondition> start_conditions;
  // Branch switches from the start: branches from the start have depth 0, from their SB points depth 1...
  int max_depth = 4;
  // Total number of half-branches; exploration ends with kMaxBranches when reached.
  int max_branches = 64;
  // SB points closer than this · (1 + ||u||) (max-norm) are one point. Located points agree to ~1e-10;
  // distinct bifurcation points of O(1) problems are far more than 1e-6 apart.
  double same_point_tolerance = 1e-6;
  // Two directions at one point with |cos| at least this are the same ray (about 8°: branch directions
  // from finite-difference ABEs are accurate to ~1e-6, distinct branches cross at visible angles).
  double same_direction_cosine = 0.99;
  // Points (after the start) of every new branch compared with the traced branches.
  int known_branch_check_points = 3;
  // Absolute part of the "lies on a traced branch" distance, · (1 + ||u||), added to the chord sag.
  double known_branch_tolerance = 1e-6;
  // Angle (radians) by which a point's tangent may differ from the traced branch's interpolated tangent
  // (plus a quarter of the angle across that chord) and still run along it. A branch crossing a traced
  // one at a small angle stays within the chord sag near the crossing but not within this angle;
  // 1e-3 is far above the tangents' error from integrator noise (~1e-6).
  double known_branch_angle = 1e-3;
  // Threads tracing half-branches concurrently (see "Threads" above); 1 traces them one after the other
  // on the calling thread, as does a problem without Clone(). The problem's clones integrate on one
  // thread each, so a time-based map with many segments does not start threads of its own on top.
  int threads = std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  // Map half-branches through the problem's symmetries instead of tracing them ("Symmetries" above).
  bool use_symmetries = true;

  std::string Validate() const;
};

enum class ExplorationStatus {
  kCompleted,    // every reachable branch within the bounds and depth was traced
  kMaxBranches,  // stopped at max_branches
  kStartFailed,  // no branch could be started (see message)
};
std::string ToString(ExplorationStatus status);

struct SwitchRecord {
  int special_point = -1;     // the SB point (or singular start) switched at
  BranchSwitch result;        // direction found (or fallback) and the ABE coefficients
  int traced = 0;             // half-branches traced from it
  int skipped = 0;            // half-branches recognized as already traced
};

struct BifurcationDiagram {
  std::vector<std::string> unknown_names;
  std::vector<Branch> branches;               // id == index
  std::vector<SpecialPoint> special_points;   // unique points, id == index
  std::vector<SwitchRecord> switches;
  BranchDirections start;                     // analysis of the start point
  ExplorationStatus status = ExplorationStatus::kCompleted;
  std::string message;
  std::vector<std::string> warnings;          // e.g. a declared symmetry that failed its check

  std::string BriefReport() const;
  std::string FullReport() const;
};

// Explores from u0: regular (corrected, both directions) or singular (branch directions from the ABE).
// Throws std::invalid_argument for invalid options.
BifurcationDiagram Explore(ZeroProblem* problem, const Vector& u0, const ExplorationOptions& options);
// Explores from a regular u0 whose tangent orientation is given (the first half-branch follows it).
BifurcationDiagram Explore(ZeroProblem* problem, const Vector& u0, const Vector& tangent,
                           const ExplorationOptions& options);

}  // namespace hybridcont

#endif  // HYBRIDCONT_EXPLORATION_H_
