#include "hybridcont/floquet_test_functions.h"

#include <algorithm>
#include <stdexcept>

#include <Eigen/LU>
#include <cmath>
#include <limits>

#include "hybridcont/classification.h"
#include "hybridcont/orbit_analysis.h"
#include "hybridcont/orbit_trace.h"
#include "hybridcont/replay.h"

namespace hybridcont {

Matrix PeriodDoublingMatrix(const Matrix& dr, const ShootingLayout& layout) {
  const int rows = layout.first_integral_row(), cols = layout.xi_index();
  HYBRIDCONT_DEMAND(rows == cols && dr.rows() >= rows && dr.cols() >= cols);
  Matrix a = dr.topLeftCorner(rows, cols);
  // The periodicity rows of block m+1 against x̄_1: −I becomes +I.
  const int last = layout.num_segments() - 1;
  a.block(layout.block_row(last), layout.state_offset(0), layout.dim(0), layout.dim(0)) *= -1.0;
  return a;
}

double PeriodDoublingTest(const Matrix& dr, const ShootingLayout& layout) {
  const Matrix a = PeriodDoublingMatrix(dr, layout);
  double log_rows = 0;
  for (Eigen::Index i = 0; i < a.rows(); ++i) {
    const double norm = a.row(i).norm();
    if (!(norm > 0)) return std::numeric_limits<double>::quiet_NaN();
    log_rows += std::log(norm);
  }
  const Eigen::PartialPivLU<Matrix> lu(a);
  const Matrix& lu_matrix = lu.matrixLU();
  double sign = lu.permutationP().determinant();
  double log_det = 0;
  for (Eigen::Index i = 0; i < a.rows(); ++i) {
    const double pivot = lu_matrix(i, i);
    if (pivot == 0) return 0.0;
    if (pivot < 0) sign = -sign;
    log_det += std::log(std::abs(pivot));
  }
  return sign * std::exp(log_det - log_rows);
}

FloquetTestFunctions::FloquetTestFunctions(const HybridModel& model, const IntegratorOptions& integrator,
                                           bool physical_only, FreeParameters free)
    : model_(&model),
      integrator_(integrator),
      physical_only_(physical_only),
      free_(std::move(free)),
      shooting_(model, integrator, free_),
      base_unknowns_(ShootingLayout(model).num_unknowns()),
      point_model_(free_.empty() ? nullptr : std::make_unique<HybridModel>(model.Clone())) {
  shooting_.set_threads(1);  // a stepper's own copy works on the stepper's thread
  const ShootingLayout base(model);
  for (int i = 0; i < base.num_segments(); ++i) time_index_.push_back(base.time_index(i));
}

std::vector<SpecialPointType> FloquetTestFunctions::types() const {
  std::vector<SpecialPointType> types = {SpecialPointType::kFloquetBranchPoint, SpecialPointType::kPeriodDoubling};
  types.insert(types.end(), model_->num_phases(), SpecialPointType::kGrazing);
  types.push_back(SpecialPointType::kNeimarkSacker);
  if (model_->num_first_integrals() > 0) types.push_back(SpecialPointType::kKreinCollision);
  types.insert(types.end(), model_->num_phases(), SpecialPointType::kGrazing);  // the own events
  types.insert(types.end(), std::max(0, model_->num_phases() - 1), SpecialPointType::kZeroDuration);
  return types;
}

int FloquetTestFunctions::first_own_event() const {
  return 2 + model_->num_phases() + 1 + (model_->num_first_integrals() > 0 ? 1 : 0);
}

const HybridModel* FloquetTestFunctions::ModelAt(const Vector& u_free) const {
  if (!point_model_) return model_;
  const ShootingLayout& layout = shooting_.layout();
  for (int i = 0; i < layout.num_free_parameters(); ++i) {
    try {
      point_model_->SetParameterValue(layout.parameter_model_index(i), u_free(layout.parameter_index(i)));
    } catch (const std::invalid_argument&) {
      return nullptr;  // outside the parameter's range: no orbit of the model
    }
  }
  return point_model_.get();
}

Classification FloquetTestFunctions::Classify(const HybridModel& model, const Vector& u,
                                              std::unique_ptr<OrbitTrace>* trace) const {
  Classification c;
  if (!ClassifyByUnknowns(model, u, ClassificationOptions{}, &c)) {
    auto orbit = std::make_unique<OrbitTrace>(model, u, integrator_);
    c = ClassifyOrbit(model, u, *orbit, ClassificationOptions{});
    if (trace != nullptr) *trace = std::move(orbit);
  }
  return c;
}

bool FloquetTestFunctions::MissedEventEndsPhysicalFamily(const Vector& u_free) const {
  return PhysicalOr(u_free, {OrbitClass::kMissedEvent, OrbitClass::kGrazing});
}

bool FloquetTestFunctions::PhysicalOr(const Vector& u_free, std::initializer_list<OrbitClass> reasons) const {
  const HybridModel* model = ModelAt(u_free);
  if (model == nullptr) return false;
  const Classification c = Classify(*model, u_free.head(base_unknowns_));
  return c.physical || std::find(reasons.begin(), reasons.end(), c.reason) != reasons.end();
}

namespace {

// Whether the trace shows a local minimum of phase i's event inside the phase once the event has been above
// 0 (armed, as OwnEventObservable counts it). Phase 1 runs the return segment m and then segment 0; a
// walker's heel-strike guard, below 0 after the strike until mid-stance (scuffing), has its dip before it is
// armed. The event is sampled on the Hermite interpolant of every step, finely enough that no state moves
// by more than 0.02 between samples (a nearly exactly integrated flight takes a few long steps).
bool HasArmedEventMinimum(const HybridModel& model, const OrbitTrace& trace, int phase) {
  const int m = model.num_phases();
  constexpr double kMaxMotion = 0.02;
  constexpr int kMaxSamplesPerStep = 1000;
  bool armed = false;
  double before = std::numeric_limits<double>::quiet_NaN(), last = before;  // the two previous samples
  for (const int s : phase == 0 ? std::vector<int>{m, 0} : std::vector<int>{phase}) {
    const auto& nodes = trace.segment(s);
    for (std::size_t j = 0; j < nodes.size(); ++j) {
      const int samples = j == 0 ? 1 : static_cast<int>(std::clamp<double>(
          std::ceil(std::max(nodes[j - 1].f.cwiseAbs().maxCoeff(), nodes[j].f.cwiseAbs().maxCoeff()) *
                    std::abs(nodes[j].t - nodes[j - 1].t) / kMaxMotion), 1, kMaxSamplesPerStep));
      for (int k = 1; k <= samples; ++k) {
        const double t = j == 0 ? nodes[0].t : nodes[j - 1].t + (nodes[j].t - nodes[j - 1].t) * k / samples;
        const double g = model.phase(phase).Event(
            k == samples ? nodes[j].x : trace.Interpolate(s, static_cast<int>(j) - 1, t), nullptr);
        if (armed && before > last && g > last) return true;  // `last` is a local minimum
        armed = armed || g > kGuardStartTolerance;
        before = last, last = g;
      }
    }
  }
  return false;
}

}  // namespace

void FloquetTestFunctions::EvaluateOwnEvents(const Vector& u, const OrbitTrace* trace, Vector* values) {
  const int m = model_->num_phases();
  // The evaluator reads the parameter values of the model it is made on: the model at u's (ModelAt).
  const HybridModel* at_u = ModelAt(u);
  if (at_u == nullptr) return;
  const HybridModel& model = *at_u;
  if (!own_event_evaluator_) {
    own_event_evaluator_ = std::make_unique<ObservableEvaluator>(model, shooting_.layout(), integrator_);
    for (int i = 0; i < m; ++i) own_events_.push_back(OwnEventObservable(model, i));
    own_defined_.assign(m, true);  // a fresh copy (a refined one) evaluates at trial points
  }
  for (int i = 0; i < m; ++i) {
    // At a branch point: where the trace shows an armed minimum. At a trial point between two branch points:
    // where the last branch point had a value (a zero is only located between two that have one).
    if (trace != nullptr) own_defined_[i] = HasArmedEventMinimum(*model_, *trace, i);
    if (!own_defined_[i]) continue;
    double value = 0.0;
    if (!own_event_evaluator_->EvaluateExtremum(own_events_[i], u, &value, nullptr).ok) continue;
    if (own_event_evaluator_->last_extremum_interior()) (*values)(first_own_event() + i) = value;
    if (trace != nullptr) own_defined_[i] = own_event_evaluator_->last_extremum_interior();
  }
}

void FloquetTestFunctions::EvaluateDurations(const Vector& u, bool branch_point, const Classification& c,
                                             Vector* values) {
  const int m = model_->num_phases();
  const bool by_duration = c.reason == OrbitClass::kReversedTime || c.reason == OrbitClass::kZeroDuration;
  const bool after_physical = last_branch_physical_;
  if (branch_point) last_branch_physical_ = c.physical;
  if (branch_point && !c.physical && !by_duration) return;
  double T = 0.0;
  for (const int k : time_index_) T += u(k);
  const double same = 1e-9 * std::max(1.0, std::abs(T));
  const double zero = ClassificationOptions{}.duration_tolerance * std::max(1.0, std::abs(T));
  for (int i = 1; i < m; ++i) {
    const double t = u(time_index_[i]);
    bool defined = !branch_point || c.physical || after_physical;
    // (a duration within the classification's zero of 0 is no side of a crossing: families whose phase lasts
    // no time, t_i rounding about 0, locate nothing)
    if (!defined && !(t < -zero)) continue;
    // Before a physical point of the trace: t_i and its symmetric copies (a gait's two flights) are the only
    // durations not positive, so that this point and a physical neighbour bracket the end of the family.
    for (int j = 0; j <= m && !defined; ++j) {
      const double tj = u(time_index_[j]);
      if (j != i && tj <= 0 && std::abs(tj - t) > same) break;
      if (j == m) defined = true;
    }
    if (defined) (*values)(first_zero_duration() + i - 1) = t;
  }
}

bool FloquetTestFunctions::Physical(const Vector& u_free) const {
  const HybridModel* model = ModelAt(u_free);
  if (model == nullptr) return false;
  const Vector u = u_free.head(base_unknowns_);
  return Classify(*model, u).physical && Replays(*model, u);
}

bool FloquetTestFunctions::Replays(const HybridModel& model, const Vector& u) const {
  return Replay(model, u).physical();
}

ReplayResult FloquetTestFunctions::Replay(const HybridModel& model, const Vector& u) const {
  return ReplayOrbit(model, u, OrbitAnalysisOptions::For(integrator_).replay);
}

bool FloquetTestFunctions::GrazingEndsPhysicalFamily(const Vector& u_free) const {
  return PhysicalOr(u_free, {OrbitClass::kGrazing});
}

void FloquetTestFunctions::Evaluate(const Vector& u, bool branch_point, Vector* values) {
  EvaluateOn(&shooting_, u, u, branch_point, values);
}

double FloquetTestFunctions::EvaluateOne(int function, const Vector& u) {
  const int m = model_->num_phases();
  const int n = static_cast<int>(types().size());
  if (function < 0 || function >= n) throw std::out_of_range("FloquetTestFunctions::EvaluateOne: no such function");
  Vector values = Vector::Constant(n, std::numeric_limits<double>::quiet_NaN());
  if (function >= first_zero_duration()) {
    EvaluateDurations(u, false, Classification{}, &values);
  } else if (function >= first_own_event()) {
    EvaluateOwnEvents(u, nullptr, &values);
  } else if (function >= 2 && function < 2 + m) {  // phase i's crossing speed, as EvaluateOn has it
    if (!shooting_.Evaluate(u, &r_, nullptr).ok) return std::numeric_limits<double>::quiet_NaN();
    const int i = function - 2;
    const Vector& x = shooting_.segment_flow(i).x;
    RowVector de;
    Vector f;
    shooting_.model().phase(i).Event(x, &de);
    shooting_.model().phase(i).VectorField(x, &f, nullptr);
    return de.dot(f) / std::max(de.norm() * f.norm(), 1e-300);
  } else {
    EvaluateOn(&shooting_, u, u, false, &values);
  }
  return values(function);
}

void FloquetTestFunctions::EvaluateAtImage(const Vector& u, const double* preimage_residual, Vector* values) {
  EvaluateOn(&shooting_, u, u, true, values, preimage_residual);
}

bool FloquetTestFunctions::SameMap(const TimeBasedShooting& map) const {
  const IntegratorOptions& o = map.integrator_options();
  return map.num_equations() == shooting_.num_equations() && map.unknown_names() == shooting_.unknown_names() &&
         o.method == integrator_.method && o.rtol == integrator_.rtol && o.atol == integrator_.atol &&
         o.initial_step == integrator_.initial_step && o.min_step == integrator_.min_step &&
         o.max_steps == integrator_.max_steps;
}

bool FloquetTestFunctions::EvaluateAtBranchPoint(const Vector& u, TimeBasedShooting* map, const Vector& at,
                                                 Vector* values) {
  if (map != nullptr && SameMap(*map) && map->HoldsEvaluation(at, shooting_.jacobian_tolerance())) {
    EvaluateOn(map, at, u, true, values);
    ++reused_evaluations_;
    return true;
  }
  Evaluate(u, true, values);
  return false;
}

void FloquetTestFunctions::EvaluateOn(TimeBasedShooting* map, const Vector& at, const Vector& u, bool branch_point,
                                      Vector* values, const double* image_residual) {
  const int m = model_->num_phases();
  const int ns = 2 + m;  // the Neimark–Sacker function, then (conservative) the Krein one
  const bool krein = model_->num_first_integrals() > 0;
  *values = Vector::Constant(ns + 1 + (krein ? 1 : 0) + m + std::max(0, m - 1), std::numeric_limits<double>::quiet_NaN());
  // A branch point's class: it decides whether the Floquet functions are defined there (physical_only) and,
  // for a conservative model, whether the crossing speeds are (see below).
  const HybridModel* model_at_u = branch_point ? ModelAt(u) : model_;
  Classification c;
  std::unique_ptr<OrbitTrace> trace;
  if (branch_point && model_at_u != nullptr) {
    c = Classify(*model_at_u, u.head(base_unknowns_), &trace);
    constexpr std::size_t kRecent = 4;  // a step's two ends, and those of the step before
    if (recent_classes_.size() == kRecent) recent_classes_.erase(recent_classes_.begin());
    recent_classes_.emplace_back(u, c);
  }
  // The crossing speeds of every orbit of a model without first integral; of a conservative model, at
  // branch points that are physical or fail only by an event's direction (wrong-direction, grazing): where
  // a physical family ends at grazing its next point is of that class, and the zeros elsewhere, on orbits
  // that are no motion of the system, would be located for nothing (they are not kept, Keep).
  const bool speeds = !krein || !branch_point ||
                      (model_at_u != nullptr && (c.physical || c.reason == OrbitClass::kWrongDirection ||
                                                 c.reason == OrbitClass::kGrazing));
  // The Floquet functions are defined on physical orbits, and on those beyond a constraint boundary that are
  // otherwise physical (a competing guard touched: the family goes on as orbits of the same phase sequence),
  // so that a multiplier crossing between a family's last physical point and a boundary the next step jumped
  // over is bracketed; its zero is kept only where the orbit is physical (Keep).
  const bool defined = c.physical || c.reason == OrbitClass::kConstraintViolated;
  // The map's evaluation: r comes with dr at no cost (a branch point's residual, for its analysis); on a map
  // that holds the evaluation at `at` (HoldsEvaluation) nothing is integrated. An image's is made only where
  // a value needs it: its residual is its preimage's (EvaluateAtImage).
  const bool needs_map = image_residual == nullptr || !physical_only_ || speeds || (defined && model_at_u != nullptr);
  const bool evaluated = needs_map && map->Evaluate(at, branch_point ? &r_ : nullptr, &dr_).ok;
  if (branch_point) {
    last_branch_point_.reset();
    if (model_at_u != nullptr) {
      // From an evaluation at a nearby iterate (EvaluateAtBranchPoint): u's residual extrapolated linearly,
      // r(at) + dr(at)(u − at), exact up to ω|u − at|²/2 (ω bounds the second derivative of r): the
      // corrector's last step makes that linear model vanish to rounding, as Newton's r(u) does.
      double residual = 0.0;
      if (evaluated) residual = &at == &u ? r_.norm() : (r_ + dr_ * (u - at)).norm();
      else if (image_residual != nullptr) residual = *image_residual;
      last_branch_point_ = BranchPointAnalysis{u, c, false, {}, false, {}, evaluated || image_residual != nullptr,
                                               residual};
    }
  }
  // A phase's own event touched inside it: at branch points where a physical family may end so (physical
  // or missed-event) and the trace shows an interior minimum of the event; at trial points always.
  if ((evaluated || !needs_map) && (!branch_point || (trace && (c.physical || c.reason == OrbitClass::kMissedEvent)))) {
    EvaluateOwnEvents(u, branch_point ? trace.get() : nullptr, values);
  }
  EvaluateDurations(u, branch_point, c, values);
  if (evaluated && speeds) {  // the crossing speed changes sign at grazing
    const HybridModel& model = map->model();  // at u's parameter values
    for (int i = 0; i < m; ++i) {
      const Vector& x = map->segment_flow(i).x;
      RowVector de;
      Vector f;
      model.phase(i).Event(x, &de);
      model.phase(i).VectorField(x, &f, nullptr);
      (*values)(2 + i) = de.dot(f) / std::max(de.norm() * f.norm(), 1e-300);
    }
  }
  if (branch_point && physical_only_) {
    if (model_at_u == nullptr || !defined) return;
    last_branch_point_->replay = Replay(*model_at_u, u.head(base_unknowns_));
    last_branch_point_->replayed = true;
    if (!last_branch_point_->replay.physical()) return;
  }
  const FloquetResult floquet = ComputeFloquet(*map, at);
  if (branch_point && last_branch_point_) {
    last_branch_point_->floquet = floquet;
    last_branch_point_->floquet_known = true;
  }
  if (!floquet.ok()) return;
  // A branch point the integration does not resolve (floquet.h, "Accuracy of the multipliers"): its
  // multipliers' functions are noise there, and no zero is bracketed next to it.
  if (branch_point && floquet.multiplier_error > kUnresolvedMultiplierError) return;
  (*values)(0) = floquet.bp_test;
  if (evaluated) (*values)(1) = PeriodDoublingTest(dr_, map->layout());  // dr_ from the evaluation above
  // On a symplectic map ns_test is 0 up to the multipliers' errors everywhere: no sign there (NaN) at
  // branch points, so that noise marks no point; a crossing elsewhere has |ns_test| of order 1 at the
  // branch points around it and keeps its values in between.
  (*values)(ns) = branch_point && std::abs(floquet.ns_test) < kNeimarkSackerUndefined ? std::nan("") : floquet.ns_test;
  if (krein) (*values)(ns + 1) = floquet.krein_test;  // NaN where the map is not symplectic
}

bool FloquetTestFunctions::MayKeepZeroBetween(int function, const Vector& a, const Vector& b) {
  // As Keep decides: an own event's zero where a physical family ends by it (any model), a crossing speed's
  // where a conservative model's physical family ends by grazing.
  if (types()[function] != SpecialPointType::kGrazing) return true;
  const bool own_event = function >= first_own_event() && function < first_zero_duration();
  if (!own_event && model_->num_first_integrals() == 0) return true;
  const auto may_end = [&](const Vector& u) {
    const auto known = std::find_if(recent_classes_.begin(), recent_classes_.end(),
                                    [&](const auto& entry) { return entry.first.size() == u.size() && entry.first == u; });
    if (known == recent_classes_.end()) {
      return own_event ? MissedEventEndsPhysicalFamily(u) : GrazingEndsPhysicalFamily(u);
    }
    const Classification& c = known->second;
    return c.physical || c.reason == OrbitClass::kGrazing || (own_event && c.reason == OrbitClass::kMissedEvent);
  };
  return may_end(a) || may_end(b);
}

bool FloquetTestFunctions::Keep(int function, const Vector& u, std::string* note) {
  const SpecialPointType type = types()[function];
  if (physical_only_ && type != SpecialPointType::kGrazing) {
    // A Floquet zero beyond a constraint boundary (see Evaluate) is no bifurcation of the mechanical system.
    const HybridModel* model = ModelAt(u);
    if (model != nullptr && Classify(*model, u.head(base_unknowns_)).reason == OrbitClass::kConstraintViolated) {
      return false;
    }
  }
  if (function >= first_own_event() && function < first_zero_duration()) {
    *note = "the event of phase '" + model_->phase(function - first_own_event()).name() + "' touched inside the phase";
    return MissedEventEndsPhysicalFamily(u);
  }
  if (type == SpecialPointType::kGrazing) {
    // A conservative model's grazing is kept where a physical family ends: the orbit there is physical
    // but for the tangency (its class is grazing). Elsewhere the crossing speed changes sign on orbits that
    // are no motion of the system, which a conservative diagram has many of.
    if (model_->num_first_integrals() == 0) return true;
    return GrazingEndsPhysicalFamily(u);
  }
  if (type == SpecialPointType::kZeroDuration) {
    // The end of a physical family: no other duration negative there (a symmetric gait's two flights vanish
    // together). Elsewhere a duration changes sign on orbits that run some phase backwards in time.
    const ShootingLayout base(*model_);
    const double tolerance = ClassificationOptions{}.duration_tolerance * std::max(1.0, std::abs(base.Period(u)));
    for (int j = 0; j < base.num_segments(); ++j) {
      if (u(base.time_index(j)) < -tolerance) return false;
    }
    *note = "phase '" + model_->phase(function - first_zero_duration() + 1).name() + "' of duration 0";
    return true;
  }
  if (type != SpecialPointType::kNeimarkSacker && type != SpecialPointType::kKreinCollision) return true;
  const FloquetResult floquet = ComputeFloquet(shooting_, u);
  if (!floquet.ok()) return true;
  (void)note;
  if (type == SpecialPointType::kKreinCollision) {
    return floquet.HasKreinCollision(kKreinMeetTolerance);  // else two real pairs met off the unit circle
  }
  return floquet.HasUnitComplexPair(kUnitPairTolerance);  // else a neutral saddle: no bifurcation
}

std::unique_ptr<TestFunctions> FloquetTestFunctions::Clone() const {
  return std::make_unique<FloquetTestFunctions>(*model_, integrator_, physical_only_, free_);
}

std::unique_ptr<TestFunctions> FloquetTestFunctions::Refined(double factor) const {
  IntegratorOptions refined = integrator_;
  refined.rtol *= factor;
  refined.atol *= factor;
  return std::make_unique<FloquetTestFunctions>(*model_, refined, physical_only_, free_);
}

}  // namespace hybridcont
