#include "study/io/study_document.h"

#include "study/io/json_fields.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <stdexcept>

namespace hybridcont::study {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

RangeEnd EndFromSummary(const nlohmann::json& r, const std::string& side, const std::string& where) {
  RangeEnd end;
  end.value = JsonNumber(r, side, where);
  if (!std::isfinite(end.value)) Malformed(where + "." + side, "expected a finite number (an end of a range)");
  end.how = JsonText(r, side + "_how", where, "");
  end.special_point = JsonInt(r, side + "_special_point", where, -1);
  // Saved is the end's text; located is what it says (family_ranges.h, RangeEnd::how).
  end.located = end.how.find("not located") == std::string::npos;
  end.precision = kNaN;
  return end;
}

std::vector<Range> RangesFromSummary(const nlohmann::json& entry, const std::string& key, const std::string& where) {
  std::vector<Range> ranges;
  const nlohmann::json* list = FindField(entry, key);
  if (list == nullptr) return ranges;
  if (!list->is_array()) Malformed(where + "." + key, "expected a list");
  for (std::size_t i = 0; i < list->size(); ++i) {
    const std::string at = where + "." + key + "[" + std::to_string(i) + "]";
    const nlohmann::json& r = (*list)[i];
    if (!r.is_object()) Malformed(at, "expected an object");
    Range range;
    range.from = EndFromSummary(r, "from", at);
    range.to = EndFromSummary(r, "to", at);
    range.first_point = JsonInt(r, "first_point", at);
    range.last_point = JsonInt(r, "last_point", at);
    range.family = JsonText(r, "family", at, "");
    ranges.push_back(range);
  }
  return ranges;
}

}  // namespace

StudyBranch BranchFromSummary(const nlohmann::json& entry, const std::vector<std::string>& unknowns,
                              const std::string& where) {
  if (!entry.is_object()) Malformed(where, "expected an object");
  StudyBranch b;
  b.id = JsonInt(entry, "id", where);
  b.model = JsonText(entry, "model", where, "");
  b.unknown_names = FindField(entry, "unknowns") ? JsonTexts(entry, "unknowns", where) : unknowns;
  b.word = JsonTexts(entry, "word", where);
  b.direction = JsonInt(entry, "direction", where, +1);
  b.parent_special_point = JsonInt(entry, "parent", where, -1);
  b.depth = JsonInt(entry, "depth", where, 0);
  b.image_of = JsonInt(entry, "image_of", where, -1);
  b.symmetry = JsonText(entry, "symmetry", where, "");
  b.reflected_from = JsonInt(entry, "reflected_from", where, -1);
  b.termination = JsonText(entry, "termination", where);
  b.message = JsonText(entry, "message", where, "");
  b.family = JsonText(entry, "family", where, "");
  b.ranges.branch = b.id;
  b.ranges.physical = RangesFromSummary(entry, "physical_ranges", where);
  b.ranges.stable = RangesFromSummary(entry, "stable_ranges", where);
  b.newton_iterations = JsonInt(entry, "newton_iterations", where, 0);
  b.rejected_steps = JsonInt(entry, "rejected_steps", where, 0);
  b.period_doubled_from = JsonInt(entry, "period_doubled_from", where, -1);
  b.handed_over_from = JsonInt(entry, "handed_over_from", where, -1);
  // Its origin (since 0.9.0; before: "started_in_word" for some families of other words, none for the others).
  const std::string started = JsonText(entry, "started_in_word", where, "");
  b.started_in_word = FindField(entry, "started_in_word") != nullptr;
  b.origin = JsonText(entry, "origin", where, b.period_doubled_from >= 0 ? "period-doubled" : started);
  return b;
}

