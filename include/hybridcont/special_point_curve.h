// Two-parameter curves of special points: a fold (turning point), a branch point, or a zero of a caller's
// scalar test function, continued in two parameters by minimally augmented defining systems (Govaerts,
// "Numerical Methods for Bifurcations of Dynamical Equilibria", ch. 3–4; MatCont's LP and BP curves).
//
// Input. A base ZeroProblem P with N+1 equations in N+2 unknowns u whose row `fix_row` is a fixing row
// u_b − c = 0 (any nonzero multiple): P's zero set is a one-parameter family in the free parameter a at
// b = c (e.g. p free at fixed H̄, or H̄ free at fixed p). Dropping that row leaves R(u) = 0, N equations in
// N+2 unknowns, a surface; write u = (x, a, b) with x the other N unknowns. The curve problem adds one or
// two defining equations and is again a ZeroProblem (one unknown more than equations) that the
// continuation engine traces (continuation.h):
//
//   fold           [R(u); g(u)],  [R_x  β_f; c_fᵀ 0] [v; g] = [0; 1]                N+1 eqs, N+2 unknowns
//                  g = 0 exactly where R_x (dR without the columns of a and b; up to sign the Jacobian of P
//                  without the column of a) is singular: a turning point of the a-family at fixed b, and
//                  equally of the b-family at fixed a. v spans ker R_x, w (adjoint solve, β_fᵀw = 1) the
//                  cokernel; ∇g = −wᵀ R_xu[v, ·].
//   branch point   [R(u) + βψ; g₁; g₂],  [M  ψ̃; Vᵀ 0] [Φ; g] = [0; I₂],  M = [R_x R_a]   N+2 eqs, N+3
//                  unknowns (u, β). g = 0 where M (P's Jacobian without its fixing row) has rank N−1, the
//                  columns of Φ spanning ker M: a branch point of the a-family. β regularizes: generic
//                  branch points are isolated in two parameters and lie where the curve crosses β = 0; where
//                  a symmetry makes them persist, β ≡ 0 along the curve. ∇gᵢ = −wᵀ R_uu[φ̂ᵢ, ·].
//   test function  [R(u); g(u)] with g the caller's smooth scalar function (ScalarTest) with a regular
//                  zero, e.g. a period-doubling test function; its gradient the caller's, or central
//                  differences of g.
//
// The borders (β_f, c_f), (ψ̃, V) start at the singular vectors of the smallest singular values at the start
// point and follow the computed null vectors from point to point (c_f ← v/|v|, β_f ← w/|w|, V ← the
// orthonormalized Φ): their orientation is kept, so g keeps its sign convention and the bordered matrix
// stays well conditioned. The zero set does not depend on the borders. ψ in R + βψ is the cokernel at the
// start and stays fixed along the curve (β is a coordinate of one fixed system).
//
// Second derivatives. R_uu[v̂, ·] (v̂ = v padded with zeros in the columns of a, b) is the directional
// difference of Jacobians wᵀ(dR(u + εv̂/|v̂|) − dR(u − εv̂/|v̂|))|v̂| / (2ε): two Jacobian evaluations, exact
// for quadratic dR. ε = second_derivative_step = 1e-4 because the gradient only steers Newton and the
// tangent (g itself is solved exactly), so its O(ε²) truncation is harmless while a Jacobian computed by
// integration, noisy to ~1e-10, enters only as noise/ε ~ 1e-6.
//
// Codimension-two points on a curve are detected between consecutive curve points and located:
//   turning         the curve turns in a or b (sign change of the tangent component; the stepper's turning
//                   points). On a fold curve a turn in b is where the fold meets a branch point of the
//                   a-family (wᵀR_a = 0, from wᵀR_a ȧ + wᵀR_b ḃ = 0), and vice versa.
//   cusp            fold curve: the fold's quadratic coefficient q = wᵀR_xx[v, v] changes sign.
//   fold on BP      branch-point curve: a second eigenvalue of R_x through zero, a fold of the other
//                   branch meeting the branch point: det[R_x β_f; c_fᵀ 0] (Hadamard-normalized) changes sign.
//   beta zero       branch-point curve: β changes sign, a branch point of the problem itself (β within the
//                   corrector's residual tolerance at both points is zero: a persistent branch point).
//   monitor         a caller's ScalarTest (SpecialPointCurveOptions::monitors) changes sign.
//   crossing        the curve system's own simple bifurcation point (curves of the same kind cross).
//
//   // the cusp a + b x − x³: u = (x, a, b), fixing row b − 3 = 0 appended as row 1
//   CurveDefinition fold{CurveKind::kFold, /*fix_row=*/1, /*family_parameter=*/"a", {}};
//   SpecialPointCurve curve = TraceSpecialPointCurve(&cusp, fold, Vector3d(1, -2, 3), options);
//   // curve.points: a = −2x³, b = 3x² through the cusp (0, 0, 0), reported as kCusp
//
// Wiring to a hybrid shooting map: free a model parameter p as an unknown of the time-based map with a
// fixed row for H̄ (or fix p and leave H̄ free), locate a turning or SB point on that one-parameter family,
// and pass the map, the fixing row's index and the free parameter's name (TraceSpecialPointCurve from a
// SpecialPoint). Contract: the base Jacobian is requested dense; each evaluation of a fold curve with dr
// costs three base Jacobians, of a branch-point curve five. Bad input (sizes, names, a fix_row that is
// not a fixing row) is std::invalid_argument; numerical outcomes are statuses. Decisions and measurements:
// docs/design/special-point-curves.md.
#ifndef HYBRIDCONT_SPECIAL_POINT_CURVE_H_
#define HYBRIDCONT_SPECIAL_POINT_CURVE_H_

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "hybridcont/continuation.h"
#include "hybridcont/special_point.h"
#include "hybridcont/test_function_root.h"
#include "hybridcont/types.h"
#include "hybridcont/zero_problem.h"

