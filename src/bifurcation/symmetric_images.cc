// Branches as symmetry images of merged branches (symmetric_images.h).
#include "bifurcation/symmetric_images.h"

#include <algorithm>
#include <limits>
#include <sstream>
#include <utility>

#include "bifurcation/branch_registry.h"
#include "continuation/branch_geometry.h"
#include "continuation/progress_report.h"
#include "hybridcont/invariant.h"

namespace hybridcont::internal {
namespace {

// source's points mapped by g (u -> S u, τ -> S τ).
std::vector<ContinuationPoint> MappedPoints(const Branch& source, const Symmetry& g) {
  std::vector<ContinuationPoint> points;
  for (const ContinuationPoint& p : source.points) {
    ContinuationPoint q = p;
    q.u = g.Apply(p.u);
    q.tangent = g.Apply(p.tangent);
    points.push_back(std::move(q));
  }
  return points;
}

// source's special points mapped by g onto branch `id`, the SB test's sign along the image being sb_sign
// times the source's.
std::vector<SpecialPoint> MappedSpecialPoints(const Branch& source, const Symmetry& g, double sb_sign, int id) {
  std::vector<SpecialPoint> points;
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
    points.push_back(std::move(q));
  }
  return points;
}

}  // namespace

SymmetricImages::SymmetricImages(ZeroProblem* problem, const ExplorationOptions& options) : options_(&options) {
  if (options.use_symmetries && !options.continuation.stop_predicate) {
    for (Symmetry& g : problem->symmetries()) {
      if (g.signs.size() == problem->num_unknowns() && MapsStopsOntoThemselves(g, *problem)) {
        symmetries_.push_back(std::move(g));
      }
    }
  }
  stops_ = LinearStops(options.continuation, *problem);
  progress_indices_ = ProgressIndices(options.continuation, *problem);
}

