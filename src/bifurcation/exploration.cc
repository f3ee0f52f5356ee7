// Automatic exploration (exploration.h).
#include "hybridcont/exploration.h"

#include "continuation/branch_geometry.h"
#include "continuation/linear_stop.h"
#include "continuation/progress_report.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <condition_variable>
#include <deque>
#include <exception>
#include <functional>
#include <memory>
#include <mutex>
#include <limits>
#include <numbers>
#include <optional>
#include <span>
#include <sstream>
#include <stdexcept>
#include <thread>

namespace hybridcont {
namespace {

// A half-branch to trace, and what tracing it produced. Serially it is traced when its turn comes; in a
// concurrent exploration a worker traces it ahead of its turn and the merge replays the serial decisions
// on the result (exploration.h, "Threads").
struct HalfBranch {
  ContinuationOptions options;
  std::function<StepStatus(ContinuationStepper*)> start;  // owns its data: it may run later, elsewhere
  int d = +1;                                             // d of eq. IVP (Branch::direction)
  int parent = -1;                                        // special point it leaves
  Vector direction;                                       // the ray it leaves `parent` along
  Vector ray_point;                                       // where it starts, once known (symmetries)
  // Symmetries usable for completing a self-symmetric loop by reflection (TraceHalfBranch); may be null.
  const std::vector<Symmetry>* symmetries = nullptr;
  bool reserved = false;  // an id is reserved for it, not handed to a worker: expected to be an image
  int id = 0;                                             // branch id it is traced under
  std::vector<const Branch*> known;                       // branches merged before it was traced
  bool with_worker = false;                               // handed to a worker, result not yet taken
  // Results.
  Branch branch;
  // The branch as it stood at each point checked against `known` without a match (concurrent only): a
  // branch merged later but preceding it in the serial order may still end it there (kKnownBranch).
  std::vector<Branch> checkpoints;
  std::vector<ProgressInfo> progress;  // concurrent only: emitted when the branch is merged
  std::exception_ptr error;
  std::atomic<bool> cancelled{false};  // its result will not be used: stop tracing
  bool done = false;                   // traced (or cancelled); guarded by the pool's mutex
  // Concurrent: the depth its branch gets, and the SB points its worker has located so far (guarded by the
  // pool's mutex; `early_seen` of them looked at by the exploring thread): their switch groups may start
  // before this half-branch is merged (Explorer::Speculate).
  int depth = 0;
  std::function<void(const SpecialPoint&)> publish;
  std::vector<SpecialPoint> early;
  size_t early_seen = 0;
};

// Id of a branch among `branches` that p lies on (within the chord sag of one of its chords, parallel
// tangent), or −1.
int OnTracedBranch(const ContinuationPoint& p, std::span<const Branch* const> branches,
                   const ExplorationOptions& options) {
  for (const Branch* branch : branches) {
    for (size_t i = 0; i + 1 < branch->points.size(); ++i) {
      const ContinuationPoint& a = branch->points[i];
      const ContinuationPoint& b = branch->points[i + 1];
      const Vector chord = b.u - a.u;
      const double length = chord.norm();
      if (!(length > 0)) continue;
      const double t = chord.dot(p.u - a.u) / (length * length);
      if (t < 0 || t > 1) continue;
      const double distance = (a.u + t * chord - p.u).norm();
      const double allowed = options.known_branch_tolerance * (1 + p.u.norm()) +
                             length * (internal::AngleBetween(a.tangent, b.tangent) / 4 + 1e-3);
      // Parallel tangent: p's tangent against the known branch's tangent at the projection (the two end
      // tangents interpolated, exact to far less than a quarter of their angle). A branch crossing the
      // known one at a small angle θ stays within the chord sag near the crossing, but its tangent is θ
      // off everywhere.
      const Vector known_tangent = ((1 - t) * a.tangent + t * b.tangent).normalized();
      const double angle = std::acos(std::min(1.0, std::abs(p.tangent.dot(known_tangent))));
      const double allowed_angle = internal::AngleBetween(a.tangent, b.tangent) / 4 + options.known_branch_angle;
      if (distance <= allowed && angle <= allowed_angle) return branch->id;
    }
  }
  return -1;
}

std::string KnownBranchMessage(int other) { return "runs along branch " + std::to_string(other) + " (already traced)"; }

// A half-branch leaving a point p0 with g(p0) = p0 along τ0 with g(τ0) = −τ0 may be a loop that g maps
// onto itself with its orientation reversed (the SLIP's closed loop from an SB point of hopping in place:
// its second half is the mirror image of the first, traversed backwards). Its midpoint M is g-fixed with
// g(τ_M) = −τ_M; where M is a located special point (there the loop meets the g-fixed family again, at an
// SB point), the trace stops and the loop is completed by reflection: after P_0..P_j (M between P_j and
// P_j+1) come g(P_j), ..., g(P_1) and the start point again, with tangents −g(τ), arclength 2 s_M − s,
// the special points before M mirrored likewise. It ends as the trace would: kClosedLoop at its start.
struct Reflection {
  const Symmetry* g = nullptr;
  int midpoint = -1;  // index of the special point M in the traced branch
  double sb_sign = 1;
};

bool IsFixed(const Symmetry& g, const Vector& u, const Vector& tangent, const ExplorationOptions& options) {
  return (g.Apply(u) - u).lpNorm<Eigen::Infinity>() <= options.same_point_tolerance * (1 + u.norm()) &&
         internal::AngleBetween(-g.Apply(tangent).normalized(), tangent.normalized()) <= options.known_branch_angle;
}

// Whether special point `m` of the branch traced so far is the midpoint of a loop reflected by g, checked
// by one evaluation at g(P_j), the first reflected point (residual, induced tangent, and the SB test's
// sign there).
bool FindReflection(ZeroProblem* problem, const Branch& branch, int m, const Symmetry& g,
                    const ExplorationOptions& options, Reflection* out) {
  const SpecialPoint& mid = branch.special_points[m];
  const int j = mid.index;
  // M beyond the points the known-branch check looks at (a concurrent merge may still end the branch at
  // one of those, with the reports of its traced points), and within max_points once reflected.
  if (mid.status != LocationStatus::kLocated || mid.tangent.size() == 0 ||
      j < options.known_branch_check_points || j + 2 != static_cast<int>(branch.points.size()) ||
      2 * j + 2 > options.continuation.max_points || !IsFixed(g, mid.u, mid.tangent, options)) {
    return false;
  }
  const ContinuationPoint& pj = branch.points[j];
  const ContinuationPoint& next = branch.points[j + 1];  // traced past M
  const Vector u = g.Apply(pj.u);
  // g(P_j) lies on the curve at arclength 2 s_M − s_j; where that is within the traced step past M, it
  // must lie on that step's chord within the chord sag (the check of the reflection itself; a residual
  // alone only checks the equivariance of r).
  const double s_image = 2 * mid.arclength - pj.arclength;
  if (s_image <= next.arclength) {
    const Vector chord = next.u - pj.u;
    const double t = chord.dot(u - pj.u) / chord.squaredNorm();
    const double sag = chord.norm() * (internal::AngleBetween(pj.tangent, next.tangent) / 4 + 1e-3);
    if (!(t >= 0 && t <= 1 && (pj.u + t * chord - u).norm() <= sag + options.known_branch_tolerance * (1 + u.norm()))) {
      return false;
    }
  }
  Vector r, tangent;
  Matrix dr;
  double sb_own = 0, sb_reference = 0;
  internal::BorderedSolver solver;
  if (!problem->Evaluate(u, &r, &dr).ok || !(r.lpNorm<Eigen::Infinity>() <= 1e-6 * (1 + u.norm())) ||
      !internal::InducedTangent(&solver, dr, -g.Apply(pj.tangent), &tangent, &sb_own, &sb_reference)) {
    return false;
  }
  out->g = &g;
  out->midpoint = m;
  out->sb_sign = (sb_own < 0) == (pj.sb_test < 0) ? 1.0 : -1.0;
  return true;
}

void CompleteByReflection(const Reflection& reflection, Branch* branch) {
  const Symmetry& g = *reflection.g;
  const SpecialPoint mid = branch->special_points[reflection.midpoint];
  const int j = mid.index;
  const double s_mid = mid.arclength;
  const ContinuationPoint start = branch->points.front();
  branch->points.resize(j + 1);
  for (int i = j; i >= 0; --i) {  // g(P_j), ..., g(P_1), then the start point itself
    const ContinuationPoint& p = branch->points[i];
    ContinuationPoint q = i == 0 ? start : p;
    if (i > 0) {
      q.u = g.Apply(p.u);
      q.tangent = -g.Apply(p.tangent);
      q.sb_test = reflection.sb_sign * p.sb_test;
      q.newton_iterations = 0;
      q.contraction = 0;
    }
    q.arclength = 2 * s_mid - p.arclength;
    q.step = i == j ? (q.u - branch->points[j].u).norm() : branch->points[i + 1].step;
    branch->points.push_back(std::move(q));
  }
  // At M: the SB point there, and the turning point that every g-invariant component has there
  // (τ_k(M) = −τ_k(M)), located next to the SB point only to the noise of that singular place — on
  // either side, even in the segment before P_j (the tangent stored at P_j, next to the SB point, may
  // have that component's sign wrong): special points of those kinds in the last two segments closer to
  // the fixed set of g than P_{j−1}. Kept once, their own images. Others past M are the images of ones
  // before it.
  const Vector& before = branch->points[j - 1].u;
  const double fixed_distance = (before - g.Apply(before)).norm();
  const auto at_mid = [&](const SpecialPoint& sp) {
    if (sp.type == SpecialPointType::kTurningPoint && g.signs(sp.component_index) < 0) return false;
    return sp.index >= j - 1 && (sp.u - g.Apply(sp.u)).norm() <= fixed_distance;
  };
  std::vector<SpecialPoint> kept, mirrored;
  for (const SpecialPoint& sp : branch->special_points) {
    if (at_mid(sp)) {
      kept.push_back(sp);
      continue;
    }
    if (sp.arclength > s_mid) continue;  // beyond M: replaced by the mirror images below
    kept.push_back(sp);
    SpecialPoint q = sp;
    q.index = 2 * j - sp.index;
    q.arclength = 2 * s_mid - sp.arclength;
    q.interval_lo = 2 * s_mid - sp.interval_hi;
    q.interval_hi = 2 * s_mid - sp.interval_lo;
    q.u = g.Apply(sp.u);
    q.tangent = -g.Apply(sp.tangent);
    q.tangent_before = -g.Apply(sp.tangent_after);
    q.tangent_after = -g.Apply(sp.tangent_before);
    q.test_value *= sp.type == SpecialPointType::kTurningPoint ? -g.signs(sp.component_index) : reflection.sb_sign;
    mirrored.push_back(std::move(q));
  }
  kept.insert(kept.end(), std::make_move_iterator(mirrored.begin()), std::make_move_iterator(mirrored.end()));
  std::stable_sort(kept.begin(), kept.end(),
                   [](const SpecialPoint& a, const SpecialPoint& b) { return a.arclength < b.arclength; });
  for (size_t i = 0; i < kept.size(); ++i) kept[i].id = static_cast<int>(i);
  branch->special_points = std::move(kept);
  branch->termination = TerminationReason::kClosedLoop;
  branch->message = "the branch returned to its start point (its second half is the image of the first under " +
                    g.name + ")";
  branch->symmetry = g.name;
  branch->reflected_from = j + 1;
}

// Traces `half` on `problem`, ending it with kKnownBranch where one of its first points lies on a known
// branch, and completing a self-symmetric loop by reflection. `concurrent`: buffers progress and keeps
// checkpoints for the merge (progress is buffered for a possible loop too: its reports past the midpoint
// are replaced by those of the reflected points).
void TraceHalfBranch(ZeroProblem* problem, const ExplorationOptions& exploration, bool concurrent, HalfBranch* half) {
  std::vector<const Symmetry*> reversing;
  if (half->symmetries != nullptr && half->ray_point.size() > 0) {
    for (const Symmetry& g : *half->symmetries) {
      if (IsFixed(g, half->ray_point, half->direction, exploration)) reversing.push_back(&g);
    }
  }
  ContinuationOptions options = half->options;
  const bool buffer = concurrent || !reversing.empty();
  if (buffer && options.progress) {
    options.progress = [half](const ProgressInfo& info) { half->progress.push_back(info); };
  }
  ContinuationStepper stepper(problem, options, half->id);
  StepStatus status = half->start(&stepper);
  Reflection reflection;
  size_t checked = 0;    // special points looked at as midpoints
  size_t published = 0;  // special points handed to half->publish
  while (status == StepStatus::kContinuing && !half->cancelled.load(std::memory_order_relaxed)) {
    status = stepper.Step();
    if (half->publish) {
      for (const auto& specials = stepper.branch().special_points; published < specials.size(); ++published) {
        if (specials[published].type == SpecialPointType::kSimpleBifurcation) half->publish(specials[published]);
      }
    }
    const auto& points = stepper.branch().points;
    const int index = static_cast<int>(points.size()) - 1;
    if (index >= 1 && index <= exploration.known_branch_check_points && status == StepStatus::kContinuing) {
      if (const int other = OnTracedBranch(points.back(), half->known, exploration); other >= 0) {
        stepper.Terminate(TerminationReason::kKnownBranch, KnownBranchMessage(other));
        status = StepStatus::kFinished;
      } else if (concurrent) {
        half->checkpoints.push_back(stepper.branch());
      }
    }
    for (const auto& specials = stepper.branch().special_points;
         status == StepStatus::kContinuing && checked < specials.size(); ++checked) {
      for (const Symmetry* g : reversing) {
        if (FindReflection(problem, stepper.branch(), static_cast<int>(checked), *g, exploration, &reflection)) {
          stepper.Terminate(TerminationReason::kClosedLoop, "");
          status = StepStatus::kFinished;
          break;
        }
      }
    }
  }
  half->branch = stepper.TakeBranch();
  if (reflection.g != nullptr) {
    CompleteByReflection(reflection, &half->branch);
    if (options.progress) {
      const Branch& b = half->branch;
      const int j = b.reflected_from - 1;
      half->progress.resize(std::min(half->progress.size(), static_cast<size_t>(j + 1)));
      const std::vector<int> indices = internal::ProgressIndices(half->options, *problem);
      for (size_t i = j + 1; i < b.points.size(); ++i) {
        const double next_step = i + 1 < b.points.size() ? b.points[i + 1].step : b.points[i].step;
        half->progress.push_back(
            internal::PointProgress(b.points[i], b.id, static_cast<int>(i), indices, next_step, b.rejected_steps));
      }
    }
  }
}

// Worker threads, each with a clone of the problem, tracing submitted half-branches in submission order;
// one more clone for the evaluations of the exploring thread. When destroyed: cancels what is left,
// joins, and adds every clone's work to the problem's counters.
class TracingPool {
 public:
  // Null unless threads > 1 and the problem can be cloned.
  static std::unique_ptr<TracingPool> Make(ZeroProblem* problem, const ExplorationOptions& options) {
    if (options.threads <= 1) return nullptr;
    std::vector<std::unique_ptr<ZeroProblem>> clones;
    for (int i = 0; i <= options.threads; ++i) {
      clones.push_back(problem->Clone());
      if (clones.back() == nullptr) return nullptr;
    }
    return std::unique_ptr<TracingPool>(new TracingPool(problem, options, std::move(clones)));
  }

