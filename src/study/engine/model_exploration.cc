#include "study/engine/model_exploration.h"

#include <fmt/format.h>

#include <algorithm>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <stdexcept>

#include "study/engine/family_boundaries.h"
#include "hybridcont/classification.h"
#include "hybridcont/branch_switching.h"
#include "hybridcont/corrector.h"
#include "hybridcont/floquet_test_functions.h"
#include "hybridcont/observable_test_functions.h"
#include "hybridcont/internal/enum_names.h"
#include "hybridcont/period_doubling.h"
#include "hybridcont/simulation_start.h"
#include "hybridcont/start_check.h"

namespace hybridcont::study {

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

namespace {

constexpr internal::EnumName<Formulation> kFormulationNames[] = {
    {Formulation::kTimeBased, "time"},
    {Formulation::kStateBased, "state"},
};

}  // namespace

// Where every copy of the Floquet test functions leaves its work when it is done (the copies live on the
// tracing threads): their maps' counters, and the curve copies' of the engine's scaled problem through a
// scaling of a clone of the formulation's map (ScaledProblem::AddWorkOf forwards to it).
class ModelExploration::TestWorkSink {
 public:
  TestWorkSink(const ZeroProblem& base, const Vector& scales) : inner_(base.Clone()), curve_(inner_.get(), scales) {}
  void AddCurveWork(const ZeroProblem& copy) {
    const std::lock_guard<std::mutex> lock(mutex_);
    curve_.AddWorkOf(copy);
  }
  void AddMapWork(const ShootingProblem& map) {
    const std::lock_guard<std::mutex> lock(mutex_);
    work_.counters += map.counters();
    work_.evaluations += map.num_evaluations();
  }
  void AddReusedPoints(long points) {
    const std::lock_guard<std::mutex> lock(mutex_);
    work_.reused_points += points;
  }
  // Integrations outside a map (the own events' minima, FloquetTestFunctions::own_event_counters).
  void AddIntegrationWork(const FlowCounters& work) {
    const std::lock_guard<std::mutex> lock(mutex_);
    work_.counters += work;
  }
  // What a copy learnt of an accepted point's orbit (FloquetTestFunctions::BranchPointAnalysis), kept until
  // the exploration ends (ModelExploration::KnownBranchPointAnalysis), found by u's exact bits.
  void Publish(const FloquetTestFunctions::BranchPointAnalysis& analysis) {
    const std::lock_guard<std::mutex> lock(mutex_);
    known_.insert_or_assign(Key(analysis.u), analysis);
  }
  // Kept after it is found: two half-branches that leave one point report it both (whichever copy evaluated
  // it, the values are those of the one map at that u), so the analysis is that of one thread at any count.
  std::optional<FloquetTestFunctions::BranchPointAnalysis> Find(const Vector& u) {
    const std::lock_guard<std::mutex> lock(mutex_);
    const auto it = known_.find(Key(u));
    if (it == known_.end()) return std::nullopt;
    return it->second;
  }
  void ForgetPoints() {
    const std::lock_guard<std::mutex> lock(mutex_);
    known_.clear();
  }
  TestFunctionWork work() {
    const std::lock_guard<std::mutex> lock(mutex_);
    const auto& curve = dynamic_cast<const ShootingProblem&>(*inner_);  // a clone of a shooting map
    TestFunctionWork w = work_;
    w.counters += curve.counters();
    w.evaluations += curve.num_evaluations();
    w.curve_evaluations = curve.num_evaluations();
    return w;
  }

