#include "floquet_points.h"

#include <fmt/format.h>

#include <cmath>

#include "hybridcont/floquet.h"
#include "hybridcont/test_function_root.h"
#include "summary_json.h"

namespace hybridcont::app {

namespace {

// A branch that leaves a bifurcation point starts on it: where a test function vanishes there (to
// kStartNoise of its value at the next point), its sign at the start is noise and the "crossing" is that
// point itself, reported on the parent branch.
constexpr double kStartNoise = 1e-3;

// The Floquet test function of one type ("BP" or "PD") along one branch: locates its roots and records them.
class FloquetRootSearch {
 public:
  FloquetRootSearch(const std::string& type, const Branch& branch, TimeBasedShooting& map, const ShootingLayout& layout,
                    nlohmann::json* special_points, std::string* report, int* count)
      : type_(type), branch_(branch), map_(map), layout_(layout), special_points_(special_points), report_(report),
        count_(count) {}

  // Scans consecutive points for sign changes of `values` (the test at each point) and for hidden pairs.
  void Scan(const std::vector<double>& values) {
    const std::vector<ContinuationPoint>& points = branch_.points;
    const std::size_t n = std::min(values.size(), points.size());
    for (std::size_t i = 0; i + 1 < n; ++i) {
      const bool finite = std::isfinite(values[i]) && std::isfinite(values[i + 1]);  // NaN: non-physical
      if (finite && values[i] != 0 && values[i + 1] != 0 && std::signbit(values[i]) != std::signbit(values[i + 1])) {
        // A test that is not small at the start of a child branch is searched as usual.
        if (i == 0 && branch_.parent_special_point >= 0 && std::abs(values[0]) <= kStartNoise * std::abs(values[1])) {
          continue;
        }
        Locate(i, points[i].u, points[i + 1].u);
      } else if (i >= 1) {
        LocateHiddenPair(i, values);
      }
    }
  }

 private:
  double Test(TimeBasedShooting& shooting, const Vector& u) const {
    const FloquetResult f = ComputeFloquet(shooting, u);
    return f.ok() ? (type_ == "BP" ? f.bp_test : f.pd_test) : std::nan("");
  }

  // Two crossings inside one step cancel in the signs: a local minimum of |test| whose parabola dips
  // through zero is probed (FindHiddenRootPair), and a confirmed pair located on both sides.
  void LocateHiddenPair(std::size_t i, const std::vector<double>& values) {
    const std::vector<ContinuationPoint>& p = branch_.points;
    const HiddenRootPair pair =
        FindHiddenRootPair(&map_, {&p[i - 1].u, &p[i].u, &p[i + 1].u},
                           {p[i - 1].arclength, p[i].arclength, p[i + 1].arclength},
                           {values[i - 1], values[i], values[i + 1]}, [&](const Vector& u) { return Test(map_, u); });
    if (pair.found) {
      const std::size_t k = i - 1 + static_cast<std::size_t>(pair.segment);
      Locate(k, p[k].u, pair.u);
      Locate(k, pair.u, p[k + 1].u);
    }
  }

  // Locates the root between u_a and u_b (after point i) and records it.
  void Locate(std::size_t i, const Vector& u_a, const Vector& u_b) {
    TestFunctionRootOptions options;
    options.refined_test = [&](ZeroProblem& refined, const Vector& u) {
      return Test(dynamic_cast<TimeBasedShooting&>(refined), u);  // Refined keeps the type
    };
    const TestFunctionRoot root =
        LocateTestFunctionRoot(&map_, u_a, u_b, [&](const Vector& u) { return Test(map_, u); }, options);
    special_points_->push_back(FloquetPointJson(static_cast<int>(special_points_->size()), type_, branch_.id,
                                                static_cast<int>(i), root, layout_));
    *report_ += fmt::format("  {} on branch {} after point {}: H = {:.12f}, T = {:.12f} ({}, precision {:.1e}){}\n",
                            type_, branch_.id, i, root.u(layout_.H_index()), layout_.Period(root.u),
                            root.located ? "located" : "bracketed", root.precision,
                            root.message.empty() ? "" : " " + root.message);
    ++*count_;
  }

  const std::string type_;
  const Branch& branch_;
  TimeBasedShooting& map_;
  const ShootingLayout& layout_;
  nlohmann::json* special_points_;
  std::string* report_;
  int* count_;
};

}  // namespace

std::string LocateFloquetPoints(const BifurcationDiagram& diagram, const std::map<int, std::vector<double>>& bp,
                                const std::map<int, std::vector<double>>& pd, TimeBasedShooting& map,
                                const ShootingLayout& layout, nlohmann::json* special_points) {
  std::string report = "Floquet special points (multiplier crossings on physical orbits):\n";
  int count = 0;
  for (const Branch& b : diagram.branches) {
    for (const auto& [type, tests] : {std::pair{"BP", &bp}, std::pair{"PD", &pd}}) {
      const auto it = tests->find(b.id);
      if (it == tests->end()) continue;
      FloquetRootSearch(type, b, map, layout, special_points, &report, &count).Scan(it->second);
    }
  }
  if (count == 0) report += "  none\n";
  return report;
}

}  // namespace hybridcont::app
