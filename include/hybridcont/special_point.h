// Special points on a branch: simple bifurcation (SB) points and turning points, detected between two
// consecutive branch points, located, and honest about how well (type, where, status, precision, interval).
//
// Test functions (paper §3.1, eq. tangentvector, Fig. pcMethod b), τ oriented continuously:
//   SB point         g_SB(u) = det([dr(u); τᵀ]) / ∏ᵢ ||row i of dr(u)||     changes sign at an SB point
//   turning point    g_k(u)  = τ_k   (the tangent component of a named unknown)
// The determinant is formed as log|pivots| and a sign (never as a product: units mix and it over/underflows);
// detection uses its sign. Location needs a smooth function, so along the bracket [u_a, u_b] the root finder
// uses g(σ) = det([dr(u(σ)); τ_aᵀ]) / ∏ᵢ ||row i of dr(u_a)|| (row and scale frozen at u_a): it has the sign
// of g_SB (det = c(u)·τ_a, cofactors c ∥ τ), is ≈ linear through the root, and needs no tangent solve.
//
// Location: safeguarded Illinois on σ = τ_aᵀ(u − u_a), every trial point corrected onto the curve on its
// hyperplane; kLocated when the bracket is narrower than location_tolerance, else kBracketed. Next to an SB
// point of a noisy problem Newton amplifies the residual noise: a trial whose interpolant is already at the
// corrector's tolerance counts as "located to the noise level", its bracket widened by its width.
//
// Integration error (ContinuationOptions::check_integration_error): the bracket holds the root of the
// *computed* test. The problem's more accurate copy (ZeroProblem::Refined, tolerances × 0.1) is evaluated
// at the estimate; with errors proportional to the tolerances the change Δg is 0.9 of g's error, so the root
// may lie δs = 2|Δg| / (0.9|slope|) along the branch and the curve 2|δu|/0.9 off it (δu the refined Newton
// correction; factor 2: a bound). interval grows to s ± (δs + |δu|), interval_width to 2(|τ_i|δs + |δu_i|),
// and the message says so. A turning point at an SB point of the same step takes that point's interval.
// Problems exact to rounding have no such copy: their precision is the bracket's.
// Tangent of an SB point: the induced tangent if inside the cone of the bracketing tangents, else their
// interpolation. Decisions and measurements: docs/design/continuation.md.
//
//   Branch branch = TraceBranch(&pitchfork, u0, options);     // x³ − λx along x = 0 from λ = −1
//   const SpecialPoint& sb = branch.special_points[0];
//   // sb.type == kSimpleBifurcation, sb.status == kLocated, |sb.u(1)| < 1e-12, sb.precision() < 1e-11
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
  // Zeros of test functions (test_function.h), located on the branch like the two above:
  kFloquetBranchPoint,  // a further Floquet multiplier crosses +1 (BP; floquet_test_functions.h)
  kPeriodDoubling,      // a Floquet multiplier crosses −1 (PD; floquet_test_functions.h)
  kUserTestFunction,    // a zero of a caller's test function
  kGrazing,             // an event met tangentially: its normalized crossing speed de·f/(|de||f|) is 0
  kNeimarkSacker,       // a complex pair of Floquet multipliers crosses the unit circle (NS; floquet.h)
  kObservableValue,     // an observable reaches a value the user monitors (UZ, as AUTO's; observable.h)
  kConstraintBoundary,  // an admissibility constraint's minimum reaches 0 (CB; observable.h)
  kKreinCollision,      // two pairs of multipliers of a symplectic map collide on the unit circle (KC; floquet.h)
  kZeroDuration,        // a phase's duration reaches 0: the phase vanishes from the cycle (ZD; the end of a
                        // physical family where running's flight shrinks to nothing and walking begins)
  kExtremum,            // an observable the user asked about is largest or smallest along the family (EX): a
                        // turning point of its component, which the continuation locates as such and the study
                        // names (the fastest gait of a family, its highest apex)
};
// The last type: the types are the integers 0 .. kLastSpecialPointType.
constexpr SpecialPointType kLastSpecialPointType = SpecialPointType::kExtremum;
std::string ToString(SpecialPointType type);
// The short code of reports and summary.json: "SB", "TP", "start", "BP", "PD", "test", "GR", "NS", "UZ", "CB",
// "KC", "ZD", "EX".
std::string Code(SpecialPointType type);
// The type of a code; false for a string that is none.
bool FromCode(const std::string& code, SpecialPointType* type);

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
  int component_index = -1;    // turning points: index of that unknown; test functions: index of the function
  Vector u;                    // best estimate of the point
  Vector tangent;              // tangent of the branch at u (SB points: see "Tangent of an SB point")
  Vector tangent_before;       // tangent at branch point [index]
  Vector tangent_after;        // tangent at branch point [index + 1]
  double test_value = 0;       // test function at u (normalized determinant, τ_k or the test function's g)
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
