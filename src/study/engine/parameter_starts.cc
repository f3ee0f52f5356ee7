#include "study/engine/parameter_starts.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "hybridcont/corrector.h"
#include "hybridcont/orbit_observables.h"
#include "study/engine/model_exploration.h"
#include "study/engine/point_analysis.h"

namespace hybridcont::study {


ParameterStarts FindParameterStarts(const HybridModel& model, const RunSetup& setup, TimeBasedShooting& free_map) {
  ParameterStarts starts;
  const ShootingLayout& free_layout = free_map.layout();
  const std::string& fixed = setup.free.fixed.front().first;
  const std::vector<std::string>& names = free_layout.unknown_names();
  const int h = static_cast<int>(std::find(names.begin(), names.end(), fixed) - names.begin());
  const int p = free_layout.parameter_index(0);
  const ShootingLayout base(model);
  const int n = base.num_unknowns();
  // The fixed unknown's value at a point of the ordinary run: an entry of u, or an observable evaluated there.
  const int observable = model.FindObservable(fixed);
  ObservableEvaluator evaluator(model, base, setup.integrator);
  const auto value_at = [&](const Vector& u) {
    if (observable < 0) return u(h);
    double v = std::nan("");
    if (!evaluator.Evaluate(observable, u, &v, nullptr).ok) v = std::nan("");
    return v;
  };
  const double c = setup.free.fixed.front().second;
  // A duration held at 0 is the boundary where that phase vanishes: its crossings leave the physical
  // family (the points there are zero-duration orbits), so one physical side suffices.
  bool duration = false;
  for (int i = 0; i < free_layout.num_segments(); ++i) duration = duration || h == free_layout.time_index(i);
  const bool boundary = duration && c == 0.0;
  const double p0 = model.parameter_value(free_layout.parameter_model_index(0));
  ModelExploration ordinary(model, DefaultScenario(model), setup.integrator, setup.seed_exploration);
  const BifurcationDiagram diagram = ordinary.Run();
  starts.ordinary_branches = static_cast<int>(diagram.branches.size());
  Corrector corrector(&free_map);
  for (const Branch& b : diagram.branches) {
    for (std::size_t i = 0; i + 1 < b.points.size(); ++i) {
      const Vector &ua = b.points[i].u, &ub = b.points[i + 1].u;
      const double da = value_at(ua) - c, db = value_at(ub) - c;
      if (!(da * db <= 0) || da == db || db == 0) continue;  // NaN: the observable is undefined there  // a point exactly at c counts once, as the chord's start
      const bool pa = IsPhysical(model, ua, setup.integrator), pb = IsPhysical(model, ub, setup.integrator);
      if (boundary ? !(pa || pb) : !(pa && pb)) continue;
      ++starts.crossings;
      Vector guess(free_layout.num_unknowns() - free_layout.num_observables());
      guess << ua + (da / (da - db)) * (ub - ua), p0;
      if (free_layout.num_observables() > 0) guess = free_map.CompleteUnknowns(guess);
      Vector u;
      const CorrectorResult result = corrector.CorrectFixedComponent(guess, p, p0, &u);
      if (!result.converged() || (!boundary && !IsPhysical(model, u.head(n), setup.integrator))) continue;
      const bool known = std::any_of(starts.points.begin(), starts.points.end(), [&](const Vector& s) {
        return (s - u).lpNorm<Eigen::Infinity>() <= 1e-6 * (1 + u.lpNorm<Eigen::Infinity>());
      });
      if (known) continue;
      starts.points.push_back(u);
      starts.report += fmt::format("  start {}: branch {} between points {} and {}, T = {:.10f}\n",
                                   starts.points.size() - 1, b.id, i, i + 1, free_layout.Period(u));
    }
  }
  starts.report = fmt::format("starts at {} = {:g}: {} {} on {} half-branches of the run in H, {} distinct\n", fixed, c,
                              starts.crossings, boundary ? "crossings out of physical families" : "physical crossings",
                              starts.ordinary_branches, starts.points.size()) +
                  starts.report;
  return starts;
}

}  // namespace hybridcont::study
