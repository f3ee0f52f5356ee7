// Completing a self-symmetric closed loop by reflection (loop_reflection.h).
#include "bifurcation/loop_reflection.h"

#include <algorithm>
#include <iterator>
#include <utility>

#include "continuation/branch_geometry.h"
#include "continuation/progress_report.h"
#include "hybridcont/invariant.h"

namespace hybridcont::internal {
namespace {

// Whether g(P_j) lies on the step traced past M (P_j to `next`) within the chord sag, where its
// arclength 2 s_M − s_j is within that step: the check of the reflection itself (a residual alone only
// checks the equivariance of r).
bool ImageOnTracedStep(const ContinuationPoint& pj, const ContinuationPoint& next, const Vector& image,
                       double s_image, const ExplorationOptions& options) {
  if (!(s_image <= next.arclength)) return true;
  const Vector chord = next.u - pj.u;
  const double t = chord.dot(image - pj.u) / chord.squaredNorm();
  const double sag = chord.norm() * (AngleBetween(pj.tangent, next.tangent) / 4 + 1e-3);
  return t >= 0 && t <= 1 && (pj.u + t * chord - image).norm() <= sag + options.known_branch_tolerance * (1 + image.norm());
}

// The points P_0..P_j followed by g(P_j), ..., g(P_1) and the start point again.
void ReflectPoints(const Symmetry& g, double sb_sign, int j, double s_mid, std::vector<ContinuationPoint>* points) {
  const ContinuationPoint start = points->front();
  points->resize(j + 1);
  for (int i = j; i >= 0; --i) {  // g(P_j), ..., g(P_1), then the start point itself
    const ContinuationPoint& p = (*points)[i];
    ContinuationPoint q = i == 0 ? start : p;
    if (i > 0) {
      q.u = g.Apply(p.u);
      q.tangent = -g.Apply(p.tangent);
      q.sb_test = sb_sign * p.sb_test;
      q.newton_iterations = 0;
      q.contraction = 0;
    }
    q.arclength = 2 * s_mid - p.arclength;
    q.step = i == j ? (q.u - (*points)[j].u).norm() : (*points)[i + 1].step;
    points->push_back(std::move(q));
  }
}

// The mirror image of special point `sp` (before M) past M.
SpecialPoint MirroredSpecialPoint(const SpecialPoint& sp, const Symmetry& g, double sb_sign, int j, double s_mid) {
  SpecialPoint q = sp;
  q.index = 2 * j - sp.index;
  q.arclength = 2 * s_mid - sp.arclength;
  q.interval_lo = 2 * s_mid - sp.interval_hi;
  q.interval_hi = 2 * s_mid - sp.interval_lo;
  q.u = g.Apply(sp.u);
  q.tangent = -g.Apply(sp.tangent);
  q.tangent_before = -g.Apply(sp.tangent_after);
  q.tangent_after = -g.Apply(sp.tangent_before);
  q.test_value *= sp.type == SpecialPointType::kTurningPoint ? -g.signs(sp.component_index) : sb_sign;
  return q;
}

// At M: the SB point there, and the turning point that every g-invariant component has there
// (τ_k(M) = −τ_k(M)), located next to the SB point only to the noise of that singular place — on either
// side, even in the segment before P_j (the tangent stored at P_j, next to the SB point, may have that
// component's sign wrong): special points of those kinds in the last two segments closer to the fixed
// set of g than P_{j−1}. Kept once, their own images. Others past M are the images of ones before it.
std::vector<SpecialPoint> ReflectSpecialPoints(const Symmetry& g, double sb_sign, int j, double s_mid,
                                               const Branch& branch) {
  const Vector& before = branch.points[j - 1].u;
  const double fixed_distance = (before - g.Apply(before)).norm();
  const auto at_mid = [&](const SpecialPoint& sp) {
    if (sp.type == SpecialPointType::kTurningPoint && g.signs(sp.component_index) < 0) return false;
    return sp.index >= j - 1 && (sp.u - g.Apply(sp.u)).norm() <= fixed_distance;
  };
  std::vector<SpecialPoint> kept, mirrored;
  for (const SpecialPoint& sp : branch.special_points) {
    if (at_mid(sp)) {
      kept.push_back(sp);
      continue;
    }
    if (sp.arclength > s_mid) continue;  // beyond M: replaced by the mirror images below
    kept.push_back(sp);
    mirrored.push_back(MirroredSpecialPoint(sp, g, sb_sign, j, s_mid));
  }
  kept.insert(kept.end(), std::make_move_iterator(mirrored.begin()), std::make_move_iterator(mirrored.end()));
  std::stable_sort(kept.begin(), kept.end(),
                   [](const SpecialPoint& a, const SpecialPoint& b) { return a.arclength < b.arclength; });
  for (size_t i = 0; i < kept.size(); ++i) kept[i].id = static_cast<int>(i);
  return kept;
}

}  // namespace

bool IsFixed(const Symmetry& g, const Vector& u, const Vector& tangent, const ExplorationOptions& options) {
  return (g.Apply(u) - u).lpNorm<Eigen::Infinity>() <= options.same_point_tolerance * (1 + u.norm()) &&
         AngleBetween(-g.Apply(tangent).normalized(), tangent.normalized()) <= options.known_branch_angle;
}

bool FindReflection(ZeroProblem* problem, const Branch& branch, int m, const Symmetry& g,
                    const ExplorationOptions& options, Reflection* out) {
  HYBRIDCONT_DEMAND(m >= 0 && m < static_cast<int>(branch.special_points.size()));
  const SpecialPoint& mid = branch.special_points[m];
  const int j = mid.index;
  // M beyond the points the known-branch check looks at (a concurrent merge may still end the branch at
  // one of those, with the reports of its traced points), past P_0 (the reflection reads P_{j−1}), and
  // within max_points once reflected.
  if (mid.status != LocationStatus::kLocated || mid.tangent.size() == 0 ||
      j < options.known_branch_check_points || j < 1 || j + 2 != static_cast<int>(branch.points.size()) ||
      2 * j + 2 > options.continuation.max_points || !IsFixed(g, mid.u, mid.tangent, options)) {
    return false;
  }
  const ContinuationPoint& pj = branch.points[j];
  const Vector u = g.Apply(pj.u);
  if (!ImageOnTracedStep(pj, branch.points[j + 1], u, 2 * mid.arclength - pj.arclength, options)) return false;
  Vector r, tangent;
  Matrix dr;
  double sb_own = 0, sb_reference = 0;
  BorderedSolver solver;
  if (!problem->Evaluate(u, &r, &dr).ok || !(r.lpNorm<Eigen::Infinity>() <= 1e-6 * (1 + u.norm())) ||
      !InducedTangent(&solver, dr, -g.Apply(pj.tangent), &tangent, &sb_own, &sb_reference)) {
    return false;
  }
  out->g = &g;
  out->midpoint = m;
  out->sb_sign = (sb_own < 0) == (pj.sb_test < 0) ? 1.0 : -1.0;
  return true;
}

void CompleteByReflection(const Reflection& reflection, Branch* branch) {
  HYBRIDCONT_DEMAND(reflection.g != nullptr && reflection.midpoint >= 0 &&
                    reflection.midpoint < static_cast<int>(branch->special_points.size()));
  const Symmetry& g = *reflection.g;
  const SpecialPoint mid = branch->special_points[reflection.midpoint];
  const int j = mid.index;
  HYBRIDCONT_DEMAND(j >= 1 && j + 1 < static_cast<int>(branch->points.size()));
  ReflectPoints(g, reflection.sb_sign, j, mid.arclength, &branch->points);
  branch->special_points = ReflectSpecialPoints(g, reflection.sb_sign, j, mid.arclength, *branch);
  branch->termination = TerminationReason::kClosedLoop;
  branch->message = "the branch returned to its start point (its second half is the image of the first under " +
                    g.name + ")";
  branch->symmetry = g.name;
  branch->reflected_from = j + 1;
}

void ReportReflectedPoints(const Branch& branch, const std::vector<int>& progress_indices,
                           std::vector<ProgressInfo>* progress) {
  const int j = branch.reflected_from - 1;
  HYBRIDCONT_DEMAND(j >= 1);
  progress->resize(std::min(progress->size(), static_cast<size_t>(j + 1)));
  const std::vector<ContinuationPoint>& points = branch.points;
  for (size_t i = j + 1; i < points.size(); ++i) {
    const double next_step = i + 1 < points.size() ? points[i + 1].step : points[i].step;
    progress->push_back(
        PointProgress(points[i], branch.id, static_cast<int>(i), progress_indices, next_step, branch.rejected_steps));
  }
}

}  // namespace hybridcont::internal
