#include "study/stages/regions.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace hybridcont::study {

namespace {

// A curve as an edge of a region: the piece of it through a range's end along which p only grows (or only
// falls), as (p, a) points sorted by p. A curve that turns in p (a PD or grazing curve folding back) has several
// arms over the same p; only the one through the end bounds that family's range.
struct Edge {
  std::vector<std::pair<double, double>> points;
};

// How close to a curve (relative to the sizes of p and a) a range's end counts as on it: the curves' sampling.
constexpr double kOnCurve = 1e-3;

// The monotone piece of `curve` ((p, a) in curve order) through its point nearest to (p, a) = at, if that point
// lies within kOnCurve of the curve (each axis relative to 1 + its size); empty otherwise.
Edge EdgeThrough(const std::vector<std::pair<double, double>>& curve, std::pair<double, double> at) {
  Edge edge;
  if (curve.size() < 2) return edge;
  const double sp = 1 + std::abs(at.first), sa = 1 + std::abs(at.second);
  std::size_t nearest = 0;
  double best = HUGE_VAL;
  for (std::size_t i = 0; i + 1 < curve.size(); ++i) {
    // Distance to the chord from i to i + 1 (scaled), and the nearer of its ends.
    const double dx = (curve[i + 1].first - curve[i].first) / sp, dy = (curve[i + 1].second - curve[i].second) / sa;
    const double px = (at.first - curve[i].first) / sp, py = (at.second - curve[i].second) / sa;
    const double length = dx * dx + dy * dy;
    const double t = length > 0 ? std::clamp((px * dx + py * dy) / length, 0.0, 1.0) : 0.0;
    const double d = std::hypot(px - t * dx, py - t * dy);
    if (d < best) best = d, nearest = t < 0.5 ? i : i + 1;
  }
  if (!(best <= kOnCurve)) return edge;
  const auto step = [&](std::size_t i, std::size_t j) { return curve[j].first - curve[i].first; };
  // The direction of p at the point: of the step after it, or before it at the curve's end.
  const double direction = nearest + 1 < curve.size() ? step(nearest, nearest + 1) : step(nearest - 1, nearest);
  std::size_t first = nearest, last = nearest;
  while (last + 1 < curve.size() && step(last, last + 1) * direction > 0) ++last;
  while (first > 0 && step(first - 1, first) * direction > 0) --first;
  edge.points.assign(curve.begin() + static_cast<long>(first), curve.begin() + static_cast<long>(last) + 1);
  std::sort(edge.points.begin(), edge.points.end());
  return edge;
}

}  // namespace

std::string CurvesCoordinate(const std::vector<StudyCurve>& curves) {
  return curves.empty() || curves.front().columns.empty() ? std::string("H") : curves.front().columns.front();
}

std::vector<StudyRegion> ParameterRegions(const std::vector<StudyBranch>& branches,
                                          const std::vector<StudyCurve>& curves, const std::string& parameter,
                                          double value) {
  std::vector<StudyRegion> regions;
  if (curves.empty() || parameter.empty()) return regions;
  const std::string a = CurvesCoordinate(curves);
  std::vector<std::vector<std::pair<double, double>>> drawn;  // each curve's (p, a), in curve order
  for (const StudyCurve& c : curves) {
    const auto h = std::find(c.columns.begin(), c.columns.end(), a) - c.columns.begin();
    const auto q = std::find(c.columns.begin(), c.columns.end(), parameter) - c.columns.begin();
    std::vector<std::pair<double, double>> points;
    if (h < static_cast<long>(c.columns.size()) && q < static_cast<long>(c.columns.size())) {
      for (const Vector& u : c.points) {
        if (std::isfinite(u(q)) && std::isfinite(u(h))) points.emplace_back(u(q), u(h));
      }
    }
    drawn.push_back(std::move(points));
  }
  // The edge a range's end lies on: the arm through it of its special point's curve, else of any curve through
  // (value, end) — a point that was not traced because it lies on another's curve (a mirror image's).
  const auto edge_of = [&](const RangeEnd& end) -> Edge {
    const std::pair<double, double> at(value, end.value);
    for (std::size_t k = 0; k < curves.size(); ++k) {
      if (end.special_point >= 0 && curves[k].special_point == end.special_point) {
        if (Edge e = EdgeThrough(drawn[k], at); !e.points.empty()) return e;
      }
    }
    for (const auto& points : drawn) {
      if (Edge e = EdgeThrough(points, at); !e.points.empty()) return e;
    }
    return {};
  };
  const auto bound = [](const RangeEnd& end) { return end.how.find("bound-reached") != std::string::npos; };
  for (const StudyBranch& b : branches) {
    if (b.family.empty() || b.continued != a || !b.origin.empty()) continue;
    for (const auto& [kind, ranges] : {std::pair<std::string, const std::vector<Range>*>{"physical", &b.ranges.physical},
                                       {"stable", &b.ranges.stable}}) {
      for (const Range& r : *ranges) {
        const Edge from_edge = edge_of(r.from), to_edge = edge_of(r.to);
        const Edge* from = from_edge.points.empty() ? nullptr : &from_edge;
        const Edge* to = to_edge.points.empty() ? nullptr : &to_edge;
        if ((!from && !bound(r.from)) || (!to && !bound(r.to)) || (!from && !to)) continue;
        // Over the p both edges cover (a bound covers every p of the other edge).
        const Edge& known = from ? *from : *to;
        double lo = known.points.front().first, hi = known.points.back().first;
        if (from && to) lo = std::max(lo, to->points.front().first), hi = std::min(hi, to->points.back().first);
        if (!(lo < hi)) continue;
        StudyRegion region;
        region.family = b.family;
        region.kind = kind;
        region.branch = b.id;
        const auto along = [&](const RangeEnd& end, const Edge* e, bool reversed) {
          std::vector<std::pair<double, double>> pts;
          if (e) {
            for (const auto& pt : e->points) {
              if (pt.first >= lo && pt.first <= hi) pts.push_back(pt);
            }
          } else {
            pts = {{lo, end.value}, {hi, end.value}};
          }
          if (reversed) std::reverse(pts.begin(), pts.end());
          region.polygon.insert(region.polygon.end(), pts.begin(), pts.end());
        };
        along(r.from, from, false);
        along(r.to, to, true);
        regions.push_back(std::move(region));
      }
    }
  }
  return regions;
}

}  // namespace hybridcont::study
