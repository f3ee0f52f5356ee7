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

#include <functional>
#include <string>

#include "hybridcont/zero_problem.h"

namespace hybridcont {

struct TestFunctionRootOptions {
  // Bracket width in sigma at which the root counts as located: with chords of O(0.1), 1e-11 gives
  // components to ~1e-12.
  double sigma_tolerance = 1e-11;
  // Illinois converges superlinearly; the budget covers the bisection fallback too.
  int max_iterations = 60;
};

struct TestFunctionRoot {
  bool located = false;  // bracket narrower than the tolerance; otherwise only bracketed
  Vector u;              // best estimate (corrected onto the curve)
  double sigma = 0;      // position along the chord
  double precision = 0;  // width of the final bracket along the chord, in units of u
  int iterations = 0;
  std::string message;   // why only bracketed
};

// test(u_a) and test(u_b) must differ in sign (else located = false with a message).
TestFunctionRoot LocateTestFunctionRoot(ZeroProblem* problem, const Vector& u_a, const Vector& u_b,
                                        const std::function<double(const Vector&)>& test,
                                        const TestFunctionRootOptions& options);

}  // namespace hybridcont

#endif  // HYBRIDCONT_TEST_FUNCTION_ROOT_H_
