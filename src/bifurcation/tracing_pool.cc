// Worker threads tracing half-branches ahead of their merge (tracing_pool.h).
#include "bifurcation/tracing_pool.h"

#include <algorithm>
#include <exception>
#include <utility>

#include "hybridcont/invariant.h"

namespace hybridcont::internal {

std::unique_ptr<TracingPool> TracingPool::Make(ZeroProblem* problem, const ExplorationOptions& options) {
  if (options.threads <= 1) return nullptr;
  std::vector<std::unique_ptr<ZeroProblem>> clones;
  for (int i = 0; i <= options.threads; ++i) {
    clones.push_back(problem->Clone());
    if (clones.back() == nullptr) return nullptr;
  }
  return std::unique_ptr<TracingPool>(new TracingPool(problem, options, std::move(clones)));
}

TracingPool::TracingPool(ZeroProblem* problem, const ExplorationOptions& options,
                         std::vector<std::unique_ptr<ZeroProblem>> clones)
    : problem_(problem), options_(options), clones_(std::move(clones)), running_(options.threads, nullptr) {
  HYBRIDCONT_DEMAND(static_cast<int>(clones_.size()) == options.threads + 1);
  for (int i = 0; i < options.threads; ++i) workers_.emplace_back([this, i] { Work(i); });
}

TracingPool::~TracingPool() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
    for (HalfBranch* half : pending_) half->job.done = true;
    pending_.clear();
    for (HalfBranch* half : running_) {
      if (half != nullptr) half->job.cancelled = true;
    }
  }
  work_.notify_all();
  for (std::thread& worker : workers_) worker.join();
  for (const auto& clone : clones_) problem_->AddWorkOf(*clone);
}

void TracingPool::Submit(HalfBranch* half) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    HYBRIDCONT_DEMAND(!half->job.done);
    pending_.push_back(half);
  }
  work_.notify_one();
}

void TracingPool::Publish(HalfBranch* half, const SpecialPoint& point) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    half->job.early.push_back(point);
    ++events_;
  }
  done_.notify_all();
}

bool TracingPool::WaitOrEvent(HalfBranch* half, long* seen) {
  std::unique_lock<std::mutex> lock(mutex_);
  done_.wait(lock, [&] { return half->job.done || events_ != *seen; });
  *seen = events_;
  return half->job.done;
}

std::vector<SpecialPoint> TracingPool::Early(HalfBranch* half, std::size_t from) {
  std::lock_guard<std::mutex> lock(mutex_);
  const std::vector<SpecialPoint>& early = half->job.early;
  if (from >= early.size()) return {};
  return std::vector<SpecialPoint>(early.begin() + static_cast<long>(from), early.end());
}

bool TracingPool::Idle() {
  std::lock_guard<std::mutex> lock(mutex_);
  return pending_.empty();
}

void TracingPool::Wait(HalfBranch* half) {
  std::unique_lock<std::mutex> lock(mutex_);
  done_.wait(lock, [half] { return half->job.done; });
  if (half->job.error) std::rethrow_exception(half->job.error);
}

void TracingPool::Cancel(HalfBranch* half) {
  std::unique_lock<std::mutex> lock(mutex_);
  Drop(half);
  done_.wait(lock, [half] { return half->job.done; });
}

void TracingPool::RequestCancel(HalfBranch* half) {
  std::lock_guard<std::mutex> lock(mutex_);
  Drop(half);
}

void TracingPool::Drop(HalfBranch* half) {
  half->job.cancelled = true;
  if (const auto it = std::find(pending_.begin(), pending_.end(), half); it != pending_.end()) {
    pending_.erase(it);
    half->job.done = true;
  }
}

void TracingPool::Work(int worker) {
  ZeroProblem* problem = clones_[worker + 1].get();
  for (;;) {
    HalfBranch* half;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      work_.wait(lock, [this] { return stop_ || !pending_.empty(); });
      if (stop_) return;
      half = pending_.front();
      pending_.pop_front();
      running_[worker] = half;
    }
    try {
      TraceHalfBranch(problem, options_, true, half);
    } catch (...) {
      half->job.error = std::current_exception();
    }
    {
      std::lock_guard<std::mutex> lock(mutex_);
      running_[worker] = nullptr;
      half->job.done = true;
    }
    done_.notify_all();
  }
}

}  // namespace hybridcont::internal
