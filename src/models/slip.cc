// SLIP hopper with swing leg (paper eq. `HDSslip`): stance (alpha, l, dalpha, dl) -> flight
// (y, alpha, dx, dy, dalpha) -> stance; anchor at nadir (a = -dl).
#include <cmath>

#include "hybridcont/model_builder.h"
#include "hybridcont/models.h"

namespace hybridcont {
namespace {

template <class T>
struct SlipParameters {
  T m = 1.0;   // point mass
  T l0 = 1.0;  // natural leg length
  T g = 1.0;   // gravity
  T k = 40.0;  // leg stiffness
  T w2 = 5.0;  // squared swing frequency of the leg in flight
};

struct Stance {
  static constexpr int kDimension = 4;  // alpha, l, dalpha, dl
  template <class T, class Q>
  static StateVector<T> VectorField(const StateVector<T>& x, const Q& p) {
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
  template <class T, class Q>
  static T FirstIntegral(const StateVector<T>& x, const Q& p) {
    using std::cos;
    const T& l = x(1);
    return 0.5 * p.m * (x(2) * x(2) * l * l + x(3) * x(3)) + p.m * p.g * cos(x(0)) * l +
           0.5 * p.k * (l - p.l0) * (l - p.l0);
  }
  template <class T, class Q>
  static T Event(const StateVector<T>& x, const Q& p) {
    return p.l0 - x(1);  // lift-off at natural length
  }
  template <class T, class Q>
  static StateVector<T> Reset(const StateVector<T>& x, const Q&) {
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
  static constexpr int kDimension = 5;  // y, alpha, dx, dy, dalpha
  template <class T, class Q>
  static StateVector<T> VectorField(const StateVector<T>& x, const Q& p) {
    StateVector<T> f(5);
    f << x(3), x(4), T(0.0), T(-p.g), -x(1) * p.w2;
    return f;
  }
  template <class T, class Q>
  static T FirstIntegral(const StateVector<T>& x, const Q& p) {
    return 0.5 * p.m * (x(2) * x(2) + x(3) * x(3)) + p.m * p.g * x(0);
  }
  template <class T, class Q>
  static T Event(const StateVector<T>& x, const Q& p) {
    using std::cos;
    return x(0) - p.l0 * cos(x(1));  // touch-down
  }
  template <class T, class Q>
  static StateVector<T> Reset(const StateVector<T>& x, const Q& p) {
    using std::cos;
    using std::sin;
    const T& a = x(1);
    StateVector<T> y(4);
    y << a, T(p.l0), -(cos(a) * x(2) + sin(a) * x(3)) / p.l0, cos(a) * x(3) - sin(a) * x(2);
    return y;
  }
};

struct Nadir {
  static constexpr int kDimension = 4;  // the stance state
  template <class T, class Q>
  static T Anchor(const StateVector<T>& x, const Q&) {
    return -x(3);
  }
};

// The paper's run (§4.4): from the vertical harmonic oscillation with zero flight time at H = m g l0 up to
// H = 2.
ModelSetup SlipSetup() {
  ModelSetup setup;
  setup.title = "SLIP hopper";
  // Vertical harmonic oscillation with zero flight time (paper §4.4): t1 = t3 = T0/2 with
  // T0 = 2 pi sqrt(m/k), t2 = 0, x̄_1 at nadir l = l0 - 2mg/k, x̄_3 at l = l0 with zero velocity,
  // H = m g l0: a singular point of r, as in the paper.
  setup.start.kind = StartSpec::Kind::kSingular;
  setup.start.values = {{"t1", "pi*sqrt(m/k)"}, {"t2", "0"},  {"t3", "pi*sqrt(m/k)"}, {"x1_l", "l0 - 2*m*g/k"},
                        {"x2_y", "l0"},         {"x3_l", "l0"}, {"H", "m*g*l0"}};
  RunSpec& run = setup.run;
  // |xi| <= 1 ends the at-rest xi-branches through the equilibria (they exist for every xi).
  run.bounds = {{"xi", "-1", "1"}, {"H", "0", "2"}, {"period", "-20", "20"}};
  run.keyframe_component = "H";
  run.keyframe_value = "1.8";
  // Steps stay at 0.1. Larger steps cost fewer evaluations (0.2: 1661 instead of 1916) and, since the
  // Floquet pass finds crossing pairs inside one step (FindHiddenRootPair), keep the PD points of
  // hopping in place. But the cluster of nearly tangent crossings near H = 1.6116 (four images of one
  // branch) is resolved differently from one step to the next above 0.135 (measured for max_step in
  // 0.14–0.23: 23 or 31 half-branches, 17 to 23 SB points), while 0.09–0.135 all give the same 23
  // half-branches and 21 SB points, all located.
  run.max_step = 0.1;
  // x2_dx is the forward speed in flight.
  setup.families = {{"hopping in place", "abs(x2_dx) < 1e-6"},
                    {"forward hopping", "x2_dx > 0"},
                    {"backward hopping", "1"}};
  setup.figures = {{"slip_durations.png", "stance durations t1, t3 over the flight time t2", "t2", {"t1", "t3"}},
                   {"slip_speed.png", "forward speed in flight over the energy", "H", {"x2_dx"}}};
  // The body at (X, height) on its massless leg. X advances with the body's horizontal speed: in flight
  // dx; in stance the time derivative of its position -l sin(alpha) relative to the fixed foot, so the
  // foot X + l sin(alpha) stays where it touched down (the flight's foot X + l0 sin(alpha) there).
  DrawingSpec::PhaseDrawing stance, flight;
  stance.phase = "stance";
  stance.x_velocity = "-dl*sin(alpha) - dalpha*l*cos(alpha)";
  stance.points = {{"body", "X", "l*cos(alpha)"}, {"foot", "X + l*sin(alpha)", "0"}};
  flight.phase = "flight";
  flight.x_velocity = "dx";
  flight.points = {{"body", "X", "y"}, {"foot", "X + l0*sin(alpha)", "y - l0*cos(alpha)"}};
  for (DrawingSpec::PhaseDrawing* d : {&stance, &flight}) {
    d->lines = {{"foot", "body"}};
    d->masses = {"body"};
  }
  setup.drawing.phases = {stance, flight};
  setup.drawing.mass_radius = 0.075;
  return setup;
}

}  // namespace

HybridModel MakeSlip() {
  ModelBuilder<SlipParameters<double>> b("slip", "spring-loaded inverted pendulum hopper with swing leg (paper §4.4)");
  b.Parameter("m", [](auto& p) -> auto& { return p.m; }, "point mass", ParameterRange::Positive())
      .Parameter("l0", [](auto& p) -> auto& { return p.l0; }, "natural leg length", ParameterRange::Positive())
      .Parameter("g", [](auto& p) -> auto& { return p.g; }, "gravity", ParameterRange::Positive())
      .Parameter("k", [](auto& p) -> auto& { return p.k; }, "leg stiffness", ParameterRange::Positive())
      // w2 > 0: the leg swings about the vertical in flight (w2 <= 0 would let it fall away from it).
      .Parameter("w2", [](auto& p) -> auto& { return p.w2; }, "squared swing frequency omega^2 of the leg in flight",
                 ParameterRange::Positive());
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
  b.Setup(SlipSetup());
  return b.Build();
}

}  // namespace hybridcont
