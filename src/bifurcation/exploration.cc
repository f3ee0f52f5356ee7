// Automatic exploration (exploration.h): the serial breadth-first search and the merge that makes its
// decisions, group by group (explorer.h). Launching ahead of the merge is in explorer_launch.cc.
#include "hybridcont/exploration.h"

#include <algorithm>
#include <iterator>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "bifurcation/explorer.h"
#include "continuation/special_point_detector.h"
#include "hybridcont/internal/enum_names.h"
#include "hybridcont/internal/options_check.h"
#include "hybridcont/invariant.h"

namespace hybridcont {
namespace internal {

Explorer::Explorer(ZeroProblem* problem, const ExplorationOptions& options)
    : problem_(problem), options_(options), registry_(options) {
  if (problem_ == nullptr) throw std::invalid_argument("Explore: problem is null");
  if (const std::string error = options_.Validate(); !error.empty()) throw std::invalid_argument(error);
  diagram_.unknown_names = problem_->unknown_names();
  if (const std::string error = options_.continuation.ValidateFor(diagram_.unknown_names); !error.empty()) {
    throw std::invalid_argument("ExplorationOptions::continuation: " + error);
  }
  pool_ = TracingPool::Make(problem_, options_);
  evaluator_ = pool_ ? pool_->own_problem() : problem_;
  images_ = SymmetricImages(problem_, options_);
  reflecting_ = images_.symmetries();
}

BifurcationDiagram Explorer::Run(const Vector& u0, const Vector* tangent) {
  if (!LaunchStart(u0, tangent)) return std::move(diagram_);
  for (;;) {
    LaunchQueued();
    if (groups_.empty()) break;
    Merge(groups_.front().get());
    groups_.pop_front();
  }
  pool_.reset();  // every clone's work is in problem_'s counters from here on
  diagram_.branches.assign(std::make_move_iterator(branches_.begin()), std::make_move_iterator(branches_.end()));
  diagram_.special_points = registry_.TakePoints();
  if (diagram_.status == ExplorationStatus::kCompleted && !diagram_.branches.empty() &&
      std::all_of(diagram_.branches.begin(), diagram_.branches.end(),
                  [](const Branch& b) { return b.termination == TerminationReason::kStartFailed; })) {
    diagram_.status = ExplorationStatus::kStartFailed;
    diagram_.message = diagram_.branches.front().message;
  }
  return std::move(diagram_);
}

// Step 1 of the search (exploration.h): the start group, or false when the start point has no direction.
bool Explorer::LaunchStart(const Vector& u0, const Vector* tangent) {
  if (tangent != nullptr) {
    Launch(RegularStart(u0, tangent));
    return true;
  }
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
    return false;
  }
  return true;
}

std::unique_ptr<Explorer::Group> Explorer::RegularStart(const Vector& u0, const Vector* tangent) {
  auto group = std::make_unique<Group>();
  group->kind = Group::Kind::kRegularStart;
  for (const int d : {+1, -1}) {
    auto half = std::make_unique<HalfBranch>();
    half->options = options_.continuation;
    half->options.direction = d;
    half->d = d;
    half->origin = u0;
    if (tangent != nullptr) {
      half->start = [u0, hint = Vector(d * *tangent)](ContinuationStepper* stepper) { return stepper->Start(u0, hint); };
    } else {
      half->start = [u0](ContinuationStepper* stepper) { return stepper->Start(u0); };
    }
    group->halves.push_back(std::move(half));
  }
  return group;
}

std::unique_ptr<Explorer::Group> Explorer::SingularStart(const Vector& u0) {
  SpecialPoint start;
  start.type = SpecialPointType::kSingularStart;
  start.status = LocationStatus::kLocated;
  start.u = u0;
  start.message = diagram_.start.BriefReport();
  const int id = registry_.AddUnique(std::move(start), 0);
  registry_.NoteLines(id, diagram_.start.directions);
  auto group = std::make_unique<Group>();
  group->kind = Group::Kind::kSingularStart;
  for (const Vector& line : diagram_.start.directions) {
    for (const int d : {+1, -1}) {
      if (options_.known_ray && options_.known_ray(u0, d * line)) continue;
      group->halves.push_back(FromPoint(id, d * line, d));
      group->halves.back()->job.depth = 1;
    }
  }
  return group;
}

// The group of a queued SB point (step 3): the transverse ABE root v gives the half-branches ±v.
std::unique_ptr<Explorer::Group> Explorer::Switch(int id) {
  if (std::unique_ptr<Group> group = AdoptSpeculative(id)) return group;
  auto group = SwitchGroup(registry_.point(id), registry_.depth(id) + 1);
  return TiedTo(id, std::move(group));
}

// A switch group tied to diagram point `id`: its record, its half-branches' parent, the point's lines.
std::unique_ptr<Explorer::Group> Explorer::TiedTo(int id, std::unique_ptr<Group> group) {
  group->record.special_point = id;
  for (const auto& half : group->halves) half->parent = id;
  const BranchSwitch& result = group->record.result;
  if (!group->halves.empty()) registry_.NoteLines(id, {result.direction, result.incoming_direction});
  return group;
}

// The switch group of an SB point, its half-branches at `depth`, not yet tied to a diagram id.
std::unique_ptr<Explorer::Group> Explorer::SwitchGroup(const SpecialPoint& point, int depth) {
  auto group = std::make_unique<Group>();
  group->kind = Group::Kind::kSwitch;
  group->record.result = SwitchDirectionAt(evaluator_, point, options_.switching);
  const BranchSwitch& result = group->record.result;
  if (result.status == BranchSwitchStatus::kOk || result.status == BranchSwitchStatus::kFallback) {
    for (const int d : {+1, -1}) {
      if (options_.known_ray && options_.known_ray(point.u, d * result.direction)) {
        ++group->record.skipped;
        continue;
      }
      group->halves.push_back(FromPoint(point.u, d * result.direction, d));
      group->halves.back()->job.depth = depth;
    }
  }
  return group;
}

std::unique_ptr<HalfBranch> Explorer::FromPoint(int id, const Vector& direction, int d) {
  auto half = FromPoint(registry_.point(id).u, direction, d);
  half->parent = id;
  return half;
}

std::unique_ptr<HalfBranch> Explorer::FromPoint(const Vector& u, const Vector& direction, int d) {
  auto half = std::make_unique<HalfBranch>();
  half->options = options_.continuation;
  half->d = d;
  half->direction = direction;
  half->ray_point = u;
  half->origin = u;
  half->symmetries = &reflecting_;
  half->start = [u, direction](ContinuationStepper* stepper) { return stepper->StartAtSingularPoint(u, direction); };
  return half;
}

// Groups of queued SB points, their switching directions computed now: serially the next one when
// nothing else is left, concurrently also ahead while half-branches can be handed to the workers.
void Explorer::LaunchQueued() {
  const auto& cancel = options_.continuation.cancel;
  if (cancel && diagram_.status == ExplorationStatus::kCompleted && cancel()) {
    diagram_.status = ExplorationStatus::kCancelled;
    diagram_.message = "cancelled";
  }
  while (!queue_.empty() && diagram_.status == ExplorationStatus::kCompleted) {
    if (!groups_.empty() && (!pool_ || BranchBudgetSpent())) return;
    const int id = queue_.front();
    queue_.pop_front();
    if (registry_.depth(id) >= options_.max_depth) continue;
    Launch(Switch(id));
  }
}

// The serial search's decisions for a group, in its order; then its skipped half-branches are given up.
void Explorer::Merge(Group* group) {
  switch (group->kind) {
    case Group::Kind::kRegularStart:
      MergeRegularStart(group);
      break;
    case Group::Kind::kSingularStart:
      for (const auto& half : group->halves) TraceFromPoint(half.get(), 1);
      break;
    case Group::Kind::kSwitch:
      MergeSwitch(group);
      break;
  }
  for (const auto& half : group->halves) {  // skipped ones: their traces are dropped
    DropSpeculative(half.get());
    Unreserve(half.get());
    Recall(half.get(), /*wait=*/true);
  }
}

// d = +1, then d = −1 unless the first closed a loop or could not start.
void Explorer::MergeRegularStart(Group* group) {
  for (const auto& half : group->halves) {
    if (options_.one_way_start && half->d == -1) break;
    if (!branches_.empty() && (branches_.back().termination == TerminationReason::kClosedLoop ||
                               branches_.back().termination == TerminationReason::kStartFailed)) {
      break;
    }
    if (half->d == -1 && !branches_.empty() && !branches_.back().points.empty()) {
      // Start(u0) corrects u0 to the same point for both directions: the second half leaves the first
      // one's start point against its tangent.
      half->ray_point = branches_.back().points.front().u;
      half->direction = -branches_.back().points.front().tangent;
    }
    Trace(half.get(), -1, 0);
  }
}

void Explorer::MergeSwitch(Group* group) {
  if (diagram_.status != ExplorationStatus::kCompleted) return;  // the serial search stopped before it
  SwitchRecord& record = group->record;
  HYBRIDCONT_DEMAND(record.special_point >= 0);
  for (const auto& half : group->halves) {
    if (diagram_.status != ExplorationStatus::kCompleted) break;
    if (TraceFromPoint(half.get(), registry_.depth(record.special_point) + 1)) {
      ++record.traced;
    } else {
      ++record.skipped;
    }
  }
  diagram_.switches.push_back(std::move(record));
}

// Traces a half-branch leaving its special point, unless that ray is known (step 4).
bool Explorer::TraceFromPoint(HalfBranch* half, int depth) {
  const int id = half->parent;
  if (registry_.RayKnown(id, half->direction)) return false;
  registry_.AddRay(id, half->direction.normalized());
  Trace(half, id, depth);
  return true;
}

void Explorer::Trace(HalfBranch* half, int parent, int depth) {
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
  registry_.DropBranchPointsAtFolds(evaluator_->family_parameter(), &branch);
  for (SpecialPoint& point : branch.special_points) {  // step 2
    if (registry_.Register(&point, depth) && point.type == SpecialPointType::kSimpleBifurcation) {
      queue_.push_back(point.id);
    }
  }
  if (branch.termination == TerminationReason::kClosedLoop && parent >= 0) {
    registry_.AddRay(parent, -branch.points.back().tangent);  // it returns to the point from this side
  }
  branches_.push_back(std::move(branch));
  // A branch merged once the exploration is cancelled may have been cut short: it is not handed on.
  // A branch that could not start is not handed on either: it costs nothing to try again.
  const auto& cancel = options_.continuation.cancel;
  if (options_.on_branch && branches_.back().termination != TerminationReason::kStartFailed && !(cancel && cancel())) {
    options_.on_branch(branches_.back());
  }
  // A half-branch with a parent starts at that special point, singular (also where it is a mapped image).
  if (parent >= 0 && !half->progress.empty() && half->progress.front().point_index == 0) {
    half->progress.front().at_singular_point = true;
  }
  for (const ProgressInfo& info : half->progress) options_.continuation.progress(info);
  if (pool_) {
    CancelKnownRays();
    LaunchQueued();  // the SB points just found: their groups can start while this one merges
    DropSpeculative(half);
  }
}

// The half-branch as the serial search traces it as branch `id`: recorded by an earlier exploration, else the
// image of a merged branch, else traced now (serially, or not handed to a worker), else its worker's result.
Branch Explorer::Traced(HalfBranch* half, int id) {
  Unreserve(half);
  if (options_.recorded_branch) {
    std::optional<Branch> recorded = options_.recorded_branch(id);
    // Only the branch this half-branch gave before: leaving the same special point in the same direction d
    // from the same point (a start corrected by Newton moves by far less than the distance between starts).
    const auto same = [&](const Branch& b) {
      if (b.parent_special_point != half->parent || b.direction != half->d || b.points.empty()) return false;
      const Vector& first = b.points.front().u;
      return half->origin.size() == first.size() &&
             (first - half->origin).norm() <= 1e-3 * (1 + half->origin.norm());
    };
    if (recorded && same(*recorded)) {
      recorded->id = id;
      Recall(half, /*wait=*/true);  // traced ahead for nothing
      if (options_.on_recorded_branch) options_.on_recorded_branch(*recorded);
      half->progress.clear();
      if (options_.continuation.progress) images_.ReportImage(*recorded, &half->progress);
      return std::move(*recorded);
    }
  }
  if (std::optional<Branch> image = images_.Image(*half, id, branches_, evaluator_, &diagram_.warnings)) {
    Recall(half, /*wait=*/true);  // traced ahead for nothing
    half->progress.clear();
    if (options_.continuation.progress) images_.ReportImage(*image, &half->progress);
    // A symmetry need not leave the test functions invariant (time reversal maps physical orbits to
    // non-physical ones): their zeros on the image are found on the image.
    RedetectTestFunctions(evaluator_, options_.continuation, 0, &*image);
    return std::move(*image);
  }
  if (half->job.with_worker) return TakeWorkerResult(half, id);
  half->id = id;
  half->known = MergedBranches();
  TraceHalfBranch(evaluator_, options_, false, half);
  return std::move(half->branch);
}

std::vector<const Branch*> Explorer::MergedBranches() const {
  std::vector<const Branch*> merged;
  for (const Branch& branch : branches_) merged.push_back(&branch);
  return merged;
}

namespace {

constexpr EnumName<ExplorationStatus> kExplorationStatusNames[] = {
    {ExplorationStatus::kCompleted, "completed"},
    {ExplorationStatus::kMaxBranches, "max-branches"},
    {ExplorationStatus::kStartFailed, "start-failed"},
    {ExplorationStatus::kCancelled, "cancelled"},
};

}  // namespace
}  // namespace internal