StudySpecialPoint SpecialPointFromSummary(const nlohmann::json& entry, const std::string& where) {
  if (!entry.is_object()) Malformed(where, "expected an object");
  StudySpecialPoint p;
  p.id = JsonInt(entry, "id", where);
  p.code = JsonText(entry, "type", where);
  if (!FromCode(p.code, &p.type)) Malformed(where + ".type", "'" + p.code + "' is no special-point code");
  p.branch = JsonInt(entry, "branch", where);
  p.index = JsonInt(entry, "index", where);
  p.H = JsonNumber(entry, "H", where, kNaN);
  p.T = JsonNumber(entry, "T", where, kNaN);
  p.status = JsonText(entry, "status", where);
  p.precision = JsonNumber(entry, "precision", where, kNaN);
  p.precision_arclength = JsonNumber(entry, "precision_arclength", where, kNaN);
  p.precision_H = JsonNumber(entry, "precision_H", where, kNaN);
  p.residual = JsonNumber(entry, "residual", where, kNaN);
  p.component = JsonText(entry, "component", where, "");
  p.duplicate_of = JsonInt(entry, "duplicate_of", where, -1);
  p.message = JsonText(entry, "message", where, "");
  const nlohmann::json* u = FindField(entry, "u");
  if (u != nullptr) {
    if (!u->is_array()) Malformed(where + ".u", "expected a list of numbers");
    p.u.resize(static_cast<Eigen::Index>(u->size()));
    for (std::size_t i = 0; i < u->size(); ++i) {
      p.u(static_cast<Eigen::Index>(i)) = JsonNumberValue((*u)[i], where + ".u[" + std::to_string(i) + "]");
    }
  }
  p.word = JsonTexts(entry, "word", where);
  p.period_doubled_from = JsonInt(entry, "period_doubled_from", where, -1);
  if (const std::string extremum = JsonText(entry, "extremum", where, ""); !extremum.empty()) {
    if (extremum != "maximum" && extremum != "minimum") {
      Malformed(where + ".extremum", "'" + extremum + "' is neither maximum nor minimum");
    }
    p.extremum = extremum == "maximum" ? 1 : -1;
  }
  // The unknowns written by name (free parameters, observables among the unknowns): every other numeric field;
  // ResultFromSummary puts them in the order of the branch's unknowns.
  static const std::set<std::string> kFields = {"id", "type", "branch", "index", "H", "T", "status", "precision",
                                                "precision_arclength", "precision_H", "residual", "component",
                                                "duplicate_of", "message", "u", "word", "period_doubled_from",
                                                "observables", "extremum"};
  for (const auto& [name, value] : entry.items()) {
    if (!kFields.count(name) && value.is_number()) p.named_unknowns.push_back({name, value.get<double>()});
  }
  if (const nlohmann::json* values = FindField(entry, "observables")) {
    if (!values->is_object()) Malformed(where + ".observables", "expected an object");
    for (const auto& [name, value] : values->items()) {
      p.observables.push_back({name, value.is_null() ? kNaN : JsonNumberValue(value, where + ".observables." + name)});
    }
  }
  return p;
}

