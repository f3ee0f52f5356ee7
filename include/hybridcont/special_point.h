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
  Vector tangent;              // tangent of the branch at u (for SB points: limit from the incoming side)
  Vector tangent_before;       // tangent at branch point [index]
  Vector tangent_after;        // tangent at branch point [index + 1]
  double test_value = 0;       // test function at u (normalized determinant or τ_k)
  // Final bracket in the arclength coordinate (absolute on the branch) and the componentwise width
  // |u(σ_hi) − u(σ_lo)| of the curve over it: the honest precision of every component of u.
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
