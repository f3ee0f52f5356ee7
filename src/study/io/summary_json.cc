#include "study/io/summary_json.h"

#include <cmath>
#include <memory>
#include <stdexcept>

#include "hybridcont/orbit_observables.h"
#include "study/engine/model_exploration.h"

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

nlohmann::json ParameterStartsJson(const StudyParameterStarts& s) {
  return {{"crossings", s.crossings},
          {"distinct", s.distinct},
          {"on_traced_branches", s.on_traced_branches},
          {"ordinary_half_branches", s.ordinary_half_branches}};
}

}  // namespace hybridcont::study
