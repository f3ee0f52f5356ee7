#include "study/io/summary_json.h"

#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>

#include "hybridcont/orbit_observables.h"
#include "study/engine/model_exploration.h"
#include "study/stages/families.h"
#include "study/stages/regions.h"

namespace hybridcont::study {

namespace {

nlohmann::json BoundsJson(const ContinuationOptions& c) {
  nlohmann::json bounds = nlohmann::json::array();
  for (const auto& b : c.bounds) bounds.push_back({{"component", b.component}, {"lower", b.lower}, {"upper", b.upper}});
  for (const auto& b : c.sum_bounds) {
    bounds.push_back({{"sum_of", b.components}, {"lower", b.lower}, {"upper", b.upper}});
  }
  return bounds;
}

}  // namespace

nlohmann::json OptionsJson(const StudyOptions& options, const RunSetup& setup) {
  nlohmann::json j;
  j["formulation"] = ToString(options.formulation);
  j["integrator"] = {{"method", ToString(setup.integrator.method)},
                     {"rtol", setup.integrator.rtol},
                     {"atol", setup.integrator.atol}};
  const ContinuationOptions& c = setup.exploration.continuation;
  j["continuation"] = {{"initial_step", c.initial_step},
                       {"min_step", c.min_step},
                       {"max_step", c.max_step},
                       {"max_points", c.max_points},
                       {"location_tolerance", c.location_tolerance}};
  j["bounds"] = BoundsJson(c);
  nlohmann::json targets = nlohmann::json::array();
  for (const auto& t : c.targets) targets.push_back({{"component", t.component}, {"value", t.value}});
  j["targets"] = targets;
  j["max_branches"] = setup.exploration.max_branches;
  j["max_depth"] = setup.exploration.max_depth;
  j["threads"] = setup.exploration.threads;
  j["use_symmetries"] = setup.exploration.use_symmetries;
  nlohmann::json conditions = nlohmann::json::array();
  for (const auto& sc : setup.scenario.start_conditions) conditions.push_back(sc.description);
  j["start_conditions"] = conditions;
  for (const auto& [name, scale] : setup.scenario.unknown_scales) j["unknown_scales"][name] = scale;
  if (!setup.free.empty()) {
    j["free"] = setup.free.parameters;
    for (const auto& [name, value] : setup.free.fixed) j["fixed"][name] = value;
  }
  if (!setup.curve_parameter.empty()) {
    j["curves"] = {{"parameter", setup.curve_parameter},
                   {"lower", setup.curve_bound.lower},
                   {"upper", setup.curve_bound.upper}};
  }
  return j;
}

nlohmann::json SpecialPointsJson(const std::vector<StudySpecialPoint>& points) {
  // NaN is written as null (JSON has no NaN); LoadStudy reads null back as NaN.
  const auto number = [](double v) { return std::isnan(v) ? nlohmann::json(nullptr) : nlohmann::json(v); };
  nlohmann::json list = nlohmann::json::array();
  for (const StudySpecialPoint& p : points) {
    nlohmann::json j = {{"id", p.id},
                        {"label", p.Label()},  // what a restart's --at names; written for the folder's readers
                        {"type", p.code},
                        {"branch", p.branch},
                        {"index", p.index},
                        {"H", number(p.H)},
                        {"T", number(p.T)},
                        {"status", p.status},
                        {"precision", number(p.precision)},
                        {"precision_arclength", number(p.precision_arclength)},
                        {"precision_H", number(p.precision_H)},
                        {"residual", number(p.residual)},
                        {"component", p.component},
                        {"duplicate_of", p.duplicate_of},
                        {"message", p.message}};
    j["u"] = std::vector<double>(p.u.data(), p.u.data() + p.u.size());
    for (const NamedValue& v : p.named_unknowns) j[v.name] = number(v.value);  // "k": 31.5 (also in "u")
    if (!p.observables.empty()) {
      nlohmann::json values = nlohmann::json::object();
      for (const NamedValue& v : p.observables) values[v.name] = number(v.value);
      j["observables"] = values;
    }
    if (!p.word.empty()) j["word"] = p.word;
    if (p.period_doubled_from >= 0) j["period_doubled_from"] = p.period_doubled_from;
    if (p.extremum != 0) j["extremum"] = p.extremum > 0 ? "maximum" : "minimum";
    list.push_back(j);
  }
  return list;
}

nlohmann::json FamiliesJson(const std::vector<StudyFamily>& families) {
  const auto intervals = [](const std::vector<FamilyInterval>& list) {
    nlohmann::json a = nlohmann::json::array();
    for (const FamilyInterval& i : list) {
      a.push_back({{"from", i.from}, {"to", i.to}, {"from_end", i.from_end}, {"to_end", i.to_end}});
    }
    return a;
  };
  nlohmann::json out = nlohmann::json::array();
  for (const StudyFamily& f : families) {
    out.push_back({{"name", f.name}, {"continued", f.continued}, {"branches", f.branches},
                   {"physical", intervals(f.physical)}, {"stable", intervals(f.stable)},
                   {"special_points", f.special_points}});
  }
  return out;
}

nlohmann::json ModelSourceJson(const StudyModelSource& source) {
  nlohmann::json j = {{"kind", ToString(source.kind)}, {"name", source.name}};
  if (!source.path.empty()) j["path"] = source.path;
  if (!source.sha256.empty()) j["sha256"] = source.sha256;
  if (source.kind == StudyModelSource::Kind::kText) j["text"] = source.text;
  return j;
}

nlohmann::json WordsJson(const std::vector<StudyWord>& words) {
  nlohmann::json list = nlohmann::json::array();
  for (const StudyWord& w : words) list.push_back({{"word", w.modes}, {"name", w.name}, {"branches", w.branches}});
  return list;
}

nlohmann::json WordChangesJson(const std::vector<StudyWordChange>& changes) {
  nlohmann::json list = nlohmann::json::array();
  for (const StudyWordChange& c : changes) {
    // NaN is written as null (JSON has no NaN): H without a first integral.
    nlohmann::json j = {{"from_word", c.from_word}, {"from_branch", c.from_branch}, {"at", c.at},
                        {"H", c.H},                 {"accepted", c.accepted}};
    if (!std::isnan(c.H_physical)) {  // an end: where it was bracketed, and what lies beyond
      j["H_bracket"] = {c.H_physical, c.H_beyond};
      j["detail"] = c.detail;
    }
    if (!c.rule.empty()) {
      j["rule"] = c.rule;
      j["to_word"] = c.to_word;
      j["residual"] = c.residual;
    }
    if (!c.reason.empty() || !c.accepted) j["reason"] = c.reason;
    if (!std::isnan(c.state_difference)) {
      j["state_difference"] = c.state_difference;
      j["period_difference"] = c.period_difference;
    }
    if (!c.to_branches.empty()) j["to_branches"] = c.to_branches;
    list.push_back(std::move(j));
  }
  return list;
}

namespace {

nlohmann::json RangesJson(const std::vector<Range>& list) {
  nlohmann::json a = nlohmann::json::array();
  for (const Range& r : list) {
    a.push_back({{"from", r.from.value}, {"to", r.to.value}, {"from_how", r.from.how}, {"to_how", r.to.how},
                 {"from_special_point", r.from.special_point}, {"to_special_point", r.to.special_point},
                 {"first_point", r.first_point}, {"last_point", r.last_point}, {"family", r.family}});
  }
  return a;
}

nlohmann::json StabilityChangesJson(const StudyBranch& b) {
  nlohmann::json list = nlohmann::json::array();
  for (const StabilityChange& c : StabilityChanges(b)) {
    nlohmann::json j = {{"after_point", c.after_point}, {b.continued, c.value}, {"stable", c.stable},
                        {"located", c.located}};
    if (c.special_point >= 0) j["special_point"] = c.special_point, j["how"] = c.how;
    list.push_back(std::move(j));
  }
  return list;
}

}  // namespace

nlohmann::json BranchJson(const StudyBranch& b, int rows, const StudyResult& study) {
  nlohmann::json j = {{"id", b.id},
                      {"file", BranchFileName(b.id)},
                      {"parent", b.parent_special_point},
                      {"direction", b.direction},
                      {"depth", b.depth},
                      {"points", rows},
                      {"termination", b.termination},
                      {"message", b.message},
                      {"newton_iterations", b.newton_iterations},
                      {"rejected_steps", b.rejected_steps},
                      {"word", b.word}};
  if (b.model != study.model) j["model"] = b.model;
  if (b.model != study.model || !b.origin.empty()) {  // another model (another word's may keep the name)
    // Its own model's quantities and observables, the names of its file's columns of them.
    std::vector<std::string> quantities, observables;
    if (!b.points.empty()) {
      for (const NamedValue& q : b.points.front().quantities) quantities.push_back(q.name);
      for (const auto& [name, value] : b.points.front().analysis.observables) observables.push_back(name);
    }
    j["quantities"] = quantities;
    j["observables"] = observables;
  }
  if (!b.origin.empty()) j["origin"] = b.origin;
  if (b.unknown_names != study.unknown_names) j["unknowns"] = b.unknown_names;
  if (b.image_of >= 0) j["image_of"] = b.image_of, j["symmetry"] = b.symmetry;
  if (b.reflected_from >= 0) j["reflected_from"] = b.reflected_from, j["symmetry"] = b.symmetry;
  if (!b.family.empty()) {
    j["family"] = b.family;
    j["physical_ranges"] = RangesJson(b.ranges.physical);
    j["stable_ranges"] = RangesJson(b.ranges.stable);
  }
  if (b.period_doubled_from >= 0) {
    j["period_doubled_from"] = b.period_doubled_from;
    j["stability_changes"] = StabilityChangesJson(b);
  }
  if (b.started_in_word) j["started_in_word"] = b.origin;
  if (b.handed_over_from >= 0) j["handed_over_from"] = b.handed_over_from;
  return j;
}

nlohmann::json CurvesJson(const std::string& parameter, const std::vector<StudyCurve>& curves) {
  nlohmann::json list = nlohmann::json::array();
  for (const StudyCurve& c : curves) {
    nlohmann::json codim_two = nlohmann::json::array();
    const std::string a = c.columns.empty() ? std::string("H") : c.columns.front();
    for (const StudyCurve::CodimTwo& q : c.codim_two) {
      codim_two.push_back({{"type", q.type}, {"name", q.name}, {"status", q.status}, {a, q.a}, {parameter, q.p}});
    }
    nlohmann::json j = {{"id", c.id},
                        {"file", "curve_" + std::to_string(c.id) + ".csv"},
                        {"type", c.type},
                        {"special_point", c.special_point >= 0 ? nlohmann::json(c.special_point) : nlohmann::json(nullptr)},
                        {"status", c.status},
                        {"message", c.message},
                        {"points", c.points.size()},
                        {"coordinate", a},
                        {"codim_two", codim_two}};
    if (!c.name.empty()) j["name"] = c.name;
    if (!c.termination.empty()) j["termination"] = c.termination;
    list.push_back(std::move(j));
  }
  return list;
}

nlohmann::json RegionsJson(const std::vector<StudyRegion>& regions) {
  nlohmann::json list = nlohmann::json::array();
  for (const StudyRegion& r : regions) {
    nlohmann::json polygon = nlohmann::json::array();
    for (const auto& [p, a] : r.polygon) polygon.push_back({p, a});
    list.push_back({{"family", r.family}, {"kind", r.kind}, {"branch", r.branch}, {"polygon", std::move(polygon)}});
  }
  return list;
}

double ParameterValue(const StudyResult& result, const std::string& name) {
  for (const NamedValue& v : result.parameters) {
    if (v.name == name) return v.value;
  }
  return std::numeric_limits<double>::quiet_NaN();
}

std::string OrbitFileName(int k) { return "orbit-" + std::to_string(k) + ".csv"; }

nlohmann::json OrbitsJson(const std::vector<StudyOrbit>& orbits, int listed) {
  nlohmann::json list = nlohmann::json::array();
  for (int k = 0; k < listed && k < static_cast<int>(orbits.size()); ++k) {
    const StudyOrbit& o = orbits[k];
    nlohmann::json entry = {{"file", OrbitFileName(k)}, {"branch", o.branch}, {"index", o.index},
                            {"H", o.H},                 {"T", o.T},           {"label", o.family}};
    if (o.monodromy.size() > 0) {
      nlohmann::json rows = nlohmann::json::array();
      for (Eigen::Index i = 0; i < o.monodromy.rows(); ++i) {
        nlohmann::json row = nlohmann::json::array();
        for (Eigen::Index j = 0; j < o.monodromy.cols(); ++j) row.push_back(o.monodromy(i, j));
        rows.push_back(std::move(row));
      }
      entry["monodromy"] = std::move(rows);
    }
    list.push_back(std::move(entry));
  }
  return list;
}

nlohmann::json SummaryJson(const StudyResult& record, const std::map<int, StudyBranch>& branches,
                           const std::map<int, int>& rows, int listed_orbits, nlohmann::json document) {
  document["model"] = record.model;
  document["version"] = record.version;
  document["model_source"] = ModelSourceJson(record.model_source);
  nlohmann::json parameters = nlohmann::json::object();
  for (const NamedValue& p : record.parameters) parameters[p.name] = p.value;
  document["parameters"] = parameters;
  document["unknowns"] = record.unknown_names;
  nlohmann::json listed = nlohmann::json::array();
  std::vector<StudyBranch> ranged;  // the branches without their points, for the families
  for (const auto& [id, b] : branches) {
    const auto r = rows.find(id);
    listed.push_back(BranchJson(b, r == rows.end() ? 0 : r->second, record));
    StudyBranch copy;
    copy.id = b.id;
    copy.continued = b.continued;
    copy.family = b.family;
    copy.ranges = b.ranges;
    copy.origin = b.origin;
    ranged.push_back(std::move(copy));
  }
  document["branches"] = std::move(listed);
  // Derived, for the folder's readers that do not fold ranges themselves (LoadStudy folds them again).
  document["families"] = FamiliesJson(FoldFamilies(ranged, record.special_points));
  document["special_points"] = SpecialPointsJson(record.special_points);
  document["orbits"] = OrbitsJson(record.orbits, listed_orbits);
  if (!record.words.empty()) {
    document["words"] = WordsJson(record.words);
    document["word_changes"] = WordChangesJson(record.word_changes);
  }
  if (record.parameter_starts) document["starts"] = ParameterStartsJson(*record.parameter_starts);
  if (!record.curve_parameter.empty()) {
    document["curves"] = CurvesJson(record.curve_parameter, record.curves);
    // Derived, as the families (LoadStudy computes them again): the regions of the curves' plane.
    document["regions"] = RegionsJson(
        ParameterRegions(ranged, record.curves, record.curve_parameter, ParameterValue(record, record.curve_parameter)));
  }
  if (!record.report.empty()) document["report"] = record.report;
  if (!record.start_note.empty()) document["start_note"] = record.start_note;
  return document;
}

nlohmann::json ParameterStartsJson(const StudyParameterStarts& s) {
  return {{"crossings", s.crossings},
          {"distinct", s.distinct},
          {"on_traced_branches", s.on_traced_branches},
          {"ordinary_half_branches", s.ordinary_half_branches}};
}

}  // namespace hybridcont::study
