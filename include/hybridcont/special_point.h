// Special points on a branch: simple bifurcation (SB) points and turning points, detected between two
// consecutive branch points and then located, and honest about how well they were located (modelled on
// BifurcationKit's SpecialPoint: type, where, status, precision, interval).
//
// Test functions (paper §3.1, eq. tangentvector and Fig. pcMethod b), along a branch whose tangent τ is
// oriented continuously (τ_new · τ_old > 0):
//
//   SB point         g_SB(u) = det([dr(u); τᵀ]) / ∏ᵢ ||row i of dr(u)||     changes sign at an SB point
//   turning point    g_k(u)  = τ_k   (the tangent component of a named unknown, e.g. "H")
//
// Scaling decision: det([dr; τᵀ]) alone mixes the units of times, states, ξ and H (entries 0.01..10) and
// over/underflows for large N, so it is never formed as a product (log|pivots| and a sign instead).
// Detection uses only its sign, stored per point as the Hadamard-normalized value (|g_SB| <= 1).
// Location needs a smooth function, and the Hadamard normalization is not smooth where a row of dr
// vanishes at the SB point (N = 1: dr itself vanishes there, and g_SB becomes a step function). Along the
// bracketing interval [u_a, u_b] the root finder therefore uses
//
//   g(σ) = det([dr(u(σ)); τ_aᵀ]) / ∏ᵢ ||row i of dr(u_a)||
//
// (tangent row frozen to τ_a, scale frozen at u_a): det([dr(u); τ_aᵀ]) = c(u)·τ_a with c the cofactor
// vector of dr, c ∥ τ(u), so g has the sign of the SB test, is O(1) at u_a, ≈ linear in σ through the
// root, and needs no ill-conditioned tangent solve next to the SB point.
//
// Location: a safeguarded Illinois (regula falsi) iteration on the test function as a function of the
// pseudo-arclength σ = τ_aᵀ(u − u_a) from the bracketing point u_a; every trial point is corrected back
// onto the curve by pseudo-arclength (hyperplane ⟂ τ_a at distance σ). It stops when the bracket
// [σ_lo, σ_hi] is narrower than location_tolerance (status kLocated) or when a trial point cannot be
// corrected / the iteration budget is spent (status kBracketed: the interval is still reported).
//
// Located to the noise level (shooting maps, residual noise ~1e-12..1e-10): next to an SB point the
// bordered matrix [dr; τ_aᵀ] is singular for every border (rank dr = N − 1 at the SB), so Newton amplifies
// the residual noise along the second kernel direction, and a trial point either leaves the bracket or
// lands on the crossing branch (a correction longer than a quarter of the bracket width counts as failed).
// When such a trial point's interpolant already has a residual at the corrector's tolerance, the curve
// cannot be resolved further on the bracket's scale: the point counts as located, `message` says "located
// to the noise level", and precision() is the bracket reached, widened on both sides by its own width
// (or by the noisy correction, if larger): its ends are themselves points inside the noise (e.g. ~5e-8 in
// arclength for the bouncing rod's SB, not location_tolerance).
//
// Integration error (ContinuationOptions::check_integration_error, on by default): the bracket is where
// the root of the *computed* test function lies. A shooting map is computed with integration error, and
// a point where the curve is badly conditioned (next to another singular point, near a family of
// solutions) amplifies it in the tangent and so in the test function. After locating, the estimate
// is evaluated again with the problem's refined copy (ZeroProblem::Refined: integration tolerances × 0.1).
// With errors proportional to the tolerances, the change Δg of the test function is 0.9 of its error;
// δs = 2|Δg| / (0.9 |slope|) is how far the exact root may lie along the branch (slope: the flatter of the
// test's secants over the step and over the final bracket; the factor 2 makes the estimate a bound, as
// errors are only roughly proportional to the tolerances), and twice the refined Newton correction δu/0.9
// how far the exact curve may lie from u. The interval grows to s ± (δs + |δu|) where that is wider,
// interval_width to 2(|τ_i| δs + |δu_i|), and the message says so (also when the check could not be
// made). A turning point at an SB point of the same step (within its interval or 1e-4 of the step) has
// no meaningful test of its own, the tangent being undefined there: it keeps its bracket and takes the SB
// point's interval and their distance.
// Measured on the SLIP (session 6): regular turning and SB points are good to 1e-11..5e-10 in arclength
// (the bracket alone said 2.5e-12), the SB point where branch 18 passes the zero-duration family to
// 1.2e-7, the turning point at the closed loop's reflection midpoint (an SB point too) to 3.8e-6 (all
// said 2.5e-12); a test explores again at 0.1x the tolerances and finds every point within the two runs'
// intervals (so do x0.3, x3, x0.03, x0.01 in norm). Points located to the noise level are the exception:
// their interval (the bracket widened by kNoiseMargin = 4 widths) is an estimate, not a bound; between
// pairs of tolerances from x3 to x0.01 four of the SLIP's 42 points (the loop's noise-limited turning
// point near T = 0, the SB of the crossing cluster near H̄ = 1.6115) moved by up to 2.9x what the two
// intervals allow.
// Problems exact to rounding (algebraic ones) have no refined copy: their precision is the bracket's.
//
// Tangent of an SB point: the induced tangent is undefined there and next to it numerically meaningless
// when dr is noisy (it mixes the two branch directions). SpecialPoint::tangent is the estimate's induced
// tangent only when it lies within the cone of the regular tangents at the bracketing points, otherwise
// their interpolation: branch switching identifies the incoming ABE root by this tangent.
//
// Tiny example (pitchfork x³ − λx traced along x = 0 from λ = −1):
//
//   Branch branch = TraceBranch(&pitchfork, u0, options);
//   const SpecialPoint& sb = branch.special_points[0];
//   // sb.type == SpecialPointType::kSimpleBifurcation, sb.status == LocationStatus::kLocated,
//   // |sb.u(1)| < 1e-12 (λ at the SB), sb.precision() < 1e-11 (width of the arclength bracket)
#ifndef HYBRIDCONT_SPECIAL_POINT_H_
#define HYBRIDCONT_SPECIAL_POINT_H_

