// Bouncing rod (paper eq. `HDSrod`): two flight phases separated by impacts of the left and right ends;
// anchor at the apex (dy = 0).
#include <cmath>

#include "hybridcont/models.h"

namespace hybridcont {
namespace {

struct RodParameters {
  double m = 1.0;   // mass
  double l0 = 1.0;  // length
  double g = 1.0;   // gravity
  double r = 0.01;  // radius of gyration
};

// Flight until the end on side `kSide` (-1: left, +1: right) hits the ground.
template <int kSide>
struct RodFlight {
  template <class T>
  static StateVector<T> VectorField(const StateVector<T>& x, const RodParameters& p) {
    StateVector<T> f(4);
    f << x(2), x(3), T(-p.g), T(0.0);
    return f;
  }
  template <class T>
  static T FirstIntegral(const StateVector<T>& x, const RodParameters& p) {
    return 0.5 * p.m * (x(2) * x(2) + p.r * p.r * x(3) * x(3)) + p.m * p.g * x(0);
  }
  template <class T>
  static T Event(const StateVector<T>& x, const RodParameters& p) {
    using std::sin;
    return x(0) + kSide * 0.5 * p.l0 * sin(x(1));  // height of that end
  }
  template <class T>
  static StateVector<T> Reset(const StateVector<T>& x, const RodParameters& p) {
    using std::cos;
    const T c = cos(x(1));
    const T scale = 4.0 / (p.l0 * p.l0 * c * c + 4.0 * p.r * p.r);
    StateVector<T> y = x;
    y(2) -= scale * (2.0 * p.r * p.r * x(2) + kSide * p.l0 * p.r * p.r * c * x(3));
    y(3) -= scale * (0.5 * p.l0 * p.l0 * c * c * x(3) + kSide * p.l0 * c * x(2));
    return y;
  }
};

struct Apex {
  template <class T>
  static T Anchor(const StateVector<T>& x, const RodParameters&) {
    return x(2);
  }
};

}  // namespace

HybridModel MakeBouncingRod() {
  ModelBuilder<RodParameters> b("bouncing-rod", "rod bouncing on its two ends (paper §4.3)");
  b.Parameter("m", &RodParameters::m, "mass")
      .Parameter("l0", &RodParameters::l0, "length")
      .Parameter("g", &RodParameters::g, "gravity")
      .Parameter("r", &RodParameters::r, "radius of gyration");
  Vector typical(4);
  typical << 0.3, 0.2, 0.1, 1.0;
  const std::vector<std::string> states = {"y", "alpha", "dy", "dalpha"};
  b.AddPhase<RodFlight<-1>>("left-impact", states, typical);
  b.AddPhase<RodFlight<+1>>("right-impact", states, typical);
  b.SetAnchor<Apex>();
  // Time reversal (velocities flip; the impact law is linear in them). The mirror alpha -> -alpha swaps
  // the two impact phases, which a sign change per phase cannot express.
  Vector reverse(4);
  reverse << 1, 1, -1, -1;
  b.Symmetry("time-reversal", {reverse, reverse}, true);
  return b.Build();
}

}  // namespace hybridcont
