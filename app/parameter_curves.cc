#include "parameter_curves.h"

#include <fmt/format.h>

#include <fstream>

#include "hybridcont/special_point_curve.h"
#include "hybridcont/timebased_shooting.h"
#include "orbit_analysis.h"

namespace hybridcont::app {

namespace {

// The curve's points as CSV: H, p, then the other unknowns. False when the file could not be written.
bool WriteCurve(const SpecialPointCurve& curve, const std::string& p, const std::filesystem::path& file) {
  std::ofstream f(file);
  std::vector<int> order = {static_cast<int>(std::find(curve.unknown_names.begin(), curve.unknown_names.end(), "H") -
                                             curve.unknown_names.begin()),
                            static_cast<int>(std::find(curve.unknown_names.begin(), curve.unknown_names.end(), p) -
                                             curve.unknown_names.begin())};
  for (int j = 0; j < static_cast<int>(curve.unknown_names.size()); ++j) {
    if (j != order[0] && j != order[1]) order.push_back(j);
  }
  for (std::size_t j = 0; j < order.size(); ++j) f << (j ? "," : "") << curve.unknown_names[order[j]];
  f << "\n";
  for (const Vector& u : curve.points) {
    for (std::size_t j = 0; j < order.size(); ++j) f << (j ? "," : "") << fmt::format("{:.17g}", u(order[j]));
    f << "\n";
  }
  return static_cast<bool>(f.flush());
}

// The special point of the run as a point of the base map: p0 appended to u and 0 to its tangents.
SpecialPoint OnBaseMap(const SpecialPoint& sp, double p0) {
  SpecialPoint point = sp;
  const auto extend = [](const Vector& v, double value) {
    if (v.size() == 0) return v;
    Vector w(v.size() + 1);
    w << v, value;
    return w;
  };
  point.u = extend(sp.u, p0);
  point.tangent = extend(sp.tangent, 0.0);
  point.tangent_before = extend(sp.tangent_before, 0.0);
  point.tangent_after = extend(sp.tangent_after, 0.0);
  point.interval_width = extend(sp.interval_width, 0.0);
  return point;
}

}  // namespace

nlohmann::json TraceParameterCurves(const HybridModel& model, const RunSetup& setup, const BifurcationDiagram& diagram,
                                    const std::filesystem::path& dir, std::string* report) {
  const std::string& p = setup.curve_parameter;
  const double p0 = model.parameter(p);
  TimeBasedShooting base(model, setup.integrator, FreeParameters{{p}, {{p, p0}}});
  const int fix_row = base.layout().fixed_row(0);
  SpecialPointCurveOptions options;
  ContinuationOptions& c = options.continuation;
  c.bounds = {setup.curve_bound};
  for (const ComponentBound& b : setup.exploration.continuation.bounds) {
    if (b.component == "H") c.bounds.push_back(b);
  }
  // Steps relative to the parameter's size: the curves are traced unscaled.
  const double scale = std::max(1.0, std::abs(p0));
  c.initial_step = setup.scenario.initial_step * scale;
  c.max_step = setup.scenario.max_step * scale;
  c.max_points = setup.scenario.max_points;
  nlohmann::json curves = nlohmann::json::array();
  *report += fmt::format("Special-point curves in (H, {}) over {} in [{:g}, {:g}]:\n", p, p, setup.curve_bound.lower,
                         setup.curve_bound.upper);
  for (const SpecialPoint& sp : diagram.special_points) {
    const bool fold = sp.type == SpecialPointType::kTurningPoint && sp.component == "H";
    if (!(fold || sp.type == SpecialPointType::kSimpleBifurcation) || sp.duplicate_of >= 0 || sp.u.size() == 0) continue;
    if (!IsPhysical(model, sp.u, setup.integrator)) continue;
    SpecialPointCurve curve;
    try {
      curve = TraceSpecialPointCurve(&base, OnBaseMap(sp, p0), fix_row, "H", options);
    } catch (const std::invalid_argument& e) {  // a point the defining system does not accept
      *report += fmt::format("  from special point {}: not traced ({})\n", sp.id, e.what());
      continue;
    }
    const int id = static_cast<int>(curves.size());
    const std::string file = "curve_" + std::to_string(id) + ".csv";
    if (!WriteCurve(curve, p, dir / file)) throw std::runtime_error("writing " + (dir / file).string() + " failed");
    const auto column = [&](const std::string& name) {
      return static_cast<int>(std::find(curve.unknown_names.begin(), curve.unknown_names.end(), name) -
                              curve.unknown_names.begin());
    };
    nlohmann::json codim_two = nlohmann::json::array();
    for (const CodimTwoPoint& q : curve.codim_two_points) {
      codim_two.push_back({{"type", ToString(q.type)}, {"name", q.name}, {"status", ToString(q.status)},
                           {"H", q.u(column("H"))}, {p, q.u(column(p))}});
    }
    curves.push_back({{"id", id},
                      {"type", ToString(curve.kind)},
                      {"file", file},
                      {"special_point", sp.id},
                      {"status", ToString(curve.status)},
                      {"message", curve.message},
                      {"points", curve.points.size()},
                      {"termination", {ToString(curve.backward_termination), ToString(curve.forward_termination)}},
                      {"codim_two", codim_two}});
    *report += fmt::format("  curve {} ({}) from special point {} at H = {:.10f}: {} points, {}; {} codimension-two "
                           "points\n",
                           id, ToString(curve.kind), sp.id, sp.u(base.layout().H_index()), curve.points.size(),
                           ToString(curve.status), curve.codim_two_points.size());
  }
  if (curves.empty()) *report += "  none\n";
  return curves;
}

}  // namespace hybridcont::app
