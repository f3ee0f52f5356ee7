// Monodromy matrix and Floquet multipliers of a periodic orbit (paper §2.5, footnote on Phi_T).
//
// From a time-based solution u (timebased_shooting.h) the monodromy is chained from the segments'
// fundamental matrices and the saltation matrices at the segment ends (eq. `fundamentalMatrixHybrid`):
//
//     Phi_T = Phi_{m+1} S_m Phi_m ... S_1 Phi_1,     S_i = D_i + (f~_{i+1}^+ - D_i f~_i^-) de_i / (de_i f~_i^-)
//
// with f~^- = f~_i(phi_i(t_i)), f~^+ = f~_{i+1}(Delta_i(phi_i(t_i))). Its eigenvalues are the Floquet
// multipliers. A conservative orbit always has two of them at +1 (Thm 2.1 and the freedom of phase):
//     Phi_T f(x0) = f(x0)          (right eigenvector: the flow direction)
//     dH(x0) Phi_T = dH(x0)         (left eigenvector: the first integral, eq. `leftEigen`)
// and generically they form a 2x2 Jordan block (the period changes with the energy). A Jordan block
// splits under a perturbation eps of Phi_T by ~sqrt(eps): with integration errors ~1e-10 the computed
// "1, 1" are 1 ± 1e-5. So the two trivial multipliers are deflated exactly instead of being read off the
// eigenvalues: Phi_T maps ker dH into itself and fixes f in it; on the quotient ker dH / span(f),
// represented by an orthonormal basis B of ker dH orthogonal to f, the reduced matrix
//     M = B^T Phi_T B     ((n1-2) x (n1-2))
// carries exactly the n1 - 2 nontrivial multipliers (its eigenvalues are those of the Poincaré map
// restricted to the energy level). The BP/PD test functions and the stability verdict use M.
//
// A model without first integral (a dissipative or forced system) has one trivial multiplier, +1 with the
// flow direction f; B is then an orthonormal basis of f^⊥ (n1 − 1 columns), M = B^T Phi_T B carries the
// n1 − 1 multipliers of the Poincaré map, and an orbit can be asymptotically stable (all |mu| < 1).
//
// Multipliers accurate relative to their own size. Eigenvalues of one matrix are accurate relative to its
// norm, so a multiplier far inside the unit circle, computed from Phi_T beside one of modulus 1e7, keeps
// only ~eps·1e7 of its own digits (the bouncing rod's symplectic pair μ, 1/μ then has a product 1.002
// instead of 1). The monodromy is a product of factors, Phi_T = Phi_{m+1} S_m ... S_1 Phi_1, each of
// modest norm; where every factor is invertible (elastic resets, no singular saltation) the inverse
// product Phi_T^{-1} = Phi_1^{-1} S_1^{-1} ... Phi_{m+1}^{-1} is formed from the inverted factors and its
// deflated matrix B^T Phi_T^{-1} B (= M^{-1}: Phi_T^{-1} keeps ker dH and fixes f too) gives the multipliers
// inside the unit circle as reciprocals of its large eigenvalues, accurate relative to their own size. A
// plastic impact (a rank-deficient reset) has no inverse: its multipliers then come from M alone
// (`product_inverse`, on by default).
//
// Stability class (FloquetResult::stability), from the nontrivial multipliers (with a first integral: on
// the orbit's energy level): asymptotically stable (every nontrivial |μ| < 1), neutrally
// stable (none outside, some on the unit circle: the best a conservative orbit can be), or unstable with
// the kind of the multipliers outside: a real one above +1 (saddle), a real one below −1 (flip), a complex
// pair (oscillatory).
//
// Accuracy of the multipliers (FloquetResult::multiplier_error). Phi_T is known to fix f and (with a first
// integral) dH exactly, so the defects |Phi_T f - f| / |f| and |dH Phi_T - dH| / |dH| measure the error of
// the computed Phi_T itself, in the units of its eigenvalues: a well-conditioned multiplier is off by about
// that much. They are ~1e-11 on ordinary orbits and grow with the orbit's sensitivity: an orbit that passes
// near an equilibrium (the slow end of a family whose period grows without bound) multiplies the
// integrator's error by e^{λT}. The same error bounds the multipliers near the unit circle taken from the
// inverse product: the inverse's own defect does not (the rimless wheel's multiplier cos²2α from the inverse
// is off by ~tol·|Phi_T|, the forward defect, at T = 10, while the inverse's defect is 300 times smaller);
// far inside the circle the inverse product's are accurate relative to their size, better than this bound.
// The defect is an estimate (the wheel's multiplier is off by 0.5 to 1.2 times it as T grows to 24), so the
// error stated is twice it (kMultiplierErrorSafety), as a located point's integration error is doubled
// (continuation.h). Where that error exceeds circle_tolerance and reaches the distance of a multiplier from
// the unit circle (and none lies clearly outside it), the stability verdict is withheld
// (StabilityClass::undetermined). Beyond kUnresolvedMultiplierError the orbit is not resolved at all: the
// Floquet test functions take no value at such a branch point (floquet_test_functions.h), so that no special
// point is bracketed on noise. The defects hold on periodic orbits: off the curve (a point displaced for a
// difference quotient) the orbit does not close and Phi_T f differs from f by that too.
//
// Tolerances (FloquetOptions) and why:
//   unit_tolerance   = 1e-6:  a nontrivial multiplier within this of +1 counts as a further unit multiplier
//                             (normal := none does). Simple multipliers are accurate to ~1e-9 at rtol 1e-10;
//                             near a collision at +1 they split by sqrt, so 1e-6 flags points within ~1e-12
//                             in the multiplier's square distance, i.e. the located BP itself.
//   circle_tolerance = 1e-6:  stable := every nontrivial |mu| <= 1 + circle_tolerance. Conservative systems
//                             cannot be asymptotically stable: "stable" means linearly (neutrally) stable,
//                             all multipliers on the unit circle. Same accuracy argument as above.
//   min_transversality = 1e-8: saltation matrices with |de f~^-| below this fraction of |de||f~^-| are
//                             refused (kSaltationUndefined): 1/(de f) would amplify the ~1e-10 errors of
//                             the segment ends to O(1e-2) in Phi_T.
//
// Test functions for special points along a branch (sign changes bracket them):
//   bp_test = prod over nontrivial mu of (mu - 1)    changes sign when a real multiplier crosses +1, or
//                                                    when a reciprocal pair collides at +1 and leaves the
//                                                    unit circle (complex pair: |mu-1|^2 > 0; real pair
//                                                    (l, 1/l): -(l-1)^2/l < 0). Compare the SB points.
//   pd_test = prod over all mu of (mu + 1)            (the trivial pair contributes 2 * 2 = 4 exactly)
//                                                    changes sign when a multiplier crosses -1.
//   ns_test = prod over nontrivial pairs i < j of (mu_i mu_j - 1)   (the bialternate product: real, smooth in
//                                                    the monodromy) vanishes where a complex pair crosses
//                                                    the unit circle (Neimark–Sacker: mu mu-bar = 1) and
//                                                    where two real multipliers have product 1 (a neutral
//                                                    saddle, no bifurcation); on a symplectic map, whose
//                                                    multipliers come in pairs mu, 1/mu, it is 0 everywhere.
//   krein_test = sign of prod over pairs a < b of (rho_a - rho_b)^2 / (1 + |rho_a|^2 + |rho_b|^2) times the
//                                                    smallest factor's modulus (the product of many factors
//                                                    would underflow), rho = mu + 1/mu
//                                                    per reciprocal pair (mu, 1/mu) of a symplectic map: real
//                                                    for real rho (pairs on the unit circle, rho = 2 cos θ, or
//                                                    real pairs off it) and negative for a conjugate pair of
//                                                    rho (a quadruplet mu, 1/mu, mu-bar, 1/mu-bar off the
//                                                    circle). It changes sign where two pairs collide and
//                                                    leave as a quadruplet: a Krein collision when they
//                                                    collide on the unit circle (|rho| < 2). Two pairs of the
//                                                    same Krein signature pass through each other instead: a
//                                                    double zero, no sign change. NaN where the multipliers
//                                                    do not pair up to pair_tolerance (the map is not
//                                                    symplectic: the SLIP with its massless leg) or fewer
//                                                    than two pairs exist.
//
//   TimeBasedShooting shooting(model, IntegratorOptions{});
//   FloquetResult fl = ComputeFloquet(shooting, u);
//   if (fl.ok()) { fl.multipliers, fl.normal, fl.stable, fl.bp_test ... }
#ifndef HYBRIDCONT_FLOQUET_H_
#define HYBRIDCONT_FLOQUET_H_

