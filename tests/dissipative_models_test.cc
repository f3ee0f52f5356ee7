// Models without first integral (shooting_layout.h, "conservative = false"): the simplest walker and a
// forced impact oscillator, continued in a parameter, checked against what does not come from the shooting
// code:
//   - the walker's gait at gamma = 0.009, its fixed point and the eigenvalues of its stride map, from a
//     simulation-and-root-solve written here (its own integrator, events by bisection, the heel-strike law
//     of Garcia et al. (1998), Newton on the stride map with a finite-difference Jacobian);
//   - the published stability bound of the long-period gait (stable for 0 < gamma < 0.015 rad): its
//     period-doubling point, located, and the period-doubled gait starting at twice the period;
//   - the oscillator's two grazing frequencies against the closed form of the non-impacting response.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <boost/numeric/odeint.hpp>
#include <cmath>
#include <complex>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

#include "hybridcont/exploration.h"
#include "hybridcont/expression_model.h"
#include "hybridcont/floquet.h"
#include "hybridcont/model_builder.h"
#include "hybridcont/model_file.h"
#include "hybridcont/period_doubling.h"
#include "hybridcont/shooting_layout.h"
#include "hybridcont/simulation_start.h"
#include "hybridcont/timebased_shooting.h"
#include "model_exploration.h"
#include "orbit_start.h"
#include "run_setup.h"
#include "scenario.h"

