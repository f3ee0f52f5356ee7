// Closed-form periodic orbits of the built-in models, in the time-based layout, and a bisection along them
// (shared by tests).
#ifndef HYBRIDCONT_TESTS_KNOWN_ORBITS_H_
#define HYBRIDCONT_TESTS_KNOWN_ORBITS_H_

#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "hybridcont/model.h"
#include "hybridcont/shooting_layout.h"

namespace hybridcont {

// The analytic bouncing-ball orbit at level H (m = g = 1): apex height H, fall and rise times sqrt(2H).
inline Vector BallOrbit(const ShootingLayout& layout, double H) {
  Vector u = Vector::Zero(layout.num_unknowns());
  const double t = std::sqrt(2.0 * H);
  u(layout.time_index(0)) = t;                 // t1: apex -> impact
  u(layout.state_offset(0)) = H;               // x1 = [H, 0]
  u(layout.time_index(1)) = t;                 // t2: impact -> apex
  u(layout.state_offset(1) + 1) = std::sqrt(2.0 * H);  // x2 = [0, +v]
  u(layout.H_index()) = H;
  return u;
}

// SLIP hopping in place (alpha = 0): harmonic stance about l_eq = l0 - mg/k from the nadir l_min,
// ballistic flight. H = m g l_min + k (l_min - l0)^2 / 2 fixes l_min.
inline Vector SlipHoppingInPlace(const HybridModel& slip, const ShootingLayout& layout, double H) {
  const double m = slip.parameter("m"), g = slip.parameter("g"), k = slip.parameter("k"), l0 = slip.parameter("l0");
  // k/2 (l - l0)^2 + m g l - H = 0, smaller root
  const double a = 0.5 * k, b = m * g - k * l0, c = 0.5 * k * l0 * l0 - H;
  const double l_min = (-b - std::sqrt(b * b - 4 * a * c)) / (2 * a);
  const double w = std::sqrt(k / m);
  const double amplitude = (l0 - m * g / k) - l_min;
  const double t_stance = std::acos(-(m * g / k) / amplitude) / w;
  const double dl_takeoff = amplitude * w * std::sin(w * t_stance);
  Vector u = Vector::Zero(layout.num_unknowns());
  u(layout.time_index(0)) = t_stance;
  u(layout.state_offset(0) + 1) = l_min;
  u(layout.time_index(1)) = 2.0 * dl_takeoff / g;
  u(layout.state_offset(1) + 0) = l0;          // y
  u(layout.state_offset(1) + 3) = dl_takeoff;  // dy
  u(layout.time_index(2)) = t_stance;
  u(layout.state_offset(2) + 1) = l0;
  u(layout.state_offset(2) + 3) = -dl_takeoff;
  u(layout.H_index()) = H;
  return u;
}

// Bisection to 1e-13 on the sign of test(H), e.g. a Floquet test function along closed-form orbits.
inline double Bisect(const std::function<double(double)>& test, double a, double b) {
  const double fa = test(a);
  EXPECT_LT(fa * test(b), 0.0) << "no sign change in [" << a << ", " << b << "]";
  double lo = a, hi = b;
  while (hi - lo > 1e-13) {
    const double mid = 0.5 * (lo + hi);
    ((test(mid) < 0.0) == (fa < 0.0) ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace hybridcont

#endif  // HYBRIDCONT_TESTS_KNOWN_ORBITS_H_
