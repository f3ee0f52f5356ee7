#include "family_report.h"

#include <fmt/format.h>

#include <algorithm>
#include <vector>

#include "hybridcont/family_ranges.h"

namespace hybridcont::study {

std::string BranchRangesReport(const Branch& b, const ShootingLayout& layout,
                               const std::function<std::string(const Vector& u)>& describe, ResultsWriter& writer) {
  const auto& points = writer.ClassifiedPoints(b.id);
  if (points.size() != b.points.size()) return "";  // points not all classified (a failed conversion)
  std::vector<bool> physical, stable, boundary;
  for (const ResultsWriter::ClassifiedPoint& p : points) {
    physical.push_back(p.classification.physical);
    stable.push_back(p.stable);
    const OrbitClass reason = p.classification.reason;
    boundary.push_back(reason == OrbitClass::kZeroDuration || reason == OrbitClass::kGrazing);
  }
  if (std::none_of(physical.begin(), physical.end(), [](bool p) { return p; })) return "";
  const int x = layout.continued_index();
  const std::string& name = layout.continued_name();
  const BranchRanges ranges = RangesOnBranch(b, physical, stable, boundary, x);
  // A stretch is named at its middle point: its ends may be shared with another family (an SB point where
  // hopping in place and forward hopping meet, a fold where two families of a forced system meet).
  const auto family_of = [&](const Range& r) { return describe(b.points[(r.first_point + r.last_point + 1) / 2].u); };
  const auto json_of = [&](const std::vector<Range>& list) {
    nlohmann::json a = nlohmann::json::array();
    for (const Range& r : list) {
      a.push_back({{"from", r.from.value}, {"to", r.to.value}, {"from_how", r.from.how}, {"to_how", r.to.how},
                   {"from_special_point", r.from.special_point}, {"to_special_point", r.to.special_point},
                   {"first_point", r.first_point}, {"last_point", r.last_point}, {"family", family_of(r)}});
    }
    return a;
  };
  const std::string family = family_of(ranges.physical.front());
  writer.AnnotateBranch(b.id, {{"family", family},
                               {"physical_ranges", json_of(ranges.physical)},
                               {"stable_ranges", json_of(ranges.stable)}});
  std::string report = fmt::format("  branch {} ({}{}):\n", b.id, family,
                                   b.image_of >= 0 ? fmt::format(", image of branch {}", b.image_of) : "");
  const auto other_family = [&](const Range& r) {
    const std::string f = family_of(r);
    return f == family ? std::string() : " (" + f + ")";
  };
  for (const Range& r : ranges.physical) {
    report += fmt::format("    physical from {} = {} to {}{}\n", name, ToString(r.from), ToString(r.to), other_family(r));
  }
  if (ranges.stable.empty()) report += "    stable nowhere\n";
  for (const Range& r : ranges.stable) {
    report += fmt::format("    stable   from {} = {} to {}{}\n", name, ToString(r.from), ToString(r.to), other_family(r));
  }
  return report;
}

}  // namespace hybridcont::study
