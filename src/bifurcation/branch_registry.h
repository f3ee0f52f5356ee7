// What an exploration knows already (exploration.h, steps 2 and 4): the special points, each stored
// once, the rays (point, direction) of the branches leaving, passing through or returning to them, and
// whether a point lies on a traced branch. These are the de-duplication rules; the order in which the
// explorer consults them is the serial order (exploration.cc).
//
//   BranchRegistry registry(options);
//   if (registry.Register(&point, depth) && point.type == SpecialPointType::kSimpleBifurcation) queue(point.id);
//   if (!registry.RayKnown(id, v)) { registry.AddRay(id, v); /* trace */ }
#ifndef HYBRIDCONT_BIFURCATION_BRANCH_REGISTRY_H_
#define HYBRIDCONT_BIFURCATION_BRANCH_REGISTRY_H_

#include <span>
#include <string>
#include <vector>

#include "hybridcont/continuation.h"
#include "hybridcont/exploration.h"
#include "hybridcont/special_point.h"
#include "hybridcont/types.h"

namespace hybridcont::internal {

// Id of a branch among `branches` that p lies on, or −1: within the chord sag of one of its chords plus
// known_branch_tolerance·(1 + ||u||), its tangent within known_branch_angle (plus a quarter of the angle
// across the chord) of the chord's interpolated tangent.
int OnTracedBranch(const ContinuationPoint& p, std::span<const Branch* const> branches,
                   const ExplorationOptions& options);

// Termination message of a branch ended on branch `other` (kKnownBranch).
std::string KnownBranchMessage(int other);

class BranchRegistry {
 public:
  explicit BranchRegistry(const ExplorationOptions& options)
      : same_point_tolerance_(options.same_point_tolerance), same_direction_cosine_(options.same_direction_cosine) {}

  // Gives a special point found on a branch its diagram id (a known point: duplicate_of) and records the
  // rays of the branch through it. True for a new point. A known point of the same kind is the same point
  // when every component differs by at most the two points' precisions (SpecialPoint::interval_width)
  // plus same_point_tolerance·(1 + ||u||): two crossing branches locate their common SB point each to
  // its own precision, and next to a singular place that is the noise level (~1e-6 on the SLIP), not
  // the tolerance.
  bool Register(SpecialPoint* point, int depth);
  // Stores `point` as a new unique point found at `depth`; returns its id.
  int AddUnique(SpecialPoint point, int depth);

  void AddRay(int id, const Vector& direction) { rays_.push_back({id, direction}); }
  // A ray matches a known one within same_direction_cosine, or within half the smallest angle between
  // the branch lines through the point when that is smaller (branches crossing at a small angle).
  bool RayKnown(int id, const Vector& direction) const;
  // Records the smallest angle between branch lines through special point `id`.
  void NoteLines(int id, const std::vector<Vector>& lines);

  // Removes from `branch` the zeros of the Floquet BP test function (a multiplier at +1) that are one of its
  // turning points in `family_parameter` within the points' precisions (as Register compares points): a
  // family folds in its parameter (or a conservative family in H̄, a saddle-centre) where a multiplier is
  // +1, and that point is reported once, as the fold.
  void DropBranchPointsAtFolds(const std::string& family_parameter, Branch* branch) const;

  // A unique point within same_point_tolerance of u.
  bool Contains(const Vector& u) const;
  const SpecialPoint& point(int id) const;
  int depth(int id) const;
  std::vector<SpecialPoint> TakePoints() { return std::move(points_); }

 private:
  struct Ray {
    int point;
    Vector direction;
  };

  void AddPassingRays(int id, const SpecialPoint& point);

  double same_point_tolerance_;
  double same_direction_cosine_;
  std::vector<SpecialPoint> points_;  // unique points, id == index
  std::vector<int> depth_;            // per unique point: depth of the branch it was found on
  std::vector<double> line_angle_;    // per unique point: smallest angle between its branch lines
  std::vector<Ray> rays_;
};

}  // namespace hybridcont::internal

#endif  // HYBRIDCONT_BIFURCATION_BRANCH_REGISTRY_H_
