#include "parameter_starts.h"

#include <fmt/format.h>

#include "hybridcont/corrector.h"
#include "model_exploration.h"
#include "orbit_analysis.h"

namespace hybridcont::app {


ParameterStarts FindParameterStarts(const HybridModel& model, const RunSetup& setup, TimeBasedShooting& free_map) {
  ParameterStarts starts;
  const ShootingLayout& free_layout = free_map.layout();
  const int h = free_layout.H_index(), p = free_layout.parameter_index(0);
  const int n = ShootingLayout(model).num_unknowns();
  const double c = setup.free.fixed.front().second;
  const double p0 = model.parameter_value(free_layout.parameter_model_index(0));
  ModelExploration ordinary(model, DefaultScenario(model), setup.integrator, setup.seed_exploration);
  const BifurcationDiagram diagram = ordinary.Run();
  starts.ordinary_branches = static_cast<int>(diagram.branches.size());
  Corrector corrector(&free_map);
  for (const Branch& b : diagram.branches) {
    for (std::size_t i = 0; i + 1 < b.points.size(); ++i) {
      const Vector &ua = b.points[i].u, &ub = b.points[i + 1].u;
      const double da = ua(h) - c, db = ub(h) - c;
      if (da * db > 0 || da == db || db == 0) continue;  // a point exactly at c counts once, as the chord's start
      if (!IsPhysical(model, ua, setup.integrator) || !IsPhysical(model, ub, setup.integrator)) continue;
      ++starts.crossings;
      Vector guess(free_layout.num_unknowns());
      guess << ua + (da / (da - db)) * (ub - ua), p0;
      Vector u;
      const CorrectorResult result = corrector.CorrectFixedComponent(guess, p, p0, &u);
      if (!result.converged() || !IsPhysical(model, u.head(n), setup.integrator)) continue;
      const bool known = std::any_of(starts.points.begin(), starts.points.end(), [&](const Vector& s) {
        return (s - u).lpNorm<Eigen::Infinity>() <= 1e-6 * (1 + u.lpNorm<Eigen::Infinity>());
      });
      if (known) continue;
      starts.points.push_back(u);
      starts.report += fmt::format("  start {}: branch {} between points {} and {}, T = {:.10f}\n",
                                   starts.points.size() - 1, b.id, i, i + 1, free_layout.Period(u));
    }
  }
  starts.report = fmt::format("starts at H = {:g}: {} physical crossings on {} half-branches of the run in H, {} "
                              "distinct\n",
                              c, starts.crossings, starts.ordinary_branches, starts.points.size()) +
                  starts.report;
  return starts;
}

}  // namespace hybridcont::app
