#include "study/stages/parameter_curves.h"

#include <fmt/format.h>

#include <algorithm>
#include <fstream>
#include <map>
#include <optional>

#include "hybridcont/floquet.h"
#include "hybridcont/floquet_test_functions.h"
#include "hybridcont/invariant.h"
#include "hybridcont/orbit_observables.h"
#include "hybridcont/special_point_curve.h"
#include "hybridcont/timebased_shooting.h"
#include "study/engine/family_boundaries.h"
#include "study/engine/point_analysis.h"

namespace hybridcont::study {

namespace {

// The order of the curve's columns in its file: the family's coordinate a (H, or the run's free parameter), p,
// then the other unknowns.
std::vector<int> CurveColumns(const SpecialPointCurve& curve, const std::string& a, const std::string& p) {
  std::vector<int> order = {static_cast<int>(std::find(curve.unknown_names.begin(), curve.unknown_names.end(), a) -
                                             curve.unknown_names.begin()),
                            static_cast<int>(std::find(curve.unknown_names.begin(), curve.unknown_names.end(), p) -
                                             curve.unknown_names.begin())};
  for (int j = 0; j < static_cast<int>(curve.unknown_names.size()); ++j) {
    if (j != order[0] && j != order[1]) order.push_back(j);
  }
  return order;
}

// The curve's points in CurveColumns' order, into `c` (its columns and points).
void SetPoints(const SpecialPointCurve& curve, const std::string& a, const std::string& p, StudyCurve* c) {
  const std::vector<int> order = CurveColumns(curve, a, p);
  for (const int j : order) c->columns.push_back(curve.unknown_names[j]);
  for (const Vector& u : curve.points) {
    Vector v(static_cast<Eigen::Index>(order.size()));
    for (std::size_t j = 0; j < order.size(); ++j) v(static_cast<Eigen::Index>(j)) = u(order[j]);
    c->points.push_back(std::move(v));
  }
}

// The curve's points as CSV: a, p, then the other unknowns. False when the file could not be written.
bool WriteCurve(const SpecialPointCurve& curve, const std::string& a, const std::string& p,
                const std::filesystem::path& file) {
  std::ofstream f(file);
  const std::vector<int> order = CurveColumns(curve, a, p);
  for (std::size_t j = 0; j < order.size(); ++j) f << (j ? "," : "") << curve.unknown_names[order[j]];
  f << "\n";
  for (const Vector& u : curve.points) {
    for (std::size_t j = 0; j < order.size(); ++j) f << (j ? "," : "") << fmt::format("{:.17g}", u(order[j]));
    f << "\n";
  }
  return static_cast<bool>(f.flush());
}

// The layout of every curve's base map: the run's (its free parameters, fixed unknowns and joined
// observables) with p free as well and held at p0 by one more fixing row, the last. Its zero set is the run's
// family at p = p0; dropping that row lets (a, p) move along a curve.
FreeParameters BaseParameters(const FreeParameters& run, const std::string& p, double p0) {
  FreeParameters base = run;
  base.parameters.push_back(p);
  base.fixed.push_back({p, p0});
  return base;
}

// A vector of the run's unknowns (`from`) as one of the base map's (`to`): each entry by its name, p (the
// one name the run does not have) at p0.
Vector ToBaseUnknowns(const Vector& v, const std::vector<std::string>& from, const std::vector<std::string>& to,
                      const std::string& p, double p0_value) {
  if (v.size() == 0) return v;
  HYBRIDCONT_DEMAND(v.size() == static_cast<Eigen::Index>(from.size()));  // v is laid out by `from`
  Vector w(static_cast<Eigen::Index>(to.size()));
  for (std::size_t j = 0; j < to.size(); ++j) {
    const auto at = std::find(from.begin(), from.end(), to[j]);
    HYBRIDCONT_DEMAND(at != from.end() || to[j] == p);
    w(static_cast<Eigen::Index>(j)) = at != from.end() ? v(at - from.begin()) : p0_value;
  }
  return w;
}

// The special point of the run as a point of the base map: p0 inserted into u and 0 into its tangents.
SpecialPoint OnBaseMap(const SpecialPoint& sp, const std::vector<std::string>& from, const std::vector<std::string>& to,
                       const std::string& p, double p0) {
  SpecialPoint point = sp;
  point.u = ToBaseUnknowns(sp.u, from, to, p, p0);
  point.tangent = ToBaseUnknowns(sp.tangent, from, to, p, 0.0);
  point.tangent_before = ToBaseUnknowns(sp.tangent_before, from, to, p, 0.0);
  point.tangent_after = ToBaseUnknowns(sp.tangent_after, from, to, p, 0.0);
  point.interval_width = ToBaseUnknowns(sp.interval_width, from, to, p, 0.0);
  return point;
}

// The Floquet test function whose zero a PD or NS point is (floquet.h: pd_test = 2^k prod (mu + 1), ns_test =
// prod (mu_i mu_j - 1)), at a point of the base map's unknowns (the orbit, then p), evaluated on a map of its
// own; NaN where the multipliers cannot be computed. Its gradient: central differences
// (SpecialPointCurveOptions::second_derivative_step), exact enough to steer Newton, which solves g = 0 itself.
ScalarTest FloquetZero(const HybridModel& model, const RunSetup& setup, double p0, SpecialPointType type) {
  // The base map's own definition: its layout is the base unknowns'; the fixing rows' residuals are not used.
  auto map = std::make_shared<TimeBasedShooting>(model, setup.integrator,
                                                 BaseParameters(setup.free, setup.curve_parameter, p0));
  const bool pd = type == SpecialPointType::kPeriodDoubling;
  return ScalarTest{pd ? "pd_test" : "ns_test", [map, pd](const Vector& u) {
                      const FloquetResult f = ComputeFloquet(*map, u);
                      if (!f.ok()) return std::nan("");
                      return pd ? f.pd_test : f.ns_test;
                    },
                    nullptr};
}

// The crossing speed of phase `phase`'s event at the phase's end (FloquetTestFunctions, the grazing test
// function of that phase: ∇e·f / (|∇e| |f|), 0 where the orbit touches the event's surface tangentially), at a
// point of the base map's unknowns; a GR point is its regular zero where the family meets the surface. NaN
// where the orbit cannot be integrated. Its gradient: central differences, as FloquetZero's.
ScalarTest CrossingSpeedZero(const HybridModel& model, const RunSetup& setup, double p0, int function) {
  auto tests = std::make_shared<FloquetTestFunctions>(model, setup.integrator, /*physical_only=*/false,
                                                      BaseParameters(setup.free, setup.curve_parameter, p0));
  return ScalarTest{"crossing_speed", [tests, function](const Vector& u) { return tests->EvaluateOne(function, u); },
                    nullptr};
}

// A boundary of the physical families: where a phase duration or a constraint's interior minimum is 0.
struct Boundary {
  std::string name;        // "t2", "clearance"
  bool observable = false; // a constraint (joins the unknowns) or a duration (an unknown already)
};

// The curve of orbits on a boundary in (a, p): the base map with the boundary's quantity held at 0 instead of
// p (a constraint joins the unknowns with its equation, shooting_layout.h), so that r(u, p) = 0, q(u, p) = 0
// is one curve. Regular where the family crosses the boundary transversally (q changes sign along it, its
// gradient independent of dr's rows) — the defining system of a boundary, as a fold's is r = 0 with a
// turning-point condition. Traced both ways from the corrected start, `orbit` in the run's unknowns (`run`).
std::vector<Vector> TraceBoundary(const HybridModel& model, const RunSetup& setup, const Boundary& boundary,
                                  const Vector& orbit, const std::vector<std::string>& run, const std::string& a,
                                  double p0,
                                  const ContinuationOptions& options, std::vector<std::string>* names,
                                  std::string* why) {
  const std::string& p = setup.curve_parameter;
  FreeParameters free = setup.free;
  free.parameters.push_back(p);
  free.fixed.push_back({boundary.name, 0.0});
  if (boundary.observable &&
      std::find(free.observables.begin(), free.observables.end(), boundary.name) == free.observables.end()) {
    free.observables.push_back(boundary.name);
  }
  TimeBasedShooting map(model, setup.integrator, free);
  *names = map.unknown_names();
  const int observables = map.layout().num_observables();
  const std::vector<std::string> head(names->begin(), names->end() - observables);
  const Vector guess = ToBaseUnknowns(orbit, run, head, p, p0);
  const Vector start = observables > 0 ? map.CompleteUnknowns(guess) : guess;
  std::vector<Vector> points;
  for (const int direction : {-1, +1}) {
    ContinuationOptions c = options;
    c.direction = direction;
    c.detect_bifurcations = false;
    c.turning_point_components = {a};
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

// Whether (a, p) of `u` lies on one of `curves` (within tol of a chord of its (a, p) polyline).
bool OnCurve(const std::vector<std::vector<Eigen::Vector2d>>& curves, const Eigen::Vector2d& x, double tol) {
  for (const auto& c : curves) {
    for (std::size_t i = 0; i + 1 < c.size(); ++i) {
      if (DistanceToSegment<Eigen::Vector2d>(x, c[i], c[i + 1]) <= tol) return true;
    }
  }
  return false;
}

// The curves of one study in (a, p), a the coordinate its families are continued in (H̄, or the free
// parameter of `--free k --fix H=1.5`, or of a model without first integral): from its special points, then
// along the boundaries of its physical families; each written as curve_<id>.csv (with a folder) and recorded
// in the summary's list and the typed result, said in the report.
class CurveTracer {
 public:
  CurveTracer(const HybridModel& model, const RunSetup& setup, const std::filesystem::path& dir, std::string* report,
              std::vector<StudyCurve>* curves)
      : model_(model), setup_(setup), p_(setup.curve_parameter), p0_(model.parameter(p_)),
        run_layout_(model, setup.free), at_point_(model.Clone()), a_(run_layout_.continued_name()),
        base_(model, setup.integrator, BaseParameters(setup.free, p_, p0_)),
        fix_row_(base_.layout().fixed_row(base_.layout().num_fixed() - 1)), dir_(dir), report_(report),
        curves_(curves) {
    // The defining systems of folds and branch points are made of dR: exact, not the continuation's cheaper
    // Jacobian without the ξ·∇²H term below 1e-8 relative (timebased_shooting.h), whose error would move the
    // curve's points by that relative amount.
    base_.set_jacobian_tolerance(0.0);
    ContinuationOptions& c = options_.continuation;
    c.bounds = {setup.curve_bound};
    for (const ComponentBound& b : setup.exploration.continuation.bounds) {
      if (b.component == a_) c.bounds.push_back(b);
    }
    // Steps relative to the coordinates' sizes: the curves are traced unscaled. At most a quarter of the
    // families' largest step: a curve is drawn through its points (a region's edge in the report, a line of a
    // figure), and the families' step would leave a visible polygon (~40 points over the SLIP's k in [10, 160]).
    double scale = std::max(1.0, std::abs(p0_));
    for (const auto& [name, value] : setup.scenario.unknown_scales) {
      if (name == a_) scale = std::max(scale, std::abs(value));
    }
    c.initial_step = setup.scenario.initial_step * scale;
    c.max_step = setup.scenario.max_step * scale / 4;
    c.max_points = setup.scenario.max_points;
  }

  void Trace(const BifurcationDiagram& diagram) {
    *report_ += fmt::format("Special-point curves in ({}, {}) over {} in [{:g}, {:g}]:\n", a_, p_, p_,
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
  const ShootingLayout run_layout_;  // the layout of the diagram's points
  HybridModel at_point_;             // the model at a point's free parameters (PhysicalAt)
  const std::string a_;              // the coordinate the run's families are continued in
  TimeBasedShooting base_;
  const int fix_row_;                // the base map's row that holds p at p0
  const std::filesystem::path dir_;
  std::string* report_;
  std::vector<StudyCurve>* curves_;
  SpecialPointCurveOptions options_;
  std::map<std::string, std::vector<std::vector<Eigen::Vector2d>>> traced_;  // boundaries' (a, p) polylines
  std::map<int, std::vector<Eigen::Vector2d>> special_point_curves_;          // by curve id: (a, p) polylines

  // How close to a traced curve's polyline a start counts as on it: the chords' sag at the curves' steps.
  double OnCurveTolerance() const { return 1e-3 * (1 + std::abs(p0_)); }
  // The same, in (a, p) each relative to its size (1 + |a|, 1 + |p0|).
  static constexpr double kOnCurveTolerance = 1e-3;

  // Whether a branch point next to `sp` (the one before it or after it on its branch) is a physical orbit.
  bool PhysicalNextTo(const SpecialPoint& sp, const BifurcationDiagram& diagram) {
    const auto branch = std::find_if(diagram.branches.begin(), diagram.branches.end(),
                                     [&](const Branch& b) { return b.id == sp.branch_id; });
    if (branch == diagram.branches.end()) return false;
    for (const int i : {sp.index, sp.index + 1}) {
      if (i >= 0 && i < static_cast<int>(branch->points.size()) && PhysicalAt(branch->points[i].u)) return true;
    }
    return false;
  }

  // The type of the curve of a special point (StudyCurve::type).
  static std::string CurveType(const SpecialPoint& sp, bool fold) {
    if (fold) return ToString(CurveKind::kFold);
    if (sp.type == SpecialPointType::kExtremum) return ToString(sp.type);
    if (sp.type == SpecialPointType::kSimpleBifurcation) return ToString(CurveKind::kBranchPoint);
    return ToString(sp.type);
  }

  // Whether the run's point u is a physical orbit of the model at u's free parameters.
  bool PhysicalAt(const Vector& u) {
    SetFreeParameters(run_layout_, u, &at_point_);
    return IsPhysical(at_point_, OrbitPart(run_layout_, u), setup_.integrator);
  }

  // Writes the curve's file (curve_<id>.csv) and records `c` with its id and points; returns its id.
  int Record(const SpecialPointCurve& curve, StudyCurve c) {
    c.id = static_cast<int>(curves_->size());
    const std::string file = "curve_" + std::to_string(c.id) + ".csv";
    if (!dir_.empty() && !WriteCurve(curve, a_, p_, dir_ / file)) throw CurveFileError("writing " + (dir_ / file).string() + " failed");
    SetPoints(curve, a_, p_, &c);
    curves_->push_back(std::move(c));
    return curves_->back().id;
  }

  // A fold, an SB point, a PD or NS point (the zero of its Floquet test function: the stability boundary a
  // multiplier crossing -1 or a complex pair crossing the circle draws in the plane), or a grazing point where a
  // phase's event is crossed tangentially (the zero of its crossing speed) continued in (a, p).
  void FromSpecialPoint(const SpecialPoint& sp, const BifurcationDiagram& diagram) {
    const bool fold = sp.type == SpecialPointType::kTurningPoint && sp.component == a_;
    // An observable's extremum along the family: a fold of the family in that observable's coordinate.
    const bool extremum = sp.type == SpecialPointType::kExtremum;
    const bool floquet = sp.type == SpecialPointType::kPeriodDoubling || sp.type == SpecialPointType::kNeimarkSacker;
    // A phase's end event grazed (FloquetTestFunctions' functions 2 .. 2 + m − 1; not an event's interior minimum).
    const bool grazing = sp.type == SpecialPointType::kGrazing && sp.component_index >= 2 &&
                         sp.component_index < 2 + model_.num_phases();
    if (!(fold || extremum || floquet || grazing || sp.type == SpecialPointType::kSimpleBifurcation) ||
        sp.duplicate_of >= 0 ||
        sp.u.size() == 0 || ((floquet || grazing) && sp.status != LocationStatus::kLocated)) {
      return;
    }
    // A grazing orbit is on the physical family's boundary: one of the branch points around it is physical.
    if (grazing ? !PhysicalNextTo(sp, diagram) : !PhysicalAt(sp.u)) return;
    // A point on a curve of its kind traced already (a mirror image's, the other end of one grazing curve): the
    // same type and component (an EX point's observable, a GR point's event), within the curves' sampling in
    // (a, p), each axis relative to its size.
    const Eigen::Vector2d scale(1 + std::abs(sp.u(run_layout_.continued_index())), 1 + std::abs(p0_));
    const Eigen::Vector2d at = Eigen::Vector2d(sp.u(run_layout_.continued_index()), p0_).cwiseQuotient(scale);
    for (const StudyCurve& c : *curves_) {
      const auto source = std::find_if(diagram.special_points.begin(), diagram.special_points.end(),
                                       [&](const SpecialPoint& q) { return q.id == c.special_point; });
      if (c.special_point < 0 || source == diagram.special_points.end() || c.type != CurveType(sp, fold) ||
          source->component != sp.component || source->component_index != sp.component_index) {
        continue;
      }
      std::vector<Eigen::Vector2d> traced = special_point_curves_[c.id];
      for (Eigen::Vector2d& q : traced) q = q.cwiseQuotient(scale);
      if (OnCurve({traced}, at, kOnCurveTolerance)) {
        *report_ += fmt::format("  from special point {} ({}): on curve {} (of special point {}, the same type)\n",
                                sp.id, Code(sp.type), c.id, c.special_point);
        return;
      }
    }
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
    SpecialPoint on_base = OnBaseMap(sp, run_layout_.unknown_names(), base_.unknown_names(), p_, p0_);
    if (extremum) on_base.type = SpecialPointType::kTurningPoint;  // in its observable (on_base.component)
    try {
      if (floquet || grazing) {
        const CurveDefinition definition{CurveKind::kTestFunction, fix_row_, a_,
                                         floquet ? FloquetZero(model_, setup_, p0_, sp.type)
                                                 : CrossingSpeedZero(model_, setup_, p0_, sp.component_index)};
        curve = TraceSpecialPointCurve(&base_, definition, on_base.u, options_);
      } else {
        curve = TraceSpecialPointCurve(&base_, on_base, fix_row_, a_, options_);
      }
    } catch (const std::invalid_argument& e) {  // a point the defining system does not accept
      *report_ += fmt::format("  from special point {}: not traced ({})\n", sp.id, e.what());
      return;
    }
    if ((floquet || grazing) && curve.status != CurveStatus::kTraced) {
      *report_ += fmt::format("  from special point {} ({}): not traced ({})\n", sp.id, Code(sp.type), curve.message);
      return;
    }
    const auto column = [&](const std::string& name) {
      return static_cast<int>(std::find(curve.unknown_names.begin(), curve.unknown_names.end(), name) -
                              curve.unknown_names.begin());
    };
    StudyCurve c;
    c.type = CurveType(sp, fold);
    c.special_point = sp.id;
    c.status = ToString(curve.status);
    c.message = curve.message;
    c.termination = {ToString(curve.backward_termination), ToString(curve.forward_termination)};
    for (const CodimTwoPoint& q : curve.codim_two_points) {
      c.codim_two.push_back({ToString(q.type), q.name, ToString(q.status), q.u(column(a_)), q.u(column(p_))});
    }
    const std::string type = c.type;
    const int id = Record(curve, std::move(c));
    std::vector<Eigen::Vector2d>& polyline = special_point_curves_[id];
    for (const Vector& u : curve.points) polyline.emplace_back(u(column(a_)), u(column(p_)));
    *report_ += fmt::format("  curve {} ({}) from special point {} at {} = {:.10f}: {} points, {}; {} codimension-two "
                            "points\n",
                            id, type, sp.id, a_, sp.u(run_layout_.continued_index()), curve.points.size(),
                            ToString(curve.status), curve.codim_two_points.size());
  }

  // The boundary through the orbit (a duration or a constraint at 0; the run's unknowns) continued in (a, p).
  void BoundaryCurve(const Boundary& boundary, const Vector& orbit, const std::string& from) {
    std::vector<std::string> names;
    std::string why;
    std::vector<Vector> points;
    try {
      points = TraceBoundary(model_, setup_, boundary, orbit, run_layout_.unknown_names(), a_, p0_,
                             options_.continuation, &names, &why);
    } catch (const std::invalid_argument& e) {
      why = e.what();
    }
    if (points.empty()) {
      *report_ += fmt::format("  boundary {} = 0 from {}: not traced ({})\n", boundary.name, from, why);
      return;
    }
    const int h = static_cast<int>(std::find(names.begin(), names.end(), a_) - names.begin());
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
    const auto by_a = [](const auto& x, const auto& y) { return x(0) < y(0); };
    *report_ += fmt::format("  curve {} (boundary {} = 0) from {}: {} points, {} in [{:.6f}, {:.6f}]\n", id,
                            boundary.name, from, points.size(), a_,
                            std::min_element(polyline.begin(), polyline.end(), by_a)->x(),
                            std::max_element(polyline.begin(), polyline.end(), by_a)->x());
    traced_[boundary.name].push_back(std::move(polyline));
  }

  // Boundaries of the physical families: a duration through 0 between two points of a branch with a physical
  // side, and located constraint boundaries (CB). One curve per boundary and place.
  void Boundaries(const BifurcationDiagram& diagram) {
    const double tol = OnCurveTolerance();
    for (const DurationCrossing& c :
         DurationCrossings(model_, diagram, setup_.integrator, /*zero_points=*/false, setup_.free)) {
      const std::string name = std::string("t").append(std::to_string(c.segment + 1));
      if (OnCurve(traced_[name], Eigen::Vector2d(c.u_run(run_layout_.continued_index()), p0_), tol)) continue;
      BoundaryCurve({name, false}, c.u_run,
                    fmt::format("branch {} between points {} and {}", c.branch, c.point, c.point + 1));
    }
    for (const SpecialPoint& sp : diagram.special_points) {
      if (sp.type != SpecialPointType::kConstraintBoundary || sp.duplicate_of >= 0 || sp.u.size() == 0) continue;
      // The constraint whose interior minimum vanishes there (the evaluator reads the free parameters of u).
      ObservableEvaluator evaluator(model_, run_layout_, setup_.integrator);
      const int best = VanishingObservable(model_, evaluator, sp.u, [](const Observable& o) { return o.constraint; },
                                           /*interior_only=*/true);
      if (best < 0) continue;
      const std::string& name = model_.observables()[best].name;
      if (OnCurve(traced_[name], Eigen::Vector2d(sp.u(run_layout_.continued_index()), p0_), tol)) continue;
      BoundaryCurve({name, true}, sp.u, fmt::format("special point {} (CB)", sp.id));
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