 private:
  static std::string Key(const Vector& u) {
    return std::string(reinterpret_cast<const char*>(u.data()), sizeof(double) * static_cast<std::size_t>(u.size()));
  }
  std::mutex mutex_;
  std::map<std::string, FloquetTestFunctions::BranchPointAnalysis> known_;
  std::unique_ptr<ZeroProblem> inner_;
  ScaledProblem curve_;
  TestFunctionWork work_;
};

namespace {

// The Floquet test functions of the time-based map on the engine's unknowns: scaled u ./ s back to model
// units, and for the state-based formulation expanded into the time-based layout (ToTimeBased on a map of
// its own: each stepper evaluates on its own thread; a refined copy's map is refined too, so that the
// integration error of the expansion is in the error estimate of a located point). Each copy leaves its
// work in `sink` when destroyed.
class EngineFloquetTests : public TestFunctions {
 public:
  // `state`: this copy's own map of the state-based formulation (null for the time-based one).
  EngineFloquetTests(std::unique_ptr<TestFunctions> floquet, std::unique_ptr<TestFunctions> observables,
                     Vector scales, std::unique_ptr<ZeroProblem> state,
                     std::shared_ptr<ModelExploration::TestWorkSink> sink)
      : floquet_(static_cast<FloquetTestFunctions*>(floquet.release())),  // Clone and Refined keep the type
        observables_(std::move(observables)),
        scales_(std::move(scales)),
        state_(static_cast<StateBasedShooting*>(state.release())),  // Clone and Refined keep the type
        sink_(std::move(sink)) {}
  ~EngineFloquetTests() override {
    sink_->AddMapWork(floquet_->shooting());
    sink_->AddReusedPoints(floquet_->reused_evaluations());
    sink_->AddIntegrationWork(floquet_->own_event_counters());
    if (state_) sink_->AddMapWork(*state_);
  }
  EngineFloquetTests(const EngineFloquetTests&) = delete;
  EngineFloquetTests& operator=(const EngineFloquetTests&) = delete;
  // The Floquet functions, then the observables' (monitors and constraints), if any.
  std::vector<SpecialPointType> types() const override {
    std::vector<SpecialPointType> types = floquet_->types();
    if (observables_) {
      const std::vector<SpecialPointType> more = observables_->types();
      types.insert(types.end(), more.begin(), more.end());
    }
    return types;
  }
  void Evaluate(const Vector& v, bool branch_point, Vector* values) override {
    EvaluateWith(v, branch_point, nullptr, values);
  }
  // The time-based image's residual is its preimage's, as this exploration's copies published it.
  void EvaluateAtImage(const Vector& v, const Vector& preimage, Vector* values) override {
    Vector u, u_preimage;
    // The state-based formulation's points are expanded by an integration each: evaluated as they are.
    if (state_ || !TimeBased(v, &u) || !TimeBased(preimage, &u_preimage)) {
      EvaluateWith(v, true, nullptr, values);
      return;
    }
    const auto known = sink_->Find(u_preimage);
    const double* residual = known && known->residual_known ? &known->residual : nullptr;
    floquet_->EvaluateAtImage(u, residual, values);
    if (!refined_ && floquet_->last_branch_point()) sink_->Publish(*floquet_->last_branch_point());
    AppendObservables(u, true, values);
  }
  // The time-based formulation's continued map is the scaling of a copy of the Floquet functions' map: the
  // corrector's last evaluation serves them (FloquetTestFunctions::EvaluateAtBranchPoint).
  bool EvaluateAtBranchPoint(const Vector& v, const CorrectorEvaluation& evaluation, Vector* values) override {
    return EvaluateWith(v, true, &evaluation, values);
  }
  // Whether the Floquet values came from the corrector's evaluation.
  bool EvaluateWith(const Vector& v, bool branch_point, const CorrectorEvaluation* evaluation, Vector* values) {
    Vector u;
    if (!TimeBased(v, &u)) {
      *values = Vector::Constant(static_cast<Eigen::Index>(types().size()), std::nan(""));
      return false;
    }
    auto* scaled = evaluation != nullptr && !state_ ? dynamic_cast<ScaledProblem*>(evaluation->problem) : nullptr;
    auto* map = scaled != nullptr ? dynamic_cast<TimeBasedShooting*>(scaled->wrapped()) : nullptr;
    bool reused = false;
    if (map != nullptr) {
      reused = floquet_->EvaluateAtBranchPoint(u, map, scaled->FromScaled(evaluation->at), values);
    } else {
      floquet_->Evaluate(u, branch_point, values);
    }
    // An accepted point (a refined copy's tolerances are not the study's): what it learnt, for the analysis.
    if (branch_point && !refined_ && floquet_->last_branch_point()) sink_->Publish(*floquet_->last_branch_point());
    AppendObservables(u, branch_point, values);
    return reused;
  }
  // The observables' functions (monitors and constraints) after the Floquet ones.
  void AppendObservables(const Vector& u, bool branch_point, Vector* values) {
    if (!observables_) return;
    Vector more;
    observables_->Evaluate(u, branch_point, &more);
    values->conservativeResize(values->size() + more.size());
    values->tail(more.size()) = more;
  }
  // One function at a trial point: the Floquet provider's own (the time-based formulation: the state-based
  // one's point is expanded by an integration, and its functions come all at once).
  double EvaluateOne(int function, const Vector& v) override {
    const int floquet = static_cast<int>(floquet_->types().size());
    Vector u;
    if (state_ || function >= floquet || !TimeBased(v, &u)) return TestFunctions::EvaluateOne(function, v);
    return floquet_->EvaluateOne(function, u);
  }
  bool MayKeepZeroBetween(int function, const Vector& a, const Vector& b) override {
    const std::vector<SpecialPointType> floquet_types = floquet_->types();
    const int floquet = static_cast<int>(floquet_types.size());
    // Only the grazing functions ask (FloquetTestFunctions::MayKeepZeroBetween): the others need no time-based
    // point, which the state-based formulation would integrate twice for.
    if (function < floquet && floquet_types[function] != SpecialPointType::kGrazing) return true;
    Vector ua, ub;
    if (!TimeBased(a, &ua) || !TimeBased(b, &ub)) return true;
    return function < floquet ? floquet_->MayKeepZeroBetween(function, ua, ub)
                              : observables_->MayKeepZeroBetween(function - floquet, ua, ub);
  }
  bool Keep(int function, const Vector& v, std::string* note) override {
    Vector u;
    if (!TimeBased(v, &u)) return true;
    const int floquet = static_cast<int>(floquet_->types().size());
    return function < floquet ? floquet_->Keep(function, u, note) : observables_->Keep(function - floquet, u, note);
  }
  std::unique_ptr<TestFunctions> Clone() const override {
    return std::make_unique<EngineFloquetTests>(floquet_->Clone(), observables_ ? observables_->Clone() : nullptr,
                                                scales_, state_ ? state_->Clone() : nullptr, sink_);
  }
  std::unique_ptr<TestFunctions> Refined(double factor) const override {
    auto refined = std::make_unique<EngineFloquetTests>(floquet_->Refined(factor),
                                                        observables_ ? observables_->Refined(factor) : nullptr, scales_,
                                                        state_ ? state_->Refined(factor) : nullptr, sink_);
    refined->refined_ = true;
    return refined;
  }
  void AddCurveWork(const ZeroProblem& copy) override { sink_->AddCurveWork(copy); }