std::string ToString(ExplorationStatus status) { return internal::EnumToString(internal::kExplorationStatusNames, status); }

std::string ExplorationOptions::Validate() const {
  return internal::OptionsCheck("ExplorationOptions")
      .Nested("continuation", continuation.Validate())
      .Nested("switching", switching.Validate())
      .AtLeast("max_depth", max_depth, 0)
      .AtLeast("max_branches", max_branches, 1)
      .Require(same_point_tolerance > 0, "same_point_tolerance", same_point_tolerance, "must be > 0")
      .Between("same_direction_cosine", same_direction_cosine, 0, 1)
      .AtLeast("known_branch_check_points", known_branch_check_points, 0)
      .Require(known_branch_tolerance >= 0, "known_branch_tolerance", known_branch_tolerance, "must be >= 0")
      .Require(known_branch_angle >= 0 && known_branch_angle < 1, "known_branch_angle", known_branch_angle,
               "must lie in [0, 1)")
      .AtLeast("threads", threads, 1)
      .message();
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
  return internal::Explorer(problem, options).Run(u0, nullptr);
}

BifurcationDiagram Explore(ZeroProblem* problem, const Vector& u0, const Vector& tangent,
                           const ExplorationOptions& options) {
  return internal::Explorer(problem, options).Run(u0, &tangent);
}

}  // namespace hybridcont
