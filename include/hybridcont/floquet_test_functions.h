// Floquet multipliers crossing +1 (BP) and −1 (PD) as test functions of the continuation
// (test_function.h), on the time-based shooting map (timebased_shooting.h), and the smooth PD test
// function of that map's Jacobian, which also serves as a defining equation of curves of PD points.
//
// PD test from the Jacobian (paper eq. `multishootJacobian`). A multiplier −1 means a solution of the
// linearized problem that returns with its sign flipped after one period: the periodicity block
// r_p = phi_1(t_{m+1}, x̄_{m+1}) − x̄_1 becomes phi_1 + x̄_1, i.e. its coupling C = [0 −I] becomes [0 +I].
// A_+(u) is dr(u) with that flip, restricted to the rows of the m+1 blocks (shooting, event, periodicity,
// anchor: the first-integral rows dropped) and the columns of the durations and states (ξ, H̄ and any
// further free unknowns dropped): a square matrix of size Σn_i + m + 1. Eliminating the durations by the
// event and anchor rows gives the saltation-chained return map P to the section (its eigenvalues: 0 along
// f, the multipliers of the energy level and the trivial +1 of the energy direction), so
//     det A_+(u) = c(u) · det(I + P) = c(u) · 2 ∏ (1 + μ_j)   over the nontrivial multipliers μ_j,
// c(u) = ± ∏ de_i f~_i^- · (da f~) ≠ 0 on a transversal orbit. It vanishes exactly where a multiplier is
// −1, smoothly (a polynomial in the entries of dr), with a regular zero where one real multiplier crosses
// −1 (or a symplectic pair collides there). The normalization divides by the product of A_+'s row norms
// (Hadamard: |value| <= 1), a smooth positive factor, so zeros and signs are those of det A_+.
//
// Contract of PeriodDoublingTest(dr, layout): dr is the N x (N+1) Jacobian of the time-based map at u (any
// further columns after H̄ are ignored); the value is det A_+ / ∏ ||rows of A_+||, computed by an LU
// factorization as a sign and a sum of logarithms; NaN if a row of A_+ is zero. A two-parameter defining
// system for PD points takes r(u) = 0 and PeriodDoublingTest = 0 (or a bordered system on
// PeriodDoublingMatrix).
//
// BP test: bp_test = ∏ (μ_j − 1) of the deflated monodromy (floquet.h): det of the reduced matrix minus I,
// smooth; it changes sign where a real multiplier crosses +1 or a reciprocal pair collides at +1.
//
//   ContinuationOptions options;
//   options.test_functions = std::make_shared<FloquetTestFunctions>(model, IntegratorOptions{});
//   Branch b = TraceBranch(&shooting, u0, options);   // kFloquetBranchPoint / kPeriodDoubling points
#ifndef HYBRIDCONT_FLOQUET_TEST_FUNCTIONS_H_
#define HYBRIDCONT_FLOQUET_TEST_FUNCTIONS_H_

#include <initializer_list>
#include <memory>
#include <optional>
#include <vector>

#include "hybridcont/classification.h"
#include "hybridcont/floquet.h"
#include "hybridcont/orbit_observables.h"
#include "hybridcont/orbit_trace.h"
#include "hybridcont/replay.h"
#include "hybridcont/shooting_layout.h"
#include "hybridcont/test_function.h"
#include "hybridcont/timebased_shooting.h"

