// Rocking block (paper eq. `HDSblock`): pivoting about the left corner, the symmetric motion about the
// right corner folded onto it; impact at alpha = 0, anchor at dalpha = 0.
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "hybridcont/model_builder.h"
#include "hybridcont/models.h"

namespace hybridcont {
namespace {

template <class T>
struct BlockParameters {
  T m = 1.0;     // mass
  T l0 = 1.0;    // half diagonal
  T g = 1.0;     // gravity
  T beta = 0.3;  // slenderness [rad]
};

struct Rocking {
  static constexpr int kDimension = 2;  // alpha, dalpha
  template <class T, class Q>
  static StateVector<T> VectorField(const StateVector<T>& x, const Q& p) {
    using std::sin;
    StateVector<T> f(2);
    f << x(1), -(3.0 * p.g / (4.0 * p.l0)) * sin(p.beta - x(0));
    return f;
  }
  template <class T, class Q>
  static T FirstIntegral(const StateVector<T>& x, const Q& p) {
    using std::cos;
    return (2.0 / 3.0) * p.m * p.l0 * p.l0 * x(1) * x(1) + (cos(x(0) - p.beta) - cos(p.beta)) * p.m * p.l0 * p.g;
  }
  template <class T, class Q>
  static T Event(const StateVector<T>& x, const Q&) {
    return x(0);
  }
  template <class T, class Q>
  static StateVector<T> Reset(const StateVector<T>& x, const Q&) {
    StateVector<T> y(2);
    y << x(0), -x(1);
    return y;
  }
};

struct TurningPoint {
  static constexpr int kDimension = 2;
  template <class T, class Q>
  static T Anchor(const StateVector<T>& x, const Q&) {
    return x(1);
  }
};

// The paper's run (§4.2): from the equilibrium u0 = 0 up to the homoclinic limit
// H_max = m g l0 (1 - cos beta), the energy of the block balanced on its corner.
ModelSetup BlockSetup() {
  const std::string H_max = "m*g*l0*(1 - cos(beta))";
  ModelSetup setup;
  setup.title = "rocking block";
  setup.start.kind = StartSpec::Kind::kSingular;  // u0 = 0: at rest on both corners, zero durations
  RunSpec& run = setup.run;
  // |xi| <= 1 ends the at-rest xi-branches through the equilibria (they exist for every xi).
  run.bounds = {{"xi", "-1", "1"}, {"H", "-1", H_max},
                // T grows without bound towards the homoclinic orbit at H_max: stop cleanly at |T| = 20,
                // where H_max - H ~ 1e-9. Beyond T ~ 30 the monodromy grows like e^{lambda T} and Newton's
                // linear systems lose all accuracy (measured: steps collapse to 1e-6 near T = 33), so
                // nothing is gained by going on.
                {"period", "-20", "20"}};
  run.keyframe_component = "H";
  run.keyframe_value = "0.5*(" + H_max + ")";
  // H <= H_max ~ 0.045 and alpha <= beta: scaled to O(1) so that the branch is resolved in H too.
  run.scales.push_back({"H", H_max});
  for (const std::string i : {"1", "2"}) {
    run.scales.push_back({"x" + i + "_alpha", "beta"});
    run.scales.push_back({"x" + i + "_dalpha", "sqrt(" + H_max + "/m)/l0"});
  }
  run.max_step = 0.5;
  // The block of width 2 l0 sin(beta) and height 2 l0 cos(beta), turned by alpha about its pivot corner.
  // The motion about the right corner is folded onto the left one (alpha >= 0 throughout): segment 1 rocks
  // on the left corner into the impact, segment 2 on the right corner after it, drawn mirrored about the
  // block's axis (x -> w - x).
  const std::string w = "2*l0*sin(beta)", h = "2*l0*cos(beta)";
  const auto turned = [&](const std::string& x, const std::string& y) {  // (x, y) turned by alpha
    return std::pair<std::string, std::string>{"(" + x + ")*cos(alpha) - (" + y + ")*sin(alpha)",
                                               "(" + x + ")*sin(alpha) + (" + y + ")*cos(alpha)"};
  };
  const std::vector<std::pair<std::string, std::pair<std::string, std::string>>> body = {
      {"pivot", {"0", "0"}},
      {"corner2", turned(w, "0")},
      {"corner3", turned(w, h)},
      {"corner4", turned("0", h)},
      {"com", turned("0.5*" + w, "0.5*" + h)}};
  for (const bool mirrored : {false, true}) {
    DrawingSpec::PhaseDrawing d;
    d.phase = "rocking";
    d.segments = {mirrored ? 2 : 1};
    for (const auto& [name, xy] : body) {
      d.points.push_back({name, mirrored ? w + " - (" + xy.first + ")" : xy.first, xy.second});
    }
    d.lines = {{"pivot", "corner2", "corner3", "corner4", "pivot"}, {"pivot", "com"}};
    d.masses = {"com"};
    setup.drawing.phases.push_back(d);
  }
  setup.drawing.mass_radius = 0.04;
  return setup;
}

}  // namespace

HybridModel MakeRockingBlock() {
  ModelBuilder<BlockParameters<double>> b("rocking-block", "rectangular block rocking on its corners (paper §4.2)");
  b.Parameter("m", [](auto& p) -> auto& { return p.m; }, "mass", ParameterRange::Positive())
      .Parameter("l0", [](auto& p) -> auto& { return p.l0; }, "half diagonal", ParameterRange::Positive())
      .Parameter("g", [](auto& p) -> auto& { return p.g; }, "gravity", ParameterRange::Positive())
      // beta = 0 is a block without width (it cannot stand), pi/2 one without height.
      .Parameter("beta", [](auto& p) -> auto& { return p.beta; }, "slenderness angle [rad]", ParameterRange::Open(0.0, M_PI / 2));
  Vector typical(2);
  typical << 0.1, 0.2;
  b.AddPhase<Rocking>("rocking", {"alpha", "dalpha"}, typical);
  b.SetAnchor<TurningPoint>();
  b.Symmetry("time-reversal", {Vector(Eigen::Vector2d(1, -1))}, true);  // the impact law is linear in dalpha
  b.Setup(BlockSetup());
  return b.Build();
}

}  // namespace hybridcont
