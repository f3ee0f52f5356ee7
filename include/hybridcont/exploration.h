// Automatic exploration: from one start point, trace every branch reachable by switching at simple
// bifurcation (SB) points, and return the bifurcation diagram as a graph whose nodes are special points
// (each stored once) and whose edges are half-branches, each leaving a start point or an SB point in one
// direction d of eq. (IVP) and ending for a TerminationReason.
//
// Breadth first over SB points:
//   1. Start: a regular u0 is traced with d = +1 and d = −1 (the second skipped when the first closes a
//      loop); a singular u0 gives its branch lines from the algebraic bifurcation equations
//      (branch_switching.h), each traced as two half-branches ±v.
//   2. A located SB point is compared with the known ones (same_point_tolerance): a new one is queued.
//   3. A queued point within max_depth gives the half-branches ±v along the transverse ABE root v.
//   4. Never twice: a half-branch whose ray (point, direction) matches that of a branch leaving, passing
//      or returning to the point is not traced; a branch whose first points lie on a traced branch ends
//      with kKnownBranch.
// Symmetries (ZeroProblem::symmetries()): a half-branch that is the image S(q, w) of a merged branch's
// start ray is that branch mapped point by point, checked by evaluations (Branch::image_of); a loop
// that a symmetry maps onto itself reversed is completed by reflection (Branch::reflected_from).
// Threads: the diagram is the serial one to the last bit; workers trace half-branches ahead and the
// exploring thread replays the serial decisions on their results. progress is called on the exploring
// thread in the serial order; stop_predicate is called on the workers and must be thread-safe.
// Design decisions: docs/design/exploration.md ("Symmetries", "Loops completed by reflection",
// "Threads", "Speculative switch groups", "Known-branch check").
//
// Tiny example (pitchfork x³ − λx from a regular point of the trivial branch):
//
//   ExplorationOptions options;
//   options.continuation.bounds = {{"lambda", -1, 1}};
//   BifurcationDiagram diagram = Explore(&pitchfork, Vector2d(0, -0.5), options);
//   // 4 half-branches: x = 0 (λ up, λ down) and λ = x² (x > 0, x < 0); one SB point at (0, 0), located.
#ifndef HYBRIDCONT_EXPLORATION_H_
#define HYBRIDCONT_EXPLORATION_H_

#include <algorithm>
#include <functional>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "hybridcont/branch_switching.h"
#include "hybridcont/continuation.h"
#include "hybridcont/exploration_status.h"
#include "hybridcont/special_point.h"
#include "hybridcont/types.h"
#include "hybridcont/zero_problem.h"

namespace hybridcont {

struct ExplorationOptions {
  // Per half-branch: bounds, targets, max_points (the limit per branch), step sizes, progress callback.
  ContinuationOptions continuation;
  // Kernel, cokernel and ABE at SB points and at a singular start.
  BranchSwitchOptions switching;
  // Linear conditions on the direction at a singular start whose kernel has dimension > 2 (e.g. a
  // symmetry of the orbits to follow, t2 = t1 + t3).
  std::vector<LinearCondition> start_conditions;
  // Branch switches from the start (its branches have depth 0): bounds the work on diagrams that keep
  // branching.
  int max_depth = 4;
  // Total number of half-branches; exploration ends with kMaxBranches when reached.
  int max_branches = 64;
  // SB points closer than this · (1 + ||u||) (max-norm) are one point: located points agree far more
  // closely, distinct bifurcation points of O(1) problems are far more than 1e-6 apart.
  double same_point_tolerance = 1e-6;
  // Two directions at one point with |cos| at least this are the same ray (about 8°): ABE directions are
  // accurate to ~1e-6, distinct branches cross at visible angles.
  double same_direction_cosine = 0.99;
  // Points (after the start) of every new branch compared with the traced branches: enough to recognize
  // a branch leaving along a traced one before it has cost much.
  int known_branch_check_points = 3;
  // Absolute part of the "lies on a traced branch" distance, · (1 + ||u||), added to the chord sag.
  double known_branch_tolerance = 1e-6;
  // Angle (radians) by which a point's tangent may differ from the traced branch's interpolated tangent
  // (plus a quarter of the angle across that chord) and still run along it: far above the tangents'
  // error from integrator noise (~1e-6), far below the angle of a branch crossing at a visible angle.
  double known_branch_angle = 1e-3;
  // Threads tracing half-branches concurrently; 1, the default (or a problem without Clone()), traces them
  // one after the other on the calling thread. Each clone integrates on one thread. A program that owns
  // the machine sets more (`hybridcont run` takes every core); a worker among many keeps 1.
  int threads = 1;
  // Map half-branches through the problem's symmetries instead of tracing them: a mapped branch costs
  // two evaluations instead of a trace.
  bool use_symmetries = true;
  // Half-branches known outside this exploration: one leaving point u along direction v (either sign of
  // a line) for which this returns true is not traced (a switch counts it as already known). Called on
  // the exploring thread; must depend on (u, v) only. Example: the parent family traversed twice, in the
  // exploration of a period-doubled family (period_doubling.h). Empty: none.
  std::function<bool(const Vector& u, const Vector& v)> known_ray;
  // Half-branches this exploration traced before (an exploration resumed after an interruption): asked with
  // the id the next half-branch gets; a branch returned is taken as its trace (no integration; its points are
  // reported as if traced) if it leaves the same special point in the same direction from the same point as
  // the half-branch (else it is traced). It must be the branch given to on_branch under that id by an
  // exploration of the same problem with the same options: the diagram is then that of an uninterrupted
  // exploration. Called on the exploring thread.
  std::function<std::optional<Branch>(int id)> recorded_branch;
  // A recorded branch the exploration takes (recorded_branch), before its points are reported: what was
  // learnt from its trace may be learnt again here. Called on the exploring thread. Empty: nothing.
  std::function<void(const Branch& branch)> on_recorded_branch;
  // A regular start traces the direction of its given tangent only (a branch continued from its end, whose
  // other side is known): Explore(problem, u0, tangent, options).
  bool one_way_start = false;
  // Each branch as it is merged into the diagram, in the serial order, on the exploring thread; not a branch
  // merged while ContinuationOptions::cancel says true (it may have been cut short), nor one that could not
  // start.
  std::function<void(const Branch& branch)> on_branch;

  std::string Validate() const;
};

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