#include <complex>
#include <limits>
#include <string>
#include <vector>

#include "hybridcont/timebased_shooting.h"

namespace hybridcont {

// FloquetResult::multiplier_error over the monodromy's measured defect (see "Accuracy of the multipliers").
inline constexpr double kMultiplierErrorSafety = 2;
// Beyond this error of its multipliers an orbit is not resolved by the integration at its tolerances: the
// monodromy keeps fewer than three digits, and the orbit's replay and class (a crossing found early or late
// by the amplified error) are no better. The shipped examples' orbits stay below 1e-5.
inline constexpr double kUnresolvedMultiplierError = 1e-3;

struct FloquetOptions {
  double unit_tolerance = 1e-6;      // |mu - 1| for a further unit multiplier (see the header comment)
  double circle_tolerance = 1e-6;    // |mu| <= 1 + this for linear stability
  // |mu_i mu_j - 1| below this pairs two multipliers as reciprocal (krein_test): the inverse product keeps
  // the pairs of symplectic maps at 1e-11 (the rod), a non-symplectic map misses by O(1) (the SLIP: 0.97).
  double pair_tolerance = 1e-6;
  double min_transversality = 1e-8;  // saltation refused below this crossing sine
  // The multipliers inside the unit circle from the inverse product where every factor is invertible.
  bool product_inverse = true;
  // The orbit is a located branch point (an SB point, where a switched half-branch starts): multipliers
  // collide at +1 there. A pair colliding at +1 is a Jordan block, which an error ε of Phi_T splits by
  // √ε, so its members lie ~1e-3 from 1 while the product of their distances, the factor of bp_test that
  // vanishes at the point, is at the noise level. Then the nontrivial multipliers within
  // branch_point_radius of +1 whose distances multiply to at most branch_point_product count as unit
  // multipliers (on the unit circle: neutral, not unstable).
  bool at_branch_point = false;
  double branch_point_radius = 1e-2;
  double branch_point_product = 1e-6;

