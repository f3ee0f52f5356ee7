// Branch directions at singular points by the Lyapunov–Schmidt reduction (paper §3.1, Allgower–Georg
// ch. 8.3; Keller ch. 5): at simple bifurcation (SB) points found on a branch, and at singular start
// points such as the paper's equilibria with zero phase durations (§4).
//
// At a singular point u* of r (r(u*) = 0, rank dr(u*) = N + 1 − k, k >= 2):
//
//   kernel    Φ = [φ₁ … φ_k],        dr(u*) Φ = 0          (right singular vectors of the zero singular values)
//   cokernel  Ψ = [ψ₁ … ψ_{k−1}],    Ψᵀ dr(u*) = 0         (left singular vectors)
//
// A branch through u* leaves it along v = Φα with α solving the algebraic bifurcation equations (ABE)
//
//   Q_j(α) = ψ_jᵀ d²r(u*)[Φα, Φα] = αᵀ A_j α = 0,   j = 1..k−1,
//   d²r[v, w] ≈ (dr(u* + εw) − dr(u* − εw)) v / (2ε)      (central differences of the exact Jacobian)
//
// k = 2: one quadratic a α₁² + 2b α₁α₂ + c α₂² with b² − ac > 0 has two real roots, the two branches
// crossing at u*; on a traced branch the new one leaves along the root transverse to the incoming
// tangent, in both directions ±v (d of eq. (IVP)). k > 2: linear conditions C v = 0 restrict the kernel
// (e.g. t2 = t1 + t3 as {{"t2", 1}, {"t1", −1}, {"t3", −1}}); the roots of the dominant restricted form
// that make all forms vanish are the branches.
// Second derivatives: the differences with step ε must be confirmed by those with ε/10 (agreement to 1 %);
// where they are not, or an evaluation fails, ε shrinks tenfold (down to 1e-6 fd_step) and the report
// says which step served. A badly conditioned map (single shooting through an orbit with multipliers
// ~1e7, docs/design/state-based.md) is far from quadratic over 1e-4 and needs it.
// Contract: directions are lines (unit, largest-magnitude component positive); a double root is one
// line; a degenerate ABE gives the kernel direction orthogonal to the incoming tangent (kFallback). At an
// SB point found on a branch the kernel is taken to be 2-dimensional. Design decisions:
// docs/design/exploration.md ("Branch switching: rank decision and fallback").
//
// Tiny example (pitchfork x³ − λx at its singular point (0, 0): d²r = [[6x, −1], [−1, 0]] → Q = −2αβ):
//
//   std::vector<Vector> lines = BranchDirectionsAt(pitchfork, Vector2d(0, 0), StartOptions());
//   // lines = {(1, 0), (0, 1)}: the parabola's tangent and the trivial branch
#ifndef HYBRIDCONT_BRANCH_SWITCHING_H_
#define HYBRIDCONT_BRANCH_SWITCHING_H_

#include <string>
#include <utility>
#include <vector>

#include "hybridcont/continuation.h"
#include "hybridcont/special_point.h"
#include "hybridcont/types.h"
#include "hybridcont/zero_problem.h"

namespace hybridcont {

struct BranchSwitchOptions {
  // Singular values below this · max(1, σ_max) count as zero: separates a located SB point's σ_min from
  // the genuinely nonzero singular values of O(1) problems.
  double rank_tolerance = 1e-8;
  // The first ε of the central differences (see "Second derivatives" above): balances truncation O(ε²)
  // against rounding and integrator noise in dr, which enter as O(δ/ε).
  double fd_step = 1e-4;
  // A discriminant below this times (a² + b² + c²) means a double root: the ABE does not separate two
  // branches (degenerate; not a simple bifurcation).
  double degeneracy_tolerance = 1e-6;
  // k > 2: a root of the dominant form is kept when every other form is below this times its norm there.
  double abe_tolerance = 1e-6;

  std::string Validate() const;
};

// cᵀ v = 0 for a branch direction v, c given by coefficients on named unknowns.
struct LinearCondition {
  std::vector<std::pair<std::string, double>> coefficients;
};

struct StartOptions {
  BranchSwitchOptions switching;
  // Conditions that restrict the kernel when its dimension exceeds 2 (ignored for k = 2 only if empty).
  std::vector<LinearCondition> conditions;

  std::string Validate() const;
};

enum class BranchSwitchStatus {
  kOk,                // directions from the ABE roots
  kFallback,          // ABE degenerate; kernel direction orthogonal to the incoming tangent used
  kRegular,           // kernel dimension 1: a regular point (the one direction is the tangent)
  kUnderdetermined,   // the kernel, restricted by the conditions, still has dimension > 2
  kNoRoots,           // the ABE have no real (common) roots, or the conditions exclude the kernel
  kEvaluationFailed,  // ZeroProblem::Evaluate failed at u* or at a finite-difference point
};
std::string ToString(BranchSwitchStatus status);

// All branch directions through a point (singular start points; also regular points).
struct BranchDirections {
  BranchSwitchStatus status = BranchSwitchStatus::kNoRoots;
  std::string message;
  int kernel_dimension = 0;
  int cokernel_dimension = 0;
  Vector singular_values;             // of dr(u0), descending
  Matrix kernel;                      // columns φ_p
  Matrix cokernel;                    // columns ψ_j
  std::vector<Vector> directions;     // one unit vector per branch line (± both half-branches)

  std::string BriefReport() const;
};

// Kernel, cokernel, ABE and their roots at u0. Throws std::invalid_argument for invalid options, a wrong
// size of u0, or a condition naming an unknown component.
BranchDirections AnalyzeSingularPoint(ZeroProblem* problem, const Vector& u0, const StartOptions& options);
// The directions only (empty when none were found; AnalyzeSingularPoint says why).
std::vector<Vector> BranchDirectionsAt(ZeroProblem& problem, const Vector& u0, const StartOptions& options);

// The direction of the new branch at a located SB point.
struct BranchSwitch {
  BranchSwitchStatus status = BranchSwitchStatus::kNoRoots;
  std::string message;
  Vector direction;              // unit, the ABE root transverse to the incoming branch (CanonicalLine sign)
  Vector incoming_direction;     // unit, the ABE root nearest the incoming tangent
  // Angle (radians) between the incoming tangent and its ABE root: a self-check of the whole reduction
  // (small when the SB point and the second derivatives are accurate).
  double incoming_root_angle = 0;
  double a = 0, b = 0, c = 0;    // ABE a α₁² + 2b α₁α₂ + c α₂² in the basis (φ₁ ∥ incoming, φ₂ ⟂)
  // σ_min / max(1, σ_max) of dr at the SB point (the rank test's scale): how singular the located point
  // is; ~ the location precision for a well-scaled problem.
  double sigma_ratio = 0;

  std::string BriefReport() const;
};
BranchSwitch SwitchDirectionAt(ZeroProblem* problem, const SpecialPoint& sb, const BranchSwitchOptions& options);

// Sign convention for lines (BranchDirections::directions, BranchSwitch::direction): unit, the
// largest-magnitude component positive. The half-branch along +direction is traced first.
Vector CanonicalLine(Vector v);

// The two half-branches leaving an SB point along ±direction (the stepper's StartAtSingularPoint: a
// predictor along the direction, then the corrector), traced with `options`. Branch ids 0 and 1.
std::vector<Branch> TraceSwitchedBranches(ZeroProblem* problem, const SpecialPoint& sb,
                                          const BranchSwitch& branch_switch, const ContinuationOptions& options);

}  // namespace hybridcont

#endif  // HYBRIDCONT_BRANCH_SWITCHING_H_