 private:
  // The time-based point of the continued (scaled, perhaps state-based) point v; false if there is none.
  bool TimeBased(const Vector& v, Vector* u) {
    *u = v.cwiseProduct(scales_);
    return !state_ || state_->ToTimeBased(Vector(*u), u).ok;
  }

  std::unique_ptr<FloquetTestFunctions> floquet_;
  std::unique_ptr<TestFunctions> observables_;  // null: the model has no constraints and nothing is monitored
  Vector scales_;
  std::unique_ptr<StateBasedShooting> state_;
  std::shared_ptr<ModelExploration::TestWorkSink> sink_;
  bool refined_ = false;  // evaluates at other tolerances than the study's (error estimates)
};

}  // namespace

void RenumberDiagram(int branch_offset, int point_offset, BifurcationDiagram* d) {
  const auto branch = [&](int* id) { *id = *id >= 0 ? *id + branch_offset : *id; };
  const auto point = [&](int* id) { *id = *id >= 0 ? *id + point_offset : *id; };
  const auto special = [&](SpecialPoint* sp) { point(&sp->id), branch(&sp->branch_id), point(&sp->duplicate_of); };
  for (Branch& b : d->branches) {
    // reflected_from is a point index of the branch itself (continuation.h), not a branch id.
    branch(&b.id), branch(&b.image_of), point(&b.parent_special_point);
    for (SpecialPoint& sp : b.special_points) special(&sp);
  }
  for (SpecialPoint& sp : d->special_points) special(&sp);
}


}  // namespace hybridcont::study

namespace hybridcont {

std::string ToString(Formulation f) { return internal::EnumToString(study::kFormulationNames, f); }

bool FromString(const std::string& text, Formulation* f) {
  return internal::EnumFromString(study::kFormulationNames, text, f);
}

}  // namespace hybridcont

namespace hybridcont::study {

ModelExploration::ModelExploration(const HybridModel& model, const Scenario& scenario,
                                   const IntegratorOptions& integrator, ExplorationOptions options,
                                   Formulation formulation, FreeParameters free,
                                   std::vector<std::pair<std::string, double>> monitors)
    : model_(model), scenario_(scenario), integrator_(integrator), formulation_(formulation),
      shooting_(model, integrator, free), options_(std::move(options)), time_options_(options_) {
  if ((!free.empty() || !free.observables.empty()) && formulation_ == Formulation::kStateBased) {
    throw std::invalid_argument("free parameters and observables as unknowns: the time-based formulation only");
  }
  if (const std::string why = options_.continuation.ValidateFor(shooting_.unknown_names()); !why.empty()) {
    throw std::invalid_argument(why);
  }
  if (formulation_ == Formulation::kStateBased) {
    PoincareOptions poincare;
    poincare.event.integrator = integrator;
    // odeint has dense output for Dormand–Prince only: event location needs it
    poincare.event.integrator.method = IntegratorMethod::kDormandPrince54;
    state_ = std::make_unique<StateBasedShooting>(model, poincare);
    const auto known = [&](const std::string& name) { return state_->UnknownIndex(name) >= 0; };
    auto& c = options_.continuation;
    std::erase_if(c.bounds, [&](const ComponentBound& b) { return !known(b.component); });
    std::erase_if(c.sum_bounds, [&](const SumBound& b) {
      return std::any_of(b.components.begin(), b.components.end(), [&](const auto& n) { return !known(n); });
    });
    for (const ComponentTarget& t : c.targets) {
      if (!known(t.component)) {
        throw std::invalid_argument("target '" + t.component + "' is not an unknown of the state-based map");
      }
    }
    options_.start_conditions.clear();
  }
  ZeroProblem& base = problem();
  const std::vector<std::string> names = base.unknown_names();
  ContinuationOptions& c = options_.continuation;
  Vector scales = Vector::Ones(base.num_unknowns());
  for (const auto& [name, scale] : scenario_.unknown_scales) {
    const int k = base.UnknownIndex(name);
    if (k < 0) {
      if (formulation_ == Formulation::kStateBased) continue;  // scales of durations, x̄_2.. do not apply
      throw std::invalid_argument("scenario scale for unknown '" + name + "', which the model lacks");
    }
    scales(k) = scale;
  }
  scaled_ = std::make_unique<ScaledProblem>(&base, scales);
  const auto scale_of = [&](const std::string& name) { return scales(base.UnknownIndex(name)); };
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
      if (base.UnknownIndex(name) < 0) throw std::invalid_argument("start condition names unknown '" + name + "'");
      coefficient *= scale_of(name);  // c^T du = c^T S dv
    }
  }
  if (const std::string why = options_.Validate(); !why.empty()) throw std::invalid_argument(why);
  test_work_ = std::make_shared<TestWorkSink>(base, scales);
  std::unique_ptr<TestFunctions> observable_tests;
  if (!state_) {
    auto tests = std::make_unique<ObservableTestFunctions>(model_, integrator_, shooting_.free_parameters(), monitors);
    if (tests->size() > 0) observable_tests = std::move(tests);
  }
  c.test_functions = std::make_shared<EngineFloquetTests>(
      std::make_unique<FloquetTestFunctions>(model_, integrator_, true, shooting_.free_parameters()),
      std::move(observable_tests), scales, state_ ? state_->Clone() : nullptr, test_work_);
}

