#include "study/stages/families.h"

#include <fmt/format.h>

#include <algorithm>
#include <optional>
#include <cmath>
#include <map>
#include <stdexcept>
#include <set>
#include <utility>

#include "study/io/results_writer.h"

namespace hybridcont::study {

BranchFamily FamilyOfBranch(const Branch& b, const std::vector<StudyPoint>& points, int coordinate,
                            const FamilyNamer& name_of) {
  if (points.size() != b.points.size() || points.empty()) return {};  // not every point analysed
  std::vector<bool> physical, stable, boundary, unresolved, undetermined;
  for (const StudyPoint& p : points) {
    const Classification& c = p.analysis.classification;
    physical.push_back(c.physical);
    stable.push_back(c.physical && p.analysis.floquet && p.analysis.stable);
    boundary.push_back(c.reason == OrbitClass::kZeroDuration || c.reason == OrbitClass::kGrazing);
    unresolved.push_back(!p.analysis.resolved());
    undetermined.push_back(c.physical && p.analysis.floquet && p.analysis.stability_undetermined);
  }
  if (std::none_of(physical.begin(), physical.end(), [](bool p) { return p; })) return {};
  BranchFamily f;
  f.ranges = RangesOnBranch(b, physical, stable, boundary, coordinate, unresolved, undetermined);
  if (f.ranges.physical.empty()) return {};  // physical only where the integration does not resolve the orbits
  // A stretch is named at its middle point: its ends may be shared with another family (an SB point where
  // hopping in place and forward hopping meet, a fold where two families of a forced system meet).
  const auto middle = [](const Range& r) { return (r.first_point + r.last_point + 1) / 2; };
  for (Range& r : f.ranges.physical) r.family = name_of(b.points[middle(r)].u);
  // A stable stretch lies within a physical one: it is that family's (a family is never stable where it is not
  // physical, whatever the rules say at the stable stretch's own middle).
  for (Range& r : f.ranges.stable) {
    const int m = middle(r);
    const auto within = std::find_if(f.ranges.physical.begin(), f.ranges.physical.end(), [&](const Range& p) {
      return m >= std::min(p.first_point, p.last_point) && m <= std::max(p.first_point, p.last_point);
    });
    r.family = within != f.ranges.physical.end() ? within->family : name_of(b.points[m].u);
  }
  f.family = f.ranges.physical.front().family;
  return f;
}

std::string AssignBranchFamily(const Branch& b, const ShootingLayout& layout, const FamilyNamer& name_of,
                               ResultsWriter& writer) {
  const std::vector<StudyPoint>* points = writer.PointsOf(b.id);
  if (points == nullptr) return "";
  const BranchFamily f = FamilyOfBranch(b, *points, layout.continued_index(), name_of);
  if (f.family.empty()) return "";
  writer.SetBranchFamily(b.id, f);
  const std::string& name = layout.continued_name();
  std::string report = fmt::format("  branch {} ({}{}):\n", b.id, f.family,
                                   b.image_of >= 0 ? fmt::format(", image of branch {}", b.image_of) : "");
  const auto other_family = [&](const Range& r) { return r.family == f.family ? std::string() : " (" + r.family + ")"; };
  for (const Range& r : f.ranges.physical) {
    report += fmt::format("    physical from {} = {} to {}{}\n", name, ToString(r.from), ToString(r.to), other_family(r));
  }
  if (f.ranges.stable.empty()) report += "    stable nowhere\n";
  for (const Range& r : f.ranges.stable) {
    report += fmt::format("    stable   from {} = {} to {}{}\n", name, ToString(r.from), ToString(r.to), other_family(r));
  }
  return report;
}

FamilyNamer PeriodDoubledNamer(FamilyNamer parent_name_of, const ShootingLayout& parent, const ShootingLayout& doubled) {
  const Eigen::Index cycle = doubled.num_unknowns() - parent.num_unknowns();  // |c|
  const Eigen::Index tail = parent.num_unknowns() - cycle;                    // ξ, H̄, free parameters
  if (cycle <= 0 || tail < 0 || doubled.num_unknowns() != 2 * cycle + tail) {  // a broken invariant
    throw std::logic_error("PeriodDoubledNamer: the layouts are not a parent's and its doubled model's");
  }
  return [name_of = std::move(parent_name_of), cycle, tail](const Vector& u) {
    std::set<std::string> names;
    for (int j = 0; j < 2; ++j) {
      Vector u_j(cycle + tail);
      u_j << u.segment(j * cycle, cycle), u.tail(tail);
      names.insert(name_of(u_j));
    }
    std::string joined;
    for (const std::string& n : names) joined += (joined.empty() ? "" : " / ") + n;
    return "period-doubled " + joined;
  };
}

}  // namespace hybridcont::study