  ~TracingPool() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
      for (HalfBranch* half : pending_) half->done = true;
      pending_.clear();
      for (HalfBranch* half : running_) {
        if (half != nullptr) half->cancelled = true;
      }
    }
    work_.notify_all();
    for (std::thread& worker : workers_) worker.join();
    for (const auto& clone : clones_) problem_->AddWorkOf(*clone);
  }

  // For evaluations on the exploring thread (start analysis, branch switching).
  ZeroProblem* own_problem() { return clones_.front().get(); }

  void Submit(HalfBranch* half) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      pending_.push_back(half);
    }
    work_.notify_one();
  }

  // From a worker: an SB point located on `half` (HalfBranch::early); wakes the exploring thread.
  void Publish(HalfBranch* half, const SpecialPoint& point) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      half->early.push_back(point);
      ++events_;
    }
    done_.notify_all();
  }

  // Blocks until `half` is traced (true) or an SB point was published since *seen (false).
  bool WaitOrEvent(HalfBranch* half, long* seen) {
    std::unique_lock<std::mutex> lock(mutex_);
    done_.wait(lock, [&] { return half->done || events_ != *seen; });
    *seen = events_;
    return half->done;
  }

  // The SB points `half` published after the first `from`.
  std::vector<SpecialPoint> Early(HalfBranch* half, size_t from) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (from >= half->early.size()) return {};
    return std::vector<SpecialPoint>(half->early.begin() + static_cast<long>(from), half->early.end());
  }

  // No half-branch waits for a worker.
  bool Idle() {
    std::lock_guard<std::mutex> lock(mutex_);
    return pending_.empty();
  }

  // Blocks until `half` is traced; rethrows what its tracing threw.
  void Wait(HalfBranch* half) {
    std::unique_lock<std::mutex> lock(mutex_);
    done_.wait(lock, [half] { return half->done; });
    if (half->error) std::rethrow_exception(half->error);
  }

  // `half` is not needed: dropped if pending, stopped at its next point if running; returns when it is.
  void Cancel(HalfBranch* half) {
    std::unique_lock<std::mutex> lock(mutex_);
    Drop(half);
    done_.wait(lock, [half] { return half->done; });
  }

  // The same without waiting for a running worker to stop (Cancel later returns at once, or soon).
  void RequestCancel(HalfBranch* half) {
    std::lock_guard<std::mutex> lock(mutex_);
    Drop(half);
  }

 private:
  TracingPool(ZeroProblem* problem, const ExplorationOptions& options, std::vector<std::unique_ptr<ZeroProblem>> clones)
      : problem_(problem), options_(options), clones_(std::move(clones)), running_(options.threads, nullptr) {
    for (int i = 0; i < options.threads; ++i) workers_.emplace_back([this, i] { Work(i); });
  }

  // Under mutex_.
  void Drop(HalfBranch* half) {
    half->cancelled = true;
    if (const auto it = std::find(pending_.begin(), pending_.end(), half); it != pending_.end()) {
      pending_.erase(it);
      half->done = true;
    }
  }

  void Work(int worker) {
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
        half->error = std::current_exception();
      }
      {
        std::lock_guard<std::mutex> lock(mutex_);
        running_[worker] = nullptr;
        half->done = true;
      }
      done_.notify_all();
    }
  }

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