ZeroProblem& ModelExploration::problem() {
  if (state_) return *state_;
  return shooting_;
}

EvaluationStatus ModelExploration::ToTimeBased(const Vector& u, Vector* u_time) {
  if (!state_) {
    *u_time = u;
    return {};
  }
  return state_->ToTimeBased(u, u_time);
}

FlowCounters ModelExploration::counters() const { return state_ ? state_->counters() : shooting_.counters(); }

long ModelExploration::num_evaluations() const {
  return state_ ? state_->num_evaluations() : shooting_.num_evaluations();
}

TestFunctionWork ModelExploration::test_function_work() const { return test_work_->work(); }

std::optional<FloquetTestFunctions::BranchPointAnalysis> ModelExploration::KnownBranchPointAnalysis(const Vector& u) {
  return test_work_->Find(u);
}

void ModelExploration::ForgetBranchPointAnalyses() { test_work_->ForgetPoints(); }

Vector ModelExploration::FindPhysicalStart(std::string* why) {
  // Trace the time-based scenario's branches from its start until a point is physical.
  ExplorationOptions options = time_options_;
  options.max_depth = 0;
  options.threads = 1;  // the predicate below writes `found`: one thread, the serial order
  Vector found;
  options.continuation.stop_predicate = [&](const Vector& u) {
    if (found.size() > 0) return true;  // every later half-branch ends at its first point
    if (Classification quick; ClassifyByUnknowns(model_, u, ClassificationOptions{}, &quick)) return false;
    const OrbitTrace trace(model_, u, integrator_);
    if (ClassifyOrbit(model_, u, trace, ClassificationOptions{}).physical) found = u;
    return found.size() > 0;
  };
  ModelExploration time_based(model_, scenario_, integrator_, options, Formulation::kTimeBased);
  time_based.abandon_without_physical_ = false;
  time_based.Run();
  if (found.size() == 0) *why = "no physical orbit on the time-based branches from the start point";
  return found;
}

