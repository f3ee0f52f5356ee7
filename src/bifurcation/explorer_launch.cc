// Launching half-branches ahead of their merge (explorer.h; docs/design/exploration.md, "Threads" and
// "Speculative switch groups"). Serially every group waits for its turn and nothing here runs but
// Launch; concurrently the workers trace ahead and the merge (exploration.cc) replays the serial
// decisions on their results.
#include <algorithm>
#include <span>
#include <utility>

#include "bifurcation/explorer.h"
#include "hybridcont/invariant.h"

namespace hybridcont::internal {

// Serially a group waits for its turn. Concurrently its half-branches are handed to the workers now,
// each under the branch id it gets if no half-branch before it is skipped, as long as they can still
// become branches within max_branches (one that is not handed over is traced when its turn comes).
void Explorer::Launch(std::unique_ptr<Group> group) {
  if (pool_) Submit(group.get());
  groups_.push_back(std::move(group));
}

// The group's half-branches not yet launched (an adopted speculative group has them launched already).
void Explorer::Submit(Group* group) {
  HYBRIDCONT_DEMAND(pool_ != nullptr);
  for (size_t i = 0; i < group->halves.size(); ++i) {
    HalfBranch* half = group->halves[i].get();
    if (half->job.with_worker || half->job.reserved) continue;
    if (BranchBudgetSpent()) break;
    half->id = static_cast<int>(branches_.size()) + in_flight_++;
    if (ExpectedImage(*half, std::span(group->halves).first(i))) {
      half->job.reserved = true;  // mapped at its merge (or traced there if its source does not come)
      continue;
    }
    half->known = MergedBranches();
    half->job.with_worker = true;
    half->job.publish = [pool = pool_.get(), half](const SpecialPoint& point) { pool->Publish(half, point); };
    pool_->Submit(half);
  }
}

bool Explorer::BranchBudgetSpent() const {
  return static_cast<int>(branches_.size()) + in_flight_ >= options_.max_branches;
}

// A worker's trace of `half` as branch `id`: ended at the first checkpoint that lies on a branch merged
// after it was launched, and relabeled when it was traced under another id. While waiting for it, the
// SB points the workers publish start their switch groups.
Branch Explorer::TakeWorkerResult(HalfBranch* half, int id) {
  for (long seen = -1; !pool_->WaitOrEvent(half, &seen);) Speculate();
  pool_->Wait(half);  // rethrows what its tracing threw
  half->job.with_worker = false;
  --in_flight_;
  Branch branch = std::move(half->branch);
  const std::vector<const Branch*> merged = MergedBranches();
  HYBRIDCONT_DEMAND(half->known.size() <= merged.size());
  const std::span<const Branch* const> unseen = std::span(merged).subspan(half->known.size());
  if (!unseen.empty()) {
    for (Branch& checkpoint : half->job.checkpoints) {
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

// While the exploring thread waits for the half-branch it merges next and no half-branch waits for a
// worker, the switch group of an SB point a worker has published is launched at once. The merge that
// queues the point adopts the group (AdoptSpeculative); one that does not drops it (DropSpeculative).
void Explorer::Speculate() {
  std::vector<HalfBranch*> sources;
  const auto collect = [&](const Group& group) {
    for (const auto& half : group.halves) {
      if (half->job.with_worker && !half->job.cancelled) sources.push_back(half.get());
    }
  };
  for (const auto& group : groups_) collect(*group);
  for (const Speculative& speculative : speculative_) collect(*speculative.group);
  for (HalfBranch* source : sources) {
    for (const SpecialPoint& point : pool_->Early(source, source->job.early_seen)) {
      if (!pool_->Idle() || BranchBudgetSpent()) return;  // looked at again on the next event
      ++source->job.early_seen;
      if (source->job.depth >= options_.max_depth || Known(point.u)) continue;
      // The serial search may never switch at this point (a later duplicate, a point its merge cuts
      // off): an exception of the problem here is not the run's. Switch(id) recomputes, and throws
      // exactly when the serial search would.
      std::unique_ptr<Group> group;
      try {
        group = SwitchGroup(point, source->job.depth + 1);
      } catch (...) {
        continue;
      }
      Submit(group.get());
      speculative_.push_back({source, point.u, std::move(group)});
    }
  }
}

// An SB point registered already, or one a speculative group was launched for.
bool Explorer::Known(const Vector& u) const {
  const auto same = [&](const Vector& v) {
    return (u - v).lpNorm<Eigen::Infinity>() <= options_.same_point_tolerance * (1 + v.norm());
  };
  return registry_.Contains(u) ||
         std::any_of(speculative_.begin(), speculative_.end(), [&](const Speculative& s) { return same(s.u); });
}

std::unique_ptr<Explorer::Group> Explorer::AdoptSpeculative(int id) {
  const SpecialPoint& point = registry_.point(id);
  const auto it =
      std::find_if(speculative_.begin(), speculative_.end(), [&](const Speculative& s) { return s.u == point.u; });
  if (it == speculative_.end()) return nullptr;
  std::unique_ptr<Group> group = std::move(it->group);
  speculative_.erase(it);
  return TiedTo(id, std::move(group));
}

// After `source` was merged (or skipped): its speculative groups whose point was not queued are dropped,
// with whatever was launched from their own half-branches.
void Explorer::DropSpeculative(const HalfBranch* source) {
  const auto queued = [&](const Vector& u) {
    return std::any_of(queue_.begin(), queue_.end(), [&](int id) { return registry_.point(id).u == u; });
  };
  for (size_t i = 0; i < speculative_.size();) {
    if (speculative_[i].source != source || queued(speculative_[i].u)) {
      ++i;
      continue;
    }
    std::unique_ptr<Group> group = std::move(speculative_[i].group);
    speculative_.erase(speculative_.begin() + static_cast<long>(i));
    for (const auto& half : group->halves) {
      Unreserve(half.get());
      Recall(half.get(), /*wait=*/false);
      DropSpeculative(half.get());
    }
    dropped_.push_back(std::move(group));  // kept until the workers are joined
    i = 0;
  }
}

// A half-branch in flight whose ray is known by now will be skipped at its merge (rays only accumulate):
// its worker stops at its next point instead of tracing it to the end. Not waited for here; the merge
// collects it as any skipped half-branch.
void Explorer::CancelKnownRays() {
  for (const auto& group : groups_) {
    for (const auto& half : group->halves) {
      if (!half->job.with_worker || half->job.cancelled || half->parent < 0) continue;
      if (registry_.RayKnown(half->parent, half->direction)) pool_->RequestCancel(half.get());
    }
  }
}

// At launch: `half` will probably be mapped at its merge, as the image of a merged branch or of a
// half-branch launched before it (`earlier`: those of its own group). Only saves a worker's time; the
// decision is SymmetricImages::Image's, at the merge.
bool Explorer::ExpectedImage(const HalfBranch& half, std::span<const std::unique_ptr<HalfBranch>> earlier) const {
  if (images_.symmetries().empty() || half.ray_point.size() == 0) return false;
  const auto image_of = [&](const Vector& q, const Vector& w) {
    return images_.MapsAnyRay(q, w, half.ray_point, half.direction);
  };
  for (const Branch& branch : branches_) {
    if (SymmetricImages::Mappable(branch) && image_of(branch.points.front().u, branch.points.front().tangent)) {
      return true;
    }
  }
  const auto launched = [&](const std::unique_ptr<HalfBranch>& other) {
    return other->ray_point.size() > 0 && image_of(other->ray_point, other->direction);
  };
  for (const auto& group : groups_) {
    if (std::any_of(group->halves.begin(), group->halves.end(), launched)) return true;
  }
  return std::any_of(earlier.begin(), earlier.end(), launched);
}

// `half` no longer holds a reserved id.
void Explorer::Unreserve(HalfBranch* half) {
  if (!half->job.reserved) return;
  half->job.reserved = false;
  --in_flight_;
  HYBRIDCONT_DEMAND(in_flight_ >= 0);
}

// `half`'s worker is not needed: cancelled (waiting until it stops, or not) and its slot freed.
void Explorer::Recall(HalfBranch* half, bool wait) {
  if (!half->job.with_worker) return;
  HYBRIDCONT_DEMAND(pool_ != nullptr);
  if (wait) {
    pool_->Cancel(half);
  } else {
    pool_->RequestCancel(half);
  }
  half->job.with_worker = false;
  --in_flight_;
  HYBRIDCONT_DEMAND(in_flight_ >= 0);
}

}  // namespace hybridcont::internal