namespace hybridcont {

// A_+(u) from dr (see above).
Matrix PeriodDoublingMatrix(const Matrix& dr, const ShootingLayout& layout);
// det A_+ / ∏ ||rows of A_+|| (see above).
double PeriodDoublingTest(const Matrix& dr, const ShootingLayout& layout);

// Test functions {kFloquetBranchPoint: bp_test, kPeriodDoubling: PeriodDoublingTest} at time-based points
// u. With physical_only, a branch point whose orbit is not physical (classification.h) or whose
// event-driven replay does not return (replay.h) has NaN values: the multipliers of a non-physical orbit
// mean nothing for the mechanical system. Trial points between two branch points are not classified.
//
// Then a kNeimarkSacker function: FloquetResult::ns_test (floquet.h), NaN at a branch point where it is
// below kNeimarkSackerUndefined (on a symplectic map it is 0 everywhere but for the multipliers' errors).
// Last, for a model with a first integral, a kKreinCollision function: FloquetResult::krein_test, NaN where
// the multipliers do not come in reciprocal pairs (the map is not symplectic); its zeros are kept where two
// pairs meet on the unit circle (two real pairs meeting off it are no Krein collision).
//
// Then one kGrazing function per event, the normalized crossing speed de_i·f_i / (|de_i| |f_i|) at the end
// of segment i (negative on a physical orbit, zero where the event is met tangentially), defined on both
// sides of the grazing point. A model without first integral keeps every zero; a conservative model keeps
// those where a physical family ends (the orbit there is physical but for the tangency: class grazing), not
// the many where the crossing speed changes sign on orbits that are no motion of the system.
//
// Last, one more kGrazing function per phase: the smallest interior minimum of the phase's own event
// (OwnEventObservable, orbit_observables.h), 0 where the event is touched inside the phase: the end of a
// physical family beyond which its orbits cross that event early (missed-event). It is evaluated at a
// branch point only where the point is physical or missed-event and its trace shows a local minimum of the
// event inside the phase after it has been above 0 (elsewhere it is NaN: no interior minimum, or no
// physical family ending), and at a trial point between branch points only where the last branch point had
// a value, so it costs integrations only on such orbits; its zeros are kept where a physical family ends.
//
// Last, one kZeroDuration function per phase 2..m: its duration t_i (an unknown: nothing is integrated), 0
// where the phase vanishes from the cycle (running's flight shrinking to nothing where walking begins). At a
// branch point it is defined where the orbit is physical, and where it fails by its durations (class
// reversed-time or zero-duration) just after a physical branch point of the same trace, or where t_i and its
// symmetric copies (equal to it) are its only durations not positive: so a zero is located only between a
// physical point and one that fails by that phase alone, where a physical family ends (followed outward or
// inward) by a vanishing phase — not on the many families of orbits that run some phase backwards, nor on
// those whose phase lasts no time (t_i rounding about 0).
// A zero is kept where no other duration is negative (a symmetric gait's two flights vanish at one point).
class FloquetTestFunctions : public TestFunctions {
 public:
  // Keeps a reference to model (it must outlive this object and its clones). With free parameters
  // (shooting_layout.h) u holds them, and orbits are classified and replayed at u's parameter values.
  FloquetTestFunctions(const HybridModel& model, const IntegratorOptions& integrator, bool physical_only = true,
                       FreeParameters free = {});

  std::vector<SpecialPointType> types() const override;
  void Evaluate(const Vector& u, bool branch_point, Vector* values) override;
  // At a branch point u, from `map`'s evaluation at `at` (a point within the corrector's distance,
  // TestFunctions::EvaluateAtBranchPoint) where map is this object's map in layout and integrator and holds
  // that evaluation (TimeBasedShooting::HoldsEvaluation): the multipliers, the BP, PD, NS and Krein tests and
  // the crossing speeds are then `at`'s, r's norm too (BranchPointAnalysis::residual), and nothing of the map
  // is integrated again; the class, the replay and the own events' minima are u's; returns true. Otherwise
  // Evaluate(u, true, values), false.
  bool EvaluateAtBranchPoint(const Vector& u, TimeBasedShooting* map, const Vector& at, Vector* values);
  // At a branch point u that is the image of another under a symmetry of the map (TestFunctions::
  // EvaluateAtImage), whose residual is `preimage_residual` (null: not known): the map is evaluated only where
  // a value needs it (the Floquet functions of a physical orbit, the crossing speeds); elsewhere, e.g. on a
  // time-reversed image of a physical family, the point is classified alone and its residual is the
  // preimage's (the symmetry maps r(u) to r of the image up to signs: the same norm).
  void EvaluateAtImage(const Vector& u, const double* preimage_residual, Vector* values);
  // Branch points whose values came from another map's evaluation (EvaluateAtBranchPoint).
  long reused_evaluations() const { return reused_evaluations_; }
  // At a trial point: the multipliers' functions from the map with its Jacobian (everything, as Evaluate);
  // a crossing speed from the map's value alone (no sensitivities: ~1/(n+1) of the work); an own event's
  // extremum from its own integration; a duration from u. Where the map cannot be evaluated at u, Evaluate
  // gives NaN throughout while a duration or an own event may still have a value here.
  double EvaluateOne(int function, const Vector& u) override;
  // An own event's zero, and a conservative model's grazing zero, is kept only where a physical family ends
  // (Keep): it is located only where one of the two points around it is physical or of the class of such an
  // end (grazing; missed-event for an own event). On the many steps of a diagram whose orbits are no motion of the system a
  // crossing speed flips sign by a jump (the event crossed the other way), which the root finder bisects.
  // Branch points' classes are taken from their evaluation; other points are classified.
  bool MayKeepZeroBetween(int function, const Vector& a, const Vector& b) override;
  // A zero of the Neimark–Sacker function is kept where a complex pair lies on the unit circle (within
  // kUnitPairTolerance); a zero from two real multipliers of product 1 (a neutral saddle) is dropped.
  bool Keep(int function, const Vector& u, std::string* note) override;
  // |ns_test| below this at a branch point: undefined there (the map is symplectic, see Evaluate).
  static constexpr double kNeimarkSackerUndefined = 1e-8;
  static constexpr double kUnitPairTolerance = 1e-6;
  // At a located Krein collision the two rho = mu + 1/mu meet to the square root of the location's accuracy
  // (krein_test is quadratic in their distance): within 1e-4 of each other.
  static constexpr double kKreinMeetTolerance = 1e-4;
  std::unique_ptr<TestFunctions> Clone() const override;
  // The integrator tolerances times factor.
  std::unique_ptr<TestFunctions> Refined(double factor) const override;

