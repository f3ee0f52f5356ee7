#include "shooting/worker_team.h"

#include <algorithm>
#include <atomic>

namespace hybridcont::internal {

// One ForEach. Shared with the helpers: one may still hold it after ForEach returned, and then only finds
// every item claimed (it never calls body, which may be gone).
struct WorkerTeam::Loop {
  const std::function<void(int)>* body = nullptr;
  int n = 0;
  std::atomic<int> helpers{0};  // helpers still allowed to join
  std::atomic<int> next{0};
  std::atomic<int> finished{0};
  std::mutex mutex;
  std::condition_variable all_done;

  void Work() {
    for (int i = next.fetch_add(1); i < n; i = next.fetch_add(1)) {
      (*body)(i);
      if (finished.fetch_add(1) + 1 == n) {
        std::lock_guard<std::mutex> lock(mutex);  // the caller checks `finished` under this lock
        all_done.notify_all();
      }
    }
  }
};

WorkerTeam::WorkerTeam(int threads) {
  for (int i = 1; i < threads; ++i) helpers_.emplace_back([this] { Help(); });
}

WorkerTeam::~WorkerTeam() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  for (std::thread& helper : helpers_) helper.join();
}

void WorkerTeam::ForEach(int n, int max_threads, const std::function<void(int)>& body) {
  if (n <= 0) return;
  auto loop = std::make_shared<Loop>();
  loop->body = &body;
  loop->n = n;
  loop->helpers = std::min(max_threads, threads()) - 1;
  if (loop->helpers > 0 && n > 1) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      loop_ = loop;
      ++generation_;
    }
    wake_.notify_all();
  }
  loop->Work();
  std::unique_lock<std::mutex> lock(loop->mutex);
  loop->all_done.wait(lock, [&] { return loop->finished.load() == n; });
}

void WorkerTeam::Help() {
  std::uint64_t seen = 0;
  for (;;) {
    std::shared_ptr<Loop> loop;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      wake_.wait(lock, [&] { return stop_ || generation_ != seen; });
      if (stop_) return;
      seen = generation_;
      loop = loop_;
    }
    if (loop->helpers.fetch_sub(1) > 0) loop->Work();
  }
}

}  // namespace hybridcont::internal