namespace {

// The key-frame orbits summary.json lists (their samples are orbit-<k>.csv's: LoadStudy reads them).
std::vector<StudyOrbit> OrbitsFromSummary(const nlohmann::json& summary) {
  std::vector<StudyOrbit> out;
  const nlohmann::json* orbits = FindField(summary, "orbits");
  if (orbits == nullptr || !orbits->is_array()) return out;
  for (std::size_t i = 0; i < orbits->size(); ++i) {
    const std::string at = "orbits[" + std::to_string(i) + "]";
    StudyOrbit o;
    o.branch = JsonInt((*orbits)[i], "branch", at);
    o.index = JsonInt((*orbits)[i], "index", at);
    o.family = JsonText((*orbits)[i], "label", at, "");
    o.H = JsonNumber((*orbits)[i], "H", at, kNaN);
    o.T = JsonNumber((*orbits)[i], "T", at, kNaN);
    if (const nlohmann::json* m = FindField((*orbits)[i], "monodromy"); m != nullptr && m->is_array()) {
      const auto n = static_cast<Eigen::Index>(m->size());
      o.monodromy = Matrix::Constant(n, n, kNaN);
      for (Eigen::Index row = 0; row < n; ++row) {
        const nlohmann::json& entries = (*m)[static_cast<std::size_t>(row)];
        if (!entries.is_array() || static_cast<Eigen::Index>(entries.size()) != n) {
          throw std::invalid_argument("summary.json: " + at + ".monodromy is not a square matrix");
        }
        for (Eigen::Index col = 0; col < n; ++col) {
          const nlohmann::json& v = entries[static_cast<std::size_t>(col)];
          if (!v.is_number()) throw std::invalid_argument("summary.json: " + at + ".monodromy holds a non-number");
          o.monodromy(row, col) = v.get<double>();
        }
      }
    }
    out.push_back(std::move(o));
  }
  return out;
}

// The record of the study's model (since 0.7.0); a folder without it is rebuilt by the model's name, as then.
StudyModelSource ModelSourceFromSummary(const nlohmann::json& summary, const std::string& model) {
  StudyModelSource source{StudyModelSource::Kind::kName, model, "", "", ""};
  const nlohmann::json* m = FindField(summary, "model_source");
  if (m == nullptr) return source;
  if (!m->is_object()) Malformed("model_source", "expected an object");
  const std::string kind = JsonText(*m, "kind", "model_source");
  if (!FromString(kind, &source.kind)) Malformed("model_source.kind", "'" + kind + "' is no kind of model source");
  source.name = JsonText(*m, "name", "model_source", model);
  source.path = JsonText(*m, "path", "model_source", "");
  source.sha256 = JsonText(*m, "sha256", "model_source", "");
  source.text = JsonText(*m, "text", "model_source", "");
  return source;
}

// summary.json's "words" and "word_changes" (summary_json.h, WordsJson and WordChangesJson).
void WordsFromSummary(const nlohmann::json& summary, StudyResult* r) {
  if (const nlohmann::json* words = FindField(summary, "words")) {
    if (!words->is_array()) Malformed("words", "expected a list");
    for (std::size_t i = 0; i < words->size(); ++i) {
      const std::string where = "words[" + std::to_string(i) + "]";
      const nlohmann::json& w = (*words)[i];
      StudyWord word{JsonText(w, "name", where), JsonTexts(w, "word", where), {}};
      for (const nlohmann::json& id : JsonField(w, "branches", where)) {
        word.branches.push_back(static_cast<int>(JsonNumberValue(id, where + ".branches[]")));
      }
      r->words.push_back(std::move(word));
    }
  }
  const nlohmann::json* changes = FindField(summary, "word_changes");
  if (changes == nullptr) return;
  if (!changes->is_array()) Malformed("word_changes", "expected a list");
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (std::size_t i = 0; i < changes->size(); ++i) {
    const std::string where = "word_changes[" + std::to_string(i) + "]";
    const nlohmann::json& j = (*changes)[i];
    StudyWordChange c;
    c.from_word = JsonTexts(j, "from_word", where);
    c.from_branch = JsonInt(j, "from_branch", where);
    c.at = JsonText(j, "at", where);
    c.H = JsonNumber(j, "H", where, nan);
    if (const nlohmann::json* bracket = FindField(j, "H_bracket")) {
      if (!bracket->is_array() || bracket->size() != 2) Malformed(where + ".H_bracket", "expected two numbers");
      c.H_physical = JsonNumberValue((*bracket)[0], where + ".H_bracket[0]");
      c.H_beyond = JsonNumberValue((*bracket)[1], where + ".H_bracket[1]");
    }
    c.detail = JsonText(j, "detail", where, "");
    c.rule = JsonText(j, "rule", where, "");
    c.to_word = JsonTexts(j, "to_word", where);
    c.residual = JsonNumber(j, "residual", where, nan);
    c.state_difference = JsonNumber(j, "state_difference", where, nan);
    c.period_difference = JsonNumber(j, "period_difference", where, nan);
    const nlohmann::json& accepted = JsonField(j, "accepted", where);
    if (!accepted.is_boolean()) Malformed(where + ".accepted", "expected true or false");
    c.accepted = accepted.get<bool>();
    c.reason = JsonText(j, "reason", where, "");
    if (const nlohmann::json* to = FindField(j, "to_branches")) {
      if (!to->is_array()) Malformed(where + ".to_branches", "expected a list");
      for (const nlohmann::json& id : *to) c.to_branches.push_back(static_cast<int>(JsonNumberValue(id, where + ".to_branches[]")));
    }
    r->word_changes.push_back(std::move(c));
  }
}

}  // namespace

StudyBranch UnlistedBranch(int id, const StudyResult& study, const std::string& continued) {
  StudyBranch missing;
  missing.id = id;
  missing.model = study.model;
  missing.unknown_names = study.unknown_names;
  missing.continued = continued;
  missing.termination = "unlisted";
  missing.ranges.branch = id;
  return missing;
}

