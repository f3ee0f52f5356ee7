// Internal: the ballistic flight phase of a ball with an elastic ground impact, and its apex anchor —
// shared by the bouncing ball (paper §4.1) and the scalable ball-chain test model.
#ifndef HYBRIDCONT_SRC_MODELS_BALL_FLIGHT_H_
#define HYBRIDCONT_SRC_MODELS_BALL_FLIGHT_H_

#include "hybridcont/model.h"
#include "hybridcont/model_builder.h"

namespace hybridcont::internal {

template <class T>
struct BallParameters {
  T m = 1.0;  // mass
  T g = 1.0;  // gravity
};

// x = [y, dy]
struct BallFlight {
  static constexpr int kDimension = 2;  // y, dy
  template <class T, class Q>
  static StateVector<T> VectorField(const StateVector<T>& x, const Q& p) {
    StateVector<T> f(2);
    f << x(1), T(-p.g);
    return f;
  }
  template <class T, class Q>
  static T FirstIntegral(const StateVector<T>& x, const Q& p) {
    return 0.5 * p.m * x(1) * x(1) + p.m * p.g * x(0);
  }
  template <class T, class Q>
  static T Event(const StateVector<T>& x, const Q&) {
    return x(0);  // ground contact
  }
  template <class T, class Q>
  static StateVector<T> Reset(const StateVector<T>& x, const Q&) {
    StateVector<T> y(2);
    y << x(0), -x(1);  // elastic impact
    return y;
  }
};

struct BallApex {
  static constexpr int kDimension = 2;
  template <class T, class Q>
  static T Anchor(const StateVector<T>& x, const Q&) {
    return x(1);
  }
};

// The builder with the two parameters registered.
inline ModelBuilder<BallParameters<double>> BallBuilder(const std::string& name, const std::string& description) {
  ModelBuilder<BallParameters<double>> b(name, description);
  b.Parameter("m", [](auto& p) -> auto& { return p.m; }, "mass").Parameter("g", [](auto& p) -> auto& { return p.g; }, "gravity");
  return b;
}

}  // namespace hybridcont::internal

#endif  // HYBRIDCONT_SRC_MODELS_BALL_FLIGHT_H_
