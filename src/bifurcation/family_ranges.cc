#include "hybridcont/family_ranges.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <initializer_list>

#include "hybridcont/invariant.h"

namespace hybridcont {

namespace {

// The special points that explain an end of a physical stretch, and of a stable one, in order of preference.
constexpr SpecialPointType kPhysicalEnds[] = {SpecialPointType::kGrazing, SpecialPointType::kZeroDuration,
                                              SpecialPointType::kConstraintBoundary, SpecialPointType::kTurningPoint,
                                              SpecialPointType::kSimpleBifurcation};
constexpr SpecialPointType kStabilityEnds[] = {
    SpecialPointType::kFloquetBranchPoint, SpecialPointType::kPeriodDoubling, SpecialPointType::kNeimarkSacker,
    SpecialPointType::kKreinCollision,     SpecialPointType::kTurningPoint,   SpecialPointType::kSimpleBifurcation,
    SpecialPointType::kGrazing,            SpecialPointType::kZeroDuration,   SpecialPointType::kConstraintBoundary};

template <std::size_t N>
const SpecialPoint* Explaining(const Branch& b, int after, const SpecialPointType (&types)[N]) {
  for (const SpecialPointType type : types) {
    for (const SpecialPoint& sp : b.special_points) {
      if (sp.index == after && sp.type == type && sp.u.size() > 0) return &sp;
    }
  }
  return nullptr;
}

RangeEnd AtPoint(const Branch& b, int i, int coordinate, bool first) {
  RangeEnd end;
  end.value = b.points[i].u(coordinate);
  end.located = true;
  const std::string start = b.parent_special_point >= 0
                                ? fmt::format("start of the branch, at special point #{}", b.parent_special_point)
                                : std::string("start of the branch");
  if (first && i == 0 && b.parent_special_point >= 0) end.special_point = b.parent_special_point;
  end.how = first ? (i == 0 ? start : "point " + std::to_string(i))
                  : (i + 1 == static_cast<int>(b.points.size()) ? "end of the branch, " + ToString(b.termination)
                                                                  : "point " + std::to_string(i));
  return end;
}

// The end between points `after` and `after` + 1; at the non-physical one of them when it lies on the
// boundary of the physical orbits (`boundary` empty: none does).
template <std::size_t N>
RangeEnd Between(const Branch& b, int after, int coordinate, const SpecialPointType (&types)[N],
                 const std::vector<bool>& boundary, int outside) {
  RangeEnd end;
  if (!boundary.empty() && boundary[outside]) {
    end.value = b.points[outside].u(coordinate);
    end.located = true;
    end.how = fmt::format("point {}, on the boundary", outside);
    return end;
  }
  if (const SpecialPoint* sp = Explaining(b, after, types)) {
    end.value = sp->u(coordinate);
    end.located = sp->status == LocationStatus::kLocated;
    end.precision = sp->interval_width.size() > coordinate ? std::abs(sp->interval_width(coordinate)) : std::nan("");
    end.special_point = sp->id;
    end.how = fmt::format("{} #{}, {}", Code(sp->type), sp->id, end.located ? "located" : "bracketed");
    if (std::isfinite(end.precision)) end.how += fmt::format(" to {:.1e}", end.precision);
    return end;
  }
  const double a = b.points[after].u(coordinate), c = b.points[after + 1].u(coordinate);
  end.value = 0.5 * (a + c);
  end.precision = 0.5 * std::abs(c - a);
  end.how = fmt::format("between points {} and {}, not located", after, after + 1);
  return end;
}

// Orbits a run cannot say anything of (RangesOnBranch): not resolved by the integration, or (for stability)
// of multipliers that cannot tell; empty vectors: none.
struct Unknown {
  const std::vector<bool>& unresolved;
  const std::vector<bool>& undetermined;
  bool at(int k) const { return (!unresolved.empty() && unresolved[k]) || (!undetermined.empty() && undetermined[k]); }
};

// The point i of a run next to such an orbit k: the run ends there, exactly; `first`: it begins there.
RangeEnd NextToUnknown(const Branch& b, int i, int k, int coordinate, bool first, const Unknown& unknown) {
  RangeEnd end = AtPoint(b, i, coordinate, first);
  const bool unresolved = !unknown.unresolved.empty() && unknown.unresolved[k];
  const char* which = first ? "first" : "last";
  end.how = unresolved ? fmt::format("point {}, the {} orbit the integration resolves", i, which)
                       : fmt::format("point {}, the {} orbit whose multipliers tell its stability", i, which);
  return end;
}

template <std::size_t N>
std::vector<Range> Runs(const Branch& b, const std::vector<bool>& in, int coordinate, const SpecialPointType (&types)[N],
                        const std::vector<bool>& boundary, const Unknown& unknown) {
  std::vector<Range> runs;
  const int n = static_cast<int>(std::min(in.size(), b.points.size()));
  for (int i = 0; i < n;) {
    if (!in[i]) {
      ++i;
      continue;
    }
    int j = i;
    while (j + 1 < n && in[j + 1]) ++j;
    Range r;
    r.first_point = i, r.last_point = j;
    r.from = i == 0                 ? AtPoint(b, 0, coordinate, true)
             : unknown.at(i - 1)    ? NextToUnknown(b, i, i - 1, coordinate, true, unknown)
                                    : Between(b, i - 1, coordinate, types, boundary, i - 1);
    r.to = j + 1 == static_cast<int>(b.points.size()) ? AtPoint(b, j, coordinate, false)
           : unknown.at(j + 1)                        ? NextToUnknown(b, j, j + 1, coordinate, false, unknown)
                                                      : Between(b, j, coordinate, types, boundary, j + 1);
    // A branch that leaves a special point (a change of the phase sequence, a bifurcation) and is physical
    // there only, its next point not, without a special point between them: the family is physical at that
    // point alone (a stance-only oscillation that meets hopping where the flight shrinks to zero).
    if (j == 0 && b.parent_special_point >= 0 && !r.to.located && r.to.special_point < 0) {
      r.to = AtPoint(b, 0, coordinate, true);
    }
    // Split at the folds of the coordinate inside the run: each stretch runs one way in it, from end to end.
    for (const SpecialPoint& sp : b.special_points) {
      if (sp.type != SpecialPointType::kTurningPoint || sp.component_index != coordinate || sp.u.size() == 0 ||
          sp.index < r.first_point || sp.index >= r.last_point) {
        continue;
      }
      const SpecialPointType fold[] = {SpecialPointType::kTurningPoint};
      Range before = r;
      before.last_point = sp.index;
      before.to = Between(b, sp.index, coordinate, fold, {}, 0);
      r.first_point = sp.index + 1;
      r.from = before.to;
      runs.push_back(std::move(before));
    }
    runs.push_back(std::move(r));
    i = j + 1;
  }
  return runs;
}

}  // namespace

BranchRanges RangesOnBranch(const Branch& b, const std::vector<bool>& physical, const std::vector<bool>& stable,
                            const std::vector<bool>& boundary, int coordinate, const std::vector<bool>& unresolved,
                            const std::vector<bool>& undetermined) {
  HYBRIDCONT_DEMAND(physical.size() == stable.size() && physical.size() == boundary.size());
  HYBRIDCONT_DEMAND(unresolved.empty() || unresolved.size() == physical.size());
  HYBRIDCONT_DEMAND(undetermined.empty() || undetermined.size() == physical.size());
  BranchRanges out;
  out.branch = b.id;
  if (b.points.empty()) return out;
  HYBRIDCONT_DEMAND(coordinate >= 0 && coordinate < b.points.front().u.size());
  std::vector<bool> both(stable.size());
  std::vector<bool> resolved(physical.size());
  for (std::size_t i = 0; i < stable.size(); ++i) {
    resolved[i] = physical[i] && (unresolved.empty() || !unresolved[i]);
    both[i] = resolved[i] && stable[i] && (undetermined.empty() || !undetermined[i]);
  }
  const std::vector<bool> none;
  out.physical = Runs(b, resolved, coordinate, kPhysicalEnds, boundary, Unknown{unresolved, none});
  out.stable = Runs(b, both, coordinate, kStabilityEnds, boundary, Unknown{unresolved, undetermined});
  if (!out.stable.empty() && b.parent_special_point >= 0 && out.stable.front().last_point == 0) {
    out.stable.erase(out.stable.begin());  // the bifurcation point the branch leaves, neutral there
  }
  return out;
}

std::string ToString(const RangeEnd& end) { return fmt::format("{:.10g} ({})", end.value, end.how); }

}  // namespace hybridcont
