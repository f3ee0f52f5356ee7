// Predictor–corrector continuation of one branch of S = r^{-1}(0) (paper §3.1).
//
// A branch is traced from a point u⁰ by repeating (eqs. IVP, predictor, corrector):
//
//   tangent     τⁱ  with dr(uⁱ)τⁱ = 0, ||τⁱ|| = 1, oriented continuously: τⁱ⁺¹·τⁱ > 0   (eq. tangentvector)
//   predictor   u_pred = uⁱ + h·pⁱ, pⁱ = τⁱ or the secant (eq. predictor), or the cubic Hermite
//               extrapolation of (uⁱ⁻¹, τⁱ⁻¹, uⁱ, τⁱ)
//   corrector   uⁱ⁺¹ = Newton on [r(u); pⁱᵀ(u − u_pred)] = 0 (or Moore–Penrose)         (eq. corrector)
//   step size   Allgower–Georg ch. 6: f = max(sqrt(κ/κ̃), sqrt(δ/δ̃), α/α̃) with κ the Newton contraction,
//               δ = ||uⁱ⁺¹ − u_pred||, α = ∠(τⁱ, τⁱ⁺¹); f > 2 rejects (h/f, at least h/4), otherwise
//               h ← h / max(f, 1/2) in [min_step, max_step], not growing after a rejection or back to a
//               step at which the corrector recently failed. Below min_step: kStepTooSmall.
//
// τ solves [dr(uⁱ⁺¹); τⁱᵀ] v = e_{N+1}: the continuous orientation, so the curve passes straight through
// simple bifurcation points, whose sign flip of det([dr; τᵀ]) is the SB test (special_point.h). At the
// start τ comes from a QR of drᵀ, oriented so that det([dr; τᵀ]) > 0, times d = `direction` (eq. IVP).
// Stops that are level sets (u_k = value, bounds on u_k or Σ u_k) end the branch exactly on them.
//
//   ContinuationOptions options;
//   options.turning_point_components = {"y"};
//   Branch branch = TraceBranch(&circle, Vector2d(1, 0), options);   // the unit circle, zero_problem.h
//   // branch.termination == TerminationReason::kClosedLoop, two turning points at (0, ±1)
//   ContinuationStepper stepper(&circle, options);                    // the same, one point at a time
//   for (stepper.Start(u0); stepper.Step() == StepStatus::kContinuing;) { ... stepper.branch() ... }
//
// Design decisions (docs/design/continuation.md): h is measured along the predictor, arclength is the sum
// of chords; singular corrected points are rejected, so branch points are regular; the first interval from
// a singular start is not searched; a curve of singular points ends at once with kStartFailed; a closed
// loop ends on its start point exactly.
#ifndef HYBRIDCONT_CONTINUATION_H_
#define HYBRIDCONT_CONTINUATION_H_

#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "hybridcont/corrector.h"
#include "hybridcont/special_point.h"
#include "hybridcont/test_function.h"
#include "hybridcont/types.h"
#include "hybridcont/zero_problem.h"

