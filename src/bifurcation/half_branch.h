// A half-branch of an exploration (exploration.h): one direction d of eq. (IVP) from a start point or
// an SB point. `HalfBranch` describes what to trace and holds what tracing produced; in a concurrent
// exploration its `TracingJob` is the record shared with the worker that traces it ahead of its turn,
// while the merge replays the serial decisions on the result (docs/design/exploration.md, "Threads").
//
//   HalfBranch half;                      // filled by the explorer: options, start, id, known, ...
//   TraceHalfBranch(problem, options, /*concurrent=*/false, &half);
//   Branch branch = std::move(half.branch);
#ifndef HYBRIDCONT_BIFURCATION_HALF_BRANCH_H_
#define HYBRIDCONT_BIFURCATION_HALF_BRANCH_H_

#include <atomic>
#include <cstddef>
#include <exception>
#include <functional>
#include <vector>

#include "hybridcont/continuation.h"
#include "hybridcont/exploration.h"
#include "hybridcont/special_point.h"
#include "hybridcont/types.h"
#include "hybridcont/zero_problem.h"

namespace hybridcont::internal {

// The concurrent half of a half-branch. `done`, `early` and the pool's queues are guarded by the pool's
// mutex; `cancelled` is read by the worker between steps.
struct TracingJob {
  bool reserved = false;     // an id is reserved for it, not handed to a worker: expected to be an image
  bool with_worker = false;  // handed to a worker, result not yet taken
  int depth = 0;             // the depth its branch gets (for the switch groups of its early SB points)
  // The branch as it stood at each point checked against `known` without a match: a branch merged later
  // but preceding it in the serial order may still end it there (kKnownBranch).
  std::vector<Branch> checkpoints;
  std::exception_ptr error;
  std::atomic<bool> cancelled{false};  // its result will not be used: stop tracing
  bool done = false;                   // traced (or cancelled)
  // The SB points its worker has located so far (`early_seen` of them looked at by the exploring thread):
  // their switch groups may start before this half-branch is merged (speculation).
  std::function<void(const SpecialPoint&)> publish;
  std::vector<SpecialPoint> early;
  std::size_t early_seen = 0;
};

struct HalfBranch {
  // What to trace.
  ContinuationOptions options;
  std::function<StepStatus(ContinuationStepper*)> start;  // owns its data: it may run later, elsewhere
  int d = +1;                                             // d of eq. (IVP) (Branch::direction)
  int parent = -1;                                        // special point it leaves
  Vector direction;                                       // the ray it leaves `parent` along
  Vector ray_point;                                       // where it starts, once known (symmetries)
  Vector origin;                                          // the point it is started from (a start's u0)
  // Symmetries usable for completing a self-symmetric loop by reflection (loop_reflection.h); may be null.
  const std::vector<Symmetry>* symmetries = nullptr;
  int id = 0;                              // branch id it is traced under
  std::vector<const Branch*> known;        // branches merged before it was traced
  // What tracing produced.
  Branch branch;
  std::vector<ProgressInfo> progress;  // buffered reports, emitted when the branch is merged
  TracingJob job;                      // concurrent only
};

// Traces `half` on `problem`, ending it with kKnownBranch where one of its first
// known_branch_check_points points lies on a branch of half->known, and completing a self-symmetric
// loop by reflection. `concurrent`: buffers progress and keeps checkpoints for the merge (progress is
// buffered for a possible loop too: its reports past the midpoint are those of the reflected points).
void TraceHalfBranch(ZeroProblem* problem, const ExplorationOptions& exploration, bool concurrent, HalfBranch* half);

}  // namespace hybridcont::internal

#endif  // HYBRIDCONT_BIFURCATION_HALF_BRANCH_H_