  std::string Validate() const;
};

enum class FloquetStatus {
  kSuccess,
  kEvaluationFailed,     // the time-based map could not be evaluated at u (integration failure)
  kSaltationUndefined,   // de_i f~_i^- ~ 0 at a segment end: grazing or zero-duration transition
  kDegenerateOrbit,      // f(x0) = 0 or dH(x0) = 0: an equilibrium, no trivial pair to deflate
  kEigenFailed,          // Eigen's eigensolver did not converge
};
std::string ToString(FloquetStatus status);

// See the header comment. Unstable classes may combine (a saddle and a flip multiplier at once).
struct StabilityClass {
  bool asymptotically_stable = false;
  bool neutrally_stable = false;  // none outside, some on the unit circle
  // With a first integral: the class is that of the orbit on its energy level (the trivial pair, which
  // moves along the family, is left out), so an asymptotically stable orbit attracts the orbits of its
  // own energy (a non-symplectic return map, e.g. the SLIP's massless swing leg).
  bool on_level = false;
  int saddle = 0;                 // real multipliers > 1 + tolerance (not counting the trivial ones)
  int flip = 0;                   // real multipliers < −1 − tolerance
  int oscillatory = 0;            // complex pairs outside the unit circle
  // The multipliers are not known well enough to tell (see "Accuracy of the multipliers"): none lies clearly
  // outside the unit circle and one lies within its error of it. Every other field is then false or 0.
  bool undetermined = false;
  double uncertainty = 0;         // that error, where undetermined
  bool unstable() const { return saddle + flip + oscillatory > 0; }
  // "asymptotically stable", "neutrally stable", "unstable (saddle)", "unstable (flip and 2 oscillatory)",
  // "undetermined (multipliers uncertain to 3e-02)" ...: no comma, the text is a cell of the branch files' CSV.
  std::string ToString() const;
};

struct FloquetResult {
  FloquetStatus status = FloquetStatus::kSuccess;
  std::string message;
  Matrix monodromy;                // Phi_T, n1 x n1
  std::vector<Matrix> saltations;  // S_1..S_m
  // All n1 eigenvalues of Phi_T, sorted by |mu - 1| ascending (the computed trivial pair first), ties by
  // descending imaginary part. Their first two are only ~sqrt(rtol) close to 1 (Jordan block).
  std::vector<std::complex<double>> multipliers;
  // The n1 - 2 nontrivial multipliers from the deflated matrix, sorted by modulus descending, then by
  // descending imaginary part (a conjugate pair: + first).
  std::vector<std::complex<double>> nontrivial;
  // 2 (the trivial pair) + nontrivial multipliers within unit_tolerance of +1 (at a branch point: those of
  // the colliding cluster, FloquetOptions::at_branch_point)
  int num_unit = 0;
  bool normal = false;     // num_unit == 2: exactly two multipliers equal 1 (paper: normal conservative orbit)
  bool stable = false;     // all nontrivial multipliers on (or inside) the unit circle within tolerance
  // All nontrivial multipliers inside the unit circle by more than the tolerance: perturbations decay
  // (possible only without first integral; a conservative orbit is at best neutrally stable).
  bool asymptotically_stable = false;
  StabilityClass stability;
  // True where the multipliers inside the unit circle came from the inverse product (see the header).
  bool from_inverse_product = false;
  int num_trivial = 2;     // trivial multipliers deflated: 2 (with a first integral) or 1 (without)
  double max_modulus = 0;  // largest |mu| of the nontrivial multipliers (1 if there are none)
  double bp_test = 0;      // prod (mu - 1) over the nontrivial multipliers
  double pd_test = 0;      // 2^num_trivial * prod (mu + 1) over the nontrivial multipliers
  double ns_test = 1;      // prod (mu_i mu_j - 1) over pairs of nontrivial multipliers (1 with fewer than 2)
  double krein_test = std::numeric_limits<double>::quiet_NaN();  // see the header comment; NaN: not symplectic
  // rho = mu + 1/mu of each reciprocal pair (empty where the multipliers do not pair up): a Krein collision
  // is where two of them meet inside (-2, 2).
  std::vector<std::complex<double>> krein_rho;
  // A complex pair of modulus 1 within `tolerance`: what makes a zero of ns_test a Neimark–Sacker point.
  bool HasUnitComplexPair(double tolerance = 1e-6) const;
  // Two rho of krein_rho within `tolerance` of each other at |Re rho| < 2: what makes a zero of krein_test a
  // Krein collision (two pairs meeting on the unit circle), not a meeting of two real pairs off it.
  bool HasKreinCollision(double tolerance) const;
  // Residuals of the theory on this orbit (|Phi_T f - f| / |f|, |dH Phi_T - dH| / |dH|): ~integration
  // error on a periodic orbit; large values mean u is not a periodic orbit at xi = 0.
  double flow_residual = 0;
  double first_integral_residual = 0;
  // The estimated absolute error of the nontrivial multipliers (see "Accuracy of the multipliers"); 0 where
  // there are none.
  double multiplier_error = 0;

  bool ok() const { return status == FloquetStatus::kSuccess; }
  std::string BriefReport() const;
};

// Monodromy and multipliers at a time-based point u. Evaluates shooting once with its Jacobian (the
// segment Phi_i are read from it); x0 = x̄_1, xi from u (multipliers are meaningful for xi = 0).
FloquetResult ComputeFloquet(TimeBasedShooting& shooting, const Vector& u, const FloquetOptions& options = {});

// The analysis part alone, for a monodromy from elsewhere (e.g. the state-based map's Phi(t^A, x0)):
// f0 = f(x0), dH0 = dH_1(x0). inverse: Phi_T^{-1} formed from inverted factors, or null.
FloquetResult AnalyzeMonodromy(const Matrix& monodromy, const Vector& f0, const RowVector& dH0,
                               const FloquetOptions& options = {}, const Matrix* inverse = nullptr);

// The eigenvalues of a real square matrix (Eigen's EigenSolver, without eigenvectors), instantiated once in
// the library: a caller that needs only the spectrum of a small matrix need not compile the solver again.
// Empty when the iteration fails.
Eigen::VectorXcd Eigenvalues(const Matrix& a);

}  // namespace hybridcont

#endif  // HYBRIDCONT_FLOQUET_H_
