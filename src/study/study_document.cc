#include "study_document.h"

#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>

namespace hybridcont::study {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

[[noreturn]] void Malformed(const std::string& where, const std::string& what) {
  throw std::invalid_argument(where + ": " + what);
}

const nlohmann::json* Find(const nlohmann::json& object, const std::string& key) {
  const auto it = object.find(key);
  return it == object.end() ? nullptr : &*it;
}

// Required and optional fields of the types the format gives them; null is NaN for numbers (JSON has no NaN).
int Int(const nlohmann::json& o, const std::string& key, const std::string& where, std::optional<int> fallback = {}) {
  const nlohmann::json* v = Find(o, key);
  if (v == nullptr) {
    if (fallback) return *fallback;
    Malformed(where + "." + key, "missing");
  }
  if (!v->is_number_integer()) Malformed(where + "." + key, "expected an integer, found " + v->dump());
  const auto value = v->get<long long>();
  if (value < std::numeric_limits<int>::min() || value > std::numeric_limits<int>::max()) {
    Malformed(where + "." + key, "out of range: " + v->dump());
  }
  return static_cast<int>(value);
}

double Number(const nlohmann::json& o, const std::string& key, const std::string& where,
              std::optional<double> fallback = {}) {
  const nlohmann::json* v = Find(o, key);
  if (v == nullptr) {
    if (fallback) return *fallback;
    Malformed(where + "." + key, "missing");
  }
  if (v->is_null()) return kNaN;
  if (!v->is_number()) Malformed(where + "." + key, "expected a number, found " + v->dump());
  return v->get<double>();
}

std::string Text(const nlohmann::json& o, const std::string& key, const std::string& where,
                 std::optional<std::string> fallback = {}) {
  const nlohmann::json* v = Find(o, key);
  if (v == nullptr) {
    if (fallback) return *fallback;
    Malformed(where + "." + key, "missing");
  }
  if (!v->is_string()) Malformed(where + "." + key, "expected a string, found " + v->dump());
  return v->get<std::string>();
}

std::vector<std::string> Texts(const nlohmann::json& o, const std::string& key, const std::string& where) {
  const nlohmann::json* v = Find(o, key);
  if (v == nullptr) return {};
  if (!v->is_array()) Malformed(where + "." + key, "expected a list of strings");
  std::vector<std::string> list;
  for (std::size_t i = 0; i < v->size(); ++i) {
    if (!(*v)[i].is_string()) Malformed(where + "." + key + "[" + std::to_string(i) + "]", "expected a string");
    list.push_back((*v)[i].get<std::string>());
  }
  return list;
}

RangeEnd EndFromSummary(const nlohmann::json& r, const std::string& side, const std::string& where) {
  RangeEnd end;
  end.value = Number(r, side, where);
  end.how = Text(r, side + "_how", where, "");
  end.special_point = Int(r, side + "_special_point", where, -1);
  // Saved is the end's text; located is what it says (family_ranges.h, RangeEnd::how).
  end.located = end.how.find("not located") == std::string::npos;
  end.precision = kNaN;
  return end;
}

std::vector<Range> RangesFromSummary(const nlohmann::json& entry, const std::string& key, const std::string& where) {
  std::vector<Range> ranges;
  const nlohmann::json* list = Find(entry, key);
  if (list == nullptr) return ranges;
  if (!list->is_array()) Malformed(where + "." + key, "expected a list");
  for (std::size_t i = 0; i < list->size(); ++i) {
    const std::string at = where + "." + key + "[" + std::to_string(i) + "]";
    const nlohmann::json& r = (*list)[i];
    if (!r.is_object()) Malformed(at, "expected an object");
    Range range;
    range.from = EndFromSummary(r, "from", at);
    range.to = EndFromSummary(r, "to", at);
    range.first_point = Int(r, "first_point", at);
    range.last_point = Int(r, "last_point", at);
    ranges.push_back(range);
  }
  return ranges;
}

}  // namespace

StudyBranch BranchFromSummary(const nlohmann::json& entry, const std::vector<std::string>& unknowns,
                              const std::string& where) {
  if (!entry.is_object()) Malformed(where, "expected an object");
  StudyBranch b;
  b.id = Int(entry, "id", where);
  b.model = Text(entry, "model", where, "");
  b.unknown_names = Find(entry, "unknowns") ? Texts(entry, "unknowns", where) : unknowns;
  b.word = Texts(entry, "word", where);
  b.direction = Int(entry, "direction", where, +1);
  b.parent_special_point = Int(entry, "parent", where, -1);
  b.depth = Int(entry, "depth", where, 0);
  b.image_of = Int(entry, "image_of", where, -1);
  b.symmetry = Text(entry, "symmetry", where, "");
  b.reflected_from = Int(entry, "reflected_from", where, -1);
  b.termination = Text(entry, "termination", where);
  b.message = Text(entry, "message", where, "");
  b.family = Text(entry, "family", where, "");
  b.ranges.branch = b.id;
  b.ranges.physical = RangesFromSummary(entry, "physical_ranges", where);
  b.ranges.stable = RangesFromSummary(entry, "stable_ranges", where);
  b.period_doubled_from = Int(entry, "period_doubled_from", where, -1);
  b.handed_over_from = Int(entry, "handed_over_from", where, -1);
  return b;
}