  // Whether the orbit at u is physical and replays (what a branch point is checked for).
  bool Physical(const Vector& u) const;
  // Whether the orbit at u is physical or fails only by a tangential event (a conservative model's grazing
  // zeros are kept there).
  bool GrazingEndsPhysicalFamily(const Vector& u) const;
  // The map the multipliers and PeriodDoublingTest are computed with: its counters are this object's work
  // (the classification and replay of branch points not included).
  const TimeBasedShooting& shooting() const { return shooting_; }
  // What the last Evaluate at a branch point learnt of its orbit, for the analysis of that point
  // (orbit_analysis.h, OrbitAnalysisOptions::known), so that the point is not integrated again: its class,
  // and for an orbit that is physical (or beyond a constraint's boundary) its replay, its multipliers (default
  // FloquetOptions); and the residual |r(u)| of the map's evaluation there. Empty before the first branch point.
  struct BranchPointAnalysis {
    Vector u;                     // the point, as given to Evaluate
    Classification classification;
    bool replayed = false;        // replay holds the event-driven replay
    ReplayResult replay;
    bool floquet_known = false;   // floquet holds the multipliers
    FloquetResult floquet;
    bool residual_known = false;  // residual holds |r| of the map's evaluation (at u, or EvaluateAtBranchPoint's `at`)
    double residual = 0;
  };
  const std::optional<BranchPointAnalysis>& last_branch_point() const { return last_branch_point_; }
  // The integrations of the own events' minima (not the map's).
  FlowCounters own_event_counters() const {
    return own_event_evaluator_ ? own_event_evaluator_->counters() : FlowCounters();
  }

 private:
  // The model at u's free-parameter values (nullptr outside a parameter's range).
  const HybridModel* ModelAt(const Vector& u_free) const;
  // Evaluate's work at u, with the map's values from map's evaluation at `at` (at = u on shooting_); with
  // image_residual, the map is evaluated only where a value needs it (EvaluateAtImage).
  void EvaluateOn(TimeBasedShooting* map, const Vector& at, const Vector& u, bool branch_point, Vector* values,
                  const double* image_residual = nullptr);
  // map has shooting_'s unknowns, equations and integrator options.
  bool SameMap(const TimeBasedShooting& map) const;
  // The class of u; with `trace`, the integrated orbit too (null where the unknowns alone decide).
  Classification Classify(const HybridModel& model, const Vector& u,
                          std::unique_ptr<OrbitTrace>* trace = nullptr) const;
  // Whether a physical family may end at u by a missed event (physical, missed-event or grazing).
  bool MissedEventEndsPhysicalFamily(const Vector& u_free) const;
  // Whether the orbit at u is physical or fails for one of `reasons` only.
  bool PhysicalOr(const Vector& u_free, std::initializer_list<OrbitClass> reasons) const;
  // Phase i's own-event functions at u into values->segment(first_own_event(), m) (see above).
  void EvaluateOwnEvents(const Vector& u, const OrbitTrace* trace, Vector* values);
  int first_own_event() const;
  // The zero-duration functions at u into values (see above); c is u's class at a branch point.
  void EvaluateDurations(const Vector& u, bool branch_point, const Classification& c, Vector* values);
  // Index of the first zero-duration function (phase 2's duration; m − 1 of them).
  int first_zero_duration() const { return first_own_event() + model_->num_phases(); }
  // The event-driven replay of u (the model's own layout) returns (replay.h).
  bool Replays(const HybridModel& model, const Vector& u) const;
  ReplayResult Replay(const HybridModel& model, const Vector& u) const;

  const HybridModel* model_;
  IntegratorOptions integrator_;
  bool physical_only_;
  FreeParameters free_;
  TimeBasedShooting shooting_;
  int base_unknowns_;                            // u without the free parameters
  std::vector<int> time_index_;                  // index of t_{i+1} in u, segment i (EvaluateDurations)
  std::unique_ptr<HybridModel> point_model_;     // with free parameters: set to u's values to classify
  Matrix dr_;
  Vector r_;
  // The own events' minima, on the shooting map's model (at u's parameter values), made at first use.
  std::unique_ptr<ObservableEvaluator> own_event_evaluator_;
  std::vector<Observable> own_events_;
  std::vector<char> own_defined_;  // per phase: whether the last branch point had a value
  std::optional<BranchPointAnalysis> last_branch_point_;
  bool last_branch_physical_ = false;  // the class of the last branch point evaluated (EvaluateDurations)
  // The classes of the last few branch points evaluated, by their u (MayKeepZeroBetween).
  std::vector<std::pair<Vector, Classification>> recent_classes_;
  long reused_evaluations_ = 0;
};

}  // namespace hybridcont

#endif  // HYBRIDCONT_FLOQUET_TEST_FUNCTIONS_H_
