// Tracing one half-branch of an exploration (half_branch.h).
#include "bifurcation/half_branch.h"

#include "bifurcation/branch_registry.h"
#include "bifurcation/loop_reflection.h"
#include "continuation/special_point_detector.h"
#include "continuation/progress_report.h"
#include "hybridcont/invariant.h"

#include <utility>
#include <vector>

namespace hybridcont::internal {
namespace {

// The symmetries that fix the half-branch's start ray with its direction reversed: those that may map it
// onto itself as a closed loop.
std::vector<const Symmetry*> ReversingSymmetries(const HalfBranch& half, const ExplorationOptions& exploration) {
  std::vector<const Symmetry*> reversing;
  if (half.symmetries != nullptr && half.ray_point.size() > 0) {
    for (const Symmetry& g : *half.symmetries) {
      if (IsFixed(g, half.ray_point, half.direction, exploration)) reversing.push_back(&g);
    }
  }
  return reversing;
}

// The trace of one half-branch, step by step, with the checks made after each step.
class HalfBranchTrace {
 public:
  HalfBranchTrace(ZeroProblem* problem, const ExplorationOptions& exploration, bool concurrent, HalfBranch* half,
                  std::vector<const Symmetry*> reversing, const ContinuationOptions& options)
      : problem_(problem), exploration_(exploration), concurrent_(concurrent), half_(half),
        reversing_(std::move(reversing)), stepper_(problem, options, half->id) {}

  // Traces until the branch ends or the half-branch is cancelled; returns the reflection found, if any.
  Reflection Run() {
    HYBRIDCONT_DEMAND(half_->start != nullptr);
    StepStatus status = half_->start(&stepper_);
    while (status == StepStatus::kContinuing && !half_->job.cancelled.load(std::memory_order_relaxed)) {
      status = stepper_.Step();
      PublishNewSbPoints();
      if (status == StepStatus::kContinuing) status = CheckKnownBranches();
      if (status == StepStatus::kContinuing) status = CheckReflections();
    }
    half_->branch = stepper_.TakeBranch();
    return reflection_;
  }

 private:
  void PublishNewSbPoints() {
    if (!half_->job.publish) return;
    // Counted by kind: the test functions' zeros are inserted in arclength order, before earlier points.
    size_t seen = 0;
    for (const SpecialPoint& point : stepper_.branch().special_points) {
      if (point.type != SpecialPointType::kSimpleBifurcation) continue;
      if (seen++ == published_) {
        half_->job.publish(point);
        ++published_;
      }
    }
  }

  // The known-branch check on the first known_branch_check_points points.
  StepStatus CheckKnownBranches() {
    const auto& points = stepper_.branch().points;
    const int index = static_cast<int>(points.size()) - 1;
    if (index < 1 || index > exploration_.known_branch_check_points) return StepStatus::kContinuing;
    if (const int other = OnTracedBranch(points.back(), half_->known, exploration_); other >= 0) {
      stepper_.Terminate(TerminationReason::kKnownBranch, KnownBranchMessage(other));
      return StepStatus::kFinished;
    }
    if (concurrent_) half_->job.checkpoints.push_back(stepper_.branch());
    return StepStatus::kContinuing;
  }

  // Every special point not yet looked at, as the midpoint of a loop reflected by a reversing symmetry.
  StepStatus CheckReflections() {
    // SB and turning points only, counted by kind (test-function zeros are inserted before earlier points).
    const auto& specials = stepper_.branch().special_points;
    size_t seen = 0;
    for (size_t m = 0; m < specials.size(); ++m) {
      const SpecialPointType type = specials[m].type;
      if (type != SpecialPointType::kSimpleBifurcation && type != SpecialPointType::kTurningPoint) continue;
      if (seen++ < checked_) continue;
      ++checked_;
      for (const Symmetry* g : reversing_) {
        if (FindReflection(problem_, stepper_.branch(), static_cast<int>(m), *g, exploration_, &reflection_)) {
          stepper_.Terminate(TerminationReason::kClosedLoop, "");
          return StepStatus::kFinished;
        }
      }
    }
    return StepStatus::kContinuing;
  }

  ZeroProblem* problem_;
  const ExplorationOptions& exploration_;
  bool concurrent_;
  HalfBranch* half_;
  std::vector<const Symmetry*> reversing_;
  ContinuationStepper stepper_;
  Reflection reflection_;
  size_t checked_ = 0;    // SB and turning points looked at as midpoints
  size_t published_ = 0;  // SB points handed to job.publish
};

}  // namespace

void TraceHalfBranch(ZeroProblem* problem, const ExplorationOptions& exploration, bool concurrent, HalfBranch* half) {
  std::vector<const Symmetry*> reversing = ReversingSymmetries(*half, exploration);
  ContinuationOptions options = half->options;
  const bool buffer = concurrent || !reversing.empty();
  if (buffer && options.progress) {
    options.progress = [half](const ProgressInfo& info) { half->progress.push_back(info); };
  }
  HalfBranchTrace trace(problem, exploration, concurrent, half, std::move(reversing), options);
  const Reflection reflection = trace.Run();
  if (reflection.g == nullptr) return;
  CompleteByReflection(reflection, &half->branch);
  // The reflected half's test functions: the reversing symmetry need not leave them invariant.
  RedetectTestFunctions(problem, options, static_cast<size_t>(half->branch.reflected_from - 1), &half->branch);
  if (options.progress) ReportReflectedPoints(half->branch, ProgressIndices(half->options, *problem), &half->progress);
}

}  // namespace hybridcont::internal