ExplorationOptions ModelExploration::EngineOptions(const PointCallback& on_point, int branch_offset) {
  ExplorationOptions options = options_;
  ContinuationOptions& c = options.continuation;
  if (c.stop_predicate) {  // the engine sees scaled unknowns; the predicate is written for model units
    c.stop_predicate = [this, user = c.stop_predicate](const Vector& v) { return user(scaled_->FromScaled(v)); };
  }
  if (abandon_without_physical_ && !state_ && c.test_functions) {
    // What the test functions learnt of each point (its class) decides; a point they did not publish keeps
    // the branch (kStepsWithoutPhysicalOrbit).
    // An arclength of the scenario's: the same for any step size the caller sets (a point count is not).
    const double length = kStepsWithoutPhysicalOrbit * scenario_.max_step;
    const double unfolded_length = kStepsOfUnfoldedOrbits * scenario_.max_step;
    c.abandon = [this, length, unfolded_length](const Branch& b) -> std::string {
      const std::size_t n = b.points.size();
      const auto crossed = [&](double l) { return n >= 2 && b.points[n - 1].arclength >= l && b.points[n - 2].arclength < l; };
      const bool at_unfolded = crossed(unfolded_length), at_length = crossed(length);
      if (!at_unfolded && !at_length) return {};
      bool unfolded = true;  // every point after the start an orbit of the unfolded system only (xi != 0)
      for (std::size_t i = 0; i < n; ++i) {
        const auto known = test_work_->Find(scaled_->FromScaled(b.points[i].u));
        if (!known) return {};
        const OrbitClass reason = known->classification.reason;
        if (known->classification.physical || reason == OrbitClass::kZeroDuration || reason == OrbitClass::kGrazing) {
          return {};
        }
        if (i > 0 && reason != OrbitClass::kDissipative) unfolded = false;
      }
      if (at_unfolded && unfolded) {
        return "its orbits are the unfolded system's (xi != 0), none the model's, over an arclength of " +
               std::to_string(kStepsOfUnfoldedOrbits) + " of the scenario's largest steps";
      }
      if (!at_length) return {};
      return "no physical orbit over an arclength of " + std::to_string(kStepsWithoutPhysicalOrbit) +
             " of the scenario's largest steps";
    };
  }
  if (on_point) {
    c.progress_components.clear();  // ProgressInfo::values = all of u
    c.progress = [this, on_point, branch_offset](const ProgressInfo& info) {
      const Vector v = Eigen::Map<const Vector>(info.values.data(), static_cast<Eigen::Index>(info.values.size()));
      ProgressInfo numbered = info;
      numbered.branch_id += branch_offset;
      // The tangent in model units (the scaling is affine: the difference of two images), in the
      // time-based layout; the state-based formulation's tangent is in other unknowns: dropped.
      if (state_ || info.tangent.size() != v.size()) {
        numbered.tangent.resize(0);
      } else {
        numbered.tangent = scaled_->FromScaled(v + info.tangent) - scaled_->FromScaled(v);
      }
      on_point(numbered, scaled_->FromScaled(v));
    };
  }
  if (ray_filter_) {
    options.known_ray = [this, known = options.known_ray](const Vector& u, const Vector& v) {
      if (known && known(u, v)) return true;
      const Vector u_model = scaled_->FromScaled(u);
      return ray_filter_(u_model, scaled_->FromScaled(u + v) - u_model);
    };
  }
  if (store_ != nullptr) {
    const int offset = store_offset_ + branch_offset;
    options.recorded_branch = [store = store_, offset](int id) { return store->Lookup(offset + id); };
    // Once taken, and once a worker tracing it ahead is recalled: nothing publishes over what is learnt.
    options.on_recorded_branch = [this](const Branch& b) { RelearnRecordedPoints(b); };
    options.on_branch = [store = store_, offset](const Branch& b) { store->Save(offset + b.id, b); };
  }
  return options;
}

void ModelExploration::RelearnRecordedPoints(const Branch& branch) {
  if (state_) return;  // the state-based formulation's test functions evaluate every point at it
  std::unique_ptr<ZeroProblem> copy = shooting_.Clone();  // one thread, the engine's tolerances
  auto& map = static_cast<TimeBasedShooting&>(*copy);
  FloquetTestFunctions tests(model_, integrator_, true, shooting_.free_parameters());
  Vector values, r;
  Matrix dr;
  // A mapped branch's points from `mapped` on (exploration.h: an image, or a loop's reflected half): as
  // EngineFloquetTests::EvaluateAtImage learnt them, from their preimages'.
  const Symmetry* symmetry = nullptr;
  const std::vector<Symmetry> symmetries = scaled_->symmetries();
  for (const Symmetry& s : symmetries) {
    if (s.name == branch.symmetry) symmetry = &s;
  }
  // (A reflected loop's images begin after its midpoint, reflected_from − 1, which was traced.)
  const std::size_t mapped = symmetry == nullptr          ? branch.points.size()
                             : branch.image_of >= 0       ? 0
                             : branch.reflected_from >= 1 ? static_cast<std::size_t>(branch.reflected_from)
                                                          : branch.points.size();
  for (std::size_t i = 0; i < std::min(mapped, branch.points.size()); ++i) {
    const ContinuationPoint& p = branch.points[i];
    if (p.evaluated_at.size() != p.u.size()) {  // the point's own evaluation (a mapped branch's preimage)
      tests.Evaluate(scaled_->FromScaled(p.u), true, &values);
      if (tests.last_branch_point()) test_work_->Publish(*tests.last_branch_point());
      continue;
    }
    const Vector at = scaled_->FromScaled(p.evaluated_at);  // as the engine's scaling passed it to the map
    if (!map.Evaluate(at, &r, &dr).ok) continue;
    if (tests.EvaluateAtBranchPoint(scaled_->FromScaled(p.u), &map, at, &values) && tests.last_branch_point()) {
      test_work_->Publish(*tests.last_branch_point());
    }
  }
  for (std::size_t i = mapped; i < branch.points.size(); ++i) {
    const Vector& v = branch.points[i].u;
    if (symmetry->signs.size() != v.size()) break;
    const auto known = test_work_->Find(scaled_->FromScaled(symmetry->Apply(v)));
    tests.EvaluateAtImage(scaled_->FromScaled(v), known && known->residual_known ? &known->residual : nullptr, &values);
    if (tests.last_branch_point()) test_work_->Publish(*tests.last_branch_point());
  }
  test_work_->AddMapWork(map);
  test_work_->AddMapWork(tests.shooting());
}

