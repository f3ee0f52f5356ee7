// SLIP hopper with swing leg (paper eq. `HDSslip`): stance (alpha, l, dalpha, dl) -> flight
// (y, alpha, dx, dy, dalpha) -> stance; anchor at nadir (a = -dl).
#include <cmath>

#include "hybridcont/models.h"

namespace hybridcont {
namespace {

struct SlipParameters {
  double m = 1.0;   // point mass
  double l0 = 1.0;  // natural leg length
  double g = 1.0;   // gravity
  double k = 40.0;  // leg stiffness
  double w2 = 5.0;  // squared swing frequency of the leg in flight
};

struct Stance {
  template <class T>
  static StateVector<T> VectorField(const StateVector<T>& x, const SlipParameters& p) {
    using std::cos;
    using std::sin;
    const T& a = x(0);
    const T& l = x(1);
    const T& da = x(2);
    const T& dl = x(3);
    StateVector<T> f(4);
    f << da, dl, -2.0 * da * dl / l + p.g / l * sin(a), l * da * da - p.g * cos(a) - p.k / p.m * (l - p.l0);
    return f;
  }
  template <class T>
  static T FirstIntegral(const StateVector<T>& x, const SlipParameters& p) {
    using std::cos;
    const T& l = x(1);
    return 0.5 * p.m * (x(2) * x(2) * l * l + x(3) * x(3)) + p.m * p.g * cos(x(0)) * l +
           0.5 * p.k * (l - p.l0) * (l - p.l0);
  }
  template <class T>
  static T Event(const StateVector<T>& x, const SlipParameters& p) {
    return p.l0 - x(1);  // lift-off at natural length
  }
  template <class T>
  static StateVector<T> Reset(const StateVector<T>& x, const SlipParameters&) {
    using std::cos;
    using std::sin;
    const T& a = x(0);
    const T& l = x(1);
    const T& da = x(2);
    const T& dl = x(3);
    StateVector<T> y(5);
    y << l * cos(a), a, -dl * sin(a) - da * l * cos(a), dl * cos(a) - da * l * sin(a), da;
    return y;
  }
};

struct Flight {
  template <class T>
  static StateVector<T> VectorField(const StateVector<T>& x, const SlipParameters& p) {
    StateVector<T> f(5);
    f << x(3), x(4), T(0.0), T(-p.g), -x(1) * p.w2;
    return f;
  }
  template <class T>
  static T FirstIntegral(const StateVector<T>& x, const SlipParameters& p) {
    return 0.5 * p.m * (x(2) * x(2) + x(3) * x(3)) + p.m * p.g * x(0);
  }
  template <class T>
  static T Event(const StateVector<T>& x, const SlipParameters& p) {
    using std::cos;
    return x(0) - p.l0 * cos(x(1));  // touch-down
  }
  template <class T>
  static StateVector<T> Reset(const StateVector<T>& x, const SlipParameters& p) {
    using std::cos;
    using std::sin;
    const T& a = x(1);
    StateVector<T> y(4);
    y << a, T(p.l0), -(cos(a) * x(2) + sin(a) * x(3)) / p.l0, cos(a) * x(3) - sin(a) * x(2);
    return y;
  }
};

struct Nadir {
  template <class T>
  static T Anchor(const StateVector<T>& x, const SlipParameters&) {
    return -x(3);
  }
};

}  // namespace

HybridModel MakeSlip() {
  ModelBuilder<SlipParameters> b("slip", "spring-loaded inverted pendulum hopper with swing leg (paper §4.4)");
  b.Parameter("m", &SlipParameters::m, "point mass")
      .Parameter("l0", &SlipParameters::l0, "natural leg length")
      .Parameter("g", &SlipParameters::g, "gravity")
      .Parameter("k", &SlipParameters::k, "leg stiffness")
      .Parameter("w2", &SlipParameters::w2, "squared swing frequency omega^2 of the leg in flight");
  Vector stance(4), flight(5);
  stance << 0.1, 0.9, 0.3, -0.4;
  flight << 0.95, 0.1, 0.3, 0.5, -0.2;
  b.AddPhase<Stance>("stance", {"alpha", "l", "dalpha", "dl"}, stance);
  b.AddPhase<Flight>("flight", {"y", "alpha", "dx", "dy", "dalpha"}, flight);
  b.SetAnchor<Nadir>();
  // x -> -x (forward/backward hopping) and time reversal (velocities flip).
  Vector mirror_stance(4), mirror_flight(5), reverse_stance(4), reverse_flight(5);
  mirror_stance << -1, 1, -1, 1;
  mirror_flight << 1, -1, -1, 1, -1;
  reverse_stance << 1, 1, -1, -1;
  reverse_flight << 1, 1, -1, -1, -1;
  b.Symmetry("mirror", {mirror_stance, mirror_flight}, false);
  b.Symmetry("time-reversal", {reverse_stance, reverse_flight}, true);
  return b.Build();
}

}  // namespace hybridcont