class Explorer {
 public:
  Explorer(ZeroProblem* problem, const ExplorationOptions& options) : problem_(problem), options_(options) {
    if (problem_ == nullptr) throw std::invalid_argument("Explore: problem is null");
    if (const std::string error = options_.Validate(); !error.empty()) throw std::invalid_argument(error);
    diagram_.unknown_names = problem_->unknown_names();
    if (const std::string error = options_.continuation.ValidateFor(diagram_.unknown_names); !error.empty()) {
      throw std::invalid_argument("ExplorationOptions::continuation: " + error);
    }
    pool_ = TracingPool::Make(problem_, options_);
    evaluator_ = pool_ ? pool_->own_problem() : problem_;
    if (options_.use_symmetries && !options_.continuation.stop_predicate) {
      for (Symmetry& g : problem_->symmetries()) {
        if (g.signs.size() == problem_->num_unknowns() && MapsStopsOntoThemselves(g)) symmetries_.push_back(std::move(g));
      }
    }
    stops_ = internal::LinearStops(options_.continuation, *problem_);
    reflecting_ = symmetries_;
    progress_indices_ = internal::ProgressIndices(options_.continuation, *problem_);
  }

  BifurcationDiagram Run(const Vector& u0, const Vector* tangent) {
    if (tangent != nullptr) {
      Launch(RegularStart(u0, tangent));
    } else {
      StartOptions start;
      start.switching = options_.switching;
      start.conditions = options_.start_conditions;
      diagram_.start = AnalyzeSingularPoint(evaluator_, u0, start);
      if (diagram_.start.status == BranchSwitchStatus::kRegular) {
        Launch(RegularStart(u0, nullptr));
      } else if (!diagram_.start.directions.empty()) {
        Launch(SingularStart(u0));
      } else {
        diagram_.status = ExplorationStatus::kStartFailed;
        diagram_.message = "singular start point without branch directions: " + diagram_.start.BriefReport();
        return std::move(diagram_);
      }
    }
    for (;;) {
      LaunchQueued();
      if (groups_.empty()) break;
      Merge(groups_.front().get());
      groups_.pop_front();
    }
    pool_.reset();  // every clone's work is in problem_'s counters from here on
    diagram_.branches.assign(std::make_move_iterator(branches_.begin()), std::make_move_iterator(branches_.end()));
    if (diagram_.status == ExplorationStatus::kCompleted && !diagram_.branches.empty() &&
        std::all_of(diagram_.branches.begin(), diagram_.branches.end(),
                    [](const Branch& b) { return b.termination == TerminationReason::kStartFailed; })) {
      diagram_.status = ExplorationStatus::kStartFailed;
      diagram_.message = diagram_.branches.front().message;
    }
    return std::move(diagram_);
  }

