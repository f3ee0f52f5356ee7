// Event location when the guard oscillates within one integrator step: a spinning rod's flight is a
// polynomial the integrator crosses in a few long steps, while its end height y - l0/2 sin(alpha) dips
// many times. The first downward crossing must still be found (the replay of the rod's orbits).
#include <gtest/gtest.h>

#include <cmath>

#include "hybridcont/event_flow.h"
#include "hybridcont/models.h"

namespace hybridcont {
namespace {

TEST(EventFlowFastGuard, FirstCrossingOfASpinningRodEndMatchesABruteForceSearch) {
  const HybridModel rod = MakeBouncingRod();
  const Phase& left = rod.phase(0);  // event: left end height y - 0.5 sin(alpha)
  Vector x0(4);
  x0 << 0.52, 0.0, 0.3, 100.0;  // spinning at 100 rad per unit time, centre rising
  // closed form: y = 0.52 + 0.3 t - t^2/2, alpha = 100 t; first t > 0 with y - 0.5 sin(alpha) = 0, downward
  const auto g = [](double t) { return 0.52 + 0.3 * t - 0.5 * t * t - 0.5 * std::sin(100.0 * t); };
  double t_exact = 0.0;
  for (double t = 1e-6;; t += 1e-6) {
    if (g(t) <= 0.0) {
      double a = t - 1e-6, b = t;  // bisection to machine precision
      for (int i = 0; i < 60; ++i) {
        const double c = 0.5 * (a + b);
        (g(c) > 0.0 ? a : b) = c;
      }
      t_exact = 0.5 * (a + b);
      break;
    }
  }
  EventFlow flow(left, EventFlowOptions{});
  EventFlowResult result;
  flow.Integrate(x0, Vector::Zero(1), PhaseEventGuard(left), false, &result);
  ASSERT_EQ(result.status, EventFlowStatus::kEventReached) << result.message;
  EXPECT_NEAR(result.t, t_exact, 1e-10);
  // The end swings down to the ground ~11 times before (min of g ~ 0.02 at first) and touches it first
  // during a later swing: the crossing sits inside a long integrator step among many oscillations.
  EXPECT_GT(t_exact * 100.0 / (2.0 * M_PI), 10.0);
}

}  // namespace
}  // namespace hybridcont