void ModelExploration::ToModelUnits(BifurcationDiagram* diagram) const {
  for (Branch& b : diagram->branches) {
    for (ContinuationPoint& p : b.points) {
      p.u = scaled_->FromScaled(p.u);
      p.tangent = scaled_->FromScaled(p.tangent).normalized();
      if (p.evaluated_at.size()) p.evaluated_at = scaled_->FromScaled(p.evaluated_at);
    }
    for (SpecialPoint& sp : b.special_points) {
      if (sp.u.size()) sp.u = scaled_->FromScaled(sp.u);
      if (sp.interval_width.size()) sp.interval_width = scaled_->FromScaled(sp.interval_width);
    }
  }
  for (SpecialPoint& sp : diagram->special_points) {
    if (sp.u.size()) sp.u = scaled_->FromScaled(sp.u);
    if (sp.interval_width.size()) sp.interval_width = scaled_->FromScaled(sp.interval_width);
  }
}

bool ModelExploration::PrepareStart(std::string* why) {
  std::string reason;
  const bool ok = CheckAndCorrectStart(&reason);
  start_failure_ = ok ? std::string() : (reason.empty() ? std::string("the start failed") : reason);
  if (why != nullptr) *why = reason;
  return ok;
}

bool ModelExploration::CheckAndCorrectStart(std::string* why) {
  start_prepared_ = true;
  prepared_start_ = scenario_.start;
  start_report_.clear();
  const StartSpec& spec = model_.setup().start;
  Vector simulated;  // a simulation start's cycle: the states and durations filled in from x1
  if (spec.kind == StartSpec::Kind::kSimulation) {
    if (model_.num_first_integrals() == 0) return true;  // its starts are FindOrbitStarts' (orbit_start.h)
    // A conservative model's: one cycle (or `cycles`) of the event-driven simulation from the given x1 is a
    // guess at the level H(x1), which Newton corrects as any guess.
    SimulationStartOptions options;
    options.integrator.integrator = integrator_;
    if (spec.cycles > 0) options.max_cycles = spec.cycles, options.require_convergence = false;
    const ShootingLayout base(model_);
    const SimulationStartResult s =
        SimulateToOrbit(model_, scenario_.start.segment(base.state_offset(0), base.dim(0)), options);
    if (!s.converged) {
      *why = "the start (kind = \"simulation\"): the event-driven simulation from the given state did not give a "
             "cycle: " + s.message;
      return false;
    }
    simulated = s.u;
    prepared_start_ = simulated;
  }
  const StartResidual residual =
      ExplainStartResidual(model_, spec, integrator_, simulated.size() ? &simulated : nullptr);
  if (spec.kind == StartSpec::Kind::kSingular) {
    const double tolerance = SingularStartTolerance(residual.u);
    if (residual.max_residual <= tolerance) return state_ || SingularStartHasDirections(why);
    const std::string size = residual.evaluated ? fmt::format("max |r| = {:.3g}", residual.max_residual)
                                                : std::string("r cannot be evaluated");
    *why = fmt::format("the start (kind = \"singular\") is not a periodic orbit: {} (an exact zero of r is needed, to "
                       "{:.1e}); give the unknowns that do not close, or kind = \"guess\" for an approximate orbit "
                       "that Newton corrects:\n{}",
                       size, tolerance, residual.Explain(tolerance));
    while (!why->empty() && why->back() == '\n') why->pop_back();
    return false;
  }
  if (state_) return true;  // a guess: corrected by the time-based exploration that finds the state start
  // An approximate orbit (StartSpec::kGuess, or a simulated cycle): Newton at the guess's level H; the
  // exploration starts from the corrected orbit, a regular point of its family.
  Vector start = simulated.size() ? simulated : scenario_.start;
  if (shooting_.layout().num_observables() > 0) start = shooting_.CompleteUnknowns(start);
  // On a clone of the problem, whose work is added to it afterwards: the exploration then starts from the
  // corrected point with the problem's cache empty, as a worker thread's copy does, so that the run is the
  // same bits whatever the number of threads.
  const std::unique_ptr<ZeroProblem> clone = scaled_->Clone();
  ZeroProblem* problem = clone ? clone.get() : scaled_.get();
  Corrector corrector(problem);
  const Vector guess = scaled_->ToScaled(start);
  const int h = scaled_->UnknownIndex("H");
  Vector corrected;
  const CorrectorResult result = corrector.CorrectFixedComponent(guess, h, guess(h), &corrected);
  if (clone) scaled_->AddWorkOf(*clone);
  const char* what = simulated.size() ? "the simulated cycle" : "the guess";
  if (!result.converged()) {
    *why = fmt::format("the start: {} does not converge to an orbit at H = {:.10g} ({}); there, max |r| = "
                       "{:.3g}:\n{}",
                       what, start(shooting_.layout().H_index()), result.message, residual.max_residual,
                       residual.Explain(SingularStartTolerance(residual.u)));
    while (!why->empty() && why->back() == '\n') why->pop_back();
    return false;
  }
  prepared_start_ = scaled_->FromScaled(corrected);
  // How far Newton moved the guess, in the unknowns' scales: beyond a thousandth of a scale it is said,
  // with the largest changes by name.
  const Vector change = (corrected - guess).cwiseAbs();
  constexpr double kReportedChange = 1e-3;
  if (change.maxCoeff() > kReportedChange) {
    std::vector<int> order(change.size());
    for (int i = 0; i < change.size(); ++i) order[i] = i;
    std::sort(order.begin(), order.end(), [&](int a, int b) { return change(a) > change(b); });
    const std::vector<std::string> names = shooting_.layout().unknown_names();
    std::string moved;
    for (int k = 0; k < 4 && k < change.size() && change(order[k]) > kReportedChange; ++k) {
      const int i = order[k];
      moved += fmt::format("{}{} {:.6g} -> {:.6g}", moved.empty() ? "" : ", ", names[i], start(i),
                           prepared_start_(i));
    }
    start_report_ = fmt::format("start: {} is not an orbit (max |r| = {:.3g}); Newton moved it at H = {:.10g} "
                                "in {} iterations: {}\n",
                                what, residual.max_residual, start(shooting_.layout().H_index()), result.iterations, moved);
  }
  return true;
}