 private:
  // A traced direction leaving a special point.
  struct Ray {
    int point;
    Vector direction;
  };

  // The serial exploration is a sequence of groups of half-branches: the start, then one group per queued
  // SB point. Groups are merged in this order; a concurrent exploration launches them earlier.
  struct Group {
    enum class Kind { kRegularStart, kSingularStart, kSwitch };
    Kind kind = Kind::kRegularStart;
    SwitchRecord record;  // kSwitch
    std::vector<std::unique_ptr<HalfBranch>> halves;
  };

  std::unique_ptr<Group> RegularStart(const Vector& u0, const Vector* tangent) {
    auto group = std::make_unique<Group>();
    group->kind = Group::Kind::kRegularStart;
    for (const int d : {+1, -1}) {
      auto half = std::make_unique<HalfBranch>();
      half->options = options_.continuation;
      half->options.direction = d;
      half->d = d;
      if (tangent != nullptr) {
        half->start = [u0, hint = Vector(d * *tangent)](ContinuationStepper* stepper) { return stepper->Start(u0, hint); };
      } else {
        half->start = [u0](ContinuationStepper* stepper) { return stepper->Start(u0); };
      }
      group->halves.push_back(std::move(half));
    }
    return group;
  }

  std::unique_ptr<Group> SingularStart(const Vector& u0) {
    SpecialPoint start;
    start.type = SpecialPointType::kSingularStart;
    start.status = LocationStatus::kLocated;
    start.u = u0;
    start.message = diagram_.start.BriefReport();
    const int id = AddUnique(std::move(start), 0);
    NoteLines(id, diagram_.start.directions);
    auto group = std::make_unique<Group>();
    group->kind = Group::Kind::kSingularStart;
    for (const Vector& line : diagram_.start.directions) {
      for (const int d : {+1, -1}) {
        group->halves.push_back(FromPoint(id, d * line, d));
        group->halves.back()->depth = 1;
      }
    }
    return group;
  }

  // The group of a queued SB point: the transverse ABE root v gives the half-branches ±v.
  std::unique_ptr<Group> Switch(int id) {
    if (std::unique_ptr<Group> group = AdoptSpeculative(id)) return group;
    auto group = SwitchGroup(diagram_.special_points[id], depth_[id] + 1);
    return TiedTo(id, std::move(group));
  }

  // A switch group tied to diagram point `id`: its record, its half-branches' parent, the point's lines.
  std::unique_ptr<Group> TiedTo(int id, std::unique_ptr<Group> group) {
    group->record.special_point = id;
    for (const auto& half : group->halves) half->parent = id;
    const BranchSwitch& result = group->record.result;
    if (!group->halves.empty()) NoteLines(id, {result.direction, result.incoming_direction});
    return group;
  }

  // The switch group of an SB point, its half-branches at `depth`, not yet tied to a diagram id.
  std::unique_ptr<Group> SwitchGroup(const SpecialPoint& point, int depth) {
    auto group = std::make_unique<Group>();
    group->kind = Group::Kind::kSwitch;
    group->record.result = SwitchDirectionAt(evaluator_, point, options_.switching);
    const BranchSwitch& result = group->record.result;
    if (result.status == BranchSwitchStatus::kOk || result.status == BranchSwitchStatus::kFallback) {
      for (const int d : {+1, -1}) {
        group->halves.push_back(FromPoint(point.u, d * result.direction, d));
        group->halves.back()->depth = depth;
      }
    }
    return group;
  }

  // --- Speculative switch groups (concurrent) ---
  // A worker publishes every SB point it locates (HalfBranch::early). While the exploring thread waits for
  // the half-branch it merges next and no half-branch waits for a worker, the switch group of such a point
  // is launched at once, before the branch it lies on is merged: the SLIP's workers otherwise idled ~9 of
  // ~106 ms waiting for the children of branch 3. Its switching direction is computed from the very point
  // the merge will register (the same bits), its half-branches are traced like any launched ahead (checked
  // at their merge against the branches merged since), and the serial run's decisions stay the merge's:
  // when the merge queues that point the group is adopted in place of a new one (AdoptSpeculative); when it
  // does not (a known point, a branch ended earlier at the merge, an image), the group is dropped.
  struct Speculative {
    const HalfBranch* source;
    Vector u;
    std::unique_ptr<Group> group;
  };

  void Speculate() {
    std::vector<HalfBranch*> sources;
    const auto collect = [&](const Group& group) {
      for (const auto& half : group.halves) {
        if (half->with_worker && !half->cancelled) sources.push_back(half.get());
      }
    };
    for (const auto& group : groups_) collect(*group);
    for (const Speculative& speculative : speculative_) collect(*speculative.group);
    for (HalfBranch* source : sources) {
      for (const SpecialPoint& point : pool_->Early(source, source->early_seen)) {
        if (!pool_->Idle() || BranchBudgetSpent()) return;  // looked at again on the next event
        ++source->early_seen;
        if (source->depth >= options_.max_depth || Known(point.u)) continue;
        // The serial run may never switch at this point (a later duplicate, a point its merge cuts off):
        // an exception of the problem here is not the run's. Switch(id) recomputes, and throws exactly when
        // the serial run would (an independent review saw 8–12 of 180 concurrent runs throw without this).
        std::unique_ptr<Group> group;
        try {
          group = SwitchGroup(point, source->depth + 1);
        } catch (...) {
          continue;
        }
        Submit(group.get());
        speculative_.push_back({source, point.u, std::move(group)});
      }
    }
  }

