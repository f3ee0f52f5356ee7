#include "study/engine/family_boundaries.h"

#include <cmath>

#include "hybridcont/shooting_layout.h"
#include "study/engine/point_analysis.h"

namespace hybridcont::study {

std::vector<DurationCrossing> DurationCrossings(const HybridModel& model, const BifurcationDiagram& d,
                                                const IntegratorOptions& integrator, bool zero_points,
                                                const FreeParameters& free) {
  const ShootingLayout layout(model), run(model, free);
  HybridModel at_point = model.Clone();  // the model at a point's free parameters
  const auto physical = [&](const Vector& u_run) {
    SetFreeParameters(run, u_run, &at_point);
    return IsPhysical(at_point, u_run.head(layout.num_unknowns()), integrator);
  };
  std::vector<DurationCrossing> crossings;
  for (const Branch& b : d.branches) {
    if (b.image_of >= 0) continue;  // an image's ends are the images of its source's
    for (std::size_t i = 0; i + 1 < b.points.size(); ++i) {
      const Vector& va = b.points[i].u;
      const Vector& vb = b.points[i + 1].u;
      for (int s = 0; s < layout.num_segments(); ++s) {
        const double ta = va(layout.time_index(s)), tb = vb(layout.time_index(s));
        const bool za = zero_points && std::abs(ta) <= kZeroDuration, zb = zero_points && std::abs(tb) <= kZeroDuration;
        if (za && zb) continue;  // a family with that duration 0 throughout: its crossings are branch points
        if (!(ta * tb < 0 || za || zb)) continue;
        if (!physical(va) && !physical(vb)) continue;
        DurationCrossing c;
        c.branch = b.id;
        c.point = static_cast<int>(i);
        c.segment = s;
        c.at_point = za || zb;
        c.u_run = za ? va : zb ? vb : Vector(va + (ta / (ta - tb)) * (vb - va));
        c.u = c.u_run.head(layout.num_unknowns());
        crossings.push_back(std::move(c));
      }
    }
  }
  return crossings;
}

int VanishingObservable(const HybridModel& model, ObservableEvaluator& evaluator, const Vector& u,
                        const std::function<bool(const Observable&)>& wanted, bool interior_only) {
  int best = -1;
  double smallest = 1e-6;
  for (int j = 0; j < static_cast<int>(model.observables().size()); ++j) {
    const Observable& o = model.observables()[j];
    double v = 0;
    if (!wanted(o) || !evaluator.Evaluate(j, u, &v, nullptr).ok) continue;
    const bool defined = !interior_only || o.kind == ObservableKind::kFinal || evaluator.last_extremum_interior();
    if (!defined || !(std::abs(v) < smallest)) continue;
    best = j, smallest = std::abs(v);
  }
  if (best >= 0) {
    double v = 0;
    evaluator.Evaluate(best, u, &v, nullptr);  // leaves the evaluator at the chosen observable
  }
  return best;
}

}  // namespace hybridcont::study
