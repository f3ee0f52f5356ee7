// Rocking block (paper eq. `HDSblock`): pivoting about the left corner, the symmetric motion about the
// right corner folded onto it; impact at alpha = 0, anchor at dalpha = 0.
#include <cmath>

#include "hybridcont/models.h"

namespace hybridcont {
namespace {

struct BlockParameters {
  double m = 1.0;     // mass
  double l0 = 1.0;    // half diagonal
  double g = 1.0;     // gravity
  double beta = 0.3;  // slenderness [rad]
};

struct Rocking {
  template <class T>
  static StateVector<T> VectorField(const StateVector<T>& x, const BlockParameters& p) {
    using std::sin;
    StateVector<T> f(2);
    f << x(1), -(3.0 * p.g / (4.0 * p.l0)) * sin(p.beta - x(0));
    return f;
  }
  template <class T>
  static T FirstIntegral(const StateVector<T>& x, const BlockParameters& p) {
    using std::cos;
    return (2.0 / 3.0) * p.m * p.l0 * p.l0 * x(1) * x(1) + (cos(x(0) - p.beta) - std::cos(p.beta)) * p.m * p.l0 * p.g;
  }
  template <class T>
  static T Event(const StateVector<T>& x, const BlockParameters&) {
    return x(0);
  }
  template <class T>
  static StateVector<T> Reset(const StateVector<T>& x, const BlockParameters&) {
    StateVector<T> y(2);
    y << x(0), -x(1);
    return y;
  }
};

struct TurningPoint {
  template <class T>
  static T Anchor(const StateVector<T>& x, const BlockParameters&) {
    return x(1);
  }
};

}  // namespace

HybridModel MakeRockingBlock() {
  ModelBuilder<BlockParameters> b("rocking-block", "rectangular block rocking on its corners (paper §4.2)");
  b.Parameter("m", &BlockParameters::m, "mass")
      .Parameter("l0", &BlockParameters::l0, "half diagonal")
      .Parameter("g", &BlockParameters::g, "gravity")
      .Parameter("beta", &BlockParameters::beta, "slenderness angle [rad]");
  Vector typical(2);
  typical << 0.1, 0.2;
  b.AddPhase<Rocking>("rocking", {"alpha", "dalpha"}, typical);
  b.SetAnchor<TurningPoint>();
  b.Symmetry("time-reversal", {Vector(Eigen::Vector2d(1, -1))}, true);  // the impact law is linear in dalpha
  return b.Build();
}

}  // namespace hybridcont