  // An SB point registered already, or one a speculative group was launched for.
  bool Known(const Vector& u) const {
    const auto same = [&](const Vector& v) {
      return (u - v).lpNorm<Eigen::Infinity>() <= options_.same_point_tolerance * (1 + v.norm());
    };
    return std::any_of(diagram_.special_points.begin(), diagram_.special_points.end(),
                       [&](const SpecialPoint& p) { return same(p.u); }) ||
           std::any_of(speculative_.begin(), speculative_.end(), [&](const Speculative& s) { return same(s.u); });
  }

  std::unique_ptr<Group> AdoptSpeculative(int id) {
    const SpecialPoint& point = diagram_.special_points[id];
    const auto it = std::find_if(speculative_.begin(), speculative_.end(),
                                 [&](const Speculative& s) { return s.u == point.u; });
    if (it == speculative_.end()) return nullptr;
    std::unique_ptr<Group> group = std::move(it->group);
    speculative_.erase(it);
    return TiedTo(id, std::move(group));
  }

  // After `source` was merged (or skipped): its speculative groups whose point was not queued are dropped,
  // with whatever was launched from their own half-branches.
  void DropSpeculative(const HalfBranch* source) {
    const auto queued = [&](const Vector& u) {
      return std::any_of(queue_.begin(), queue_.end(), [&](int id) { return diagram_.special_points[id].u == u; });
    };
    for (size_t i = 0; i < speculative_.size();) {
      if (speculative_[i].source != source || queued(speculative_[i].u)) {
        ++i;
        continue;
      }
      std::unique_ptr<Group> group = std::move(speculative_[i].group);
      speculative_.erase(speculative_.begin() + static_cast<long>(i));
      for (const auto& half : group->halves) {
        if (half->reserved) {
          half->reserved = false;
          --in_flight_;
        }
        if (half->with_worker) {
          pool_->RequestCancel(half.get());
          half->with_worker = false;
          --in_flight_;
        }
        DropSpeculative(half.get());
      }
      dropped_.push_back(std::move(group));  // kept until the workers are joined
      i = 0;
    }
  }

  std::unique_ptr<HalfBranch> FromPoint(int id, const Vector& direction, int d) {
    auto half = FromPoint(diagram_.special_points[id].u, direction, d);
    half->parent = id;
    return half;
  }

  std::unique_ptr<HalfBranch> FromPoint(const Vector& u, const Vector& direction, int d) {
    auto half = std::make_unique<HalfBranch>();
    half->options = options_.continuation;
    half->d = d;
    half->direction = direction;
    half->ray_point = u;
    half->symmetries = &reflecting_;
    half->start = [u, direction](ContinuationStepper* stepper) { return stepper->StartAtSingularPoint(u, direction); };
    return half;
  }

  // Serially a group waits for its turn. Concurrently its half-branches are handed to the workers now,
  // each under the branch id it gets if no half-branch before it is skipped, as long as they can still
  // become branches within max_branches (one that is not handed over is traced when its turn comes).
  void Launch(std::unique_ptr<Group> group) {
    if (pool_) Submit(group.get());
    groups_.push_back(std::move(group));
  }

  // The group's half-branches not yet launched (an adopted speculative group has them launched already).
  void Submit(Group* group) {
    for (size_t i = 0; i < group->halves.size(); ++i) {
      HalfBranch* half = group->halves[i].get();
      if (half->with_worker || half->reserved) continue;
      if (BranchBudgetSpent()) break;
      half->id = static_cast<int>(branches_.size()) + in_flight_++;
      if (ExpectedImage(*half, std::span(group->halves).first(i))) {
        half->reserved = true;  // mapped at its merge (or traced there if its source does not come)
        continue;
      }
      half->known = MergedBranches();
      half->with_worker = true;
      half->publish = [pool = pool_.get(), half](const SpecialPoint& point) { pool->Publish(half, point); };
      pool_->Submit(half);
    }
  }

  bool BranchBudgetSpent() const { return static_cast<int>(branches_.size()) + in_flight_ >= options_.max_branches; }

  // Groups of queued SB points, their switching directions computed now: serially the next one when
  // nothing else is left, concurrently also ahead while half-branches can be handed to the workers.
  void LaunchQueued() {
    while (!queue_.empty() && diagram_.status == ExplorationStatus::kCompleted) {
      if (!groups_.empty() && (!pool_ || BranchBudgetSpent())) return;
      const int id = queue_.front();
      queue_.pop_front();
      if (depth_[id] >= options_.max_depth) continue;
      Launch(Switch(id));
    }
  }

  // The serial exploration's decisions for a group, in its order.
  void Merge(Group* group) {
    switch (group->kind) {
      case Group::Kind::kRegularStart: {
        // d = +1, then d = −1 unless the first closed a loop or could not start
        for (const auto& half : group->halves) {
          if (!branches_.empty() && (branches_.back().termination == TerminationReason::kClosedLoop ||
                                     branches_.back().termination == TerminationReason::kStartFailed)) {
            break;
          }
          if (half->d == -1 && !branches_.empty() && !branches_.back().points.empty()) {
            // Start(u0) corrects u0 to the same point for both directions: the second half leaves the
            // first one's start point against its tangent.
            half->ray_point = branches_.back().points.front().u;
            half->direction = -branches_.back().points.front().tangent;
          }
          Trace(half.get(), -1, 0);
        }
        break;
      }
      case Group::Kind::kSingularStart:
        for (const auto& half : group->halves) TraceFromPoint(half.get(), 1);
        break;
      case Group::Kind::kSwitch: {
        if (diagram_.status != ExplorationStatus::kCompleted) break;  // the serial run stopped before it
        SwitchRecord& record = group->record;
        for (const auto& half : group->halves) {
          if (diagram_.status != ExplorationStatus::kCompleted) break;
          if (TraceFromPoint(half.get(), depth_[record.special_point] + 1)) {
            ++record.traced;
          } else {
            ++record.skipped;
          }
        }
        diagram_.switches.push_back(std::move(record));
        break;
      }
    }
    for (const auto& half : group->halves) {  // skipped ones: their traces are dropped
      DropSpeculative(half.get());
      if (half->reserved) {
        half->reserved = false;
        --in_flight_;
      }
      if (!half->with_worker) continue;
      pool_->Cancel(half.get());
      half->with_worker = false;
      --in_flight_;
    }
  }

  // Traces a half-branch leaving its special point, unless that ray is known.
  bool TraceFromPoint(HalfBranch* half, int depth) {
    const int id = half->parent;
    if (RayKnown(id, half->direction)) return false;
    rays_.push_back({id, half->direction.normalized()});
    Trace(half, id, depth);
    return true;
  }