// Every bound, sum bound and target of the continuation is mapped onto itself by g.
bool SymmetricImages::MapsStopsOntoThemselves(const Symmetry& g, const ZeroProblem& problem) const {
  const ContinuationOptions& c = options_->continuation;
  const auto sign = [&](const std::string& name) {
    const int index = problem.UnknownIndex(name);
    HYBRIDCONT_DEMAND(index >= 0);  // the names were validated (ContinuationOptions::ValidateFor)
    return g.signs(index);
  };
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
bool SymmetricImages::MapsRay(const Symmetry& g, const Vector& q, const Vector& w, const Vector& p,
                              const Vector& v) const {
  if ((g.Apply(q) - p).lpNorm<Eigen::Infinity>() > options_->same_point_tolerance * (1 + p.norm())) return false;
  return AngleBetween(g.Apply(w).normalized(), v.normalized()) <= options_->known_branch_angle;
}

bool SymmetricImages::MapsAnyRay(const Vector& q, const Vector& w, const Vector& p, const Vector& v) const {
  return std::any_of(symmetries_.begin(), symmetries_.end(),
                     [&](const Symmetry& g) { return MapsRay(g, q, w, p, v); });
}

bool SymmetricImages::Mappable(const Branch& source) {
  return source.points.size() >= 2 && source.termination != TerminationReason::kKnownBranch &&
         source.termination != TerminationReason::kStartFailed &&
         source.termination != TerminationReason::kNotFinished;
}

std::optional<Branch> SymmetricImages::Image(const HalfBranch& half, int id, const std::deque<Branch>& merged,
                                             ZeroProblem* evaluator, std::vector<std::string>* warnings) {
  if (symmetries_.empty() || half.ray_point.size() == 0) return std::nullopt;
  for (const Branch& source : merged) {
    if (!Mappable(source)) continue;
    for (size_t k = 0; k < symmetries_.size(); ++k) {
      const Symmetry& g = symmetries_[k];
      if (!MapsRay(g, source.points.front().u, source.points.front().tangent, half.ray_point, half.direction)) {
        continue;
      }
      std::optional<Branch> image = MapBranch(source, g, id, merged, evaluator, warnings);
      if (image) return image;
      symmetries_.erase(symmetries_.begin() + static_cast<long>(k));  // failed its check: not used again
      return std::nullopt;
    }
  }
  return std::nullopt;
}

// source mapped by g as branch `id`; nothing if a mapped point fails its check.
std::optional<Branch> SymmetricImages::MapBranch(const Branch& source, const Symmetry& g, int id,
                                                 const std::deque<Branch>& merged, ZeroProblem* evaluator,
                                                 std::vector<std::string>* warnings) const {
  HYBRIDCONT_DEMAND(Mappable(source));
  Branch image;
  image.id = id;
  image.termination = source.termination;
  image.message = ImageStopMessage(source.message, g);
  image.image_of = source.id;
  image.symmetry = g.name;
  image.points = MappedPoints(source, g);
  const std::optional<double> sb_sign = CheckImage(source, image, g, evaluator, warnings);
  if (!sb_sign) return std::nullopt;
  for (ContinuationPoint& p : image.points) p.sb_test *= *sb_sign;
  image.special_points = MappedSpecialPoints(source, g, *sb_sign, id);
  EndAtKnownBranch(merged, &image);
  for (size_t i = 0; i < image.special_points.size(); ++i) image.special_points[i].id = static_cast<int>(i);
  return image;
}

// The check: r and the induced tangent at the first point after the start (the start may be singular)
// and at the last one (of a closed loop: the one before it, the last being the start again). Returns the
// sign of the SB test along the image relative to the source's, or nothing (with a warning).
std::optional<double> SymmetricImages::CheckImage(const Branch& source, const Branch& image, const Symmetry& g,
                                                  ZeroProblem* evaluator, std::vector<std::string>* warnings) const {
  double sb_sign = 1.0;
  const size_t last = image.points.size() - (source.termination == TerminationReason::kClosedLoop ? 2 : 1);
  for (const size_t i : {size_t{1}, std::max<size_t>(1, last)}) {
    const ContinuationPoint& point = image.points[i];
    Vector r;
    Matrix dr;
    const EvaluationStatus status = evaluator->Evaluate(point.u, &r, &dr);
    Vector tangent;
    double sb_own = 0, sb_reference = 0;
    BorderedSolver solver;
    const bool regular = status.ok && InducedTangent(&solver, dr, point.tangent, &tangent, &sb_own, &sb_reference);
    const double residual = status.ok ? r.lpNorm<Eigen::Infinity>() : std::numeric_limits<double>::infinity();
    if (!regular || !(residual <= 1e-6 * (1 + point.u.norm())) ||
        AngleBetween(tangent, point.tangent) > options_->known_branch_angle) {
      std::ostringstream out;
      out << "symmetry '" << g.name << "' does not map branch " << source.id << " onto solutions (|r| = " << residual
          << (regular ? ", tangent off by " + std::to_string(AngleBetween(tangent, point.tangent)) + " rad"
                      : ", singular")
          << " at its point " << i << "): not used";
      warnings->push_back(out.str());
      return std::nullopt;
    }
    // det([dr; τᵀ]) at S u with S τ is ± the source's: the sign is the same along the whole branch.
    if (i == 1) sb_sign = (sb_own < 0) == (source.points[1].sb_test < 0) ? 1.0 : -1.0;
  }
  return sb_sign;
}

// The serial trace's known-branch check on the first points (not on the last: the trace had ended).
void SymmetricImages::EndAtKnownBranch(const std::deque<Branch>& merged, Branch* image) const {
  std::vector<const Branch*> branches;
  for (const Branch& branch : merged) branches.push_back(&branch);
  const int check_points = options_->known_branch_check_points;
  for (int j = 1; j <= check_points && j + 1 < static_cast<int>(image->points.size()); ++j) {
    if (const int other = OnTracedBranch(image->points[j], branches, *options_); other >= 0) {
      image->points.resize(j + 1);
      std::erase_if(image->special_points, [j](const SpecialPoint& sp) { return sp.index >= j; });
      image->termination = TerminationReason::kKnownBranch;
      image->message = KnownBranchMessage(other);
      return;
    }
  }
}

// The termination message of an image: the stop the source reached, mapped by g (a lower bound on a
// flipped component becomes the upper one, e.g. "reached lambda >= -2" -> "reached lambda <= 2").
std::string SymmetricImages::ImageStopMessage(const std::string& message, const Symmetry& g) const {
  for (const LinearStop& stop : stops_) {
    const std::string reached = "reached " + stop.label;
    if (message.rfind(reached, 0) != 0) continue;
    const Vector c = g.Apply(stop.c);  // the image stops at cᵀ(S u) = value, i.e. (S c)ᵀu = value
    for (const LinearStop& other : stops_) {
      const bool same = other.c == c && other.value == stop.value && other.kind == stop.kind;
      const bool flipped = other.c == -c && other.value == -stop.value &&
                           (stop.kind == LinearStop::Kind::kTarget
                                ? other.kind == stop.kind
                                : other.kind != stop.kind && other.kind != LinearStop::Kind::kTarget);
      if (same || flipped) return "reached " + other.label + message.substr(reached.size());
    }
  }
  return message;
}

void SymmetricImages::ReportImage(const Branch& image, std::vector<ProgressInfo>* reports) const {
  for (size_t i = 0; i < image.points.size(); ++i) {
    const double next_step = i + 1 < image.points.size() ? image.points[i + 1].step : image.points[i].step;
    reports->push_back(PointProgress(image.points[i], image.id, static_cast<int>(i), progress_indices_, next_step, 0));
  }
}

}  // namespace hybridcont::internal
