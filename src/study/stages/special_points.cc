#include "study/stages/special_points.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>

#include "hybridcont/orbit_observables.h"
#include "hybridcont/special_point.h"

namespace hybridcont::study {

int ExtremumSign(const SpecialPoint& sp) {
  const int k = sp.component_index;
  if (sp.type != SpecialPointType::kExtremum || k < 0 || k >= sp.tangent_before.size() ||
      k >= sp.tangent_after.size()) {
    return 0;
  }
  const double before = sp.tangent_before(k), after = sp.tangent_after(k);
  return before > 0 && after < 0 ? 1 : before < 0 && after > 0 ? -1 : 0;
}

void MarkExtrema(const std::vector<std::string>& extrema, BifurcationDiagram* d) {
  if (extrema.empty()) return;
  const auto mark = [&](SpecialPoint& sp) {
    if (sp.type != SpecialPointType::kTurningPoint ||
        std::find(extrema.begin(), extrema.end(), sp.component) == extrema.end()) {
      return;
    }
    sp.type = SpecialPointType::kExtremum;
    const int sign = ExtremumSign(sp);
    const std::string what = sign > 0 ? "largest" : sign < 0 ? "smallest" : "an extremum (neither side's tangent tells which)";
    sp.message = (sign != 0 ? sp.component + " is " + what : sp.component + ": " + what) + " along the family" +
                 (sp.message.empty() ? "" : "; " + sp.message);
  };
  for (SpecialPoint& sp : d->special_points) mark(sp);
  for (Branch& b : d->branches) {
    for (SpecialPoint& sp : b.special_points) mark(sp);
  }
}

std::vector<StudySpecialPoint> RecordSpecialPoints(const BifurcationDiagram& d, const ShootingLayout& layout,
                                                   const HybridModel* model, const IntegratorOptions& integrator) {
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  std::vector<StudySpecialPoint> out;
  // The model at a point's parameter values (free parameters are unknowns), for its observables.
  std::unique_ptr<HybridModel> at_point;
  if (model != nullptr && !model->observables().empty()) at_point = std::make_unique<HybridModel>(model->Clone());
  const bool level = layout.has_level();  // no H̄ without a first integral
  for (const SpecialPoint& sp : d.special_points) {
    StudySpecialPoint p;
    p.id = sp.id;
    p.type = sp.type;
    p.code = Code(sp.type);
    p.branch = sp.branch_id;
    p.index = sp.index;
    p.H = sp.u.size() && level ? sp.u(layout.H_index()) : kNaN;
    p.T = sp.u.size() ? layout.Period(sp.u) : kNaN;
    p.status = ToString(sp.status);
    // The width of the interval that holds the point, as a distance in u (model units); state-based runs know
    // the widths of their own unknowns only (x̄_1, ξ, H̄; NaN for the rest, left out of the distance).
    p.precision = sp.interval_width.size()
                      ? sp.interval_width.array().isNaN().select(0.0, sp.interval_width.array()).matrix().norm()
                      : sp.precision();
    p.precision_arclength = sp.precision();
    p.precision_H = sp.interval_width.size() && level ? sp.interval_width(layout.H_index()) : kNaN;
    p.residual = sp.residual_norm;
    p.component = sp.component;
    p.extremum = ExtremumSign(sp);
    p.duplicate_of = sp.duplicate_of;
    p.message = sp.message;
    p.u = sp.u;
    if (sp.u.size() == layout.num_unknowns()) {
      for (int i = 0; i < layout.num_free_parameters(); ++i) {
        p.named_unknowns.push_back({layout.unknown_names()[layout.parameter_index(i)], sp.u(layout.parameter_index(i))});
      }
      for (int i = 0; i < layout.num_observables(); ++i) {
        p.named_unknowns.push_back({layout.unknown_names()[layout.observable_index(i)], sp.u(layout.observable_index(i))});
      }
      if (at_point) {
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
          const bool ok = in_range && evaluator.Evaluate(k, sp.u, &v, nullptr).ok;
          p.observables.push_back({at_point->observables()[k].name, ok ? v : kNaN});
        }
      }
    }
    out.push_back(std::move(p));
  }
  return out;
}

}  // namespace hybridcont::study