  void Trace(HalfBranch* half, int parent, int depth) {
    if (static_cast<int>(branches_.size()) >= options_.max_branches) {
      diagram_.status = ExplorationStatus::kMaxBranches;
      diagram_.message = "max_branches = " + std::to_string(options_.max_branches) + " reached";
      return;
    }
    const int id = static_cast<int>(branches_.size());
    Branch branch = Traced(half, id);
    branch.parent_special_point = parent;
    branch.depth = depth;
    branch.direction = half->d;
    for (SpecialPoint& point : branch.special_points) Register(&point, depth);
    if (branch.termination == TerminationReason::kClosedLoop && parent >= 0) {
      rays_.push_back({parent, -branch.points.back().tangent});  // it returns to the point from this side
    }
    branches_.push_back(std::move(branch));
    for (const ProgressInfo& info : half->progress) options_.continuation.progress(info);
    if (pool_) {
      CancelKnownRays();
      LaunchQueued();  // the SB points just found: their groups can start while this one merges
      DropSpeculative(half);
    }
  }

  // The half-branch as the serial run traces it as branch `id`. Serially (or not handed to a worker):
  // traced now. Otherwise its worker's result, ended at the first checkpoint that lies on a branch
  // merged after it was launched, and relabeled when it was traced under another id.
  Branch Traced(HalfBranch* half, int id) {
    if (half->reserved) {
      half->reserved = false;
      --in_flight_;
    }
    if (std::optional<Branch> image = Image(*half, id)) {
      if (half->with_worker) {  // traced ahead for nothing
        pool_->Cancel(half);
        half->with_worker = false;
        --in_flight_;
      }
      half->progress.clear();
      if (options_.continuation.progress) ReportImage(*image, &half->progress);
      return std::move(*image);
    }
    if (!half->with_worker) {
      half->id = id;
      half->known = MergedBranches();
      TraceHalfBranch(evaluator_, options_, false, half);
      return std::move(half->branch);
    }
    for (long seen = -1; !pool_->WaitOrEvent(half, &seen);) Speculate();
    pool_->Wait(half);  // rethrows what its tracing threw
    half->with_worker = false;
    --in_flight_;
    Branch branch = std::move(half->branch);
    const std::vector<const Branch*> merged = MergedBranches();
    const std::span<const Branch* const> unseen = std::span(merged).subspan(half->known.size());
    if (!unseen.empty()) {
      for (Branch& checkpoint : half->checkpoints) {
        if (const int other = OnTracedBranch(checkpoint.points.back(), unseen, options_); other >= 0) {
          branch = std::move(checkpoint);
          branch.termination = TerminationReason::kKnownBranch;
          branch.message = KnownBranchMessage(other);
          break;
        }
      }
    }
    half->progress.resize(std::min(half->progress.size(), branch.points.size()));  // one report per point
    if (branch.id != id) {
      branch.id = id;
      for (SpecialPoint& point : branch.special_points) point.branch_id = id;
      for (ProgressInfo& info : half->progress) info.branch_id = id;
    }
    return branch;
  }

  // Concurrent: a half-branch in flight whose ray is known by now will be skipped at its merge (rays
  // only accumulate): its worker stops at its next point instead of tracing it to the end (SLIP: ~80
  // points a run). Not waited for here; the merge collects it as any skipped half-branch.
  void CancelKnownRays() {
    for (const auto& group : groups_) {
      for (const auto& half : group->halves) {
        if (!half->with_worker || half->cancelled || half->parent < 0) continue;
        if (RayKnown(half->parent, half->direction)) pool_->RequestCancel(half.get());
      }
    }
  }

  std::vector<const Branch*> MergedBranches() const {
    std::vector<const Branch*> merged;
    for (const Branch& branch : branches_) merged.push_back(&branch);
    return merged;
  }

  // Gives a special point found on a branch its diagram id (a known point: duplicate_of) and records the
  // rays of the branch through it.
  void Register(SpecialPoint* point, int depth) {
    for (const SpecialPoint& known : diagram_.special_points) {
      const bool comparable = point->type == known.type ||
                              (point->type == SpecialPointType::kSimpleBifurcation &&
                               known.type == SpecialPointType::kSingularStart);
      if (comparable && point->component == known.component &&
          (point->u - known.u).lpNorm<Eigen::Infinity>() <= options_.same_point_tolerance * (1 + known.u.norm())) {
        point->duplicate_of = known.id;
        point->id = known.id;
        AddPassingRays(known.id, *point);
        return;
      }
    }
    const int id = AddUnique(*point, depth);
    point->id = id;
    AddPassingRays(id, *point);
    if (point->type == SpecialPointType::kSimpleBifurcation) queue_.push_back(id);
  }

  int AddUnique(SpecialPoint point, int depth) {
    point.id = static_cast<int>(diagram_.special_points.size());
    point.duplicate_of = -1;
    diagram_.special_points.push_back(std::move(point));
    depth_.push_back(depth);
    line_angle_.push_back(std::numbers::pi / 2);
    return diagram_.special_points.back().id;
  }

  void AddPassingRays(int id, const SpecialPoint& point) {
    if (point.type == SpecialPointType::kTurningPoint) return;
    rays_.push_back({id, point.tangent});
    rays_.push_back({id, -point.tangent});
  }

  // A ray matches a known one within same_direction_cosine, or within half the smallest angle between
  // the branch lines through the point when that is smaller (branches crossing at a small angle).
  bool RayKnown(int id, const Vector& direction) const {
    const Vector unit = direction.normalized();
    const double cosine = std::max(options_.same_direction_cosine, std::cos(0.5 * line_angle_[id]));
    return std::any_of(rays_.begin(), rays_.end(), [&](const Ray& ray) {
      return ray.point == id && ray.direction.dot(unit) >= cosine;
    });
  }

  // Records the smallest angle between branch lines through special point `id`.
  void NoteLines(int id, const std::vector<Vector>& lines) {
    for (size_t i = 0; i < lines.size(); ++i) {
      for (size_t j = i + 1; j < lines.size(); ++j) {
        const double c = std::abs(lines[i].normalized().dot(lines[j].normalized()));
        line_angle_[id] = std::min(line_angle_[id], std::acos(std::min(1.0, c)));
      }
    }
  }

  // --- Symmetries (exploration.h, "Symmetries") ---

  // Every bound, sum bound and target of the continuation is mapped onto itself by g.
  bool MapsStopsOntoThemselves(const Symmetry& g) const {
    const ContinuationOptions& c = options_.continuation;
    const auto sign = [&](const std::string& name) { return g.signs(problem_->UnknownIndex(name)); };
    for (const ComponentBound& b : c.bounds) {
      if (sign(b.component) < 0 && b.lower != -b.upper) return false;
    }
    for (const ComponentTarget& t : c.targets) {
      if (sign(t.component) < 0 && t.value != 0) return false;
    }
    for (const SumBound& b : c.sum_bounds) {
      const double s = sign(b.components.front());
      for (const std::string& name : b.components) {
        if (sign(name) != s) return false;
      }
      if (s < 0 && b.lower != -b.upper) return false;
    }
    return true;
  }

