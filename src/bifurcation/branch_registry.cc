// Known special points, rays and branches of an exploration (branch_registry.h).
#include "bifurcation/branch_registry.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <utility>

#include "continuation/branch_geometry.h"
#include "hybridcont/invariant.h"

namespace hybridcont::internal {

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
                             length * (AngleBetween(a.tangent, b.tangent) / 4 + 1e-3);
      // Parallel tangent: p's tangent against the known branch's tangent at the projection (the two end
      // tangents interpolated, exact to far less than a quarter of their angle). A branch crossing the
      // known one at a small angle θ stays within the chord sag near the crossing, but its tangent is θ
      // off everywhere.
      const Vector known_tangent = ((1 - t) * a.tangent + t * b.tangent).normalized();
      const double angle = std::acos(std::min(1.0, std::abs(p.tangent.dot(known_tangent))));
      const double allowed_angle = AngleBetween(a.tangent, b.tangent) / 4 + options.known_branch_angle;
      if (distance <= allowed && angle <= allowed_angle) return branch->id;
    }
  }
  return -1;
}

namespace {

// |a.u − b.u| <= a's and b's interval widths + tolerance·(1 + ||b.u||), componentwise.
bool WithinPrecisions(const SpecialPoint& a, const SpecialPoint& b, double tolerance) {
  Vector allowed = Vector::Constant(a.u.size(), tolerance * (1 + b.u.norm()));
  for (const SpecialPoint* p : {&a, &b}) {
    if (p->interval_width.size() == allowed.size()) allowed += p->interval_width.cwiseAbs();
  }
  return ((a.u - b.u).cwiseAbs().array() <= allowed.array()).all();
}

}  // namespace

std::string KnownBranchMessage(int other) { return "runs along branch " + std::to_string(other) + " (already traced)"; }

void BranchRegistry::DropBranchPointsAtFolds(const std::string& family_parameter, Branch* branch) const {
  std::vector<SpecialPoint>& points = branch->special_points;
  const auto at_fold = [&](const SpecialPoint& bp) {
    if (bp.type != SpecialPointType::kFloquetBranchPoint || bp.u.size() == 0) return false;
    return std::any_of(points.begin(), points.end(), [&](const SpecialPoint& tp) {
      return tp.type == SpecialPointType::kTurningPoint && tp.component == family_parameter &&
             tp.u.size() == bp.u.size() && WithinPrecisions(bp, tp, same_point_tolerance_);
    });
  };
  points.erase(std::remove_if(points.begin(), points.end(), at_fold), points.end());
}

bool BranchRegistry::Register(SpecialPoint* point, int depth) {
  for (const SpecialPoint& known : points_) {
    const bool comparable = point->type == known.type || (point->type == SpecialPointType::kSimpleBifurcation &&
                                                          known.type == SpecialPointType::kSingularStart);
    if (comparable && point->component == known.component && point->u.size() == known.u.size() &&
        WithinPrecisions(*point, known, same_point_tolerance_)) {
      point->duplicate_of = known.id;
      point->id = known.id;
      AddPassingRays(known.id, *point);
      return false;
    }
  }
  const int id = AddUnique(*point, depth);
  point->id = id;
  AddPassingRays(id, *point);
  return true;
}

int BranchRegistry::AddUnique(SpecialPoint point, int depth) {
  point.id = static_cast<int>(points_.size());
  point.duplicate_of = -1;
  points_.push_back(std::move(point));
  depth_.push_back(depth);
  line_angle_.push_back(std::numbers::pi / 2);
  return points_.back().id;
}

void BranchRegistry::AddPassingRays(int id, const SpecialPoint& point) {
  if (point.type == SpecialPointType::kTurningPoint) return;
  rays_.push_back({id, point.tangent});
  rays_.push_back({id, -point.tangent});
}

bool BranchRegistry::RayKnown(int id, const Vector& direction) const {
  HYBRIDCONT_DEMAND(id >= 0 && id < static_cast<int>(line_angle_.size()));
  const Vector unit = direction.normalized();
  const double cosine = std::max(same_direction_cosine_, std::cos(0.5 * line_angle_[id]));
  return std::any_of(rays_.begin(), rays_.end(),
                     [&](const Ray& ray) { return ray.point == id && ray.direction.dot(unit) >= cosine; });
}

void BranchRegistry::NoteLines(int id, const std::vector<Vector>& lines) {
  HYBRIDCONT_DEMAND(id >= 0 && id < static_cast<int>(line_angle_.size()));
  for (size_t i = 0; i < lines.size(); ++i) {
    for (size_t j = i + 1; j < lines.size(); ++j) {
      const double c = std::abs(lines[i].normalized().dot(lines[j].normalized()));
      line_angle_[id] = std::min(line_angle_[id], std::acos(std::min(1.0, c)));
    }
  }
}

bool BranchRegistry::Contains(const Vector& u) const {
  return std::any_of(points_.begin(), points_.end(), [&](const SpecialPoint& p) {
    return (u - p.u).lpNorm<Eigen::Infinity>() <= same_point_tolerance_ * (1 + p.u.norm());
  });
}

const SpecialPoint& BranchRegistry::point(int id) const {
  HYBRIDCONT_DEMAND(id >= 0 && id < static_cast<int>(points_.size()));
  return points_[id];
}

int BranchRegistry::depth(int id) const {
  HYBRIDCONT_DEMAND(id >= 0 && id < static_cast<int>(depth_.size()));
  return depth_[id];
}

}  // namespace hybridcont::internal