StudyResult ResultFromSummary(const nlohmann::json& summary, std::map<int, std::vector<StudyPoint>> points) {
  if (!summary.is_object()) Malformed("summary", "expected an object");
  StudyResult r;
  r.version = JsonText(summary, "version", "summary", "");
  r.model = JsonText(summary, "model", "summary");
  if (const nlohmann::json* p = FindField(summary, "parameters")) {
    if (!p->is_object()) Malformed("parameters", "expected an object");
    for (const auto& [name, value] : p->items()) {
      if (!value.is_number()) Malformed("parameters." + name, "expected a number");
      r.parameters.push_back({name, value.get<double>()});
    }
  }
  r.unknown_names = JsonTexts(summary, "unknowns", "summary");
  r.model_source = ModelSourceFromSummary(summary, r.model);
  // The continued coordinate: the first free parameter, else H (options.free, summary_json.h).
  std::string continued = "H";
  if (const nlohmann::json* options = FindField(summary, "options"); options != nullptr && options->is_object()) {
    const std::vector<std::string> free = JsonTexts(*options, "free", "options");
    if (!free.empty()) continued = free.front();
  }
  const nlohmann::json* branches = FindField(summary, "branches");
  if (branches == nullptr || !branches->is_array()) Malformed("branches", "expected a list");
  std::map<int, StudyBranch> listed;
  for (std::size_t i = 0; i < branches->size(); ++i) {
    const std::string where = "branches[" + std::to_string(i) + "]";
    StudyBranch b = BranchFromSummary((*branches)[i], r.unknown_names, where);
    if (b.id < 0 || b.id > 1000000) Malformed(where + ".id", "out of range: " + std::to_string(b.id));
    if (b.model.empty()) b.model = r.model;
    b.continued = continued;
    if (auto it = points.find(b.id); it != points.end()) b.points = std::move(it->second);
    if (!listed.emplace(b.id, std::move(b)).second) Malformed(where + ".id", "listed twice");
  }
  // id == index: a branch an interrupted study had not listed yet (it had no point) is there, "unlisted".
  for (auto& [id, b] : listed) {
    while (static_cast<int>(r.branches.size()) < id) {
      r.branches.push_back(UnlistedBranch(static_cast<int>(r.branches.size()), r, continued));
    }
    r.branches.push_back(std::move(b));
  }
  const nlohmann::json* special = FindField(summary, "special_points");
  if (special != nullptr) {
    if (!special->is_array()) Malformed("special_points", "expected a list");
    for (std::size_t i = 0; i < special->size(); ++i) {
      r.special_points.push_back(SpecialPointFromSummary((*special)[i], "special_points[" + std::to_string(i) + "]"));
    }
  }
  r.report = JsonText(summary, "report", "summary", "");
  r.start_note = JsonText(summary, "start_note", "summary", "");
  r.message = JsonText(summary, "status_message", "summary", "");
  const std::string status = JsonText(summary, "status", "summary", "complete");
  r.status = status == "complete" ? ExplorationStatus::kCompleted : ExplorationStatus::kCancelled;
  if (const nlohmann::json* e = FindField(summary, "exploration")) {
    if (!e->is_object()) Malformed("exploration", "expected an object");
    const std::string s = JsonText(*e, "status", "exploration");
    for (ExplorationStatus candidate : {ExplorationStatus::kCompleted, ExplorationStatus::kMaxBranches,
                                        ExplorationStatus::kStartFailed, ExplorationStatus::kCancelled}) {
      if (ToString(candidate) == s) r.status = candidate;
    }
    if (r.message.empty()) r.message = JsonText(*e, "message", "exploration", "");
  }
  r.orbits = OrbitsFromSummary(summary);
  WordsFromSummary(summary, &r);
  if (const nlohmann::json* starts = FindField(summary, "starts")) {
    r.parameter_starts = StudyParameterStarts{JsonInt(*starts, "crossings", "starts"), JsonInt(*starts, "distinct", "starts"),
                                              JsonInt(*starts, "on_traced_branches", "starts"),
                                              JsonInt(*starts, "ordinary_half_branches", "starts")};
  }
  for (StudySpecialPoint& p : r.special_points) {  // named unknowns in the order of the branch's layout
    if (p.branch < 0 || p.branch >= static_cast<int>(r.branches.size()) || p.named_unknowns.size() < 2) continue;
    const std::vector<std::string>& names = r.branches[p.branch].unknown_names;
    const auto position = [&](const NamedValue& v) { return std::find(names.begin(), names.end(), v.name) - names.begin(); };
    std::stable_sort(p.named_unknowns.begin(), p.named_unknowns.end(),
                     [&](const NamedValue& a, const NamedValue& b) { return position(a) < position(b); });
  }
  // Observables in the model's order (the presentation's list; a JSON object keeps its keys sorted).
  std::vector<std::string> declared;
  if (const nlohmann::json* presentation = FindField(summary, "presentation"); presentation && presentation->is_object()) {
    if (const nlohmann::json* list = FindField(*presentation, "observables"); list && list->is_array()) {
      for (const nlohmann::json& o : *list) {
        if (o.is_object() && o.contains("name") && o["name"].is_string()) declared.push_back(o["name"]);
      }
    }
  }
  for (StudySpecialPoint& p : r.special_points) {
    const auto position = [&](const NamedValue& v) { return std::find(declared.begin(), declared.end(), v.name) - declared.begin(); };
    std::stable_sort(p.observables.begin(), p.observables.end(),
                     [&](const NamedValue& a, const NamedValue& b) { return position(a) < position(b); });
  }
  r.families = FoldFamilies(r.branches, r.special_points);  // derived: summary.json's "families" is not read
  // Derived too ("regions" is not read); the curves are read after the summary (study_folder.cc) and set them.
  r.summary_json = summary.dump(1);
  return r;
}

}  // namespace hybridcont::study
