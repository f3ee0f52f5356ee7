// Internal: a small team of persistent threads for loops whose items are independent (the segments of
// the time-based map, timebased_shooting.h).
//
//   WorkerTeam team(2);                                 // the calling thread and one helper
//   team.ForEach(n, 2, [&](int i) { integrate(i); });   // each i once; returns when all are done
//
// The calling thread takes part, and items are claimed one at a time from a shared counter: a helper the
// OS does not get to run (a busy machine) holds nothing up, the caller does its share, and the caller
// waits only for items a helper has started. (An OpenMP static loop waits at its barrier for every
// thread of the team: with two other busy processes on a 2-core machine, the ball-chain's evaluation
// became 3 to 100 times slower; with this team, at worst ~7% slower.) Helpers sleep on a condition
// variable between loops: they spend no CPU while the caller solves its linear systems.
#ifndef HYBRIDCONT_SRC_SHOOTING_WORKER_TEAM_H_
#define HYBRIDCONT_SRC_SHOOTING_WORKER_TEAM_H_

#include <condition_variable>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

namespace hybridcont::internal {

class WorkerTeam {
 public:
  // threads >= 1: the caller and threads − 1 helpers.
  explicit WorkerTeam(int threads);
  ~WorkerTeam();
  WorkerTeam(const WorkerTeam&) = delete;
  WorkerTeam& operator=(const WorkerTeam&) = delete;

  int threads() const { return static_cast<int>(helpers_.size()) + 1; }

  // Calls body(i) for every i in [0, n), each once, on this thread and up to max_threads − 1 helpers;
  // returns when every call has returned (its effects visible to the caller). body must not throw.
  void ForEach(int n, int max_threads, const std::function<void(int)>& body);

 private:
  struct Loop;
  void Help();

  std::vector<std::thread> helpers_;
  std::mutex mutex_;
  std::condition_variable wake_;
  std::shared_ptr<Loop> loop_;  // the latest loop; a helper that wakes late finds it done
  std::uint64_t generation_ = 0;
  bool stop_ = false;
};

}  // namespace hybridcont::internal

#endif  // HYBRIDCONT_SRC_SHOOTING_WORKER_TEAM_H_