namespace hybridcont {
namespace {

namespace odeint = boost::numeric::odeint;

HybridModel Load(const std::string& name) {
  ModelFileOptions options;
  options.cache_dir = std::filesystem::temp_directory_path() / "hybridcont-test-cache";
  return LoadModelFile(std::filesystem::path(HYBRIDCONT_SOURCE_DIR) / "models" / (name + ".toml"), options);
}

// The run `hybridcont run MODEL` makes: starts, then the families in the model's parameter.
struct ParameterRun {
  BifurcationDiagram diagram;
  std::unique_ptr<app::ModelExploration> exploration;
  app::RunSetup setup;
};

ParameterRun Explore(const HybridModel& model) {
  ParameterRun run;
  app::RunArguments args;
  args.model = model.name();
  run.setup = app::MakeRunSetup(args, model);
  run.setup.exploration.threads = 1;
  run.exploration = std::make_unique<app::ModelExploration>(model, run.setup.scenario, run.setup.integrator,
                                                            run.setup.exploration, app::Formulation::kTimeBased,
                                                            run.setup.free);
  const app::OrbitStarts starts = app::FindOrbitStarts(model, run.setup, run.exploration->shooting().layout());
  int skipped = 0;
  run.diagram = run.exploration->RunFromStarts(starts.points, {}, &skipped);
  return run;
}

// ---- the walker by hand: state (theta, phi, theta', phi') right after a heel strike, phi = 2 theta.
constexpr double kGamma = 0.009;
using State = std::array<double, 4>;

void WalkerRhs(const State& x, State& dx, double) {
  const double a = std::sin(x[0] - kGamma);
  dx = {x[2], x[3], a, a + x[2] * x[2] * std::sin(x[1]) - std::cos(x[0] - kGamma) * std::sin(x[1])};
}

// The stride map on (theta, theta') after heel strike: integrate to the next heel strike (2 theta - phi
// crossing zero downward with theta < 0), located by bisection on the dense output, then the heel strike.
Eigen::Vector2d Stride(const Eigen::Vector2d& z, double* period) {
  State x = {z(0), 2 * z(0), z(1), (1 - std::cos(2 * z(0))) * z(1)};
  auto stepper = odeint::make_dense_output(1e-13, 1e-13, odeint::runge_kutta_dopri5<State>());
  stepper.initialize(x, 0.0, 1e-3);
  const auto e = [](const State& s) { return 2 * s[0] - s[1]; };
  for (int steps = 0; steps < 100000; ++steps) {
    stepper.do_step(WalkerRhs);
    const State& a = stepper.previous_state();
    const State& b = stepper.current_state();
    if (b[0] < 0 && e(a) > 0 && e(b) <= 0) {
      double lo = stepper.previous_time(), hi = stepper.current_time();
      State s;
      for (int it = 0; it < 200 && hi - lo > 1e-15; ++it) {
        const double mid = 0.5 * (lo + hi);
        stepper.calc_state(mid, s);
        (e(s) > 0 ? lo : hi) = mid;
      }
      stepper.calc_state(hi, s);
      *period = hi;
      const double c = std::cos(2 * s[0]);
      return {-s[0], c * s[2]};
    }
  }
  *period = NAN;
  return {NAN, NAN};
}

TEST(SimplestWalker, GaitAndStrideEigenvaluesAgreeWithAnIndependentRootSolve) {
  // The independent fixed point: Newton on z -> Stride(z) - z from the paper's rounded values.
  Eigen::Vector2d z(0.2, -0.2);
  double T = 0;
  for (int it = 0; it < 20; ++it) {
    const Eigen::Vector2d r = Stride(z, &T) - z;
    if (r.norm() < 1e-13) break;
    Eigen::Matrix2d J;
    for (int j = 0; j < 2; ++j) {
      Eigen::Vector2d zp = z, zm = z;
      zp(j) += 1e-7;
      zm(j) -= 1e-7;
      double t;
      J.col(j) = (Stride(zp, &t) - Stride(zm, &t)) / 2e-7 - Eigen::Vector2d::Unit(j);
    }
    z -= J.lu().solve(r);
  }
  Eigen::Matrix2d S;  // the stride map's Jacobian at the fixed point
  for (int j = 0; j < 2; ++j) {
    Eigen::Vector2d zp = z, zm = z;
    zp(j) += 1e-6;
    zm(j) -= 1e-6;
    double t;
    S.col(j) = (Stride(zp, &t) - Stride(zm, &t)) / 2e-6;
  }
  Stride(z, &T);
  const Eigen::Vector2cd mu = S.eigenvalues();

  // The tool's: the first start of the run at gamma = 0.009 (simulation, then Newton).
  const HybridModel model = Load("simplest-walker");
  const ParameterRun run = Explore(model);
  ASSERT_EQ(run.diagram.status, ExplorationStatus::kCompleted) << run.diagram.message;
  const ShootingLayout& layout = run.exploration->shooting().layout();
  const Vector& u = run.diagram.branches.front().points.front().u;
  EXPECT_NEAR(u(layout.parameter_index(0)), kGamma, 1e-14);
  const int x2 = layout.state_offset(1);  // right after the heel strike
  EXPECT_NEAR(u(x2), z(0), 1e-9);
  EXPECT_NEAR(u(x2 + 2), z(1), 1e-9);
  EXPECT_NEAR(u(x2 + 1), 2 * z(0), 1e-9);
  EXPECT_NEAR(layout.Period(u), T, 1e-9);
  // The published values (Garcia et al. 1998, long-period gait at gamma = 0.009).
  EXPECT_NEAR(z(0), 0.2003109, 1e-6);
  EXPECT_NEAR(z(1), -0.1998325, 1e-6);
  // Multipliers: the stride map's two (the third of the tool's section map is 0: the heel strike puts
  // phi = 2 theta, a rank-deficient reset).
  FloquetResult f = ComputeFloquet(run.exploration->shooting(), u);
  ASSERT_TRUE(f.ok()) << f.message;
  EXPECT_EQ(f.num_trivial, 1);
  ASSERT_EQ(f.nontrivial.size(), 3u);
  EXPECT_TRUE(f.asymptotically_stable);
  EXPECT_LT(std::abs(f.nontrivial[2]), 1e-9);
  for (int i = 0; i < 2; ++i) {
    const double d = std::min(std::abs(f.nontrivial[i] - mu(0)), std::abs(f.nontrivial[i] - mu(1)));
    EXPECT_LT(d, 1e-6) << f.nontrivial[i] << " vs " << mu.transpose();
  }
  std::printf("walker at gamma = 0.009: fixed point (%.12f, %.12f), period %.12f; tool - root solve: %.1e, %.1e, "
              "%.1e; multipliers %.9f%+.9fi (root solve %.9f%+.9fi)\n",
              z(0), z(1), T, u(x2) - z(0), u(x2 + 2) - z(1), layout.Period(u) - T, f.nontrivial[0].real(),
              f.nontrivial[0].imag(), mu(0).real(), std::abs(mu(0).imag()));
}

TEST(SimplestWalker, LongPeriodGaitLosesStabilityByPeriodDoublingAtThePublishedSlope) {
  const HybridModel model = Load("simplest-walker");
  const ParameterRun run = Explore(model);
  const ShootingLayout& layout = run.exploration->shooting().layout();
  const int p = layout.parameter_index(0);
  // Both period-one gaits (two starts), each traced both ways.
  int long_period = 0, short_period = 0;
  for (const Branch& b : run.diagram.branches) {
    if (b.points.empty()) continue;
    (layout.Period(b.points.front().u) > 3.5 ? long_period : short_period)++;
  }
  EXPECT_EQ(long_period, 2);
  EXPECT_EQ(short_period, 2);
  const SpecialPoint* pd = nullptr;
  for (const SpecialPoint& sp : run.diagram.special_points) {
    if (sp.type == SpecialPointType::kPeriodDoubling) {
      EXPECT_EQ(pd, nullptr) << "a second PD point: " << sp.BriefReport();
      pd = &sp;
    }
  }
  ASSERT_NE(pd, nullptr) << run.diagram.FullReport();
  EXPECT_EQ(pd->status, LocationStatus::kLocated);
  EXPECT_LT(pd->precision(), 1e-8);
  // "stable when 0 < gamma < 0.015 rad": the bound, to the digits published.
  EXPECT_NEAR(pd->u(p), 0.0151, 5e-5) << pd->BriefReport();
  const FloquetResult at_pd = ComputeFloquet(run.exploration->shooting(), pd->u);
  ASSERT_TRUE(at_pd.ok());
  EXPECT_NEAR(at_pd.nontrivial.front().real(), -1.0, 1e-6);
  // The period-doubled gait: starts at twice the period, is stable at first (the paper's period-two gait).
  const HybridModel doubled = RepeatedModel(model, 2);
  const app::Scenario scenario = app::DefaultScenario(doubled);
  ExplorationOptions options = app::ScenarioExplorationOptions(scenario);
  options.threads = 1;
  options.continuation.max_points = 20;
  app::ModelExploration ex2(doubled, scenario, IntegratorOptions{}, options, app::Formulation::kTimeBased, run.setup.free);
  const BifurcationDiagram d2 = ex2.RunPeriodDoubled(layout, pd->u);
  ASSERT_EQ(d2.status, ExplorationStatus::kCompleted) << d2.message;
  ASSERT_FALSE(d2.branches.empty());
  const ShootingLayout& layout2 = ex2.shooting().layout();
  const Branch& b = d2.branches.front();
  ASSERT_GE(b.points.size(), 5u);
  EXPECT_NEAR(layout2.Period(b.points.front().u), 2 * layout.Period(pd->u), 1e-10);
  const FloquetResult f = ComputeFloquet(ex2.shooting(), b.points[4].u);
  ASSERT_TRUE(f.ok());
  EXPECT_TRUE(f.asymptotically_stable) << f.BriefReport();
  EXPECT_GT(b.points[4].u(layout2.parameter_index(0)), pd->u(p));  // beyond the PD point in gamma
  std::printf("walker: PD at gamma = %.12f (precision %.1e); period-doubled gait from T = %.12f, stable at "
              "gamma = %.6f (|mu|max %.3f)\n",
              pd->u(p), pd->precision(), layout2.Period(b.points.front().u), b.points[4].u(layout2.parameter_index(0)),
              f.max_modulus);
}

TEST(ForcedImpactOscillator, GrazingFrequenciesMatchTheClosedForm) {
  const HybridModel model = Load("forced-impact-oscillator");
  const ParameterRun run = Explore(model);
  ASSERT_EQ(run.diagram.status, ExplorationStatus::kCompleted) << run.diagram.message;
  const ShootingLayout& layout = run.exploration->shooting().layout();
  const double k = 1.0, c = 0.1, A = 0.3, d = 1.0;
  const double q = 2 * k - c * c, disc = std::sqrt(q * q - 4 * (k * k - (A / d) * (A / d)));
  const double low = std::sqrt((q - disc) / 2), high = std::sqrt((q + disc) / 2);
  std::vector<double> found;
  for (const SpecialPoint& sp : run.diagram.special_points) {
    if (sp.type != SpecialPointType::kGrazing) continue;
    EXPECT_EQ(sp.status, LocationStatus::kLocated) << sp.BriefReport();
    found.push_back(sp.u(layout.parameter_index(0)));
  }
  ASSERT_EQ(found.size(), 2u) << run.diagram.FullReport();
  std::sort(found.begin(), found.end());
  EXPECT_NEAR(found[0], low, 1e-9);
  EXPECT_NEAR(found[1], high, 1e-9);
  std::printf("grazing at w = %.12f and %.12f; closed form %.12f and %.12f (errors %.1e, %.1e)\n", found[0], found[1],
              low, high, found[0] - low, found[1] - high);
}

// The time-based maps of two models with the same layout and free parameter agree, r and dr to 1e-12, at
// random points: states and durations near 0 and `min_time` + |·|, the parameter in p0 ± spread.
void ExpectSameMap(const HybridModel& x, const HybridModel& y, const FreeParameters& free, double min_time,
                   double p0, double spread) {
  TimeBasedShooting a(x, IntegratorOptions{}, free), b(y, IntegratorOptions{}, free);
  ASSERT_EQ(a.layout().unknown_names(), b.layout().unknown_names());
  const ShootingLayout& layout = a.layout();
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> d(-0.3, 0.3);
  for (int trial = 0; trial < 10; ++trial) {
    Vector u(layout.num_unknowns());
    for (int i = 0; i < u.size(); ++i) u(i) = d(rng);
    for (int i = 0; i < layout.num_segments(); ++i) u(layout.time_index(i)) = min_time + std::abs(u(layout.time_index(i)));
    u(layout.parameter_index(0)) = p0 + spread * d(rng) / 0.3;
    Vector ra, rb;
    Matrix da, db;
    ASSERT_TRUE(a.Evaluate(u, &ra, &da).ok) << trial;
    ASSERT_TRUE(b.Evaluate(u, &rb, &db).ok) << trial;
    EXPECT_LE((ra - rb).lpNorm<Eigen::Infinity>(), 1e-12 * (1 + ra.lpNorm<Eigen::Infinity>())) << trial;
    EXPECT_LE((da - db).lpNorm<Eigen::Infinity>(), 1e-12 * (1 + da.lpNorm<Eigen::Infinity>())) << trial;
  }
}

// The walker in C++ (model_builder.h): a phase functor whose FirstIntegrals are none (an empty vector) is a
// model without first integral. Its map with gamma free equals the model file's.
template <class T>
struct WalkerParameters {
  T gamma = 0.009;
};
struct WalkerStep {
  template <class T, class Q>
  static StateVector<T> VectorField(const StateVector<T>& x, const Q& p) {
    using std::cos, std::sin;
    const T a = sin(x(0) - p.gamma);
    StateVector<T> f(4);
    f << x(2), x(3), a, a + x(2) * x(2) * sin(x(1)) - cos(x(0) - p.gamma) * sin(x(1));
    return f;
  }
  template <class T, class Q>
  static StateVector<T> FirstIntegrals(const StateVector<T>&, const Q&) {
    return StateVector<T>(0);
  }
  template <class T, class Q>
  static T Event(const StateVector<T>& x, const Q&) {
    return 2.0 * x(0) - x(1);
  }
  template <class T, class Q>
  static StateVector<T> Reset(const StateVector<T>& x, const Q&) {
    using std::cos;
    const T c2 = cos(2.0 * x(0));
    StateVector<T> y(4);
    y << -x(0), -2.0 * x(0), c2 * x(2), c2 * (1.0 - c2) * x(2);
    return y;
  }
};
struct WalkerSection {
  template <class T, class Q>
  static T Anchor(const StateVector<T>& x, const Q&) {
    return 2.0 * x(2) - x(3);
  }
};

TEST(SimplestWalker, CppModelWithoutFirstIntegralIsTheModelFile) {
  ModelBuilder<WalkerParameters<double>> b("simplest-walker", "C++ walker");
  b.Parameter("gamma", [](auto& p) -> auto& { return p.gamma; }, "slope");
  b.AddPhase<WalkerStep>("step", {"theta", "phi", "dtheta", "dphi"}, (Vector(4) << 0.1, 0.25, -0.2, 0.05).finished());
  b.SetAnchor<WalkerSection>();
  const HybridModel cpp = b.Build();
  EXPECT_EQ(cpp.num_first_integrals(), 0);
  const HybridModel file = Load("simplest-walker");
  const FreeParameters free{{"gamma"}, {}};
  ExpectSameMap(cpp, file, free, 1.0, 0.01, 0.005);
}

// The oscillator written from its mechanics (mechanics.h) without first integral: T = v²/2, V = k x²/2, the
// damping and forcing as a generalized force, the forcing phase an explicit state beside the mechanical
// ones, and the impact as Newton's law with restitution e at the contact d − x = 0. Its map is the explicit
// file's, r and dr to 1e-12 at random points with the frequency free.
TEST(ForcedImpactOscillator, LagrangianFormWithRestitutionIsTheExplicitModel) {
  std::ifstream in(std::filesystem::path(HYBRIDCONT_SOURCE_DIR) / "models" / "forced-impact-oscillator.toml");
  std::stringstream text;
  text << in.rdbuf();
  std::string lagrangian = text.str();
  const auto replace = [&](const std::string& from, const std::string& to) {
    const std::size_t at = lagrangian.find(from);
    ASSERT_NE(at, std::string::npos) << from;
    lagrangian.replace(at, from.size(), to);
  };
  const std::string mechanics = "coordinates = [\"x\"]\nvelocities = [\"v\"]\n"
                                "kinetic = \"0.5*v^2\"\npotential = \"0.5*k*x^2\"\n"
                                "forces = { x = \"-c*v + A*cos(s)\" }\node = { s = \"w\" }\n";
  // approach: its field, event and reset from the mechanics and the impact law
  replace("ode = { x = \"v\", v = \"-k*x - c*v + A*cos(s)\", s = \"w\" }\nevent = \"d - x\"", mechanics +
          "impact = { constraint = \"d - x\", restitution = \"e\" }");
  replace("reset = { x = \"x\", v = \"-e*v\", s = \"s\" }\n", "");
  // rebound: its field from the mechanics, its wrap written out
  replace("ode = { x = \"v\", v = \"-k*x - c*v + A*cos(s)\", s = \"w\" }\nevent = \"pi - s\"", mechanics +
          "event = \"pi - s\"");
  const HybridModel explicit_model = Load("forced-impact-oscillator");
  const HybridModel mechanical = BuildExpressionModel(ParseModelText(lagrangian, "oscillator-lagrangian.toml"));
  const FreeParameters free{{"w"}, {}};
  ExpectSameMap(explicit_model, mechanical, free, 0.5, 0.9, 0.1);
}

}  // namespace
}  // namespace hybridcont