namespace hybridcont {

namespace {

// An end as the answer says it: the special point's label where one is there, else how it is known.
std::string EndText(const RangeEnd& e, const std::vector<StudySpecialPoint>& special) {
  if (e.special_point >= 0 && e.special_point < static_cast<int>(special.size())) {
    return special[e.special_point].Label() + (e.located ? "" : ", not located");
  }
  return e.how;
}

FamilyInterval IntervalOf(const Range& r, const std::vector<StudySpecialPoint>& special) {
  const bool forward = r.from.value <= r.to.value;
  const RangeEnd& lo = forward ? r.from : r.to;
  const RangeEnd& hi = forward ? r.to : r.from;
  return {lo.value, hi.value, EndText(lo, special), EndText(hi, special)};
}

// The union of intervals: ascending, overlapping or touching ones (within 1e-9 relative) joined, the outer
// ends kept; disjoint ones stay apart.
std::vector<FamilyInterval> Union(std::vector<FamilyInterval> list) {
  std::sort(list.begin(), list.end(), [](const FamilyInterval& a, const FamilyInterval& b) {
    return a.from < b.from || (a.from == b.from && a.to > b.to);
  });
  std::vector<FamilyInterval> out;
  for (const FamilyInterval& i : list) {
    if (!out.empty() && i.from <= out.back().to + 1e-9 * (1 + std::abs(out.back().to))) {
      if (i.to > out.back().to) out.back().to = i.to, out.back().to_end = i.to_end;
      continue;
    }
    out.push_back(i);
  }
  return out;
}

}  // namespace

std::vector<study::StabilityChange> study::StabilityChanges(const StudyBranch& b) {
  std::vector<StabilityChange> changes;
  const auto c = std::find(b.unknown_names.begin(), b.unknown_names.end(), b.continued);
  if (c == b.unknown_names.end()) return changes;
  const auto coordinate = static_cast<Eigen::Index>(c - b.unknown_names.begin());
  std::optional<bool> previous;  // the stability of the last physical point with multipliers
  for (std::size_t i = 0; i < b.points.size(); ++i) {
    const OrbitAnalysis& a = b.points[i].analysis;
    if (!a.classification.physical || !a.floquet) continue;
    if (previous && a.stable != *previous) {
      StabilityChange change{static_cast<int>(i) - 1, b.points[i].u(coordinate), a.stable, false, -1, ""};
      for (const Range& r : b.ranges.stable) {  // a stable stretch that begins at point i or ends before it
        const RangeEnd* end = r.first_point == static_cast<int>(i)      ? &r.from
                              : r.last_point + 1 == static_cast<int>(i) ? &r.to
                                                                        : nullptr;
        if (end == nullptr || end->special_point < 0) continue;
        change.value = end->value;
        change.located = end->located;
        change.special_point = end->special_point;
        change.how = end->how;
      }
      changes.push_back(change);
    }
    previous = a.stable;
  }
  return changes;
}

bool StudyBranch::OnPhysicalStretch(int index) const {
  for (const Range& r : ranges.physical) {
    if (index >= std::min(r.first_point, r.last_point) - 1 && index <= std::max(r.first_point, r.last_point)) {
      return true;
    }
  }
  return false;
}

std::vector<StudyFamily> FoldFamilies(const std::vector<StudyBranch>& branches,
                                      const std::vector<StudySpecialPoint>& special_points) {
  std::vector<StudyFamily> families;
  std::map<std::pair<std::string, std::string>, std::size_t> index;  // (name, coordinate) -> families[i]
  const auto family = [&](const std::string& name, const std::string& continued) -> StudyFamily& {
    const auto [it, added] = index.try_emplace({name, continued}, families.size());
    if (added) families.push_back(StudyFamily{name, continued, {}, {}, {}, {}});
    return families[it->second];
  };
  for (const StudyBranch& b : branches) {
    for (const bool physical : {true, false}) {
      for (const Range& r : physical ? b.ranges.physical : b.ranges.stable) {
        StudyFamily& f = family(r.family.empty() ? b.family : r.family, b.continued);
        (physical ? f.physical : f.stable).push_back(IntervalOf(r, special_points));
        if (f.branches.empty() || f.branches.back() != b.id) f.branches.push_back(b.id);
      }
    }
  }
  for (StudyFamily& f : families) {
    f.physical = Union(std::move(f.physical));
    f.stable = Union(std::move(f.stable));
    std::sort(f.branches.begin(), f.branches.end());
    f.branches.erase(std::unique(f.branches.begin(), f.branches.end()), f.branches.end());
  }
  // The located special points on each family's physical stretches (the branch's own family, or the family of
  // the stretch the point lies on).
  for (const StudySpecialPoint& sp : special_points) {
    if (sp.duplicate_of >= 0 || sp.code == "start" || sp.status != "located") continue;
    const auto on = std::find_if(branches.begin(), branches.end(), [&](const StudyBranch& b) { return b.id == sp.branch; });
    if (on == branches.end()) continue;
    const StudyBranch& b = *on;
    for (const Range& r : b.ranges.physical) {
      if (sp.index < std::min(r.first_point, r.last_point) - 1 || sp.index > std::max(r.first_point, r.last_point)) {
        continue;
      }
      std::vector<std::string>& labels = family(r.family.empty() ? b.family : r.family, b.continued).special_points;
      if (std::find(labels.begin(), labels.end(), sp.Label()) == labels.end()) labels.push_back(sp.Label());
      break;
    }
  }
  return families;
}

}  // namespace hybridcont