#include <string>
#include <vector>

#include "hybridcont/types.h"

namespace hybridcont {

enum class SpecialPointType {
  kSimpleBifurcation,  // sign change of det([dr; τᵀ]); branches cross here (paper: SB point)
  kTurningPoint,       // sign change of the tangent component τ_k: the component has an extremum
  kSingularStart,      // a start point where dr has a kernel of dimension >= 2 (e.g. an equilibrium)
};
std::string ToString(SpecialPointType type);

enum class LocationStatus {
  kLocated,    // bracket narrower than the location tolerance
  kBracketed,  // only bracketed: the root finder stopped early (see message); u is the best estimate
};
std::string ToString(LocationStatus status);

struct SpecialPoint {
  int id = -1;                 // unique within a branch (TraceBranch) or a diagram (Explore)
  SpecialPointType type = SpecialPointType::kSimpleBifurcation;
  LocationStatus status = LocationStatus::kBracketed;
  int branch_id = -1;          // branch on which it was found
  int index = -1;              // lies between branch points [index] and [index + 1]
  double arclength = 0;        // arclength coordinate on the branch (from the branch start)
  std::string component;       // turning points: the unknown that turns; empty otherwise
  int component_index = -1;
  Vector u;                    // best estimate of the point
  Vector tangent;              // tangent of the branch at u (SB points: see "Tangent of an SB point")
  Vector tangent_before;       // tangent at branch point [index]
  Vector tangent_after;        // tangent at branch point [index + 1]
  double test_value = 0;       // test function at u (normalized determinant or τ_k)
  // Interval in the arclength coordinate (absolute on the branch) that holds the special point: the final
  // bracket, widened by the integration error where that is larger ("Integration error" above), and the
  // componentwise width of u over it: the honest precision of every component of u.
  double interval_lo = 0;
  double interval_hi = 0;
  Vector interval_width;
  double residual_norm = 0;    // ||r(u)|| of the corrector at u
  int iterations = 0;          // root-finder iterations (each one corrected trial point)
  int duplicate_of = -1;       // in a diagram: id of the same point found earlier on another branch
  std::string message;         // why only bracketed, or notes

  double precision() const { return interval_hi - interval_lo; }
  // One line: type, status, branch/index, position, precision. names labels u (may be empty).
  std::string BriefReport(const std::vector<std::string>& names = {}) const;
};

}  // namespace hybridcont

#endif  // HYBRIDCONT_SPECIAL_POINT_H_
