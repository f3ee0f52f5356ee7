#include "study/stages/parameter_curves.h"

#include <fmt/format.h>

#include <algorithm>
#include <fstream>
#include <map>

#include "hybridcont/floquet.h"
#include "hybridcont/orbit_observables.h"
#include "hybridcont/special_point_curve.h"
#include "hybridcont/timebased_shooting.h"
#include "study/engine/family_boundaries.h"
#include "study/engine/point_analysis.h"

namespace hybridcont::study {

namespace {

// The order of the curve's columns in its file: H, p, then the other unknowns.
std::vector<int> CurveColumns(const SpecialPointCurve& curve, const std::string& p) {
  std::vector<int> order = {static_cast<int>(std::find(curve.unknown_names.begin(), curve.unknown_names.end(), "H") -
                                             curve.unknown_names.begin()),
                            static_cast<int>(std::find(curve.unknown_names.begin(), curve.unknown_names.end(), p) -
                                             curve.unknown_names.begin())};
  for (int j = 0; j < static_cast<int>(curve.unknown_names.size()); ++j) {
    if (j != order[0] && j != order[1]) order.push_back(j);
  }
  return order;
}

// The curve's points in CurveColumns' order, into `c` (its columns and points).
void SetPoints(const SpecialPointCurve& curve, const std::string& p, StudyCurve* c) {
  const std::vector<int> order = CurveColumns(curve, p);
  for (const int j : order) c->columns.push_back(curve.unknown_names[j]);
  for (const Vector& u : curve.points) {
    Vector v(static_cast<Eigen::Index>(order.size()));
    for (std::size_t j = 0; j < order.size(); ++j) v(static_cast<Eigen::Index>(j)) = u(order[j]);
    c->points.push_back(std::move(v));
  }
}

// The curve's points as CSV: H, p, then the other unknowns. False when the file could not be written.
bool WriteCurve(const SpecialPointCurve& curve, const std::string& p, const std::filesystem::path& file) {
  std::ofstream f(file);
  const std::vector<int> order = CurveColumns(curve, p);
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

// The Floquet test function whose zero a PD or NS point is (floquet.h: pd_test = 2^k prod (mu + 1), ns_test =
// prod (mu_i mu_j - 1)), at a point of the base map's unknowns (the orbit, then p), evaluated on a map of its
// own; NaN where the multipliers cannot be computed. Its gradient: central differences
// (SpecialPointCurveOptions::second_derivative_step), exact enough to steer Newton, which solves g = 0 itself.
ScalarTest FloquetZero(const HybridModel& model, const RunSetup& setup, double p0, SpecialPointType type) {
  // The base map's own definition (p free, held at p0 by a fixing row): its layout is the base unknowns'; the
  // fixing row's residual is not used.
  const std::string& p = setup.curve_parameter;
  auto map = std::make_shared<TimeBasedShooting>(model, setup.integrator, FreeParameters{{p}, {{p, p0}}, {}});
  const bool pd = type == SpecialPointType::kPeriodDoubling;
  return ScalarTest{pd ? "pd_test" : "ns_test", [map, pd](const Vector& u) {
                      const FloquetResult f = ComputeFloquet(*map, u);
                      if (!f.ok()) return std::nan("");
                      return pd ? f.pd_test : f.ns_test;
                    },
                    nullptr};
}

// A boundary of the physical families: where a phase duration or a constraint's interior minimum is 0.
struct Boundary {
  std::string name;        // "t2", "clearance"
  bool observable = false; // a constraint (joins the unknowns) or a duration (an unknown already)
};

// The curve of orbits on a boundary in (H̄, p): the time-based map with p free, the boundary's quantity held
// at 0 by a fixing row (a constraint joins the unknowns with its equation, shooting_layout.h), so that
// r(u, p) = 0, q(u, p) = 0 is one curve. Regular where the family crosses the boundary transversally (q
// changes sign along it, its gradient independent of dr's rows) — the defining system of a boundary, as a
// fold's is r = 0 with a turning-point condition. Traced both ways from the corrected start.
std::vector<Vector> TraceBoundary(const HybridModel& model, const RunSetup& setup, const Boundary& boundary,
                                  const Vector& orbit, double p0, const ContinuationOptions& options,
                                  std::vector<std::string>* names, std::string* why) {
  const std::string& p = setup.curve_parameter;
  TimeBasedShooting map(model, setup.integrator,
                        FreeParameters{{p}, {{boundary.name, 0.0}},
                                       boundary.observable ? std::vector<std::string>{boundary.name}
                                                           : std::vector<std::string>{}});
  *names = map.unknown_names();
  Vector guess(map.num_unknowns() - map.layout().num_observables());
  guess << orbit, p0;
  const Vector start = map.layout().num_observables() > 0 ? map.CompleteUnknowns(guess) : guess;
  std::vector<Vector> points;
  for (const int direction : {-1, +1}) {
    ContinuationOptions c = options;
    c.direction = direction;
    c.detect_bifurcations = false;
    c.turning_point_components = {"H"};
    const Branch half = TraceBranch(&map, start, c);
    if (half.points.empty()) {
      *why = half.message;
      return {};
    }
    std::vector<Vector> us;
    for (const ContinuationPoint& q : half.points) us.push_back(q.u);
    if (direction < 0) {
      points.assign(us.rbegin(), us.rend());
    } else {
      points.insert(points.end(), us.begin() + 1, us.end());
    }
  }
  return points;
}

// Whether (H, p) of `u` lies on one of `curves` (within tol of a chord of its (H, p) polyline).
bool OnCurve(const std::vector<std::vector<Eigen::Vector2d>>& curves, const Eigen::Vector2d& x, double tol) {
  for (const auto& c : curves) {
    for (std::size_t i = 0; i + 1 < c.size(); ++i) {
      if (DistanceToSegment<Eigen::Vector2d>(x, c[i], c[i + 1]) <= tol) return true;
    }
  }
  return false;
}

// The curves of one study in (H, p): from its special points, then along the boundaries of its physical
// families; each written as curve_<id>.csv (with a folder) and recorded in the summary's list and the typed
// result, said in the report.
class CurveTracer {
 public:
  CurveTracer(const HybridModel& model, const RunSetup& setup, const std::filesystem::path& dir, std::string* report,
              std::vector<StudyCurve>* curves)
      : model_(model), setup_(setup), p_(setup.curve_parameter), p0_(model.parameter(p_)),
        base_(model, setup.integrator, FreeParameters{{p_}, {{p_, p0_}}, {}}), fix_row_(base_.layout().fixed_row(0)),
        layout_(model), dir_(dir), report_(report), curves_(curves) {
    ContinuationOptions& c = options_.continuation;
    c.bounds = {setup.curve_bound};
    for (const ComponentBound& b : setup.exploration.continuation.bounds) {
      if (b.component == "H") c.bounds.push_back(b);
    }
    // Steps relative to the parameter's size: the curves are traced unscaled. At most a quarter of the
    // families' largest step: a curve is drawn through its points (a region's edge in the report, a line of a
    // figure), and the families' step would leave a visible polygon (~40 points over the SLIP's k in [10, 160]).
    const double scale = std::max(1.0, std::abs(p0_));
    c.initial_step = setup.scenario.initial_step * scale;
    c.max_step = setup.scenario.max_step * scale / 4;
    c.max_points = setup.scenario.max_points;
  }

  void Trace(const BifurcationDiagram& diagram) {
    *report_ += fmt::format("Special-point curves in (H, {}) over {} in [{:g}, {:g}]:\n", p_, p_,
                            setup_.curve_bound.lower, setup_.curve_bound.upper);
    for (const SpecialPoint& sp : diagram.special_points) FromSpecialPoint(sp, diagram);
    Boundaries(diagram);
    if (curves_->empty()) *report_ += "  none\n";
  }

 private:
  const HybridModel& model_;
  const RunSetup& setup_;
  const std::string p_;
  const double p0_;
  TimeBasedShooting base_;
  const int fix_row_;
  const ShootingLayout layout_;
  const std::filesystem::path dir_;
  std::string* report_;
  std::vector<StudyCurve>* curves_;
  SpecialPointCurveOptions options_;
  std::map<std::string, std::vector<std::vector<Eigen::Vector2d>>> traced_;  // boundaries' (H, p) polylines

  // Writes the curve's file (curve_<id>.csv) and records `c` with its id and points; returns its id.
  int Record(const SpecialPointCurve& curve, StudyCurve c) {
    c.id = static_cast<int>(curves_->size());
    const std::string file = "curve_" + std::to_string(c.id) + ".csv";
    if (!dir_.empty() && !WriteCurve(curve, p_, dir_ / file)) throw CurveFileError("writing " + (dir_ / file).string() + " failed");
    SetPoints(curve, p_, &c);
    curves_->push_back(std::move(c));
    return curves_->back().id;
  }

  // A fold, an SB point, or a PD or NS point (the zero of its Floquet test function: the stability boundary a
  // multiplier crossing -1 or a complex pair crossing the circle draws in the plane) continued in (H, p).
  void FromSpecialPoint(const SpecialPoint& sp, const BifurcationDiagram& diagram) {
    const bool fold = sp.type == SpecialPointType::kTurningPoint && sp.component == "H";
    const bool floquet = sp.type == SpecialPointType::kPeriodDoubling || sp.type == SpecialPointType::kNeimarkSacker;
    if (!(fold || floquet || sp.type == SpecialPointType::kSimpleBifurcation) || sp.duplicate_of >= 0 ||
        sp.u.size() == 0 || (floquet && sp.status != LocationStatus::kLocated)) {
      return;
    }
    if (!IsPhysical(model_, sp.u, setup_.integrator)) return;
    // A PD or NS point at a branch point of its family (the SLIP's PD where forward hopping leaves hopping in
    // place) is no regular zero of its test function there: its curve is the branch point's.
    const bool at_branch_point =
        std::any_of(diagram.special_points.begin(), diagram.special_points.end(), [&](const SpecialPoint& q) {
          return q.branch_id == sp.branch_id && q.id != sp.id && q.u.size() == sp.u.size() &&
                 (q.type == SpecialPointType::kSimpleBifurcation || q.type == SpecialPointType::kFloquetBranchPoint) &&
                 (q.u - sp.u).lpNorm<Eigen::Infinity>() <= 1e-6 * (1 + sp.u.lpNorm<Eigen::Infinity>());
        });
    if (floquet && at_branch_point) {
      *report_ += fmt::format("  from special point {} ({}): not traced (at a branch point of its family, where its "
                              "test function has no regular zero)\n", sp.id, Code(sp.type));
      return;
    }
    SpecialPointCurve curve;
    try {
      if (floquet) {
        const CurveDefinition definition{CurveKind::kTestFunction, fix_row_, "H", FloquetZero(model_, setup_, p0_, sp.type)};
        curve = TraceSpecialPointCurve(&base_, definition, OnBaseMap(sp, p0_).u, options_);
      } else {
        curve = TraceSpecialPointCurve(&base_, OnBaseMap(sp, p0_), fix_row_, "H", options_);
      }
    } catch (const std::invalid_argument& e) {  // a point the defining system does not accept
      *report_ += fmt::format("  from special point {}: not traced ({})\n", sp.id, e.what());
      return;
    }
    if (floquet && curve.status != CurveStatus::kTraced) {
      *report_ += fmt::format("  from special point {} ({}): not traced ({})\n", sp.id, Code(sp.type), curve.message);
      return;
    }
    const auto column = [&](const std::string& name) {
      return static_cast<int>(std::find(curve.unknown_names.begin(), curve.unknown_names.end(), name) -
                              curve.unknown_names.begin());
    };
    StudyCurve c;
    c.type = floquet ? ToString(sp.type) : ToString(curve.kind);
    c.special_point = sp.id;
    c.status = ToString(curve.status);
    c.message = curve.message;
    c.termination = {ToString(curve.backward_termination), ToString(curve.forward_termination)};
    for (const CodimTwoPoint& q : curve.codim_two_points) {
      c.codim_two.push_back({ToString(q.type), q.name, ToString(q.status), q.u(column("H")), q.u(column(p_))});
    }
    const std::string type = c.type;
    const int id = Record(curve, std::move(c));
    *report_ += fmt::format("  curve {} ({}) from special point {} at H = {:.10f}: {} points, {}; {} codimension-two "
                            "points\n",
                            id, type, sp.id, sp.u(base_.layout().H_index()), curve.points.size(),
                            ToString(curve.status), curve.codim_two_points.size());
  }

  // The boundary through the orbit (a duration or a constraint at 0) continued in (H, p).
  void BoundaryCurve(const Boundary& boundary, const Vector& orbit, const std::string& from) {
    std::vector<std::string> names;
    std::string why;
    std::vector<Vector> points;
    try {
      points = TraceBoundary(model_, setup_, boundary, orbit, p0_, options_.continuation, &names, &why);
    } catch (const std::invalid_argument& e) {
      why = e.what();
    }
    if (points.empty()) {
      *report_ += fmt::format("  boundary {} = 0 from {}: not traced ({})\n", boundary.name, from, why);
      return;
    }
    const int h = static_cast<int>(std::find(names.begin(), names.end(), "H") - names.begin());
    const int q = static_cast<int>(std::find(names.begin(), names.end(), p_) - names.begin());
    std::vector<Eigen::Vector2d> polyline;
    for (const Vector& u : points) polyline.emplace_back(u(h), u(q));
    SpecialPointCurve curve;
    curve.unknown_names = names;
    curve.points = points;
    StudyCurve c;
    c.type = "boundary";
    c.name = boundary.name + " = 0";
    c.status = "traced";
    const int id = Record(curve, std::move(c));
    const auto by_H = [](const auto& a, const auto& b) { return a(0) < b(0); };
    *report_ += fmt::format("  curve {} (boundary {} = 0) from {}: {} points, H in [{:.6f}, {:.6f}]\n", id,
                            boundary.name, from, points.size(),
                            std::min_element(polyline.begin(), polyline.end(), by_H)->x(),
                            std::max_element(polyline.begin(), polyline.end(), by_H)->x());
    traced_[boundary.name].push_back(std::move(polyline));
  }

  // Boundaries of the physical families: a duration through 0 between two points of a branch with a physical
  // side, and located constraint boundaries (CB). One curve per boundary and place.
  void Boundaries(const BifurcationDiagram& diagram) {
    const double tol = 1e-3 * (1 + std::abs(p0_));
    for (const DurationCrossing& c : DurationCrossings(model_, diagram, setup_.integrator, /*zero_points=*/false)) {
      const std::string name = std::string("t").append(std::to_string(c.segment + 1));
      if (OnCurve(traced_[name], Eigen::Vector2d(c.u(layout_.H_index()), p0_), tol)) continue;
      BoundaryCurve({name, false}, c.u, fmt::format("branch {} between points {} and {}", c.branch, c.point, c.point + 1));
    }
    for (const SpecialPoint& sp : diagram.special_points) {
      if (sp.type != SpecialPointType::kConstraintBoundary || sp.duplicate_of >= 0 || sp.u.size() == 0) continue;
      // The constraint whose interior minimum vanishes there.
      ObservableEvaluator evaluator(model_, layout_, setup_.integrator);
      const Vector u = sp.u.head(layout_.num_unknowns());
      const int best = VanishingObservable(model_, evaluator, u, [](const Observable& o) { return o.constraint; },
                                           /*interior_only=*/true);
      if (best < 0) continue;
      const std::string& name = model_.observables()[best].name;
      if (OnCurve(traced_[name], Eigen::Vector2d(sp.u(layout_.H_index()), p0_), tol)) continue;
      BoundaryCurve({name, true}, u, fmt::format("special point {} (CB)", sp.id));
    }
  }
};

}  // namespace

std::vector<StudyCurve> TraceParameterCurves(const HybridModel& model, const RunSetup& setup,
                                             const BifurcationDiagram& diagram, const std::filesystem::path& dir,
                                             std::string* report) {
  std::vector<StudyCurve> curves;
  CurveTracer(model, setup, dir, report, &curves).Trace(diagram);
  return curves;
}

}  // namespace hybridcont::study