  // Whether the ray (p, v) is the image of the ray (q, w) under g: the points within same_point_tolerance,
  // the directions within known_branch_angle (a true image is exact to rounding or to the switching
  // directions' accuracy, ~1e-6; same_direction_cosine, ~8°, would take a branch crossing at a small
  // angle for the image of the other).
  bool MapsRay(const Symmetry& g, const Vector& q, const Vector& w, const Vector& p, const Vector& v) const {
    if ((g.Apply(q) - p).lpNorm<Eigen::Infinity>() > options_.same_point_tolerance * (1 + p.norm())) return false;
    return internal::AngleBetween(g.Apply(w).normalized(), v.normalized()) <= options_.known_branch_angle;
  }

  static bool Mappable(const Branch& source) {
    return source.points.size() >= 2 && source.termination != TerminationReason::kKnownBranch &&
           source.termination != TerminationReason::kStartFailed &&
           source.termination != TerminationReason::kNotFinished;
  }

  // At launch: `half` will probably be mapped at its merge, as the image of a merged branch or of a
  // half-branch launched before it (`earlier`: those of its own group). Only saves a worker's time;
  // the decision is Image()'s, at the merge.
  bool ExpectedImage(const HalfBranch& half, std::span<const std::unique_ptr<HalfBranch>> earlier) const {
    if (symmetries_.empty() || half.ray_point.size() == 0) return false;
    const auto image_of = [&](const Vector& q, const Vector& w) {
      return std::any_of(symmetries_.begin(), symmetries_.end(),
                         [&](const Symmetry& g) { return MapsRay(g, q, w, half.ray_point, half.direction); });
    };
    for (const Branch& branch : branches_) {
      if (Mappable(branch) && image_of(branch.points.front().u, branch.points.front().tangent)) return true;
    }
    const auto launched = [&](const std::unique_ptr<HalfBranch>& other) {
      return other->ray_point.size() > 0 && image_of(other->ray_point, other->direction);
    };
    for (const auto& group : groups_) {
      if (std::any_of(group->halves.begin(), group->halves.end(), launched)) return true;
    }
    return std::any_of(earlier.begin(), earlier.end(), launched);
  }

  // The half-branch as the image of a merged branch, or nothing (then it is traced).
  std::optional<Branch> Image(const HalfBranch& half, int id) {
    if (symmetries_.empty() || half.ray_point.size() == 0) return std::nullopt;
    for (const Branch& source : branches_) {
      if (!Mappable(source)) continue;
      for (size_t k = 0; k < symmetries_.size(); ++k) {
        const Symmetry& g = symmetries_[k];
        if (!MapsRay(g, source.points.front().u, source.points.front().tangent, half.ray_point, half.direction)) {
          continue;
        }
        std::optional<Branch> image = MapBranch(source, g, id);
        if (image) return image;
        symmetries_.erase(symmetries_.begin() + static_cast<long>(k));  // failed its check: not used again
        return std::nullopt;
      }
    }
    return std::nullopt;
  }

  // source mapped by g as branch `id`; nothing if the first mapped point fails its check.
  std::optional<Branch> MapBranch(const Branch& source, const Symmetry& g, int id) {
    Branch image;
    image.id = id;
    image.termination = source.termination;
    image.message = ImageStopMessage(source.message, g);
    image.image_of = source.id;
    image.symmetry = g.name;
    for (const ContinuationPoint& p : source.points) {
      ContinuationPoint q = p;
      q.u = g.Apply(p.u);
      q.tangent = g.Apply(p.tangent);
      image.points.push_back(std::move(q));
    }
    // The check: r and the induced tangent at the first point after the start (the start may be singular)
    // and at the last one (of a closed loop: the one before it, the last being the start again).
    double sb_sign = 1.0;
    const size_t last = image.points.size() - (source.termination == TerminationReason::kClosedLoop ? 2 : 1);
    for (const size_t i : {size_t{1}, std::max<size_t>(1, last)}) {
      const ContinuationPoint& point = image.points[i];
      Vector r;
      Matrix dr;
      const EvaluationStatus status = evaluator_->Evaluate(point.u, &r, &dr);
      Vector tangent;
      double sb_own = 0, sb_reference = 0;
      internal::BorderedSolver solver;
      const bool regular =
          status.ok && internal::InducedTangent(&solver, dr, point.tangent, &tangent, &sb_own, &sb_reference);
      const double residual = status.ok ? r.lpNorm<Eigen::Infinity>() : std::numeric_limits<double>::infinity();
      if (!regular || !(residual <= 1e-6 * (1 + point.u.norm())) ||
          internal::AngleBetween(tangent, point.tangent) > options_.known_branch_angle) {
        std::ostringstream out;
        out << "symmetry '" << g.name << "' does not map branch " << source.id << " onto solutions (|r| = "
            << residual
            << (regular ? ", tangent off by " + std::to_string(internal::AngleBetween(tangent, point.tangent)) + " rad"
                        : ", singular")
            << " at its point " << i << "): not used";
        diagram_.warnings.push_back(out.str());
        return std::nullopt;
      }
      // det([dr; τᵀ]) at S u with S τ is ± the source's: the sign is the same along the whole branch.
      if (i == 1) sb_sign = (sb_own < 0) == (source.points[1].sb_test < 0) ? 1.0 : -1.0;
    }
    for (ContinuationPoint& p : image.points) p.sb_test *= sb_sign;
    for (const SpecialPoint& sp : source.special_points) {
      SpecialPoint q = sp;
      q.branch_id = id;
      q.id = -1;
      q.duplicate_of = -1;
      q.u = g.Apply(sp.u);
      q.tangent = g.Apply(sp.tangent);
      q.tangent_before = g.Apply(sp.tangent_before);
      q.tangent_after = g.Apply(sp.tangent_after);
      q.test_value *= sp.type == SpecialPointType::kTurningPoint ? g.signs(sp.component_index) : sb_sign;
      image.special_points.push_back(std::move(q));
    }
    // The serial trace's known-branch check on the first points (not on the last: the trace had ended).
    const std::vector<const Branch*> merged = MergedBranches();
    for (int j = 1; j <= options_.known_branch_check_points && j + 1 < static_cast<int>(image.points.size()); ++j) {
      if (const int other = OnTracedBranch(image.points[j], merged, options_); other >= 0) {
        image.points.resize(j + 1);
        std::erase_if(image.special_points, [j](const SpecialPoint& sp) { return sp.index >= j; });
        image.termination = TerminationReason::kKnownBranch;
        image.message = KnownBranchMessage(other);
        break;
      }
    }
    for (size_t i = 0; i < image.special_points.size(); ++i) image.special_points[i].id = static_cast<int>(i);
    return image;
  }

