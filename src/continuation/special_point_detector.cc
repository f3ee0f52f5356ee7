#include "continuation/special_point_detector.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <sstream>
#include <utility>

#include "hybridcont/invariant.h"

namespace hybridcont::internal {

SpecialPointDetector::SpecialPointDetector(ZeroProblem* problem, Corrector* corrector, BorderedSolver* solver,
                                           const ContinuationOptions& options)
    : problem_(problem),
      corrector_(corrector),
      solver_(solver),
      names_(problem->unknown_names()),
      detect_bifurcations_(options.detect_bifurcations),
      check_integration_error_(options.check_integration_error),
      location_tolerance_(options.location_tolerance),
      max_location_iterations_(options.max_location_iterations) {
  std::vector<std::string> turning = options.turning_point_components;
  if (turning.empty() && !problem_->family_parameter().empty()) turning.push_back(problem_->family_parameter());
  for (const std::string& name : turning) {
    turning_.push_back(problem_->UnknownIndex(name));
    HYBRIDCONT_DEMAND(turning_.back() >= 0);  // ValidateFor checked the names
  }
}

void SpecialPointDetector::Detect(size_t index, Branch* branch) {
  HYBRIDCONT_DEMAND(index + 1 < branch->points.size());
  const ContinuationPoint& a = branch->points[index];
  const ContinuationPoint& b = branch->points[index + 1];
  std::vector<SpecialPoint> found;
  std::vector<SpecialPoint> bracket_only;  // each found point as its root finder left it
  if (detect_bifurcations_ && a.sb_test != 0 && b.sb_test != 0 && std::signbit(a.sb_test) != std::signbit(b.sb_test)) {
    found.push_back(Locate(SpecialPointType::kSimpleBifurcation, -1,
                           [](const Segment::Probe& p) { return p.sb_test; }, index, branch, &bracket_only));
  }
  for (const int k : turning_) {
    if (a.tangent(k) * b.tangent(k) < 0) {
      found.push_back(Locate(SpecialPointType::kTurningPoint, k,
                             [k](const Segment::Probe& p) { return p.tangent(k); }, index, branch, &bracket_only));
    }
  }
  PlaceTurningPointsAtSbPoints(b.arclength - a.arclength, bracket_only, &found);
  std::sort(found.begin(), found.end(),
            [](const SpecialPoint& x, const SpecialPoint& y) { return x.arclength < y.arclength; });
  for (SpecialPoint& point : found) {
    point.id = static_cast<int>(branch->special_points.size());
    branch->special_points.push_back(std::move(point));
  }
}

SpecialPoint SpecialPointDetector::Locate(SpecialPointType type, int k, const Test& test, size_t index,
                                          Branch* branch, std::vector<SpecialPoint>* bracket_only) {
  const ContinuationPoint& a = branch->points[index];
  const ContinuationPoint& b = branch->points[index + 1];
  Segment segment(corrector_, solver_, problem_, a, b, type == SpecialPointType::kSimpleBifurcation);
  const RootLocation root = LocateRoot(&segment, test, location_tolerance_, max_location_iterations_);
  SpecialPoint point;
  point.type = type;
  point.status = root.located ? LocationStatus::kLocated : LocationStatus::kBracketed;
  point.branch_id = branch->id;
  point.index = static_cast<int>(index);
  point.arclength = a.arclength + root.sigma;
  point.component_index = k;
  if (k >= 0) point.component = names_[k];
  point.u = root.estimate.u;
  point.tangent = root.estimate.tangent;
  if (type == SpecialPointType::kSimpleBifurcation) {
    // The induced tangent is undefined at an SB point, and next to it can be numerically meaningless
    // (dr has a second near-zero singular value, so a noisy dr mixes both branch directions in the
    // computed kernel). Kept only inside the cone of the bracketing points' regular tangents.
    point.tangent = segment.ReliableTangent(root.estimate, root.sigma);
  }
  point.tangent_before = a.tangent;
  point.tangent_after = b.tangent;
  point.test_value = root.test;
  point.interval_lo = a.arclength + root.lo;
  point.interval_hi = a.arclength + root.hi;
  point.interval_width = (root.u_hi - root.u_lo).cwiseAbs();
  point.residual_norm = root.estimate.residual;
  point.iterations = root.iterations;
  point.message = root.message;
  // An interval wider than the bracket (noise-limited locations widen it, AddIntegrationError may):
  // the components vary over all of it.
  const auto cover = [](SpecialPoint* p) {
    p->interval_width = p->interval_width.cwiseMax(p->tangent.cwiseAbs() * p->precision());
  };
  cover(&point);
  bracket_only->push_back(point);
  if (check_integration_error_) AddIntegrationError(&segment, root, test, &point);
  cover(&point);
  branch->located_iterations += root.iterations;
  return point;
}

// The estimate evaluated again with the problem's refined copy: with the error of an evaluation
// proportional to the tolerances, the change Δ of a quantity is (1 − factor) of its error at the
// problem's own tolerances. The test function's error over its slope is how far the exact root may lie
// from the computed one (δs, along the branch), the refined Newton correction how far the exact curve
// may lie from the point (δu). Where δs or δu exceed the bracket, the interval and the componentwise
// widths grow to cover them, and the message says so.
void SpecialPointDetector::AddIntegrationError(Segment* segment, const RootLocation& root, const Test& test,
                                               SpecialPoint* point) {
  constexpr double kFactor = ContinuationOptions::kIntegrationErrorFactor;
  constexpr double kScale = ContinuationOptions::kIntegrationErrorScale;
  const std::unique_ptr<ZeroProblem> refined = problem_->Refined(kFactor);
  if (refined == nullptr) return;  // exact to rounding: the bracket is the precision
  const auto not_estimated = [point](const std::string& why) {
    if (!point->message.empty()) point->message += "; ";
    point->message += "integration error not estimated (" + why + "): the precision is the bracket's";
  };
  if (root.estimate.u.size() != problem_->num_unknowns() || !(root.slope != 0)) {
    return not_estimated("no test function slope");
  }
  Segment::Probe fine;
  Vector du;
  const bool ok = segment->RefinedProbe(refined.get(), root.estimate, &fine, &du);
  problem_->AddWorkOf(*refined);
  if (!ok) return not_estimated("the evaluation at 0.1x the tolerances failed");
  const double change = std::abs(test(fine) - root.test), refined_step = du.norm();
  du *= kScale;
  const double ds = kScale * change / std::abs(root.slope);
  if (!std::isfinite(ds)) return not_estimated("not finite");
  const Vector tangent = point->tangent.size() == du.size() ? point->tangent : root.estimate.tangent;
  const Vector spread = 2 * (tangent.cwiseAbs() * ds + du.cwiseAbs());
  const double bracket = point->precision();
  // The arclength interval also takes the point's distance from the exact curve: one number that
  // bounds how far the exact special point may be from u, along the branch or off it.
  const double reach = ds + du.norm();
  point->interval_lo = std::min(point->interval_lo, point->arclength - reach);
  point->interval_hi = std::max(point->interval_hi, point->arclength + reach);
  if (point->interval_width.size() == spread.size()) point->interval_width = point->interval_width.cwiseMax(spread);
  if (point->precision() > bracket) {
    char text[640];
    std::snprintf(text, sizeof(text),
                  "integration error: evaluated with %gx the tolerances the test function moves by %.2g "
                  "(slope %.2g along the branch) and Newton by %.2g, so the root may lie %.2g away along "
                  "the branch and the point %.2g off it (twice the estimate; precision %.2g, the bracket was %.2g)",
                  kFactor, change, std::abs(root.slope), refined_step, ds, du.norm(), point->precision(), bracket);
    if (!point->message.empty()) point->message += "; ";
    point->message += text;
  }
}

// A turning point at an SB point of the same step cannot be told apart from it: the tangent, and so τ_k,
// is undefined at the SB point and next to it set by the noise, and so is the turning point's own
// integration-error estimate. "At" means inside the SB point's interval or closer than kCoincidence of
// the step (docs/design/continuation.md, "Turning point at an SB point").
void SpecialPointDetector::PlaceTurningPointsAtSbPoints(double step, const std::vector<SpecialPoint>& bracket_only,
                                                        std::vector<SpecialPoint>* found) {
  for (const SpecialPoint& sb : *found) {
    if (sb.type != SpecialPointType::kSimpleBifurcation) continue;
    for (size_t i = 0; i < found->size(); ++i) {
      SpecialPoint& tp = (*found)[i];
      const double distance = std::abs(tp.arclength - sb.arclength);
      const bool inside = tp.arclength >= sb.interval_lo && tp.arclength <= sb.interval_hi;
      if (tp.type != SpecialPointType::kTurningPoint || !(inside || distance <= kCoincidence * step)) continue;
      const SpecialPoint& bracket = bracket_only[i];
      tp.interval_lo = std::min({bracket.interval_lo, sb.interval_lo, tp.arclength - distance});
      tp.interval_hi = std::max({bracket.interval_hi, sb.interval_hi, tp.arclength + distance});
      if (bracket.interval_width.size() == sb.interval_width.size() && tp.u.size() == sb.u.size()) {
        tp.interval_width = bracket.interval_width.cwiseMax(sb.interval_width + 2 * (tp.u - sb.u).cwiseAbs());
      }
      std::ostringstream text;
      text.precision(12);
      text << "at the simple bifurcation point at s = " << sb.arclength << " (";
      if (inside) {
        text << "inside its interval";
      } else {
        text << "closer than " << kCoincidence << " of the step";
      }
      text << "), where the tangent is undefined: located as well as that point, its own integration-error "
           << "estimate is meaningless there";
      tp.message = bracket.message.empty() ? text.str() : bracket.message + "; " + text.str();
    }
  }
}

}  // namespace hybridcont::internal
