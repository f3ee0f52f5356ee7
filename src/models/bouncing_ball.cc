// Bouncing ball (paper eq. `HDSball`): one flight phase, impact at y = 0, anchor at the apex (dy = 0).
#include "hybridcont/models.h"

namespace hybridcont {
namespace {

struct BallParameters {
  double m = 1.0;  // mass
  double g = 1.0;  // gravity
};

struct Flight {
  template <class T>
  static StateVector<T> VectorField(const StateVector<T>& x, const BallParameters& p) {
    StateVector<T> f(2);
    f << x(1), T(-p.g);
    return f;
  }
  template <class T>
  static T FirstIntegral(const StateVector<T>& x, const BallParameters& p) {
    return 0.5 * p.m * x(1) * x(1) + p.m * p.g * x(0);
  }
  template <class T>
  static T Event(const StateVector<T>& x, const BallParameters&) {
    return x(0);  // ground contact
  }
  template <class T>
  static StateVector<T> Reset(const StateVector<T>& x, const BallParameters&) {
    StateVector<T> y(2);
    y << x(0), -x(1);  // elastic impact
    return y;
  }
};

struct Apex {
  template <class T>
  static T Anchor(const StateVector<T>& x, const BallParameters&) {
    return x(1);
  }
};

}  // namespace

HybridModel MakeBouncingBall() {
  ModelBuilder<BallParameters> b("bouncing-ball", "ball bouncing elastically on the ground (paper §4.1)");
  b.Parameter("m", &BallParameters::m, "mass").Parameter("g", &BallParameters::g, "gravity");
  Vector typical(2);
  typical << 0.5, 0.3;
  b.AddPhase<Flight>("flight", {"y", "dy"}, typical);
  b.SetAnchor<Apex>();
  return b.Build();
}

}  // namespace hybridcont