  // The termination message of an image: the stop the source reached, mapped by g (a lower bound on a
  // flipped component becomes the upper one, e.g. "reached lambda >= -2" -> "reached lambda <= 2").
  std::string ImageStopMessage(const std::string& message, const Symmetry& g) const {
    for (const internal::LinearStop& stop : stops_) {
      const std::string reached = "reached " + stop.label;
      if (message.rfind(reached, 0) != 0) continue;
      const Vector c = g.Apply(stop.c);  // the image stops at cᵀ(S u) = value, i.e. (S c)ᵀu = value
      for (const internal::LinearStop& other : stops_) {
        const bool same = other.c == c && other.value == stop.value && other.kind == stop.kind;
        const bool flipped = other.c == -c && other.value == -stop.value &&
                             (stop.kind == internal::LinearStop::Kind::kTarget
                                  ? other.kind == stop.kind
                                  : other.kind != stop.kind && other.kind != internal::LinearStop::Kind::kTarget);
        if (same || flipped) return "reached " + other.label + message.substr(reached.size());
      }
    }
    return message;
  }

  // The progress reports the stepper would have made for the image's points.
  void ReportImage(const Branch& image, std::vector<ProgressInfo>* reports) const {
    for (size_t i = 0; i < image.points.size(); ++i) {
      const double next_step = i + 1 < image.points.size() ? image.points[i + 1].step : image.points[i].step;
      reports->push_back(internal::PointProgress(image.points[i], image.id, static_cast<int>(i), progress_indices_,
                                                 next_step, 0));
    }
  }

  ZeroProblem* problem_;
  ExplorationOptions options_;
  // For self-symmetric loops; fixed after construction. Workers read it: declared before pool_, so that
  // it outlives the workers (pool_ joins them when destroyed), also when an exception leaves Explore.
  std::vector<Symmetry> reflecting_;
  BifurcationDiagram diagram_;
  std::deque<Branch> branches_;     // merged branches, id == index; elements never move (workers read them)
  std::vector<int> depth_;          // per unique special point: depth of the branch it was found on
  std::vector<double> line_angle_;  // per unique special point: smallest angle between its branch lines
  std::vector<Ray> rays_;
  std::deque<int> queue_;                     // SB points not yet switched at
  std::deque<std::unique_ptr<Group>> groups_;  // launched, in the serial order, not yet merged
  std::vector<Speculative> speculative_;       // launched ahead of the merge of their SB point (concurrent)
  std::vector<std::unique_ptr<Group>> dropped_;  // speculative groups given up, kept until the pool joins
  int in_flight_ = 0;                         // half-branches of groups_ (concurrent)
  std::unique_ptr<TracingPool> pool_;         // null: serial (destroyed before groups_: joins first)
  ZeroProblem* evaluator_ = nullptr;          // evaluations on this thread: problem_, or the pool's clone
  std::vector<Symmetry> symmetries_;          // those used (exploration.h, "Symmetries")
  std::vector<internal::LinearStop> stops_;   // ContinuationOptions' linear stops, for image messages
  std::vector<int> progress_indices_;         // ContinuationOptions::progress_components
};

}  // namespace

std::string ToString(ExplorationStatus status) {
  switch (status) {
    case ExplorationStatus::kCompleted: return "completed";
    case ExplorationStatus::kMaxBranches: return "max-branches";
    case ExplorationStatus::kStartFailed: return "start-failed";
  }
  return "unknown";
}

std::string ExplorationOptions::Validate() const {
  std::ostringstream out;
  if (const std::string error = continuation.Validate(); !error.empty()) {
    out << "ExplorationOptions::continuation: " << error;
  } else if (const std::string switch_error = switching.Validate(); !switch_error.empty()) {
    out << "ExplorationOptions::switching: " << switch_error;
  } else if (max_depth < 0) {
    out << "ExplorationOptions::max_depth = " << max_depth << " must be >= 0";
  } else if (max_branches < 1) {
    out << "ExplorationOptions::max_branches = " << max_branches << " must be >= 1";
  } else if (!(same_point_tolerance > 0)) {
    out << "ExplorationOptions::same_point_tolerance = " << same_point_tolerance << " must be > 0";
  } else if (!(same_direction_cosine > 0 && same_direction_cosine < 1)) {
    out << "ExplorationOptions::same_direction_cosine = " << same_direction_cosine << " must lie in (0, 1)";
  } else if (known_branch_check_points < 0) {
    out << "ExplorationOptions::known_branch_check_points = " << known_branch_check_points << " must be >= 0";
  } else if (!(known_branch_tolerance >= 0)) {
    out << "ExplorationOptions::known_branch_tolerance = " << known_branch_tolerance << " must be >= 0";
  } else if (!(known_branch_angle >= 0 && known_branch_angle < 1)) {
    out << "ExplorationOptions::known_branch_angle = " << known_branch_angle << " must lie in [0, 1)";
  } else if (threads < 1) {
    out << "ExplorationOptions::threads = " << threads << " must be >= 1";
  }
  return out.str();
}

std::string BifurcationDiagram::BriefReport() const {
  int sb = 0, located = 0, turning = 0;
  for (const SpecialPoint& point : special_points) {
    if (point.type == SpecialPointType::kSimpleBifurcation) {
      ++sb;
      if (point.status == LocationStatus::kLocated) ++located;
    } else if (point.type == SpecialPointType::kTurningPoint) {
      ++turning;
    }
  }
  std::ostringstream out;
  out << "Exploration " << ToString(status) << ": " << branches.size() << " branches, " << sb << " SB points ("
      << located << " located), " << turning << " turning points";
  return out.str();
}

std::string BifurcationDiagram::FullReport() const {
  std::ostringstream out;
  out << BriefReport() << "\n";
  if (!message.empty()) out << "  " << message << "\n";
  for (const std::string& warning : warnings) out << "  warning: " << warning << "\n";
  if (start.kernel_dimension > 1) out << "Start: " << start.BriefReport() << "\n";
  out << "Branches:\n";
  for (const Branch& branch : branches) out << "  " << branch.FullReport(unknown_names);
  out << "Special points:\n";
  for (const SpecialPoint& point : special_points) out << "  " << point.BriefReport(unknown_names) << "\n";
  out << "Branch switches:\n";
  for (const SwitchRecord& record : switches) {
    out << "  at #" << record.special_point << ": " << record.result.BriefReport() << ", traced " << record.traced
        << ", already known " << record.skipped << "\n";
  }
  return out.str();
}

BifurcationDiagram Explore(ZeroProblem* problem, const Vector& u0, const ExplorationOptions& options) {
  return Explorer(problem, options).Run(u0, nullptr);
}

BifurcationDiagram Explore(ZeroProblem* problem, const Vector& u0, const Vector& tangent,
                           const ExplorationOptions& options) {
  return Explorer(problem, options).Run(u0, &tangent);
}

}  // namespace hybridcont
