// Locating where a scalar test function changes sign between two consecutive points of a branch.
//
// Used for special points defined by quantities the continuation does not track itself, e.g. Floquet
// multipliers crossing +1 (BP) or -1 (PD) (floquet.h). Between branch points u_a and u_b the branch is
// parametrized by sigma in [0, 1]: the predictor (1 - sigma) u_a + sigma u_b is corrected onto the curve in
// the hyperplane through it orthogonal to the chord (pseudo-arclength), and the test function is evaluated
// there. Illinois (regula falsi with halving) narrows the bracket in sigma.
//
//   TestFunctionRoot root = LocateTestFunctionRoot(&shooting, u_a, u_b, [&](const Vector& u) {
//     return ComputeFloquet(shooting, u).bp_test; }, TestFunctionRootOptions{});
//   if (root.located) ... root.u, root.precision (bracket width along the chord, in units of u)
#ifndef HYBRIDCONT_TEST_FUNCTION_ROOT_H_
#define HYBRIDCONT_TEST_FUNCTION_ROOT_H_

#include <array>
#include <functional>
#include <optional>
#include <string>

#include "hybridcont/zero_problem.h"

namespace hybridcont {

struct TestFunctionRootOptions {
  // Bracket width in sigma at which the root counts as located: with chords of O(0.1), 1e-11 gives
  // components to ~1e-12.
  double sigma_tolerance = 1e-11;
  // Illinois converges superlinearly; the budget covers the bisection fallback too.
  int max_iterations = 60;
  // The test function evaluated with the problem's more accurate copy (ZeroProblem::Refined, factor
  // ContinuationOptions::kIntegrationErrorFactor). When set and the problem has one, the located root's
  // error is estimated as for the continuation's special points (special_point.h, "Integration error"):
  // the estimate is corrected onto the refined curve (on its hyperplane ⟂ the chord), the test evaluated
  // there, and twice the implied error along and off the branch widens `precision` where that exceeds
  // the bracket.
  std::function<double(ZeroProblem& refined, const Vector& u)> refined_test;
};

struct TestFunctionRoot {
  bool located = false;  // bracket narrower than the tolerance; otherwise only bracketed
  Vector u;              // best estimate (corrected onto the curve)
  double sigma = 0;      // position along the chord
  // Width of the final bracket along the chord, in units of u, or of the interval the integration error
  // allows (TestFunctionRootOptions::refined_test) where that is wider.
  double precision = 0;
  int iterations = 0;
  std::string message;   // why only bracketed
};

// u_a and u_b have num_unknowns() entries (an invariant); test(u_a) and test(u_b) must differ in sign
// (else located = false with a message).
TestFunctionRoot LocateTestFunctionRoot(ZeroProblem* problem, const Vector& u_a, const Vector& u_b,
                                        const std::function<double(const Vector&)>& test,
                                        const TestFunctionRootOptions& options);

// Two roots between samples: a smooth test function sampled at three consecutive points of a branch
// with one sign and its smallest |value| in the middle may dip through zero and back between them (two
// crossings inside one continuation step cancel in the signs; docs/design/continuation.md, "Two roots
// between samples"). The parabola through the samples (in arclength s) predicts the dip; when
// its extremum has the other sign the test is evaluated on the curve there (one corrector solve on the
// chord of the sample interval that holds it). A value of the other sign confirms two roots, bracketed
// by [u_k, probe] and [probe, u_k+1] around it (`segment` = k, 0 or 1).
struct HiddenRootPair {
  bool found = false;
  Vector u;          // the probe on the curve (valid when found)
  double value = 0;  // the test there
  int segment = -1;  // the probe lies between samples segment and segment + 1
};
// The extremum of the parabola through (s_k, g_k), k = 0, 1, 2, when it has the opposite sign of g_1 and
// lies strictly between s_0 and s_2; nullopt otherwise (also when the samples are not a local minimum of
// |g| of one sign).
std::optional<double> ParabolaDipThroughZero(const std::array<double, 3>& s, const std::array<double, 3>& g);
HiddenRootPair FindHiddenRootPair(ZeroProblem* problem, const std::array<const Vector*, 3>& u,
                                  const std::array<double, 3>& s, const std::array<double, 3>& g,
                                  const std::function<double(const Vector&)>& test);

}  // namespace hybridcont

#endif  // HYBRIDCONT_TEST_FUNCTION_ROOT_H_
