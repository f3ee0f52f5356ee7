// Bouncing rod (paper eq. `HDSrod`): two flight phases separated by impacts of the left and right ends;
// anchor at the apex (dy = 0).
#include <cmath>
#include <string>

#include "hybridcont/model_builder.h"
#include "hybridcont/models.h"

namespace hybridcont {
namespace {

template <class T>
struct RodParameters {
  T m = 1.0;   // mass
  T l0 = 1.0;  // length
  T g = 1.0;   // gravity
  T r = 0.01;  // radius of gyration
};

// Flight until the end on side `kSide` (-1: left, +1: right) hits the ground.
template <int kSide>
struct RodFlight {
  static constexpr int kDimension = 4;  // y, alpha, dy, dalpha
  template <class T, class Q>
  static StateVector<T> VectorField(const StateVector<T>& x, const Q& p) {
    StateVector<T> f(4);
    f << x(2), x(3), T(-p.g), T(0.0);
    return f;
  }
  template <class T, class Q>
  static T FirstIntegral(const StateVector<T>& x, const Q& p) {
    return 0.5 * p.m * (x(2) * x(2) + p.r * p.r * x(3) * x(3)) + p.m * p.g * x(0);
  }
  template <class T, class Q>
  static T Event(const StateVector<T>& x, const Q& p) {
    using std::sin;
    return x(0) + kSide * 0.5 * p.l0 * sin(x(1));  // height of that end
  }
  template <class T, class Q>
  static StateVector<T> Reset(const StateVector<T>& x, const Q& p) {
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
  static constexpr int kDimension = 4;
  template <class T, class Q>
  static T Anchor(const StateVector<T>& x, const Q&) {
    return x(2);
  }
};

// The paper's run (§4.3): from the equilibrium u0 = 0, a non-simple start (kernel of dimension 3), along
// the symmetric direction t2 = t1 + t3, up to H = 0.6.
ModelSetup RodSetup() {
  ModelSetup setup;
  setup.title = "bouncing rod";
  setup.start.kind = StartSpec::Kind::kSingular;  // u0 = 0: the rod at rest on both ends, zero durations
  setup.start.conditions = {{{{"t2", 1.0}, {"t1", -1.0}, {"t3", -1.0}}, "t2 = t1 + t3"}};
  RunSpec& run = setup.run;
  // |xi| <= 1 ends the at-rest xi-branches through the equilibria (they exist for every xi).
  run.bounds = {{"xi", "-1", "1"}, {"H", "-1", "0.6"}, {"period", "-10", "10"}};
  run.keyframe_component = "T";
  run.keyframe_value = "0.8";
  // dalpha = sqrt(2H)/r ~ 100 would dominate every norm of u; r * dalpha is O(1) (an energy-like
  // velocity), and durations are O(0.1).
  for (const std::string i : {"1", "2", "3"}) run.scales.push_back({"x" + i + "_dalpha", "l0/r"});
  // On symmetric orbits the second flight lasts as long as the first and the third together.
  setup.families = {{"symmetric orbit (t2 = t1 + t3)", "abs(t2 - t1 - t3) < 1e-6"},
                    {"non-symmetric orbit (t2 > t1 + t3)", "t2 - t1 - t3 > 0"},
                    {"non-symmetric orbit (t2 < t1 + t3)", "1"}};
  setup.quantities = {{"asym", "t2 - (t1 + t3)", "asymmetry t2 - (t1 + t3) of the flight times (0: symmetric orbit)"}};
  setup.figures = {{"rod_t2.png", "energy over the second flight time", "t2", {"H"}},
                   {"rod_asymmetry.png", "asymmetry t2 - (t1 + t3) over the period (0: symmetric orbits)", "T",
                    {"asym"}},
                   {"rod_zoom.png", "zoom on the special points: energy over the period", "T", {"H"}, true}};
  // The rod of length l0 about its centre (X, y), turned by alpha; the left end hits in phase 1, the right
  // end in phase 2. Its mass is near the centre (r << l0).
  for (const char* phase : {"left-impact", "right-impact"}) {
    DrawingSpec::PhaseDrawing d;
    d.phase = phase;
    d.points = {{"left", "X - 0.5*l0*cos(alpha)", "y - 0.5*l0*sin(alpha)"},
                {"right", "X + 0.5*l0*cos(alpha)", "y + 0.5*l0*sin(alpha)"},
                {"centre", "X", "y"}};
    d.lines = {{"left", "right"}};
    d.masses = {"centre"};
    setup.drawing.phases.push_back(d);
  }
  setup.drawing.mass_radius = 0.04;
  return setup;
}

}  // namespace

HybridModel MakeBouncingRod() {
  ModelBuilder<RodParameters<double>> b("bouncing-rod", "rod bouncing on its two ends (paper §4.3)");
  b.Parameter("m", [](auto& p) -> auto& { return p.m; }, "mass", ParameterRange::Positive())
      .Parameter("l0", [](auto& p) -> auto& { return p.l0; }, "length", ParameterRange::Positive())
      .Parameter("g", [](auto& p) -> auto& { return p.g; }, "gravity", ParameterRange::Positive())
      // r > 0: a rod without rotational inertia has no impact law (the reset divides by l0^2 cos^2 + 4 r^2).
      .Parameter("r", [](auto& p) -> auto& { return p.r; }, "radius of gyration", ParameterRange::Positive());
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
  b.Setup(RodSetup());
  return b.Build();
}

}  // namespace hybridcont
