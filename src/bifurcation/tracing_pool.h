// Worker threads tracing half-branches ahead of their merge (docs/design/exploration.md, "Threads").
//
// Each worker traces submitted half-branches in submission order on its own clone of the problem; one
// more clone serves the evaluations of the exploring thread. A worker publishes every SB point it
// locates (TracingJob::early), which wakes the exploring thread. Destroying the pool cancels what is
// left, joins the workers, and adds every clone's work to the problem's counters.
//
//   std::unique_ptr<TracingPool> pool = TracingPool::Make(problem, options);  // null: trace serially
//   pool->Submit(&half);
//   pool->Wait(&half);  // half.branch is the trace; rethrows what tracing threw
#ifndef HYBRIDCONT_BIFURCATION_TRACING_POOL_H_
#define HYBRIDCONT_BIFURCATION_TRACING_POOL_H_

#include <condition_variable>
#include <cstddef>
#include <deque>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

#include "bifurcation/half_branch.h"
#include "hybridcont/exploration.h"
#include "hybridcont/special_point.h"
#include "hybridcont/zero_problem.h"

namespace hybridcont::internal {

class TracingPool {
 public:
  // Null unless threads > 1 and the problem can be cloned.
  static std::unique_ptr<TracingPool> Make(ZeroProblem* problem, const ExplorationOptions& options);
  ~TracingPool();

  // For evaluations on the exploring thread (start analysis, branch switching).
  ZeroProblem* own_problem() { return clones_.front().get(); }

  void Submit(HalfBranch* half);
  // From a worker: an SB point located on `half` (TracingJob::early); wakes the exploring thread.
  void Publish(HalfBranch* half, const SpecialPoint& point);
  // Blocks until `half` is traced (true) or an SB point was published since *seen (false).
  bool WaitOrEvent(HalfBranch* half, long* seen);
  // The SB points `half` published after the first `from`.
  std::vector<SpecialPoint> Early(HalfBranch* half, std::size_t from);
  // No half-branch waits for a worker.
  bool Idle();
  // Blocks until `half` is traced; rethrows what its tracing threw.
  void Wait(HalfBranch* half);
  // `half` is not needed: dropped if pending, stopped at its next point if running; returns when it is.
  void Cancel(HalfBranch* half);
  // The same without waiting for a running worker to stop (Cancel later returns at once, or soon).
  void RequestCancel(HalfBranch* half);

 private:
  TracingPool(ZeroProblem* problem, const ExplorationOptions& options, std::vector<std::unique_ptr<ZeroProblem>> clones);

  void Drop(HalfBranch* half);  // under mutex_
  void Work(int worker);

  ZeroProblem* problem_;
  const ExplorationOptions& options_;
  std::vector<std::unique_ptr<ZeroProblem>> clones_;  // [0] for the exploring thread, [1 + i] for worker i
  std::vector<std::thread> workers_;
  std::mutex mutex_;
  std::condition_variable work_;
  std::condition_variable done_;
  std::deque<HalfBranch*> pending_;
  std::vector<HalfBranch*> running_;  // per worker
  long events_ = 0;                   // SB points published so far
  bool stop_ = false;
};

}  // namespace hybridcont::internal

#endif  // HYBRIDCONT_BIFURCATION_TRACING_POOL_H_