namespace hybridcont {

enum class CurveKind {
  kFold,          // turning points of the one-parameter family
  kBranchPoint,   // simple bifurcation points of the one-parameter family (regularized by β)
  kTestFunction,  // zeros of a caller's scalar test function
};
std::string ToString(CurveKind kind);
// Parses "fold" / "branch-point" / "test-function"; returns false for anything else.
bool FromString(const std::string& text, CurveKind* kind);

// A smooth scalar function of the base unknowns u (N+2 entries). `value` returns NaN where it cannot be
// evaluated. `gradient` (optional, 1 x (N+2)) returns false where it cannot; without it the gradient is
// the central difference of `value` with step second_derivative_step in every unknown.
struct ScalarTest {
  std::string name;
  std::function<double(const Vector& u)> value;
  std::function<bool(const Vector& u, RowVector* gradient)> gradient;
};

struct CurveDefinition {
  CurveKind kind = CurveKind::kFold;
  int fix_row = -1;                 // the base problem's fixing row u_b − c = 0; b is its only nonzero column
  std::string family_parameter;     // a: the unknown free on the base family (its turning points are folds)
  ScalarTest test;                  // kTestFunction: the defining function g
};

struct SpecialPointCurveOptions {
  // Settings of the tracing (bounds, targets, steps, max_points per direction). Empty
  // turning_point_components means both parameters a and b (turns of the curve).
  ContinuationOptions continuation;
  // ε of the directional differences of Jacobians (see "Second derivatives"); also the step of central
  // differences of a ScalarTest without a gradient.
  double second_derivative_step = 1e-4;
  // Follow the null vectors with the borders after every accepted point (MatCont's update); off, the
  // start's borders serve throughout, and the bordered matrix degrades as the null vectors rotate.
  bool update_borders = true;
  // Detect and locate the cusp (fold curves) and the fold-on-BP and β-zero points (branch-point curves).
  bool detect_codim_two = true;
  // Further test functions whose sign changes on the curve are located (kMonitor).
  std::vector<ScalarTest> monitors;
  // Root finding of the codimension-two test functions along the curve.
  TestFunctionRootOptions location;

  std::string Validate() const;
};

// The curve problem: a ZeroProblem on the base unknowns (plus "beta" for branch points).
class SpecialPointCurveProblem : public ZeroProblem {
 public:
  // base must outlive this problem. Throws std::invalid_argument for sizes, names or a bad fix_row
  // (checked on the base Jacobian at u0, a point near the curve, base unknowns or curve unknowns).
  SpecialPointCurveProblem(ZeroProblem* base, const CurveDefinition& definition, const Vector& u0,
                           const SpecialPointCurveOptions& options = SpecialPointCurveOptions());
  ~SpecialPointCurveProblem() override;

