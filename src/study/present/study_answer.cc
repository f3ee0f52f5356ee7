#include "hybridcont/study_answer.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "hybridcont/classification.h"

namespace hybridcont {

namespace {

// The branch's continued coordinate at u (H, or the free parameter).
double Coordinate(const StudyBranch& b, const Vector& u) {
  const auto at = std::find(b.unknown_names.begin(), b.unknown_names.end(), b.continued);
  if (at == b.unknown_names.end() || u.size() == 0) return std::nan("");
  const auto k = static_cast<Eigen::Index>(at - b.unknown_names.begin());
  return k < u.size() ? u(k) : std::nan("");
}

// "1.2828 .. 1.6144  (PD4 .. BP6)" for a range: the values and how each end is known.
std::string RangeText(const Range& r, const std::vector<StudySpecialPoint>& special) {
  const auto end = [&](const RangeEnd& e) { return RangeEndText(e, special); };
  const double lo = std::min(r.from.value, r.to.value), hi = std::max(r.from.value, r.to.value);
  const bool forward = r.from.value <= r.to.value;
  return fmt::format("{:.10g} .. {:.10g}   ({} .. {})", lo, hi, end(forward ? r.from : r.to), end(forward ? r.to : r.from));
}

// Whether two lists of ranges are the same stretches of the coordinate (ends within 1e-8 relative).
bool SameRanges(const std::vector<Range>& a, const std::vector<Range>& b) {
  if (a.size() != b.size()) return false;
  const auto near = [](double x, double y) { return std::abs(x - y) <= 1e-8 * (1 + std::abs(x)); };
  for (std::size_t i = 0; i < a.size(); ++i) {
    const double a_lo = std::min(a[i].from.value, a[i].to.value), a_hi = std::max(a[i].from.value, a[i].to.value);
    const double b_lo = std::min(b[i].from.value, b[i].to.value), b_hi = std::max(b[i].from.value, b[i].to.value);
    if (!near(a_lo, b_lo) || !near(a_hi, b_hi)) return false;
  }
  return true;
}

// The branch listed before `b` that is its twin: the same family, leaving the same special point, physical and
// stable over the same ranges (the two directions from a branch point of a symmetric model, whose symmetry the
// model does not declare); -1 for none.
int TwinOf(const StudyResult& study, const StudyBranch& b) {
  if (b.parent_special_point < 0 || b.image_of >= 0 || b.family.empty()) return -1;
  for (const StudyBranch& a : study.branches) {
    if (a.id >= b.id) break;
    if (a.family == b.family && a.parent_special_point == b.parent_special_point && a.image_of < 0 &&
        SameRanges(a.ranges.physical, b.ranges.physical) && SameRanges(a.ranges.stable, b.ranges.stable)) {
      return a.id;
    }
  }
  return -1;
}

// What an orbit class usually says about a model where a whole study finds no physical orbit of it.
std::string ClassMeaning(OrbitClass c) {
  switch (c) {
    case OrbitClass::kWrongDirection:
      return "a phase ends where its event is crossed upward, while a phase ends at a downward crossing (e_i from "
             "positive to negative): an event's sign is likely reversed";
    case OrbitClass::kReversedTime:
      return "a duration is negative: the orbit runs backward in time (the family's mirror image of a physical one, "
             "or a reset or event that sends the motion back)";
    case OrbitClass::kMissedEvent:
      return "the event was crossed earlier in the phase, or the phase starts beyond it: the phase would have ended "
             "sooner (check the event and the reset into the phase)";
    case OrbitClass::kAnchorGrazing:
    case OrbitClass::kMissedAnchor:
      return "the anchor (the Poincaré section) is not crossed once, downward: check the anchor";
    case OrbitClass::kConstraintViolated:
      return "a constraint of the model is negative (a foot below the ground, a contact force pulling)";
    case OrbitClass::kDissipative:
    case OrbitClass::kAtRest:
      return "xi is not zero: the orbit is one of the unfolded field f + xi grad H, not of the model (the first "
             "integral is not kept by a phase or a reset, or the family is at rest)";
    case OrbitClass::kZeroDuration:
      return "a phase lasts no time: the orbit sits on a boundary of its phase sequence";
    case OrbitClass::kReplayFailed:
      return "the event-driven simulation from the orbit's first state does not return to it: an event is crossed "
             "between the phases' own ends";
    default:
      return "";
  }
}

// For each explored word of an automaton that repeats a shorter cycle of modes (the bipedal model's walking,
// stance > double twice: two steps), what T and the multipliers are of: the whole word, so a multiplier of one
// step's map is squared in them (a one-step flip, -1, shows as +1: a BP or SB point of the two-step cycle).
std::string RepeatedWordNote(const StudyResult& study) {
  std::vector<std::string> cycles;
  for (const StudyWord& w : study.words) {
    const std::size_t n = w.modes.size();
    if (w.branches.empty() || n < 2) continue;
    std::size_t period = n;
    for (std::size_t p = 1; p < n && period == n; ++p) {
      if (n % p != 0) continue;
      bool repeats = true;
      for (std::size_t i = p; i < n && repeats; ++i) repeats = w.modes[i] == w.modes[i % p];
      if (repeats) period = p;
    }
    if (period == n) continue;
    std::string cycle;
    for (std::size_t i = 0; i < period; ++i) cycle += (i ? " > " : "") + w.modes[i];
    const std::size_t times = n / period;
    cycles.push_back(fmt::format("{} {}", cycle, times == 2 ? std::string("twice") : fmt::format("{} times", times)));
  }
  if (cycles.empty()) return "";
  std::string list;
  for (std::size_t i = 0; i < cycles.size(); ++i) list += (i ? ", " : "") + cycles[i];
  return fmt::format("  (T and the multipliers are of the whole cycle: {};\n   a one-step flip, -1 over one step, "
                     "is +1 over the cycle: a BP or SB point)\n",
                     list);
}

// The answer's lines at most kAnswerWidth characters (a terminal's, a log's, a notebook cell's): a longer line is
// broken at its last space before the width, its continuation indented two more than the line.
constexpr std::size_t kAnswerWidth = 100;

std::string WrapLines(const std::string& text) {
  std::string out;
  std::size_t start = 0;
  while (start < text.size()) {
    const std::size_t end = std::min(text.find('\n', start), text.size());
    std::string line = text.substr(start, end - start);
    const std::string indent(line.find_first_not_of(' ') == std::string::npos ? 0 : line.find_first_not_of(' ') + 2,
                             ' ');
    while (line.size() > kAnswerWidth) {
      const std::size_t cut = line.rfind(' ', kAnswerWidth);
      if (cut == std::string::npos || cut <= indent.size()) break;  // one word longer than the width: left whole
      out += line.substr(0, cut) + "\n";
      line = indent + line.substr(cut + 1);
    }
    out += line + (end < text.size() ? "\n" : "");
    start = end + 1;
  }
  return out;
}

// Whether two located points of branch b are one point: the coordinate and the period agree within the larger of
// their precisions (and 1e-9 relative). EX points keep their own lines (they say their observable's value).
bool Coincide(const StudyBranch& b, const StudySpecialPoint& p, const StudySpecialPoint& q) {
  if (p.type == SpecialPointType::kExtremum || q.type == SpecialPointType::kExtremum || p.status != "located" ||
      q.status != "located") {
    return false;
  }
  const double x = Coordinate(b, p.u), y = Coordinate(b, q.u);
  const double tolerance = std::max({p.precision, q.precision, 1e-9 * (1 + std::abs(x))});
  return std::abs(x - y) <= tolerance && std::abs(p.T - q.T) <= std::max(tolerance, 1e-9 * (1 + std::abs(p.T)));
}

// What a special point's code says, in a few words (the README's table, special-point codes).
std::string CodeMeaning(const std::string& code) {
  static const std::map<std::string, std::string> kMeaning = {
      {"SB", "families cross"},        {"TP", "a fold"},
      {"BP", "a multiplier at +1"},    {"PD", "a multiplier at -1"},
      {"NS", "a pair on the circle"},  {"KC", "two pairs collide"},
      {"GR", "an event grazed"},       {"CB", "a constraint at 0"},
      {"ZD", "a phase vanishes"},      {"UZ", "a monitored value"},
      {"EX", "an extremum"}};
  const auto it = kMeaning.find(code);
  return it == kMeaning.end() ? code : it->second;
}

// "largest speed 0.853": an EX point's observable, which extreme, and its value there.
std::string ExtremumText(const StudySpecialPoint& sp) {
  double value = std::numeric_limits<double>::quiet_NaN();
  for (const NamedValue& v : sp.named_unknowns) {
    if (v.name == sp.component) value = v.value;
  }
  const char* which = sp.extremum > 0 ? "largest" : sp.extremum < 0 ? "smallest" : "extremal";
  return fmt::format("{} {} {:.10g}", which, sp.component, value);
}

}  // namespace

std::string RangeEndText(const RangeEnd& e, const std::vector<StudySpecialPoint>& special) {
  if (e.special_point >= 0 && e.special_point < static_cast<int>(special.size())) {
    return special[e.special_point].Label() + (e.located ? "" : ", not located");
  }
  return e.how;
}

std::string OneScreenAnswer(const StudyResult& study, double seconds) {
  std::string out;
  int points = 0, physical_branches = 0;
  for (const StudyBranch& b : study.branches) {
    points += static_cast<int>(b.points.size());
    physical_branches += !b.ranges.physical.empty();
  }
  out += fmt::format("\n{}: {} branch{} with physical orbits of {} ({} points)\n", study.model, physical_branches,
                     physical_branches == 1 ? "" : "es", study.branches.size(), points);
  // The parameter values it was computed at: the answer holds for these. A parameter the families are continued
  // in (--free, a model without first integral) varies along them: named as such, not given a value.
  if (!study.parameters.empty()) {
    std::set<std::string> continued;
    for (const StudyBranch& b : study.branches) continued.insert(b.continued);
    std::string values, varying;
    for (const NamedValue& p : study.parameters) {
      if (continued.count(p.name)) {
        varying += (varying.empty() ? "" : ", ") + p.name;
      } else {
        values += fmt::format("{}{} = {:.6g}", values.empty() ? "" : ", ", p.name, p.value);
      }
    }
    out += "at " + values + (varying.empty() ? "" : " (" + varying + " varies along the families)") + "\n";
  }
  if (!study.start_note.empty()) out += study.start_note + "\n";
  // The families over all their branches (FoldFamilies): what a sweep's table and Python's families say.
  if (!study.families.empty()) {
    out += "families, over all their branches:\n";
    const auto list = [](const std::vector<FamilyInterval>& intervals) {
      std::string text;
      for (const FamilyInterval& i : intervals) text += fmt::format("{}{:.10g} .. {:.10g}", text.empty() ? "" : ", ", i.from, i.to);
      return text.empty() ? std::string("nowhere") : text;
    };
    for (const StudyFamily& f : study.families) {
      out += fmt::format("  {}: physical {} {}; stable {}\n", f.name, f.continued, list(f.physical),
                         f.stable.empty() ? std::string("nowhere") : f.continued + " " + list(f.stable));
    }
    out += RepeatedWordNote(study);
  }
  // The extrema of the observables asked about (--extremum), on the families' physical stretches.
  std::string extrema;
  for (const StudySpecialPoint& sp : study.special_points) {
    if (sp.type != SpecialPointType::kExtremum || sp.duplicate_of >= 0 || sp.branch < 0) continue;
    const StudyBranch& b = study.branch(sp.branch);
    if (b.family.empty() || !b.OnPhysicalStretch(sp.index)) continue;
    extrema += fmt::format("  {}: {} at {} = {:.10g} ({})\n", b.family, ExtremumText(sp), b.continued,
                           Coordinate(b, sp.u), sp.Label());
  }
  if (!extrema.empty()) out += "extrema along the families:\n" + extrema;
  // Which branches leave each special point: the families a point connects.
  std::map<int, std::vector<int>> children;
  for (const StudyBranch& b : study.branches) {
    if (b.parent_special_point >= 0) children[b.parent_special_point].push_back(b.id);
  }
  const auto name = [&](const StudyBranch& b) {
    return b.family.empty() ? std::string("no physical orbit") : b.family;
  };
  for (const StudyBranch& b : study.branches) {
    if (b.ranges.physical.empty()) continue;
    const std::string& c = b.continued;
    if (const int twin = TwinOf(study, b); twin >= 0) {
      const int parent = b.parent_special_point;
      out += fmt::format("\n{} (branch {}): as branch {}, the other direction from {}: the same physical and stable "
                         "ranges\n", b.family, b.id, twin,
                         parent < static_cast<int>(study.special_points.size()) ? study.special_points[parent].Label()
                                                                               : std::to_string(parent));
      continue;
    }
    std::string head = fmt::format("\n{} (branch {}", b.family.empty() ? "unnamed family" : b.family, b.id);
    if (!b.origin.empty() && b.family.rfind(b.origin, 0) != 0) head += ", " + b.origin;
    // The image of a traced branch under a symmetry: where that branch is a physical family too, its special
    // points and connections were listed with it.
    const bool image_of_family = b.image_of >= 0 && !study.branch(b.image_of).ranges.physical.empty();
    if (b.image_of >= 0) {
      const StudyBranch& traced = study.branch(b.image_of);
      out += head + fmt::format("): the {} image of branch {}, {}\n", b.symmetry, b.image_of,
                                image_of_family ? traced.family : "which holds no physical orbit");
    } else {
      out += head + ")\n";
    }
    // A branch whose stretches belong to different families (one that turns at a fold from late to early
    // impacts) names the family of each stretch that is not the branch's.
    const auto of = [&](const Range& r) {
      return r.family.empty() || r.family == b.family ? std::string() : "  " + r.family;
    };
    for (const Range& r : b.ranges.physical) {
      out += fmt::format("  physical  {} {}{}\n", c, RangeText(r, study.special_points), of(r));
    }
    if (b.ranges.stable.empty()) out += "  stable    nowhere\n";
    for (const Range& r : b.ranges.stable) {
      out += fmt::format("  stable    {} {}{}\n", c, RangeText(r, study.special_points), of(r));
    }
    if (image_of_family) continue;
    // Its located special points on physical stretches, and where other families leave them.
    std::string located, leads;
    std::vector<const StudySpecialPoint*> listed;
    for (const StudySpecialPoint& sp : study.special_points) {
      if (sp.branch != b.id || sp.duplicate_of >= 0 || sp.code == "start" || !b.OnPhysicalStretch(sp.index)) continue;
      listed.push_back(&sp);
    }
    // Points that coincide (within their precision: an SB point of a physical family is always a BP point too)
    // are one line, their labels joined, with what each says.
    for (std::size_t i = 0; i < listed.size();) {
      std::size_t j = i + 1;
      while (j < listed.size() && Coincide(b, *listed[i], *listed[j])) ++j;
      const StudySpecialPoint& sp = *listed[i];
      std::string labels, meanings;
      double precision = 0;
      bool all_located = true;
      for (std::size_t k = i; k < j; ++k) {
        labels += (k > i ? " = " : "") + listed[k]->Label();
        meanings += (k > i ? ", " : "") + CodeMeaning(listed[k]->code);
        precision = std::max(precision, listed[k]->precision);
        all_located = all_located && listed[k]->status == "located";
      }
      if (j - i > 1) labels += " ";  // "SB1 = BP2 = PD3  H = ..."
      located += fmt::format("    {:<6} {} = {:.10g}  T = {:.10g}  {}{}\n", labels, c, Coordinate(b, sp.u), sp.T,
                             all_located ? fmt::format("(to {:.1e})", precision) : "(" + sp.status + ")",
                             j - i > 1 ? ": " + meanings
                             : sp.type == SpecialPointType::kExtremum ? "  " + ExtremumText(sp) : std::string());
      i = j;
    }
    for (const StudySpecialPoint* listed_point : listed) {
      const StudySpecialPoint& sp = *listed_point;
      const auto it = children.find(sp.id);
      if (it == children.end()) continue;
      std::vector<std::string> names;
      for (const int child : it->second) {
        const StudyBranch& k = study.branch(child);
        names.push_back(fmt::format("{} (branch {})", name(k), k.id));
      }
      std::string joined;
      for (std::size_t i = 0; i < names.size(); ++i) joined += (i ? ", " : "") + names[i];
      leads += fmt::format("    at {}: {}\n", sp.Label(), joined);
    }
    if (!located.empty()) out += "  special points (label, " + c + ", period, precision)\n" + located;
    if (!leads.empty()) out += "  families leaving it\n" + leads;
  }
  const int others = static_cast<int>(study.branches.size()) - physical_branches;
  if (others > 0) {
    // Why, as the classification of their points says it (classification.h), most frequent first.
    std::map<std::string, int> reasons;
    for (const StudyBranch& b : study.branches) {
      if (!b.ranges.physical.empty()) continue;
      for (const StudyPoint& p : b.points) ++reasons[ToString(p.analysis.classification.reason)];
    }
    std::vector<std::pair<int, std::string>> ranked;
    for (const auto& [reason, count] : reasons) ranked.push_back({-count, reason});
    std::sort(ranked.begin(), ranked.end());
    std::string why;
    for (std::size_t i = 0; i < ranked.size() && i < 3; ++i) {
      why += fmt::format("{}{} {}", i ? ", " : "", -ranked[i].first, ranked[i].second);
    }
    if (ranked.size() > 3) why += ", ...";
    out += fmt::format("\n{} more branch{} no physical orbit{}.\n", others, others == 1 ? " holds" : "es hold",
                       why.empty() ? "" : " (their points: " + why + ")");
    // What the most frequent classes usually mean, where no family is physical at all: the first thing to check.
    if (physical_branches == 0) {
      for (std::size_t i = 0; i < ranked.size() && i < 3; ++i) {
        OrbitClass c;
        if (FromString(ranked[i].second, &c) && !ClassMeaning(c).empty()) {
          out += fmt::format("  {}: {}\n", ranked[i].second, ClassMeaning(c));
        }
      }
    }
  }
  if (study.status != ExplorationStatus::kCompleted) {
    out += fmt::format("\nThe run did not complete ({}): {}\n", ToString(study.status), study.message);
  }
  out += "Every branch, special point and switch: --verbose, or \"report\" in summary.json;\n"
         "restart from a label with --from DIR --at LABEL.\n";
  out += fmt::format("wall time {:.3f} s\n", seconds);
  return WrapLines(out);
}

}  // namespace hybridcont
