// Saltation matrices: how perturbations cross a discrete transition (paper §2.2, eq. `Saltation`;
// Appendix A derives it, Appendix B gives the variant for an anchor at the last event).
//
// At an event of phase i, with x^- the pre-event state, x^+ = Delta_i(x^-) the post-event state,
// f^- = f~_i(x^-), f^+ = f~_{i+1}(x^+), D = dDelta_i(x^-) and de = de_i(x^-):
//
//                 (f^+ - D f^-) de                      eq. `Saltation`: perturbations at equal
//     S  =  D  +  ----------------                       *global time* before and after the event
//                     de f^-
//
//                 (     f^- de  )                       eq. `LastSaltation` (Appendix B): the
//     S~ =  D     ( I - ------- )                        event-to-event map, no time shift after it
//                 (     de f^-  )
//
// S maps f^- to f^+ (the flow to the flow) and satisfies dH_i(x^-) = dH_{i+1}(x^+) S for first
// integrals (proof of Lemma `theoremHybrid`); S~ annihilates f^-. Both divide by de·f^- = g_dot, the
// transversality of the crossing (assumption As2): at a grazing point they do not exist, and the
// functions here return kDegenerate instead of a matrix of Infs.
//
// The hybrid fundamental matrix (eq. `fundamentalMatrixHybrid`) chains them with the phase Phi_i:
//     Phi(t, x0) = Phi_1(t - t^E, x̄_{m+1}) S_m Phi_m ... S_1 Phi_1.
//
//   Matrix S;
//   if (Saltation(D, f_minus, f_plus, de, &S) == SaltationStatus::kSuccess) Phi_bar = S * Phi_i * Phi_bar;
#ifndef HYBRIDCONT_SALTATION_H_
#define HYBRIDCONT_SALTATION_H_

#include <string>

#include "hybridcont/types.h"

namespace hybridcont {

enum class SaltationStatus {
  kSuccess,
  kDegenerate,  // |de f^-| <= min_transversality |de| |f^-|: grazing, the saltation matrix is undefined
};
std::string ToString(SaltationStatus status);

// Default lower bound on |de f^-| / (|de| |f^-|) (the sine of the crossing angle). Below 1e-12 the
// division turns round-off of the pre-event state (~1e-16 relative) into O(1e-4) errors of S.
inline constexpr double kDefaultMinTransversality = 1e-12;

// eq. `Saltation`. D: n_{i+1} x n_i, f_minus: n_i, f_plus: n_{i+1}, de: 1 x n_i. *S is resized.
SaltationStatus Saltation(const Matrix& D, const Vector& f_minus, const Vector& f_plus, const RowVector& de,
                          Matrix* S, double min_transversality = kDefaultMinTransversality);

// eq. `LastSaltation` (Appendix B): S~ = D (I - f^- de / (de f^-)).
SaltationStatus LastSaltation(const Matrix& D, const Vector& f_minus, const RowVector& de, Matrix* S,
                              double min_transversality = kDefaultMinTransversality);

// The section projection of eq. `PoincareJacobian`: I - f da / (da f) (it removes the time direction f
// from a perturbation so that it stays on the section a = 0). Same degeneracy rule.
SaltationStatus SectionProjection(const Vector& f, const RowVector& da, Matrix* Pi,
                                  double min_transversality = kDefaultMinTransversality);

}  // namespace hybridcont

#endif  // HYBRIDCONT_SALTATION_H_