  int num_equations() const override;
  std::vector<std::string> unknown_names() const override;
  EvaluationStatus Evaluate(const Vector& u, Vector* r, Matrix* dr) override;

  // Borders from the singular vectors of the smallest singular values at u (also done by the
  // constructor at u0).
  EvaluationStatus InitializeBorders(const Vector& u);
  // Borders from the null vectors computed at u with the present borders (orientation kept).
  EvaluationStatus UpdateBorders(const Vector& u);

  // Built-in codimension-two test functions at u (curve unknowns), NaN where not defined or failed:
  // fold: the cusp coefficient q = wᵀR_xx[v, v] (v, w normalized to unit length); branch point: the
  // normalized determinant of the fold-bordered R_x, then β.
  std::vector<std::string> codim_two_names() const;
  std::vector<double> CodimTwoTests(const Vector& u);

  // The defining quantities g (1 or 2 values) at u: zero on the curve.
  EvaluationStatus DefiningValues(const Vector& u, Vector* g);

  CurveKind kind() const;
  int family_index() const;   // a
  int second_index() const;   // b
  int base_unknowns() const;  // N + 2

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

enum class CodimTwoType {
  kTurning,             // the curve turns in a parameter (component)
  kCusp,                // fold curve: quadratic coefficient through zero
  kFoldOnBranchPoint,   // branch-point curve: a fold of the other branch meets the branch point
  kBetaZero,            // branch-point curve: β through zero, a branch point of the problem itself
  kMonitor,             // a caller's test function through zero (name)
  kCrossing,            // a simple bifurcation point of the curve system
};
std::string ToString(CodimTwoType type);

struct CodimTwoPoint {
  CodimTwoType type = CodimTwoType::kTurning;
  std::string name;          // the component (turning), the monitor's name, or the type's name
  LocationStatus status = LocationStatus::kBracketed;
  int index = -1;            // lies between SpecialPointCurve::points [index] and [index + 1]
  Vector u;                  // curve unknowns
  double precision = 0;      // turning/crossing: in arclength; others: bracket along the chord in u
  std::string message;

  std::string BriefReport(const std::vector<std::string>& names = {}) const;
};

enum class CurveStatus {
  kTraced,        // both directions traced (or a closed curve); see the terminations
  kStartFailed,   // the start point could not be corrected onto the curve (message)
};
std::string ToString(CurveStatus status);

struct SpecialPointCurve {
  CurveKind kind = CurveKind::kFold;
  CurveStatus status = CurveStatus::kStartFailed;
  std::string message;
  std::vector<std::string> unknown_names;     // of the curve unknowns
  std::vector<std::string> test_names;        // codim-two tests, then monitors
  // Points from the end of the backward direction through the start to the end of the forward one.
  std::vector<Vector> points;
  std::vector<double> arclength;              // signed: negative on the backward part, 0 at the start
  std::vector<Vector> tests;                  // per point, in test_names order (NaN: not defined)
  int start_index = 0;                        // the start point in `points`
  std::vector<CodimTwoPoint> codim_two_points;  // in curve order
  TerminationReason forward_termination = TerminationReason::kNotFinished;
  TerminationReason backward_termination = TerminationReason::kNotFinished;
  std::string forward_message, backward_message;
  int newton_iterations = 0;

  // Column of a named curve unknown; throws std::invalid_argument for an unknown name.
  Vector Column(const std::string& name) const;
  std::string BriefReport() const;
  std::string FullReport() const;
};

// Traces the curve through (or from near) u0 in both directions.
SpecialPointCurve TraceSpecialPointCurve(ZeroProblem* base, const CurveDefinition& definition,
                                         const Vector& u0, const SpecialPointCurveOptions& options);
// From a located special point of the base family: a turning point gives a fold curve (in its component,
// which then serves as a), an SB point a branch-point curve of the family in `family_parameter`. Other
// types are std::invalid_argument.
SpecialPointCurve TraceSpecialPointCurve(ZeroProblem* base, const SpecialPoint& point, int fix_row,
                                         const std::string& family_parameter,
                                         const SpecialPointCurveOptions& options);

}  // namespace hybridcont

#endif  // HYBRIDCONT_SPECIAL_POINT_CURVE_H_