bool ModelExploration::SingularStartHasDirections(std::string* why) {
  Vector start = scenario_.start;
  if (shooting_.layout().num_observables() > 0) start = shooting_.CompleteUnknowns(start);
  StartOptions options;
  options.switching = options_.switching;
  options.conditions = options_.start_conditions;
  const BranchDirections d = AnalyzeSingularPoint(scaled_.get(), scaled_->ToScaled(start), options);
  if (d.status == BranchSwitchStatus::kRegular || !d.directions.empty()) return true;
  // No branch direction: name the kernel of dr, each basis vector in model units by its largest components,
  // so that the conditions that select the families (linear conditions on the direction) can be written.
  const std::vector<std::string> names = shooting_.layout().unknown_names();
  std::string kernel;
  for (Eigen::Index c = 0; c < d.kernel.cols(); ++c) {
    const Vector v = (d.kernel.col(c).cwiseProduct(scaled_->scales())).normalized();
    std::vector<int> order(v.size());
    for (int i = 0; i < v.size(); ++i) order[i] = i;
    std::sort(order.begin(), order.end(), [&](int a, int b) { return std::abs(v(a)) > std::abs(v(b)); });
    std::string terms;
    for (int k = 0; k < v.size() && std::abs(v(order[k])) >= 0.05; ++k) {
      terms += fmt::format("{}{} {:+.3f}", terms.empty() ? "" : ", ", names[order[k]], v(order[k]));
    }
    kernel += fmt::format("    direction {}: {}\n", c + 1, terms.empty() ? "(no component above 0.05)" : terms);
  }
  *why = fmt::format("the start (kind = \"singular\") is an orbit, but no family through it can be chosen: {}; the "
                     "kernel of dr there (the directions families may leave in, components of at least 0.05, in the "
                     "unknowns' units) is spanned by\n{}  give [start] conditions (Σ coefficient · direction[unknown] = 0) "
                     "that leave one or two of them",
                     d.BriefReport(), kernel);
  return false;
}

BifurcationDiagram ModelExploration::Run(const PointCallback& on_point) {
  ExplorationOptions options = EngineOptions(on_point);
  if (!start_prepared_) PrepareStart(nullptr);
  if (!start_failure_.empty()) {  // checked before (PrepareStart) or now: no start to explore from
    BifurcationDiagram failed;
    failed.unknown_names = problem().unknown_names();
    failed.status = ExplorationStatus::kStartFailed;
    failed.message = start_failure_;
    return failed;
  }
  Vector start = prepared_start_;
  if (!state_ && shooting_.layout().num_observables() > 0 && start.size() != shooting_.num_unknowns()) {
    start = shooting_.CompleteUnknowns(start);
  }
  if (state_) {
    std::string why;
    const Vector physical = FindPhysicalStart(&why);
    if (physical.size() == 0) {
      BifurcationDiagram failed;
      failed.status = ExplorationStatus::kStartFailed;
      failed.message = "state-based formulation: " + why;
      return failed;
    }
    start = state_->FromTimeBased(physical);
  }
  BifurcationDiagram diagram = Explore(scaled_.get(), scaled_->ToScaled(start), options);
  ToModelUnits(&diagram);
  return diagram;
}

namespace {

// Appends d to all, renumbering d's branches and special points after all's.
void Append(BifurcationDiagram&& d, BifurcationDiagram* all) {
  const int bo = static_cast<int>(all->branches.size()), so = static_cast<int>(all->special_points.size());
  const auto renumber = [&](SpecialPoint& sp) {
    sp.id += so, sp.branch_id += bo;
    if (sp.duplicate_of >= 0) sp.duplicate_of += so;
  };
  for (Branch& b : d.branches) {
    b.id += bo;
    if (b.parent_special_point >= 0) b.parent_special_point += so;
    if (b.image_of >= 0) b.image_of += bo;
    for (SpecialPoint& sp : b.special_points) renumber(sp);
    all->branches.push_back(std::move(b));
  }
  for (SpecialPoint& sp : d.special_points) renumber(sp), all->special_points.push_back(std::move(sp));
  for (SwitchRecord& s : d.switches) {
    if (s.special_point >= 0) s.special_point += so;
    all->switches.push_back(std::move(s));
  }
  all->warnings.insert(all->warnings.end(), d.warnings.begin(), d.warnings.end());
  if (d.status == ExplorationStatus::kMaxBranches || d.status == ExplorationStatus::kCancelled) all->status = d.status;
}

}  // namespace