namespace hybridcont {

struct Branch;

enum class TerminationReason {
  kNotFinished,     // the stepper can still take steps
  kMaxPoints,       // max_points reached
  kTargetReached,   // a ComponentTarget was reached (the last point has exactly that value)
  kBoundReached,    // a ComponentBound or SumBound was reached (the last point lies on it)
  kUserStop,        // stop_predicate returned true for the last point
  kStepTooSmall,    // the corrector failed even with min_step; the branch keeps its points
  kClosedLoop,      // the branch returned to its start point (last point == first point)
  kKnownBranch,     // exploration: the branch runs along a branch already traced
  kStartFailed,     // the start point could not be corrected or is singular (see message)
  kAbandoned,       // ContinuationOptions::abandon gave a reason for the branch so far (the message)
};
// The last reason: an interrupted run's store keeps them by number, so new reasons are appended after it and
// named here.
inline constexpr TerminationReason kLastTerminationReason = TerminationReason::kAbandoned;
std::string ToString(TerminationReason reason);

enum class PredictorType {
  kTangent,  // Euler predictor along τ (eq. predictor)
  kSecant,   // along the chord of the last two points: free, and often better on curved branches
  // The cubic Hermite interpolant of the last two points and their tangents, extrapolated by h (its
  // derivative there the hyperplane normal): error O(h⁴) instead of O(h²) at no extra evaluation, so
  // Newton needs fewer iterations. Falls back to the tangent where there is no previous point or h > 2 ×
  // the last chord (docs/design/continuation.md, "Hermite predictor").
  kHermite,
};
std::string ToString(PredictorType type);
// Parses "tangent" / "secant" / "hermite"; returns false for anything else.
bool FromString(const std::string& text, PredictorType* type);

enum class StepStatus {
  kContinuing,  // more steps can follow (a point was added)
  kFinished,    // the branch is finished: see Branch::termination
};

// lower <= u[component] <= upper; the branch ends on the bound it reaches.
struct ComponentBound {
  std::string component;
  double lower = -std::numeric_limits<double>::infinity();
  double upper = std::numeric_limits<double>::infinity();
};
// The branch ends on the first point with u[component] == value (reached from either side).
struct ComponentTarget {
  std::string component;
  double value = 0;
};
// lower <= Σ u[c] over components <= upper, e.g. the period {"t1", "t2", "t3"} <= T_max.
struct SumBound {
  std::vector<std::string> components;
  double lower = -std::numeric_limits<double>::infinity();
  double upper = std::numeric_limits<double>::infinity();
};

struct ContinuationPoint {
  Vector u;
  Vector tangent;               // unit, oriented continuously along the branch
  double arclength = 0;         // sum of chord lengths from the branch start
  double step = 0;              // predictor step h that produced this point (0 for the start)
  int newton_iterations = 0;    // corrector iterations for this point
  double contraction = 0;       // Newton contraction κ of its corrector
  // Hadamard-normalized det([dr; τᵀ]) ∈ [−1, 1] (special_point.h); its sign flips across SB points.
  // 0 at a singular start point.
  double sb_test = 0;
  // ContinuationOptions::test_functions at u (NaN where undefined); empty without test functions.
  Vector test_values;
  // Where the test functions took their values from the corrector's last evaluation
  // (TestFunctions::EvaluateAtBranchPoint): that iterate, within CorrectorOptions::max_jacobian_distance of u;
  // empty where they are u's own.
  Vector evaluated_at;
};

// What the progress callback sees after every accepted point (the library itself never prints).
struct ProgressInfo {
  int branch_id = 0;
  int point_index = 0;
  std::vector<double> values;   // the components named in progress_components (all if empty)
  double step = 0;              // step h used for this point
  double next_step = 0;         // step the controller proposes next
  int newton_iterations = 0;
  int rejected_steps = 0;       // on this branch so far
  // The point is the branch's start at a singular point of r (a branch switched at an SB point, a singular
  // start): multipliers collide at +1 there (floquet.h, FloquetOptions::at_branch_point).
  bool at_singular_point = false;
  // The branch's unit tangent at the point, in the problem's unknowns (ContinuationPoint::tangent); empty
  // where none is known.
  Vector tangent;
};

struct ContinuationOptions {
  // First predictor step. Small enough for Newton to converge from the tangent predictor on typical
  // problems scaled to O(1); the controller grows it quickly when the curve is easy.
  double initial_step = 0.05;
  // Below this the branch is given up (kStepTooSmall): the corrector keeps failing at a scale where the
  // curve is no longer resolved in double precision relative to u = O(1).
  double min_step = 1e-8;
  // Upper bound for h: keeps special points from being stepped over (two SB sign changes in one step
  // cancel) and bounds the chord error of the plotted branch.
  double max_step = 0.25;
  // d of eq. IVP: which of the two orientations of the start tangent to follow (det > 0 convention).
  int direction = +1;
  // Branch points including the start point.
  int max_points = 1000;
  PredictorType predictor = PredictorType::kHermite;
  CorrectorType corrector_type = CorrectorType::kPseudoArclength;
  CorrectorOptions corrector;
  // Nominal Newton contraction κ̃ (Allgower–Georg use 0.3–0.5): faster contraction lets h grow.
  double nominal_contraction = 0.3;
  // Nominal distance δ̃ between predictor and corrected point, in the units of u.
  double nominal_distance = 0.1;
  // Nominal angle α̃ (radians) between consecutive tangents: ~8.6°, fine enough to resolve folds.
  double nominal_angle = 0.15;
  // Corrector iterates farther than this multiple of h from the predictor count as divergence: a
  // Newton iteration that travels farther than the step is probably jumping to another branch.
  double max_corrector_distance = 1.0;
  // Correct the start point with the Moore–Penrose corrector (a start guess need not be on the curve).
  bool correct_start_point = true;
  // Detect (and locate) simple bifurcation points by the sign of det([dr; τᵀ]).
  bool detect_bifurcations = true;
  // Components whose turning points (sign changes of τ_k) are detected and located. Empty means the
  // problem's family parameter (ZeroProblem::family_parameter: "H", the level of a first integral, or
  // the free model parameter at fixed H̄), and none when it has none.
  std::vector<std::string> turning_point_components;
  // Test (monitor) functions whose zeros are detected and located as special points (test_function.h):
  // each stepper evaluates its own Clone(), so options stay copyable and threads share nothing mutable.
  // nullptr: none.
  std::shared_ptr<const TestFunctions> test_functions;
  // Width of the final root-finder bracket (in arclength) at which a special point counts as located.
  // 1e-11 makes located components exact to ~1e-11 (turning-point values to ~1e-20) when the
  // residual allows.
  double location_tolerance = 1e-11;
  // Root-finder budget per special point; Illinois needs ~10, bisection fallback ~40 for 1e-11.
  int max_location_iterations = 60;
  // Estimate the evaluation error of every located special point (special_point.h, "Integration
  // error"): one evaluation of the problem's more accurate copy (ZeroProblem::Refined, tolerances times
  // kIntegrationErrorFactor) at the point, which widens precision() where the point amplifies the error
  // beyond the root finder's bracket. Problems without such a copy (exact to rounding) skip it.
  bool check_integration_error = true;
  // An order of magnitude: the change it shows is 0.9 of the error, yet the copy costs little more.
  static constexpr double kIntegrationErrorFactor = 0.1;
  // The estimate is doubled to make it a bound: errors are only roughly proportional to the tolerances
  // (docs/design/continuation.md, "Integration error of special points").
  static constexpr double kIntegrationErrorSafety = 2;
  // What turns the change a refined evaluation shows into the bound: safety over the part (1 − factor)
  // of the error the change is (errors proportional to the tolerances).
  static constexpr double kIntegrationErrorScale = kIntegrationErrorSafety / (1 - kIntegrationErrorFactor);
  std::vector<ComponentBound> bounds;
  std::vector<ComponentTarget> targets;
  std::vector<SumBound> sum_bounds;
  // Called with each accepted point; returning true ends the branch there (kUserStop). E.g. a maximum
  // period computed from u by the caller.
  std::function<bool(const Vector& u)> stop_predicate;
  // Called with the branch so far after each accepted point, on the tracing thread (so thread-safe): a
  // non-empty reason ends the branch there (kAbandoned, with that reason as its message). E.g. an
  // exploration that gives up a branch whose orbits, so far, are no motion of the system.
  std::function<std::string(const Branch& branch)> abandon;
  // Asked before every step, on the tracing thread (so thread-safe): true ends the branch at its last
  // point (kUserStop, "cancelled"), and an exploration launches no further branch (kCancelled). E.g. a
  // results writer whose disk is full, or a user's interrupt.
  std::function<bool()> cancel;
  // Recognize a branch that returns to its start point (kClosedLoop).
  bool detect_closed_loop = true;
  // Components reported in ProgressInfo::values (names); empty reports all of u.
  std::vector<std::string> progress_components;
  std::function<void(const ProgressInfo&)> progress;

