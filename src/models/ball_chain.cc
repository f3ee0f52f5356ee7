// A scalable test model: a ball that bounces m times per period, written with m identical flight phases
// (phase i ends at the i-th impact). Its multiple-shooting Jacobian is block-cyclic with m + 1 blocks; it
// measures how the cost of a Newton step grows with the number of phases (issue 6).
#include <cmath>
#include <stdexcept>

#include "hybridcont/models.h"
#include "hybridcont/shooting_layout.h"

namespace hybridcont {
namespace {

struct ChainParameters {
  double m = 1.0;  // mass
  double g = 1.0;  // gravity
};

struct Flight {
  template <class T>
  static StateVector<T> VectorField(const StateVector<T>& x, const ChainParameters& p) {
    StateVector<T> f(2);
    f << x(1), T(-p.g);
    return f;
  }
  template <class T>
  static T FirstIntegral(const StateVector<T>& x, const ChainParameters& p) {
    return 0.5 * p.m * x(1) * x(1) + p.m * p.g * x(0);
  }
  template <class T>
  static T Event(const StateVector<T>& x, const ChainParameters&) {
    return x(0);
  }
  template <class T>
  static StateVector<T> Reset(const StateVector<T>& x, const ChainParameters&) {
    StateVector<T> y(2);
    y << x(0), -x(1);
    return y;
  }
};

struct Apex {
  template <class T>
  static T Anchor(const StateVector<T>& x, const ChainParameters&) {
    return x(1);
  }
};

}  // namespace

HybridModel MakeBallChain(int num_phases) {
  if (num_phases < 1) throw std::invalid_argument("ball-chain: number of phases must be >= 1");
  ModelBuilder<ChainParameters> b("ball-chain", "ball bouncing m times per period, one phase per bounce");
  b.Parameter("m", &ChainParameters::m, "mass").Parameter("g", &ChainParameters::g, "gravity");
  Vector typical(2);
  typical << 0.5, 0.3;
  for (int i = 0; i < num_phases; ++i) b.AddPhase<Flight>("flight-" + std::to_string(i + 1), {"y", "dy"}, typical);
  b.SetAnchor<Apex>();
  return b.Build();
}

Vector BallChainOrbit(const HybridModel& chain, double H) {
  const ShootingLayout layout(chain);
  const double g = chain.parameter("g"), mass = chain.parameter("m");
  const double height = H / (mass * g), v = std::sqrt(2.0 * g * height), t_fall = v / g;
  Vector u = Vector::Zero(layout.num_unknowns());
  for (int i = 0; i < layout.num_segments(); ++i) {
    const bool first = i == 0, last = i == layout.num_segments() - 1;
    u(layout.time_index(i)) = (first || last) ? t_fall : 2.0 * t_fall;
    u(layout.state_offset(i)) = first ? height : 0.0;
    u(layout.state_offset(i) + 1) = first ? 0.0 : v;
  }
  u(layout.H_index()) = H;
  return u;
}

}  // namespace hybridcont
