#include "model_exploration.h"

#include <stdexcept>

namespace hybridcont::app {

ExplorationOptions ScenarioExplorationOptions(const Scenario& sc) {
  ExplorationOptions o;
  ContinuationOptions& c = o.continuation;
  c.bounds = sc.bounds;
  c.sum_bounds = sc.sum_bounds;
  c.max_points = sc.max_points;
  c.initial_step = sc.initial_step;
  c.max_step = sc.max_step;
  o.max_depth = sc.max_depth;
  o.max_branches = sc.max_branches;
  for (const StartCondition& cond : sc.start_conditions) o.start_conditions.push_back({cond.terms});
  return o;
}

ModelExploration::ModelExploration(const HybridModel& model, const Scenario& scenario,
                                   const IntegratorOptions& integrator, ExplorationOptions options)
    : model_(model), scenario_(scenario), shooting_(model, integrator), options_(std::move(options)) {
  const std::vector<std::string> names = shooting_.unknown_names();
  ContinuationOptions& c = options_.continuation;
  if (const std::string why = c.ValidateFor(names); !why.empty()) throw std::invalid_argument(why);
  Vector scales = Vector::Ones(shooting_.num_unknowns());
  for (const auto& [name, scale] : scenario_.unknown_scales) {
    const int k = shooting_.UnknownIndex(name);
    if (k < 0) throw std::invalid_argument("scenario scale for unknown '" + name + "', which the model lacks");
    scales(k) = scale;
  }
  scaled_ = std::make_unique<ScaledProblem>(&shooting_, scales);
  const auto scale_of = [&](const std::string& name) { return scales(shooting_.UnknownIndex(name)); };
  for (ComponentBound& b : c.bounds) b.lower /= scale_of(b.component), b.upper /= scale_of(b.component);
  for (ComponentTarget& t : c.targets) t.value /= scale_of(t.component);
  for (SumBound& b : c.sum_bounds) {
    const double s0 = scale_of(b.components.front());
    for (const std::string& name : b.components) {
      if (scale_of(name) != s0) throw std::invalid_argument("a sum bound needs components of one scale");
    }
    b.lower /= s0, b.upper /= s0;
  }
  for (LinearCondition& cond : options_.start_conditions) {
    for (auto& [name, coefficient] : cond.coefficients) {
      if (shooting_.UnknownIndex(name) < 0) throw std::invalid_argument("start condition names unknown '" + name + "'");
      coefficient *= scale_of(name);  // c^T du = c^T S dv
    }
  }
  if (const std::string why = options_.Validate(); !why.empty()) throw std::invalid_argument(why);
}

BifurcationDiagram ModelExploration::Run(const PointCallback& on_point) {
  ExplorationOptions options = options_;
  ContinuationOptions& c = options.continuation;
  const std::function<void(const ProgressInfo&)> user_progress = c.progress;
  if (on_point) {
    c.progress_components.clear();  // ProgressInfo::values = all of u
    c.progress = [&](const ProgressInfo& info) {
      const Vector v = Eigen::Map<const Vector>(info.values.data(), static_cast<Eigen::Index>(info.values.size()));
      on_point(info, scaled_->FromScaled(v));
    };
  }
  BifurcationDiagram diagram = Explore(scaled_.get(), scaled_->ToScaled(scenario_.start), options);
  for (Branch& b : diagram.branches) {
    for (ContinuationPoint& p : b.points) {
      p.u = scaled_->FromScaled(p.u);
      p.tangent = scaled_->FromScaled(p.tangent).normalized();
    }
    for (SpecialPoint& sp : b.special_points) {
      if (sp.u.size()) sp.u = scaled_->FromScaled(sp.u);
      if (sp.interval_width.size()) sp.interval_width = scaled_->FromScaled(sp.interval_width);
    }
  }
  for (SpecialPoint& sp : diagram.special_points) {
    if (sp.u.size()) sp.u = scaled_->FromScaled(sp.u);
    if (sp.interval_width.size()) sp.interval_width = scaled_->FromScaled(sp.interval_width);
  }
  return diagram;
}

}  // namespace hybridcont::app