  // Empty if valid; otherwise names the field, its value and the violated constraint.
  std::string Validate() const;
  // Validate() plus: every component named in the options is one of `unknown_names`.
  std::string ValidateFor(const std::vector<std::string>& unknown_names) const;
};

struct Branch {
  int id = 0;
  int direction = +1;                 // d of eq. IVP used at the start
  int parent_special_point = -1;      // SB point / singular start this branch leaves, −1 for none
  int depth = 0;                      // exploration: number of branch switches from the start
  std::vector<ContinuationPoint> points;
  std::vector<SpecialPoint> special_points;  // in arclength order
  TerminationReason termination = TerminationReason::kNotFinished;
  std::string message;
  int newton_iterations = 0;          // total over accepted and rejected steps
  int rejected_steps = 0;
  int located_iterations = 0;         // root-finder iterations spent locating special points
  // Exploration: the branch is the image of branch `image_of` under the problem's symmetry `symmetry`
  // (zero_problem.h), mapped instead of traced (no Newton iterations of its own); −1 if traced.
  int image_of = -1;
  std::string symmetry;
  // Exploration: a loop mapped onto itself by `symmetry` with its orientation reversed, traced to its
  // midpoint; its points from this index on are the images of the earlier ones. −1 if traced throughout.
  int reflected_from = -1;

  std::string BriefReport() const;
  std::string FullReport(const std::vector<std::string>& unknown_names = {}) const;
};

// Traces one branch point by point. Construct, call one Start*, then Step() until kFinished.
class ContinuationStepper {
 public:
  // problem must outlive the stepper. Throws std::invalid_argument if options are invalid for problem.
  ContinuationStepper(ZeroProblem* problem, const ContinuationOptions& options, int branch_id = 0);
  ~ContinuationStepper();
  ContinuationStepper(ContinuationStepper&&) noexcept;
  ContinuationStepper& operator=(ContinuationStepper&&) noexcept;

  // Regular start: corrects u0 (if correct_start_point), tangent with det([dr; τᵀ]) > 0 times direction.
  StepStatus Start(const Vector& u0);
  // Regular start, tangent oriented so that τ·direction_hint > 0.
  StepStatus Start(const Vector& u0, const Vector& direction_hint);
  // Start at a singular point (an SB point or a singular start) along a given branch direction, e.g. from
  // branch_switching.h. No correction and no tangent computation at u0.
  StepStatus StartAtSingularPoint(const Vector& u0, const Vector& tangent);
  // Adds one point (or finishes the branch).
  StepStatus Step();
  // Ends the branch from outside (exploration: kKnownBranch). Keeps the points.
  void Terminate(TerminationReason reason, const std::string& message);

  bool finished() const;
  double step_size() const;           // h proposed for the next step
  const Branch& branch() const;
  Branch TakeBranch();                // moves the branch out; the stepper is finished afterwards

 private:
  class Impl;
  std::unique_ptr<Impl> impl_;
};

// Convenience driver: Start(u0) then Step() until finished.
Branch TraceBranch(ZeroProblem* problem, const Vector& u0, const ContinuationOptions& options);

}  // namespace hybridcont

#endif  // HYBRIDCONT_CONTINUATION_H_
