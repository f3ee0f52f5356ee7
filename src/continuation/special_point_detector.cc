#include "continuation/special_point_detector.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <sstream>
#include <utility>

#include "hybridcont/invariant.h"

namespace hybridcont::internal {

SpecialPointDetector::SpecialPointDetector(ZeroProblem* problem, Corrector* corrector, BorderedSolver* solver,
                                           const ContinuationOptions& options)
    : problem_(problem),
      corrector_(corrector),
      solver_(solver),
      names_(problem->unknown_names()),
      detect_bifurcations_(options.detect_bifurcations),
      check_integration_error_(options.check_integration_error),
      location_tolerance_(options.location_tolerance),
      max_location_iterations_(options.max_location_iterations),
      corrector_options_(options.corrector) {
  std::vector<std::string> turning = options.turning_point_components;
  if (turning.empty() && !problem_->family_parameter().empty()) turning.push_back(problem_->family_parameter());
  for (const std::string& name : turning) {
    turning_.push_back(problem_->UnknownIndex(name));
    HYBRIDCONT_DEMAND(turning_.back() >= 0);  // ValidateFor checked the names
  }
  if (options.test_functions) {
    functions_ = options.test_functions->Clone();
    function_types_ = functions_->types();
  }
}

SpecialPointDetector::~SpecialPointDetector() {
  if (functions_ && test_problem_) functions_->AddCurveWork(*test_problem_);
}

SpecialPointDetector::Curve SpecialPointDetector::TestCurve() {
  if (!test_problem_) {
    test_problem_ = problem_->Clone();
    if (!test_problem_) return ContinuationCurve();  // a serial problem: its work stays the problem's
    test_corrector_ = std::make_unique<Corrector>(test_problem_.get(), corrector_options_);
  }
  return {test_problem_.get(), test_corrector_.get(), &test_solver_};
}

void SpecialPointDetector::Sample(ContinuationPoint* point, bool corrected) {
  if (!functions_) return;
  const Vector& at = corrector_->evaluated_point();
  const double distance = corrector_->options().max_jacobian_distance * (1.0 + point->u.norm());
  point->evaluated_at.resize(0);
  if (corrected && at.size() == point->u.size() && (at - point->u).norm() <= distance) {
    if (functions_->EvaluateAtBranchPoint(point->u, TestFunctions::CorrectorEvaluation{problem_, at},
                                          &point->test_values)) {
      point->evaluated_at = at;
    }
  } else {
    functions_->Evaluate(point->u, true, &point->test_values);
  }
  HYBRIDCONT_DEMAND(point->test_values.size() == static_cast<Eigen::Index>(function_types_.size()));
}

bool SpecialPointDetector::Detect(size_t index, bool from_singular, Branch* branch) {
  HYBRIDCONT_DEMAND(index + 1 < branch->points.size());
  const ContinuationPoint& a = branch->points[index];
  const ContinuationPoint& b = branch->points[index + 1];
  std::vector<SpecialPoint> found;
  std::vector<SpecialPoint> bracket_only;  // each found point as its root finder left it
  one_curve_ = true;
  if (from_singular) {
    DetectTestFunctions(index, true, branch);
    return true;
  }
  if (detect_bifurcations_ && a.sb_test != 0 && b.sb_test != 0 && std::signbit(a.sb_test) != std::signbit(b.sb_test)) {
    found.push_back(Locate(SpecialPointType::kSimpleBifurcation, -1,
                           [](const Segment::Probe& p) { return p.sb_test; }, index, branch, &bracket_only));
  }
  for (const int k : turning_) {
    if (a.tangent(k) * b.tangent(k) < 0 &&
        std::max(std::abs(a.tangent(k)), std::abs(b.tangent(k))) > kConstantComponent) {
      found.push_back(Locate(SpecialPointType::kTurningPoint, k,
                             [k](const Segment::Probe& p) { return p.tangent(k); }, index, branch, &bracket_only));
    }
  }
  PlaceTurningPointsAtSbPoints(b.arclength - a.arclength, bracket_only, &found);
  Insert(std::move(found), branch);
  DetectTestFunctions(index, false, branch);
  return one_curve_;
}

void SpecialPointDetector::Insert(std::vector<SpecialPoint> found, Branch* branch) {
  std::vector<SpecialPoint>& list = branch->special_points;
  for (SpecialPoint& point : found) {
    const bool of_test_function = functions_ && point.type != SpecialPointType::kSimpleBifurcation &&
                                  point.type != SpecialPointType::kTurningPoint && point.component_index >= 0 &&
                                  point.component_index < static_cast<int>(function_types_.size()) &&
                                  function_types_[point.component_index] == point.type;
    if (of_test_function) {
      std::string note;
      if (!functions_->Keep(point.component_index, point.u, &note)) continue;
      if (!note.empty()) point.message += (point.message.empty() ? "" : "; ") + note;
    }
    const auto at = std::upper_bound(list.begin(), list.end(), point.arclength,
                                     [](double s, const SpecialPoint& p) { return s < p.arclength; });
    list.insert(at, std::move(point));
  }
  for (size_t i = 0; i < list.size(); ++i) list[i].id = static_cast<int>(i);
}

SpecialPoint SpecialPointDetector::Locate(SpecialPointType type, int k, const Test& test, size_t index,
                                          Branch* branch, std::vector<SpecialPoint>* bracket_only) {
  return LocateOn(ContinuationCurve(), branch->points[index], branch->points[index + 1], type, k, test, nullptr, index, branch,
                  bracket_only);
}

SpecialPoint SpecialPointDetector::LocateOn(const Curve& curve, const ContinuationPoint& a, const ContinuationPoint& b,
                                            SpecialPointType type, int k, const Test& test, const Test* refined_test,
                                            size_t index, Branch* branch, std::vector<SpecialPoint>* bracket_only) {
  Segment segment(curve.corrector, curve.solver, curve.problem, a, b, type == SpecialPointType::kSimpleBifurcation);
  const RootLocation root = LocateRoot(&segment, test, location_tolerance_, max_location_iterations_);
  SpecialPoint point;
  point.type = type;
  point.status = root.located ? LocationStatus::kLocated : LocationStatus::kBracketed;
  const bool continuation_point = type == SpecialPointType::kSimpleBifurcation || type == SpecialPointType::kTurningPoint;
  if (continuation_point && !root.located && root.uncorrectable) one_curve_ = false;
  point.branch_id = branch->id;
  point.index = static_cast<int>(index);
  point.arclength = a.arclength + root.sigma;
  point.component_index = k;
  if (k >= 0 && type == SpecialPointType::kTurningPoint) point.component = names_[k];
  point.u = root.estimate.u;
  point.tangent = root.estimate.tangent;
  if (type == SpecialPointType::kSimpleBifurcation) {
    // The induced tangent is undefined at an SB point, and next to it can be numerically meaningless
    // (dr has a second near-zero singular value, so a noisy dr mixes both branch directions in the
    // computed kernel). Kept only inside the cone of the bracketing points' regular tangents.
    point.tangent = segment.ReliableTangent(root.estimate, root.sigma);
  }
  point.tangent_before = a.tangent;
  point.tangent_after = b.tangent;
  point.test_value = root.test;
  point.interval_lo = a.arclength + root.lo;
  point.interval_hi = a.arclength + root.hi;
  point.interval_width = (root.u_hi - root.u_lo).cwiseAbs();
  point.residual_norm = root.estimate.residual;
  point.iterations = root.iterations;
  point.message = root.message;
  // An interval wider than the bracket (noise-limited locations widen it, AddIntegrationError may):
  // the components vary over all of it, by |τ|·P to first order and ½|dτ/ds|·P² more to second over
  // a length P (dτ/ds from the step's end tangents): the second-order term is the whole variation of
  // the turning component at a turning point.
  const double step_length = std::abs(b.arclength - a.arclength);
  const Vector bending = step_length > 0 ? Vector((b.tangent - a.tangent).cwiseAbs() / step_length)
                                         : Vector::Zero(a.u.size());
  const auto cover = [&bending](SpecialPoint* p) {
    const double length = p->precision();
    p->interval_width =
        p->interval_width.cwiseMax(p->tangent.cwiseAbs() * length + 0.5 * bending * length * length);
  };
  cover(&point);
  bracket_only->push_back(point);
  if (check_integration_error_) AddIntegrationError(curve.problem, &segment, root, test, refined_test ? *refined_test : test, &point);
  cover(&point);
  branch->located_iterations += root.iterations;
  return point;
}

// The estimate evaluated again with the problem's refined copy: with the error of an evaluation
// proportional to the tolerances, the change Δ of a quantity is (1 − factor) of its error at the
// problem's own tolerances. The test function's error — its refined value's change, plus its change over
// the refined Newton correction δu (where the exact curve lies) — over its slope is how far the exact root
// may lie from the computed one (δs, along the branch), δu how far the exact curve may lie from the point. Where δs or δu exceed the bracket, the interval and the componentwise
// widths grow to cover them, and the message says so.
void SpecialPointDetector::AddIntegrationError(ZeroProblem* problem, Segment* segment, const RootLocation& root, const Test& test,
                                               const Test& refined_test, SpecialPoint* point) {
  constexpr double kFactor = ContinuationOptions::kIntegrationErrorFactor;
  constexpr double kScale = ContinuationOptions::kIntegrationErrorScale;
  const std::unique_ptr<ZeroProblem> refined = problem->Refined(kFactor);
  if (refined == nullptr) return;  // exact to rounding: the bracket is the precision
  const auto not_estimated = [point](const std::string& why) {
    if (!point->message.empty()) point->message += "; ";
    point->message += "integration error not estimated (" + why + "): the precision is the bracket's";
  };
  if (root.estimate.u.size() != problem->num_unknowns() || !(root.slope != 0)) {
    return not_estimated("no test function slope");
  }
  Segment::Probe fine;
  Vector du;
  const bool ok = segment->RefinedProbe(refined.get(), root.estimate, &fine, &du);
  problem->AddWorkOf(*refined);
  if (!ok) return not_estimated("the evaluation at 0.1x the tolerances failed");
  // The test function changes with its own evaluation's error and with the point: on the exact curve, du away,
  // it differs by about g(u + du) − g(u). A function of the unknowns alone (a phase's duration) moves only so;
  // where the root is ill-conditioned (the function changes slowly along the branch) that is what matters.
  Segment::Probe shifted = root.estimate;
  shifted.u += du;
  const double moved = test(shifted) - root.test;
  const double change = std::abs(refined_test(fine) - root.test) + (std::isfinite(moved) ? std::abs(moved) : 0.0);
  const double refined_step = du.norm();
  du *= kScale;
  const double ds = kScale * change / std::abs(root.slope);
  if (!std::isfinite(ds)) return not_estimated("not finite");
  const Vector tangent = point->tangent.size() == du.size() ? point->tangent : root.estimate.tangent;
  const Vector spread = 2 * (tangent.cwiseAbs() * ds + du.cwiseAbs());
  const double bracket = point->precision();
  // The arclength interval also takes the point's distance from the exact curve: one number that
  // bounds how far the exact special point may be from u, along the branch or off it.
  const double reach = ds + du.norm();
  point->interval_lo = std::min(point->interval_lo, point->arclength - reach);
  point->interval_hi = std::max(point->interval_hi, point->arclength + reach);
  if (point->interval_width.size() == spread.size()) point->interval_width = point->interval_width.cwiseMax(spread);
  if (point->precision() > bracket) {
    char text[640];
    std::snprintf(text, sizeof(text),
                  "integration error: evaluated with %gx the tolerances the test function moves by %.2g "
                  "(slope %.2g along the branch) and Newton by %.2g, so the root may lie %.2g away along "
                  "the branch and the point %.2g off it (twice the estimate; precision %.2g, the bracket was %.2g)",
                  kFactor, change, std::abs(root.slope), refined_step, ds, du.norm(), point->precision(), bracket);
    if (!point->message.empty()) point->message += "; ";
    point->message += text;
  }
}

// A turning point at an SB point of the same step cannot be told apart from it: the tangent, and so τ_k,
// is undefined at the SB point and next to it set by the noise, and so is the turning point's own
// integration-error estimate. "At" means inside the SB point's interval or closer than kCoincidence of
// the step (docs/design/continuation.md, "Turning point at an SB point").
void SpecialPointDetector::PlaceTurningPointsAtSbPoints(double step, const std::vector<SpecialPoint>& bracket_only,
                                                        std::vector<SpecialPoint>* found) {
  for (const SpecialPoint& sb : *found) {
    if (sb.type != SpecialPointType::kSimpleBifurcation) continue;
    for (size_t i = 0; i < found->size(); ++i) {
      SpecialPoint& tp = (*found)[i];
      const double distance = std::abs(tp.arclength - sb.arclength);
      const bool inside = tp.arclength >= sb.interval_lo && tp.arclength <= sb.interval_hi;
      if (tp.type != SpecialPointType::kTurningPoint || !(inside || distance <= kCoincidence * step)) continue;
      const SpecialPoint& bracket = bracket_only[i];
      tp.interval_lo = std::min({bracket.interval_lo, sb.interval_lo, tp.arclength - distance});
      tp.interval_hi = std::max({bracket.interval_hi, sb.interval_hi, tp.arclength + distance});
      if (bracket.interval_width.size() == sb.interval_width.size() && tp.u.size() == sb.u.size()) {
        tp.interval_width = bracket.interval_width.cwiseMax(sb.interval_width + 2 * (tp.u - sb.u).cwiseAbs());
      }
      std::ostringstream text;
      text.precision(12);
      text << "at the simple bifurcation point at s = " << sb.arclength << " (";
      if (inside) {
        text << "inside its interval";
      } else {
        text << "closer than " << kCoincidence << " of the step";
      }
      text << "), where the tangent is undefined: located as well as that point, its own integration-error "
           << "estimate is meaningless there";
      tp.message = bracket.message.empty() ? text.str() : bracket.message + "; " + text.str();
    }
  }
}


// ---- Test functions (test_function.h)

double SpecialPointDetector::TestValue(int j, const Vector& u) { return functions_->EvaluateOne(j, u); }

// A point of the curve inside the interval l–r: the cubic Hermite interpolant of the two samples at σ
// (τ_lᵀ(u − u_l) = σ), corrected on that hyperplane (Segment::Evaluate).
bool SpecialPointDetector::CurvePoint(const CurveSample& l, const CurveSample& r, double sigma, CurveSample* out) {
  const Curve curve = TestCurve();
  Segment segment(curve.corrector, curve.solver, curve.problem, l.point, r.point, false);
  Segment::Probe pl, pr, probe;
  std::string message;
  if (!segment.EndProbe(false, &pl, &message) || !segment.EndProbe(true, &pr, &message)) return false;
  if (!segment.Evaluate(sigma, pl, 0, pr, segment.sigma_b(), &probe, &message)) return false;
  out->point.u = probe.u;
  out->point.tangent = probe.tangent.normalized();
  out->point.arclength = l.point.arclength + (probe.u - l.point.u).norm();
  out->point.sb_test = 0;
  functions_->Evaluate(probe.u, false, &out->point.test_values);
  out->step = l.step;
  return true;
}

// The samples of step `index`: its two branch points and, when SB or turning points were located inside
// it, the curve between them at the midpoints of the intervals they divide the step into (a fold and an
// SB point in one step may hold a whole excursion of the multipliers between them).
std::vector<SpecialPointDetector::CurveSample> SpecialPointDetector::StepSamples(size_t index, const Branch& branch) {
  const ContinuationPoint& a = branch.points[index];
  const ContinuationPoint& b = branch.points[index + 1];
  std::vector<double> cuts = {0.0};
  const double sigma_b = a.tangent.dot(b.u - a.u);
  for (const SpecialPoint& sp : branch.special_points) {
    const bool continuation_point =
        sp.type == SpecialPointType::kSimpleBifurcation || sp.type == SpecialPointType::kTurningPoint;
    if (!continuation_point || sp.index != static_cast<int>(index) || sp.u.size() != a.u.size()) continue;
    const double sigma = a.tangent.dot(sp.u - a.u);
    if (sigma > 0 && sigma < sigma_b) cuts.push_back(sigma);
  }
  cuts.push_back(sigma_b);
  std::sort(cuts.begin(), cuts.end());
  std::vector<CurveSample> samples(1);
  samples[0].point = a;
  samples[0].step = index;
  CurveSample end;
  end.point = b;
  end.step = index + 1;
  // Where no function is defined at both branch points, none is in between: no samples to take.
  const bool any_defined = (a.test_values.array().isFinite() && b.test_values.array().isFinite()).any();
  if (cuts.size() > 2 && any_defined) {
    for (size_t i = 0; i + 1 < cuts.size(); ++i) {
      CurveSample mid;
      if (cuts[i + 1] > cuts[i] && CurvePoint(samples[0], end, 0.5 * (cuts[i] + cuts[i + 1]), &mid)) {
        mid.step = index;
        // A function undefined at either branch point (a non-physical orbit) is undefined in between.
        Vector& g = mid.point.test_values;
        g = (a.test_values.array().isFinite() && b.test_values.array().isFinite()).select(g, std::nan(""));
        samples.push_back(std::move(mid));
      }
    }
  }
  samples.push_back(std::move(end));
  return samples;
}

SpecialPoint SpecialPointDetector::LocateTestZero(int j, const CurveSample& l, const CurveSample& r, Branch* branch) {
  if (!refined_functions_ && check_integration_error_) {
    refined_functions_ = functions_->Refined(ContinuationOptions::kIntegrationErrorFactor);
  }
  const Test test = [this, j](const Segment::Probe& p) { return TestValue(j, p.u); };
  const Test refined = [this, j, &test](const Segment::Probe& p) {
    return refined_functions_ ? refined_functions_->EvaluateOne(j, p.u) : test(p);
  };
  std::vector<SpecialPoint> unused;
  SpecialPoint point = LocateOn(TestCurve(), l.point, r.point, function_types_[j], j, test, &refined, l.step, branch, &unused);
  point.tangent_before = l.point.tangent;
  point.tangent_after = r.point.tangent;
  return point;
}

namespace {

// Golden-section search for the minimum of a function on σ ∈ [0, width], bracketed by its values at the
// ends: eval(σ, &sample) is the value at σ (NaN where it cannot be evaluated, which ends the search), its
// point left in sample. Stops once the bracket is below 1e-6 of width. True, at once, when a value is
// negative (the other sign); otherwise false with the final bracket in [*a_out, *b_out].
template <class Sample, class Eval>
bool GoldenSectionSearch(Eval&& eval, double width, double* a_out, double* b_out) {
  constexpr double kGolden = 0.6180339887498949;
  double a = 0, b = width;
  double x1 = b - kGolden * (b - a), x2 = a + kGolden * (b - a);
  Sample c1, c2;
  double f1 = eval(x1, &c1), f2 = eval(x2, &c2);
  while (std::isfinite(f1) && std::isfinite(f2)) {
    if (f1 < 0 || f2 < 0) return true;
    if (b - a < 1e-6 * width) break;
    if (f1 < f2) {
      b = x2, x2 = x1, f2 = f1, c2 = c1;
      x1 = b - kGolden * (b - a);
      f1 = eval(x1, &c1);
    } else {
      a = x1, x1 = x2, f1 = f2, c1 = c2;
      x2 = a + kGolden * (b - a);
      f2 = eval(x2, &c2);
    }
  }
  *a_out = a, *b_out = b;
  return false;
}

// Brent's minimization of f (parabolic steps with a golden-section fallback) on the bracket [*a_io, *b_io]
// from x, where f(x) = fx, to `tolerance` in σ, with at most max_evaluations evaluations; a non-finite
// value ends it. True, at once, when f takes a negative value (the other sign); otherwise false with the
// narrowed bracket in [*a_io, *b_io].
template <class F>
bool BrentMinimize(F&& f, double tolerance, int max_evaluations, double x, double fx, double* a_io, double* b_io) {
  constexpr double kGoldenStep = 0.3819660112501051;
  double a = *a_io, b = *b_io;
  double w = x, v = x;
  double fw = fx, fv = fx;
  double d = 0, e = 0;
  for (int it = 0; it < max_evaluations; ++it) {
    const double mid = 0.5 * (a + b);
    const double tol1 = 0.5 * tolerance + 1e-15 * std::abs(x), tol2 = 2 * tol1;
    if (std::abs(x - mid) <= tol2 - 0.5 * (b - a)) break;
    bool golden = true;
    if (std::abs(e) > tol1) {
      // The parabola through (x, fx), (w, fw), (v, fv): its vertex x + p/q.
      const double rr = (x - w) * (fx - fv);
      double q = (x - v) * (fx - fw);
      double p = (x - v) * q - (x - w) * rr;
      q = 2 * (q - rr);
      if (q > 0) p = -p;
      q = std::abs(q);
      const double previous = e;
      e = d;
      if (std::abs(p) < std::abs(0.5 * q * previous) && p > q * (a - x) && p < q * (b - x)) {
        d = p / q;
        golden = false;
        if ((x + d) - a < tol2 || b - (x + d) < tol2) d = mid > x ? tol1 : -tol1;
      }
    }
    if (golden) {
      e = x >= mid ? a - x : b - x;
      d = kGoldenStep * e;
    }
    const double u = x + (std::abs(d) >= tol1 ? d : (d > 0 ? tol1 : -tol1));
    const double fu = f(u);
    if (!std::isfinite(fu)) break;
    if (fu < 0) return true;
    if (fu <= fx) {
      (u >= x ? a : b) = x;
      v = w, fv = fw, w = x, fw = fx, x = u, fx = fu;
    } else {
      (u < x ? a : b) = u;
      if (fu <= fw || w == x) {
        v = w, fv = fw, w = u, fw = fu;
      } else if (fu <= fv || v == x || v == w) {
        v = u, fv = fu;
      }
    }
  }
  *a_io = a, *b_io = b;
  return false;
}

// The miss distance sqrt(value/κ) of the bowl g ≈ κ(σ − σ*)² + value around a minimum `value` at σ* =
// sigma, with κ from the evaluation (σ, g) in trace nearest σ* whose value is well above the minimum (the
// minimum's own neighbours are at its noise); half the bracket where there is none.
double BowlMissDistance(const std::vector<std::pair<double, double>>& trace, double sigma, double value,
                        double bracket) {
  double kappa = 0, nearest = std::numeric_limits<double>::infinity();
  for (const auto& [s, g] : trace) {
    const double distance = std::abs(s - sigma);
    if (g > 100 * std::max(value, 0.0) && distance > 0 && distance < nearest) {
      nearest = distance;
      kappa = (g - value) / (distance * distance);
    }
  }
  return kappa > 0 ? std::sqrt(std::max(value, 0.0) / kappa) : 0.5 * bracket;
}

}  // namespace

// Golden-section search for the minimum of sign·g_j on each of the intervals l–m and m–r (the one the
// parabola through the three samples points to first), stopped at the first sample of the other sign.
// Where the smallest value found is a candidate touching zero, Brent's method (parabolic steps with a
// golden-section fallback) refines that interval's bracket to location_tolerance in σ.
SpecialPointDetector::CurveMinimum SpecialPointDetector::MinimizeOnCurve(int j, double sign, const CurveSample& l,
                                                                         const CurveSample& m, const CurveSample& r) {
  const auto value = [&](const CurveSample& c) { return sign * c.point.test_values(j); };
  const double s0 = 0, s1 = (m.point.u - l.point.u).norm(), s2 = s1 + (r.point.u - m.point.u).norm();
  const double g0 = value(l), g1 = value(m), g2 = value(r);
  // Vertex of the parabola through the three samples (in chord length): which side to search first.
  const double d1 = (g1 - g0) / (s1 - s0), d2 = (g2 - g1) / (s2 - s1);
  const double curvature = (d2 - d1) / (s2 - s0);
  const double vertex = curvature > 0 ? 0.5 * (s0 + s1) - d1 / (2 * curvature) : s1;
  CurveMinimum best;
  best.sample = m;
  best.value = g1;
  // Per interval (0: l–m, 1: m–r): the final golden bracket and every evaluation (σ, value) in it, for
  // the refinement and the bowl's curvature.
  struct Side {
    bool searched = false;
    double a = 0, b = 0;
    std::vector<std::pair<double, double>> trace;
  };
  Side sides[2];
  int budget = kPairSearchEvaluations;
  for (const bool on_left : {vertex < s1, !(vertex < s1)}) {
    const CurveSample& lo = on_left ? l : m;
    const CurveSample& hi = on_left ? m : r;
    const double width = lo.point.tangent.dot(hi.point.u - lo.point.u);
    if (!(width > 0)) continue;
    Side& side = sides[on_left ? 0 : 1];
    side.trace = {{on_left ? width : 0.0, g1}};
    const auto eval = [&](double x, CurveSample* c) {
      if (budget-- <= 0 || !CurvePoint(lo, hi, x, c)) return std::numeric_limits<double>::quiet_NaN();
      ++best.evaluations;
      const double v = value(*c);
      side.trace.emplace_back(x, v);
      if (v < best.value) best.value = v, best.sample = *c, best.sigma = x, best.left = on_left;
      return v;
    };
    // Golden section on σ ∈ [0, width] of this interval, the minimum bracketed by the samples' values.
    double a = 0, b = 0;
    if (GoldenSectionSearch<CurveSample>(eval, width, &a, &b)) {
      best.other_sign = true;
      return best;
    }
    side.searched = true;
    side.a = a, side.b = b;
  }
  const double scale = std::max({std::abs(g0), std::abs(g1), std::abs(g2)});
  if (!(best.value <= kTouchCandidate * scale)) return best;

  // Brent's minimization on the final bracket of the interval that holds the smallest value, or of both
  // when that is still the middle sample m (the minimum lies next to it, on either side).
  const bool at_m = best.value == g1;
  for (const int k : {0, 1}) {
    Side& side = sides[k];
    const bool on_left = k == 0;
    if (!side.searched || !(at_m || best.left == on_left)) continue;
    const CurveSample& lo = on_left ? l : m;
    const CurveSample& hi = on_left ? m : r;
    const auto f = [&](double x) {
      CurveSample c;
      if (!CurvePoint(lo, hi, x, &c)) return std::numeric_limits<double>::quiet_NaN();
      ++best.evaluations;
      const double v = value(c);
      side.trace.emplace_back(x, v);
      if (v < best.value) best.value = v, best.sample = std::move(c), best.sigma = x, best.left = on_left;
      return v;
    };
    const double x = at_m ? (on_left ? side.b : side.a) : best.sigma;
    if (BrentMinimize(f, location_tolerance_, kTouchEvaluations, x, best.value, &side.a, &side.b)) {
      best.other_sign = true;
      return best;
    }
  }
  const Side& side = sides[best.left ? 0 : 1];
  best.bracket = side.b - side.a;
  best.miss = BowlMissDistance(side.trace, best.sigma, best.value, best.bracket);
  return best;
}

SpecialPoint SpecialPointDetector::TouchingZero(int j, const CurveSample& lo, const CurveSample& hi,
                                                const CurveMinimum& minimum, double scale, Branch* branch) {
  SpecialPoint point;
  point.type = function_types_[j];
  point.status = LocationStatus::kLocated;
  point.branch_id = branch->id;
  point.index = static_cast<int>(lo.step);
  point.component_index = j;
  point.u = minimum.sample.point.u;
  point.tangent = minimum.sample.point.tangent;
  point.tangent_before = lo.point.tangent;
  point.tangent_after = hi.point.tangent;
  point.arclength = minimum.sample.point.arclength;
  point.test_value = minimum.sample.point.test_values(j);
  // The minimum is known to its bracket; where g does not reach zero at the evaluations' resolution the
  // zero may lie anywhere the bowl is below that resolution: half-width max(bracket, miss distance).
  const double half = std::max(0.5 * minimum.bracket, minimum.miss);
  point.interval_lo = point.arclength - half;
  point.interval_hi = point.arclength + half;
  point.interval_width = point.tangent.cwiseAbs() * (2 * half);
  point.iterations = minimum.evaluations;
  Vector residual;
  if (TestCurve().problem->Evaluate(point.u, &residual, nullptr).ok) point.residual_norm = residual.norm();
  char text[320];
  std::snprintf(text, sizeof(text),
                "touching zero: the test function reaches zero without changing sign (a double zero: |g| = %.2g, "
                "%.2g of its value at the samples around it); located as the minimum of |g| on the curve",
                std::abs(point.test_value), std::abs(point.test_value) / scale);
  point.message = text;
  branch->located_iterations += minimum.evaluations;
  return point;
}

void SpecialPointDetector::DetectTestFunctions(size_t index, bool from_singular, Branch* branch) {
  if (!functions_) return;
  const std::vector<ContinuationPoint>& points = branch->points;
  const int n = static_cast<int>(function_types_.size());
  if (points[index].test_values.size() != n || points[index + 1].test_values.size() != n) return;
  std::vector<CurveSample> samples = StepSamples(index, *branch);
  // The previous branch point: a local minimum of |g| at this step's start spans both steps.
  const bool with_previous = index >= 1 && points[index - 1].test_values.size() == n;
  if (with_previous) {
    CurveSample previous;
    previous.point = points[index - 1];
    previous.step = index - 1;
    samples.insert(samples.begin(), std::move(previous));
  }
  const size_t first = with_previous ? 1 : 0;  // samples[first] is points[index]
  std::vector<SpecialPoint> found;
  for (int j = 0; j < n; ++j) {
    const auto g = [&](size_t k) { return samples[k].point.test_values(j); };
    const auto defined = [&](size_t k) { return std::isfinite(g(k)) && g(k) != 0; };
    // The first interval from a bifurcation point: a test that vanishes there marks the parent's point.
    const bool skip_first = from_singular && samples.size() > first + 1 && defined(first + 1) &&
                            !(std::abs(g(first)) > kStartNoise * std::abs(g(first + 1)));
    const auto may_keep = [&](size_t lo, size_t hi) {
      return functions_->MayKeepZeroBetween(j, samples[lo].point.u, samples[hi].point.u);
    };
    for (size_t k = first; k + 1 < samples.size(); ++k) {
      if (k == first && skip_first) continue;
      if (defined(k) && defined(k + 1) && std::signbit(g(k)) != std::signbit(g(k + 1)) && may_keep(k, k + 1)) {
        found.push_back(LocateTestZero(j, samples[k], samples[k + 1], branch));
      }
    }
    // Two zeros between samples: at a local minimum of |g| of one sign, minimize on the curve.
    for (size_t k = std::max<size_t>(first, 1); k + 1 < samples.size(); ++k) {
      if (!(defined(k - 1) && defined(k) && defined(k + 1))) continue;
      const bool one_sign = std::signbit(g(k - 1)) == std::signbit(g(k)) && std::signbit(g(k)) == std::signbit(g(k + 1));
      if (!one_sign || !(std::abs(g(k)) < std::abs(g(k - 1)) && std::abs(g(k)) <= std::abs(g(k + 1)))) continue;
      // A dip at the noise level of g is no bowl: a function constant along the branch (a homogeneous
      // model's multipliers) has such "minima" at a third of its samples.
      const double rim = std::min(std::abs(g(k - 1)), std::abs(g(k + 1)));
      if (rim - std::abs(g(k)) <= kNoiseDip * std::abs(g(k))) continue;
      if (!may_keep(k - 1, k) && !may_keep(k, k + 1)) continue;  // the middle sample may be the physical one
      CurveMinimum minimum = MinimizeOnCurve(j, std::signbit(g(k)) ? -1.0 : 1.0, samples[k - 1], samples[k], samples[k + 1]);
      const CurveSample& lo = minimum.left ? samples[k - 1] : samples[k];
      const CurveSample& hi = minimum.left ? samples[k] : samples[k + 1];
      minimum.sample.step = lo.step;
      if (minimum.other_sign) {
        found.push_back(LocateTestZero(j, lo, minimum.sample, branch));
        found.push_back(LocateTestZero(j, minimum.sample, hi, branch));
        continue;
      }
      const double scale = std::max({std::abs(g(k - 1)), std::abs(g(k)), std::abs(g(k + 1))});
      if (minimum.value <= kTouchingZero * scale) found.push_back(TouchingZero(j, lo, hi, minimum, scale, branch));
    }
  }
  Insert(std::move(found), branch);
}

void SpecialPointDetector::RedetectTestFunctions(size_t from, Branch* branch) {
  if (!functions_) return;
  // Sampled anew; where every value is the mapped one (the symmetry leaves the functions invariant, e.g.
  // a mirror that keeps the multipliers), the mapped zeros stand.
  bool invariant = true;
  // The symmetry that mapped the branch (an involution: it maps each point back onto its preimage).
  const Symmetry* symmetry = nullptr;
  const std::vector<Symmetry> symmetries = problem_->symmetries();
  for (const Symmetry& s : symmetries) {
    if (s.name == branch->symmetry) symmetry = &s;
  }
  // A mapped branch is images from its start; a reflected loop from after its midpoint (`from`, traced).
  const size_t first_image = branch->image_of >= 0 ? from : from + 1;
  for (size_t i = from; i < branch->points.size(); ++i) {
    ContinuationPoint& p = branch->points[i];
    const Vector mapped = p.test_values;
    p.evaluated_at.resize(0);
    if (symmetry != nullptr && i >= first_image && symmetry->signs.size() == p.u.size()) {
      functions_->EvaluateAtImage(p.u, symmetry->Apply(p.u), &p.test_values);
    } else {
      Sample(&p);
    }
    if (mapped.size() != p.test_values.size()) {
      invariant = false;
      continue;
    }
    for (Eigen::Index j = 0; j < mapped.size(); ++j) {
      const double x = mapped(j), y = p.test_values(j);
      const bool same = (std::isnan(x) && std::isnan(y)) || std::abs(x - y) <= kInvariantTolerance * std::abs(x);
      invariant = invariant && same;
    }
  }
  if (invariant) return;
  std::erase_if(branch->special_points, [from](const SpecialPoint& sp) {
    const bool test_zero = sp.type != SpecialPointType::kSimpleBifurcation &&
                           sp.type != SpecialPointType::kTurningPoint && sp.type != SpecialPointType::kSingularStart;
    return test_zero && sp.index >= static_cast<int>(from);
  });
  for (size_t i = from; i + 1 < branch->points.size(); ++i) {
    DetectTestFunctions(i, i == 0 && branch->parent_special_point >= 0, branch);
  }
}

void RedetectTestFunctions(ZeroProblem* problem, const ContinuationOptions& options, size_t from, Branch* branch) {
  if (!options.test_functions) return;
  Corrector corrector(problem, options.corrector);
  BorderedSolver solver;
  SpecialPointDetector(problem, &corrector, &solver, options).RedetectTestFunctions(from, branch);
}

}  // namespace hybridcont::internal
