#include "hybridcont/test_function_root.h"

#include <cmath>
#include <cstdio>
#include <memory>

#include "hybridcont/continuation.h"
#include "hybridcont/corrector.h"
#include "hybridcont/invariant.h"

namespace hybridcont {
namespace {

// TestFunctionRootOptions::refined_test, with the factor and scale of the continuation's special points
// (ContinuationOptions::kIntegrationErrorScale).
void AddIntegrationError(ZeroProblem* problem, const Vector& chord, double slope, double value,
                         const std::function<double(ZeroProblem&, const Vector&)>& refined_test,
                         TestFunctionRoot* root) {
  constexpr double kFactor = ContinuationOptions::kIntegrationErrorFactor;
  const std::unique_ptr<ZeroProblem> refined = problem->Refined(kFactor);
  if (refined == nullptr || !(slope != 0)) return;
  Corrector corrector(refined.get());
  Vector u;
  const bool corrected = corrector.CorrectPseudoArclength(root->u, chord, &u).converged();
  const double refined_value = corrected ? refined_test(*refined, u) : std::nan("");
  problem->AddWorkOf(*refined);
  if (!std::isfinite(refined_value)) return;
  const double along = std::abs(refined_value - value) / std::abs(slope);
  const double off = (u - root->u).norm();
  const double reach = ContinuationOptions::kIntegrationErrorScale * (along + off);
  if (2 * reach <= root->precision) return;
  char text[256];
  std::snprintf(text, sizeof(text),
                "integration error: at %gx the tolerances the point moves by %.2g and the test by %.2g "
                "(slope %.2g): precision %.2g (twice the estimate; the bracket was %.2g)",
                kFactor, off, std::abs(refined_value - value), std::abs(slope), 2 * reach, root->precision);
  root->precision = 2 * reach;
  if (!root->message.empty()) root->message += "; ";
  root->message += text;
}

}  // namespace

TestFunctionRoot LocateTestFunctionRoot(ZeroProblem* problem, const Vector& u_a, const Vector& u_b,
                                        const std::function<double(const Vector&)>& test,
                                        const TestFunctionRootOptions& options) {
  HYBRIDCONT_DEMAND(u_a.size() == problem->num_unknowns() && u_b.size() == u_a.size());
  TestFunctionRoot root;
  const Vector chord = u_b - u_a;
  Corrector corrector(problem);
  double lo = 0.0, hi = 1.0;
  double f_lo = test(u_a), f_hi = test(u_b);
  double slope = (f_hi - f_lo) / chord.norm();  // the test's secant slope per unit of u
  double g_lo = f_lo, g_hi = f_hi;              // the test at the bracket ends (f_*: Illinois-halved)
  root.u = std::abs(f_lo) < std::abs(f_hi) ? u_a : u_b;
  double value = std::abs(f_lo) < std::abs(f_hi) ? f_lo : f_hi;  // the test at root.u
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
    value = f;
    if (f == 0.0) {
      // Exactly on the root: the slope from the bracket just before, as below.
      for (const auto& [end, end_value] : {std::pair{lo, g_lo}, std::pair{hi, g_hi}}) {
        const double local = end_value / ((end - sigma) * chord.norm());
        if (end != sigma && std::abs(local) < std::abs(slope)) slope = local;
      }
      lo = hi = sigma;
      break;
    }
    if ((f < 0.0) == (f_lo < 0.0)) {
      lo = sigma, f_lo = g_lo = f;
      if (side == -1) f_hi *= 0.5;
      side = -1;
    } else {
      hi = sigma, f_hi = g_hi = f;
      if (side == +1) f_lo *= 0.5;
      side = +1;
    }
  }
  root.precision = (hi - lo) * chord.norm();
  root.located = hi - lo <= options.sigma_tolerance;
  if (!root.located && root.message.empty()) root.message = "iteration budget exhausted";
  // The flatter of the secants over the chord and over the final bracket (as RootLocation::slope).
  if (hi > lo) {
    const double local = (g_hi - g_lo) / ((hi - lo) * chord.norm());
    if (std::abs(local) < std::abs(slope)) slope = local;
  }
  if (options.refined_test) AddIntegrationError(problem, chord, slope, value, options.refined_test, &root);
  return root;
}

std::optional<double> ParabolaDipThroughZero(const std::array<double, 3>& s, const std::array<double, 3>& g) {
  const bool one_sign = (g[0] > 0 && g[1] > 0 && g[2] > 0) || (g[0] < 0 && g[1] < 0 && g[2] < 0);
  if (!one_sign || !(std::abs(g[1]) < std::abs(g[0]) && std::abs(g[1]) <= std::abs(g[2]))) return std::nullopt;
  if (!(s[0] < s[1] && s[1] < s[2])) return std::nullopt;
  // Newton's divided differences: p(x) = g0 + d01 (x − s0) + d012 (x − s0)(x − s1).
  const double d01 = (g[1] - g[0]) / (s[1] - s[0]);
  const double d12 = (g[2] - g[1]) / (s[2] - s[1]);
  const double d012 = (d12 - d01) / (s[2] - s[0]);
  if (d012 == 0) return std::nullopt;
  const double x = 0.5 * (s[0] + s[1]) - d01 / (2 * d012);  // p'(x) = 0
  if (!(x > s[0] && x < s[2])) return std::nullopt;
  const double extremum = g[0] + d01 * (x - s[0]) + d012 * (x - s[0]) * (x - s[1]);
  if (!(extremum != 0 && std::signbit(extremum) != std::signbit(g[1]))) return std::nullopt;
  return x;
}

HiddenRootPair FindHiddenRootPair(ZeroProblem* problem, const std::array<const Vector*, 3>& u,
                                  const std::array<double, 3>& s, const std::array<double, 3>& g,
                                  const std::function<double(const Vector&)>& test) {
  HYBRIDCONT_DEMAND(u[0] != nullptr && u[1] != nullptr && u[2] != nullptr);
  HiddenRootPair pair;
  const std::optional<double> x = ParabolaDipThroughZero(s, g);
  if (!x) return pair;
  const int k = *x < s[1] ? 0 : 1;
  const Vector chord = *u[k + 1] - *u[k];
  // Predictor: the quadratic interpolant of the three samples in s (the chord point lies off a curved
  // branch by ~|chord|²·curvature); corrected on the hyperplane ⟂ chord through it, within a quarter of
  // the chord: a probe that Newton takes to a neighbouring branch (whose test may have the other sign)
  // must not confirm a pair.
  Vector predictor = Vector::Zero(chord.size());
  for (int i = 0; i < 3; ++i) {
    double weight = 1;
    for (int j = 0; j < 3; ++j) {
      if (j != i) weight *= (*x - s[j]) / (s[i] - s[j]);
    }
    predictor += weight * *u[i];
  }
  CorrectorOptions options;
  options.max_distance = 0.25 * chord.norm();
  Corrector corrector(problem, options);
  Vector probe;
  if (!corrector.CorrectPseudoArclength(predictor, chord, &probe).converged()) return pair;
  const double value = test(probe);
  if (!(std::isfinite(value) && value != 0 && std::signbit(value) != std::signbit(g[1]))) return pair;
  pair.found = true;
  pair.u = std::move(probe);
  pair.value = value;
  pair.segment = k;
  return pair;
}

}  // namespace hybridcont