int ModelExploration::BranchThrough(const BifurcationDiagram& d, const Vector& u) const {
  const Vector& s = scaled_->scales();
  const Vector x = u.cwiseQuotient(s);
  // The chord sag of a step is a small fraction of it (curvature · step² / 8); a distinct family crosses a
  // traced one at a visible angle, far from every chord but at the crossing itself.
  constexpr double kSagFraction = 0.05;
  for (const Branch& b : d.branches) {
    for (std::size_t i = 0; i + 1 < b.points.size(); ++i) {
      const Vector a = b.points[i].u.cwiseQuotient(s), c = b.points[i + 1].u.cwiseQuotient(s);
      const double distance = DistanceToSegment<Vector>(x, a, c);
      if (distance <= options_.known_branch_tolerance * (1 + x.norm()) + kSagFraction * (c - a).norm()) {
        return b.id;
      }
    }
  }
  return -1;
}

BifurcationDiagram ModelExploration::RunFromStarts(const std::vector<Vector>& starts, const PointCallback& on_point,
                                                   int* skipped) {
  BifurcationDiagram all;
  all.unknown_names = problem().unknown_names();
  *skipped = 0;
  int started = 0;
  std::string failures;
  for (Vector start : starts) {
    // Starts without the observables that joined the unknowns get their values (shooting_layout.h).
    if (start.size() == shooting_.num_unknowns() - shooting_.layout().num_observables()) {
      start = shooting_.CompleteUnknowns(start);
    }
    // A start whose image under a symmetry lies on a traced branch: its families are that branch's images,
    // which the exploration maps where it maps images (use_symmetries), so they are not traced twice.
    const std::vector<Symmetry> symmetries = options_.use_symmetries ? problem().symmetries() : std::vector<Symmetry>{};
    const bool image_known = std::any_of(symmetries.begin(), symmetries.end(),
                                         [&](const Symmetry& g) { return OnBranch(all, g.Apply(start)); });
    if (OnBranch(all, start) || image_known) {
      ++*skipped;
      continue;
    }
    const int offset = static_cast<int>(all.branches.size());
    if (offset >= options_.max_branches) {
      all.status = ExplorationStatus::kMaxBranches;
      break;
    }
    if (all.status == ExplorationStatus::kCancelled) break;
    ExplorationOptions options = EngineOptions(on_point, offset);
    options.max_branches = options_.max_branches - offset;
    BifurcationDiagram d = Explore(scaled_.get(), scaled_->ToScaled(start), options);
    if (d.status == ExplorationStatus::kStartFailed) {
      failures += (failures.empty() ? "" : "; ") + d.message;
      continue;
    }
    ToModelUnits(&d);
    if (started++ == 0) all.start = d.start;
    Append(std::move(d), &all);
  }
  if (started == 0) {
    all.status = ExplorationStatus::kStartFailed;
    all.message = starts.empty() ? "no start point" : "no start converged: " + failures;
  }
  return all;
}

BifurcationDiagram ModelExploration::RunFromPoint(const Vector& u, const Vector& tangent,
                                                  const PointCallback& on_point) {
  if (state_) throw std::invalid_argument("a restart from a point: the time-based formulation only");
  ExplorationOptions options = EngineOptions(on_point);
  options.one_way_start = true;
  Vector start = u;
  if (shooting_.layout().num_observables() > 0 && start.size() != shooting_.num_unknowns()) {
    start = shooting_.CompleteUnknowns(start);
  }
  Vector direction = Vector::Zero(start.size());
  direction.head(tangent.size()) = tangent;
  BifurcationDiagram diagram =
      Explore(scaled_.get(), scaled_->ToScaled(start), scaled_->ToScaled(direction).normalized(), options);
  ToModelUnits(&diagram);
  return diagram;
}

BifurcationDiagram ModelExploration::RunPeriodDoubled(const ShootingLayout& parent, const Vector& u_pd,
                                                      const PointCallback& on_point) {
  if (state_) throw std::invalid_argument("period-doubled families: the time-based formulation only");
  // The doubled scales repeat the parent's (RepeatedModel's set-up), so the parent's are the first cycle's.
  const Vector& s2 = scaled_->scales();
  const int cycle = parent.xi_index(0), tail = parent.num_unknowns() - cycle;
  Vector s(parent.num_unknowns());
  s << s2.head(cycle), s2.tail(tail);
  BifurcationDiagram diagram =
      ExplorePeriodDoubled(scaled_.get(), parent, u_pd.cwiseQuotient(s), EngineOptions(on_point));
  ToModelUnits(&diagram);
  return diagram;
}

}  // namespace hybridcont::study
