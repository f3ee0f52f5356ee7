#include "hybridcont/test_function_root.h"

#include <cmath>

#include "hybridcont/corrector.h"

namespace hybridcont {

TestFunctionRoot LocateTestFunctionRoot(ZeroProblem* problem, const Vector& u_a, const Vector& u_b,
                                        const std::function<double(const Vector&)>& test,
                                        const TestFunctionRootOptions& options) {
  TestFunctionRoot root;
  const Vector chord = u_b - u_a;
  Corrector corrector(problem);
  double lo = 0.0, hi = 1.0;
  double f_lo = test(u_a), f_hi = test(u_b);
  root.u = std::abs(f_lo) < std::abs(f_hi) ? u_a : u_b;
  if (!(f_lo * f_hi < 0.0)) {
    root.message = "no sign change between the two points";
    return root;
  }
  int side = 0;  // Illinois: which end was kept last time
  for (root.iterations = 0; root.iterations < options.max_iterations; ++root.iterations) {
    if (hi - lo <= options.sigma_tolerance) break;
    double sigma = (lo * f_hi - hi * f_lo) / (f_hi - f_lo);
    if (!(sigma > lo && sigma < hi)) sigma = 0.5 * (lo + hi);
    Vector u;
    const CorrectorResult c = corrector.CorrectPseudoArclength(u_a + sigma * chord, chord, &u);
    if (!c.converged()) {
      root.message = "trial point not corrected: " + c.message;
      break;
    }
    const double f = test(u);
    if (!std::isfinite(f)) {
      root.message = "test function not finite at a trial point";
      break;
    }
    root.u = u;
    root.sigma = sigma;
    if (f == 0.0) {
      lo = hi = sigma;
      break;
    }
    if ((f < 0.0) == (f_lo < 0.0)) {
      lo = sigma, f_lo = f;
      if (side == -1) f_hi *= 0.5;
      side = -1;
    } else {
      hi = sigma, f_hi = f;
      if (side == +1) f_lo *= 0.5;
      side = +1;
    }
  }
  root.precision = (hi - lo) * chord.norm();
  root.located = hi - lo <= options.sigma_tolerance;
  if (!root.located && root.message.empty()) root.message = "iteration budget exhausted";
  return root;
}

}  // namespace hybridcont
