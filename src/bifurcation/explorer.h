// The explorer behind Explore() (exploration.h): a breadth-first search over SB points, run as a
// sequence of groups of half-branches (the start, then one group per queued SB point) merged in that
// order. The merge makes every decision of the serial search (exploration.cc); a concurrent exploration
// launches groups early and speculatively, and the merge replays the same decisions on what the workers
// traced (explorer_launch.cc; docs/design/exploration.md, "Threads").
//
//   BifurcationDiagram diagram = Explorer(problem, options).Run(u0, nullptr);
#ifndef HYBRIDCONT_BIFURCATION_EXPLORER_H_
#define HYBRIDCONT_BIFURCATION_EXPLORER_H_

#include <deque>
#include <memory>
#include <span>
#include <vector>

#include "bifurcation/branch_registry.h"
#include "bifurcation/half_branch.h"
#include "bifurcation/symmetric_images.h"
#include "bifurcation/tracing_pool.h"
#include "hybridcont/exploration.h"
#include "hybridcont/zero_problem.h"

namespace hybridcont::internal {

class Explorer {
 public:
  // Throws std::invalid_argument for a null problem or invalid options.
  Explorer(ZeroProblem* problem, const ExplorationOptions& options);
  Explorer(const Explorer&) = delete;
  Explorer& operator=(const Explorer&) = delete;

  // Explores from u0: regular (tangent given, or found) or singular (directions from the ABE).
  BifurcationDiagram Run(const Vector& u0, const Vector* tangent);

 private:
  // A group of half-branches the serial search traces one after the other.
  struct Group {
    enum class Kind { kRegularStart, kSingularStart, kSwitch };
    Kind kind = Kind::kRegularStart;
    SwitchRecord record;  // kSwitch
    std::vector<std::unique_ptr<HalfBranch>> halves;
  };
  // A switch group launched ahead of the merge of the branch its SB point lies on.
  struct Speculative {
    const HalfBranch* source;
    Vector u;
    std::unique_ptr<Group> group;
  };

  // --- The serial search and the merge (exploration.cc) ---
  bool LaunchStart(const Vector& u0, const Vector* tangent);
  std::unique_ptr<Group> RegularStart(const Vector& u0, const Vector* tangent);
  std::unique_ptr<Group> SingularStart(const Vector& u0);
  std::unique_ptr<Group> Switch(int id);
  std::unique_ptr<Group> TiedTo(int id, std::unique_ptr<Group> group);
  std::unique_ptr<Group> SwitchGroup(const SpecialPoint& point, int depth);
  std::unique_ptr<HalfBranch> FromPoint(int id, const Vector& direction, int d);
  std::unique_ptr<HalfBranch> FromPoint(const Vector& u, const Vector& direction, int d);
  void LaunchQueued();
  void Merge(Group* group);
  void MergeRegularStart(Group* group);
  void MergeSwitch(Group* group);
  bool TraceFromPoint(HalfBranch* half, int depth);
  void Trace(HalfBranch* half, int parent, int depth);
  Branch Traced(HalfBranch* half, int id);
  std::vector<const Branch*> MergedBranches() const;

  // --- Launching ahead of the merge (explorer_launch.cc; concurrent only) ---
  void Launch(std::unique_ptr<Group> group);
  void Submit(Group* group);
  bool BranchBudgetSpent() const;
  Branch TakeWorkerResult(HalfBranch* half, int id);
  void Speculate();
  bool Known(const Vector& u) const;
  std::unique_ptr<Group> AdoptSpeculative(int id);
  void DropSpeculative(const HalfBranch* source);
  void CancelKnownRays();
  bool ExpectedImage(const HalfBranch& half, std::span<const std::unique_ptr<HalfBranch>> earlier) const;
  void Unreserve(HalfBranch* half);
  void Recall(HalfBranch* half, bool wait);

  ZeroProblem* problem_;
  ExplorationOptions options_;
  // For self-symmetric loops; fixed after construction. Workers read it: declared before pool_, so that
  // it outlives the workers (pool_ joins them when destroyed), also when an exception leaves Explore.
  std::vector<Symmetry> reflecting_;
  BranchRegistry registry_;
  SymmetricImages images_;
  BifurcationDiagram diagram_;
  std::deque<Branch> branches_;                   // merged branches, id == index; elements never move
  std::deque<int> queue_;                         // SB points not yet switched at
  std::deque<std::unique_ptr<Group>> groups_;     // launched, in the serial order, not yet merged
  std::vector<Speculative> speculative_;          // launched ahead of the merge of their SB point
  std::vector<std::unique_ptr<Group>> dropped_;   // speculative groups given up, kept until the pool joins
  int in_flight_ = 0;                             // half-branches of groups_ reserved or with a worker
  std::unique_ptr<TracingPool> pool_;             // null: serial (destroyed first: joins the workers)
  ZeroProblem* evaluator_ = nullptr;              // evaluations on this thread: problem_, or the pool's clone
};

}  // namespace hybridcont::internal

#endif  // HYBRIDCONT_BIFURCATION_EXPLORER_H_