StudySpecialPoint SpecialPointFromSummary(const nlohmann::json& entry, const std::string& where) {
  if (!entry.is_object()) Malformed(where, "expected an object");
  StudySpecialPoint p;
  p.id = Int(entry, "id", where);
  p.code = Text(entry, "type", where);
  if (!FromCode(p.code, &p.type)) Malformed(where + ".type", "'" + p.code + "' is no special-point code");
  p.branch = Int(entry, "branch", where);
  p.index = Int(entry, "index", where);
  p.H = Number(entry, "H", where, kNaN);
  p.T = Number(entry, "T", where, kNaN);
  p.status = Text(entry, "status", where);
  p.precision = Number(entry, "precision", where, kNaN);
  p.residual = Number(entry, "residual", where, kNaN);
  p.component = Text(entry, "component", where, "");
  p.duplicate_of = Int(entry, "duplicate_of", where, -1);
  p.message = Text(entry, "message", where, "");
  const nlohmann::json* u = Find(entry, "u");
  if (u != nullptr) {
    if (!u->is_array()) Malformed(where + ".u", "expected a list of numbers");
    p.u.resize(static_cast<Eigen::Index>(u->size()));
    for (std::size_t i = 0; i < u->size(); ++i) {
      const nlohmann::json& x = (*u)[i];
      if (!x.is_number() && !x.is_null()) Malformed(where + ".u[" + std::to_string(i) + "]", "expected a number");
      p.u(static_cast<Eigen::Index>(i)) = x.is_null() ? kNaN : x.get<double>();
    }
  }
  p.word = Texts(entry, "word", where);
  p.period_doubled_from = Int(entry, "period_doubled_from", where, -1);
  return p;
}

StudyResult ResultFromSummary(const nlohmann::json& summary, std::map<int, std::vector<StudyPoint>> points) {
  if (!summary.is_object()) Malformed("summary", "expected an object");
  StudyResult r;
  r.version = Text(summary, "version", "summary", "");
  r.model = Text(summary, "model", "summary");
  if (const nlohmann::json* p = Find(summary, "parameters")) {
    if (!p->is_object()) Malformed("parameters", "expected an object");
    for (const auto& [name, value] : p->items()) {
      if (!value.is_number()) Malformed("parameters." + name, "expected a number");
      r.parameters.push_back({name, value.get<double>()});
    }
  }
  r.unknown_names = Texts(summary, "unknowns", "summary");
  // The continued coordinate: the first free parameter, else H (options.free, summary_json.h).
  std::string continued = "H";
  if (const nlohmann::json* options = Find(summary, "options"); options != nullptr && options->is_object()) {
    const std::vector<std::string> free = Texts(*options, "free", "options");
    if (!free.empty()) continued = free.front();
  }
  const nlohmann::json* branches = Find(summary, "branches");
  if (branches == nullptr || !branches->is_array()) Malformed("branches", "expected a list");
  std::map<int, StudyBranch> listed;
  for (std::size_t i = 0; i < branches->size(); ++i) {
    const std::string where = "branches[" + std::to_string(i) + "]";
    StudyBranch b = BranchFromSummary((*branches)[i], r.unknown_names, where);
    if (b.id < 0 || b.id > 1000000) Malformed(where + ".id", "out of range: " + std::to_string(b.id));
    if (b.model.empty()) b.model = r.model;
    if (b.period_doubled_from >= 0) b.origin = "period-doubled";
    b.continued = continued;
    if (auto it = points.find(b.id); it != points.end()) b.points = std::move(it->second);
    if (!listed.emplace(b.id, std::move(b)).second) Malformed(where + ".id", "listed twice");
  }
  // id == index: a branch an interrupted study had not listed yet (it had no point) is there, "unlisted".
  for (auto& [id, b] : listed) {
    while (static_cast<int>(r.branches.size()) < id) {
      StudyBranch missing;
      missing.id = static_cast<int>(r.branches.size());
      missing.model = r.model;
      missing.unknown_names = r.unknown_names;
      missing.continued = continued;
      missing.termination = "unlisted";
      r.branches.push_back(std::move(missing));
    }
    r.branches.push_back(std::move(b));
  }
  const nlohmann::json* special = Find(summary, "special_points");
  if (special != nullptr) {
    if (!special->is_array()) Malformed("special_points", "expected a list");
    for (std::size_t i = 0; i < special->size(); ++i) {
      r.special_points.push_back(SpecialPointFromSummary((*special)[i], "special_points[" + std::to_string(i) + "]"));
    }
  }
  r.report = Text(summary, "report", "summary", "");
  r.message = Text(summary, "status_message", "summary", "");
  const std::string status = Text(summary, "status", "summary", "complete");
  r.status = status == "complete" ? ExplorationStatus::kCompleted : ExplorationStatus::kCancelled;
  if (const nlohmann::json* e = Find(summary, "exploration")) {
    if (!e->is_object()) Malformed("exploration", "expected an object");
    const std::string s = Text(*e, "status", "exploration");
    for (ExplorationStatus candidate : {ExplorationStatus::kCompleted, ExplorationStatus::kMaxBranches,
                                        ExplorationStatus::kStartFailed, ExplorationStatus::kCancelled}) {
      if (ToString(candidate) == s) r.status = candidate;
    }
    if (r.message.empty()) r.message = Text(*e, "message", "exploration", "");
  }
  if (const nlohmann::json* orbits = Find(summary, "orbits"); orbits != nullptr && orbits->is_array()) {
    for (std::size_t i = 0; i < orbits->size(); ++i) {
      const std::string at = "orbits[" + std::to_string(i) + "]";
      StudyOrbit o;
      o.branch = Int((*orbits)[i], "branch", at);
      o.index = Int((*orbits)[i], "index", at);
      o.family = Text((*orbits)[i], "label", at, "");
      o.H = Number((*orbits)[i], "H", at, kNaN);
      o.T = Number((*orbits)[i], "T", at, kNaN);
      r.orbits.push_back(std::move(o));
    }
  }
  r.summary_json = summary.dump(1);
  return r;
}

}  // namespace hybridcont::study
