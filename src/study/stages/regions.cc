#include "study/stages/regions.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace hybridcont::study {

namespace {

// A curve as an edge: its (p, a) points sorted by p.
struct Edge {
  std::vector<std::pair<double, double>> points;
};

}  // namespace

std::vector<StudyRegion> ParameterRegions(const std::vector<StudyBranch>& branches,
                                          const std::vector<StudyCurve>& curves, const std::string& parameter,
                                          double value) {
  std::vector<StudyRegion> regions;
  if (curves.empty() || parameter.empty()) return regions;
  // The families' coordinate: the first column of every curve (parameter_curves.h).
  const std::string a = curves.front().columns.empty() ? std::string("H") : curves.front().columns.front();
  std::vector<Edge> edges;
  for (const StudyCurve& c : curves) {
    const auto h = std::find(c.columns.begin(), c.columns.end(), a) - c.columns.begin();
    const auto q = std::find(c.columns.begin(), c.columns.end(), parameter) - c.columns.begin();
    Edge e;
    if (h < static_cast<long>(c.columns.size()) && q < static_cast<long>(c.columns.size())) {
      for (const Vector& u : c.points) {
        if (std::isfinite(u(q)) && std::isfinite(u(h))) e.points.emplace_back(u(q), u(h));
      }
    }
    std::sort(e.points.begin(), e.points.end());
    edges.push_back(std::move(e));
  }
  // The edge a range's end lies on: the curve of its special point, else a curve through (value, end).
  const auto edge_of = [&](const RangeEnd& end) -> const Edge* {
    for (std::size_t k = 0; k < curves.size(); ++k) {
      if (end.special_point >= 0 && curves[k].special_point == end.special_point && !edges[k].points.empty()) {
        return &edges[k];
      }
    }
    for (const Edge& e : edges) {
      for (const auto& [p, level] : e.points) {
        if (std::abs(p - value) <= 1e-9 * (1 + std::abs(value)) &&
            std::abs(level - end.value) <= 1e-6 * (1 + std::abs(end.value))) {
          return &e;
        }
      }
    }
    return nullptr;
  };
  const auto bound = [](const RangeEnd& end) { return end.how.find("bound-reached") != std::string::npos; };
  for (const StudyBranch& b : branches) {
    if (b.family.empty() || b.continued != a || !b.origin.empty()) continue;
    for (const auto& [kind, ranges] : {std::pair<std::string, const std::vector<Range>*>{"physical", &b.ranges.physical},
                                       {"stable", &b.ranges.stable}}) {
      for (const Range& r : *ranges) {
        const Edge* from = edge_of(r.from);
        const Edge* to = edge_of(r.to);
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
