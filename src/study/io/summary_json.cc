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

nlohmann::json SpecialPointsJson(const BifurcationDiagram& d, const ShootingLayout& layout, const HybridModel* model,
                                 const IntegratorOptions& integrator) {
  nlohmann::json list = nlohmann::json::array();
  // The model at a point's parameter values (free parameters are unknowns), for its observables.
  std::unique_ptr<HybridModel> at_point;
  if (model != nullptr && !model->observables().empty()) at_point = std::make_unique<HybridModel>(model->Clone());
  for (const SpecialPoint& sp : d.special_points) {
    const bool level = layout.has_level();  // no H̄ without a first integral
    const double H = sp.u.size() && level ? sp.u(layout.H_index()) : std::nan("");
    const double precision_H = sp.interval_width.size() && level ? sp.interval_width(layout.H_index()) : std::nan("");
    // "precision": the width of the interval that holds the point, as a distance in u (model units); state-based runs know the widths of their own unknowns
    // only (x̄_1, ξ, H̄; NaN for the rest). "precision_arclength": the same interval along the branch in
    // the engine's scaled arclength (SpecialPoint::precision()).
    const double precision_u =
        sp.interval_width.size() ? sp.interval_width.array().isNaN().select(0.0, sp.interval_width.array()).matrix().norm()
                                 : sp.precision();
    nlohmann::json j = {{"id", sp.id},
                        {"type", Code(sp.type)},
                        {"branch", sp.branch_id},
                        {"index", sp.index},
                        {"H", H},
                        {"T", sp.u.size() ? layout.Period(sp.u) : std::nan("")},
                        {"status", ToString(sp.status)},
                        {"precision", precision_u},
                        {"precision_arclength", sp.precision()},
                        {"precision_H", precision_H},
                        {"residual", sp.residual_norm},
                        {"component", sp.component},
                        {"duplicate_of", sp.duplicate_of},
                        {"message", sp.message}};
    j["u"] = std::vector<double>(sp.u.data(), sp.u.data() + sp.u.size());
    // Each free parameter's value as a field of its own, e.g. "k": 31.5 (also in "u").
    if (sp.u.size() == layout.num_unknowns()) {
      for (int i = 0; i < layout.num_free_parameters(); ++i) {
        j[layout.unknown_names()[layout.parameter_index(i)]] = sp.u(layout.parameter_index(i));
      }
      // And each observable that joined the unknowns, e.g. "speed": 0.5.
      for (int i = 0; i < layout.num_observables(); ++i) {
        j[layout.unknown_names()[layout.observable_index(i)]] = sp.u(layout.observable_index(i));
      }
      if (at_point) {
        nlohmann::json values = nlohmann::json::object();
        bool in_range = true;
        for (int i = 0; i < layout.num_free_parameters() && in_range; ++i) {
          try {
            at_point->SetParameterValue(layout.parameter_model_index(i), sp.u(layout.parameter_index(i)));
          } catch (const std::invalid_argument&) {
            in_range = false;
          }
        }
        ObservableEvaluator evaluator(*at_point, layout, integrator);
        for (int k = 0; k < static_cast<int>(at_point->observables().size()); ++k) {
          double v = 0.0;
          const std::string& name = at_point->observables()[k].name;
          if (in_range && evaluator.Evaluate(k, sp.u, &v, nullptr).ok) values[name] = v;
          else values[name] = nullptr;
        }
        j["observables"] = values;
      }
    }
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

}  // namespace hybridcont::study
