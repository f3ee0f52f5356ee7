// Models without first integral (shooting_layout.h, "conservative = false"): the simplest walker and a
// forced impact oscillator, continued in a parameter, checked against what does not come from the shooting
// code:
//   - the walker's gait at gamma = 0.009, its fixed point and the eigenvalues of its stride map, from a
//     simulation-and-root-solve written here (its own integrator, events by bisection, the heel-strike law
//     of Garcia et al. (1998), Newton on the stride map with a finite-difference Jacobian);
//   - the published stability bound of the long-period gait (stable for 0 < gamma < 0.015 rad): its
//     period-doubling point, located, and the period-doubled gait starting at twice the period;
//   - the oscillator's two grazing frequencies against the closed form of the non-impacting response;
//   - the compass gait's heel strike, which the tool derives in extended coordinates, against the
//     angular-momentum balance written here in Cartesian terms; its gaits, multipliers, first period
//     doubling and period-doubled gait against a simulation-and-root-solve with hand-derived equations.
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
#include "study/engine/model_exploration.h"
#include "study/engine/orbit_start.h"
#include "study/engine/run_setup.h"
#include "study/engine/scenario.h"

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
  std::unique_ptr<study::ModelExploration> exploration;
  study::RunSetup setup;
};

ParameterRun Explore(const HybridModel& model) {
  ParameterRun run;
  StudyOptions args;
  args.model = model.name();
  run.setup = study::MakeRunSetup(args, model);
  run.setup.exploration.threads = 1;
  run.exploration = std::make_unique<study::ModelExploration>(model, run.setup.scenario, run.setup.integrator,
                                                            run.setup.exploration, Formulation::kTimeBased,
                                                            run.setup.free);
  const study::OrbitStarts starts = study::FindOrbitStarts(model, run.setup, run.exploration->shooting().layout());
  int skipped = 0;
  run.diagram = run.exploration->RunFromStarts(starts.points, {}, &skipped);
  return run;
}

// The run's one period-doubling point, checked located to 1e-8; null if there is none.
const SpecialPoint* OnlyPeriodDoubling(const BifurcationDiagram& diagram) {
  const SpecialPoint* pd = nullptr;
  for (const SpecialPoint& sp : diagram.special_points) {
    if (sp.type == SpecialPointType::kPeriodDoubling) {
      EXPECT_EQ(pd, nullptr) << "a second PD point: " << sp.BriefReport();
      pd = &sp;
    }
  }
  if (pd != nullptr) {
    EXPECT_EQ(pd->status, LocationStatus::kLocated);
    EXPECT_LT(pd->precision(), 1e-8);
  }
  return pd;
}

// The period-doubled family from `pd`, `points` points of it, in the run's free parameter.
struct DoubledRun {
  std::unique_ptr<HybridModel> model;  // the exploration refers to it
  std::unique_ptr<study::ModelExploration> exploration;
  BifurcationDiagram diagram;
};
DoubledRun ExplorePeriodDoubled(const HybridModel& model, const ParameterRun& run, const SpecialPoint& pd,
                                int points) {
  DoubledRun out;
  out.model = std::make_unique<HybridModel>(RepeatedModel(model, 2));
  const study::Scenario scenario = study::DefaultScenario(*out.model);
  ExplorationOptions options = study::ScenarioExplorationOptions(scenario);
  options.threads = 1;
  options.continuation.max_points = points;
  out.exploration = std::make_unique<study::ModelExploration>(*out.model, scenario, IntegratorOptions{}, options,
                                                            Formulation::kTimeBased, run.setup.free);
  out.diagram = out.exploration->RunPeriodDoubled(run.exploration->shooting().layout(), pd.u);
  return out;
}

// ---- the walker by hand: state (theta, phi, theta', phi') right after a heel strike, phi = 2 theta.
constexpr double kGamma = 0.009;
using State = std::array<double, 4>;

// Integrates x from t = 0 (odeint's dopri5 with dense output, tolerances 1e-13) to the first zero of the
// guard e crossed downward where `ahead` holds, located by bisection on the dense output to 1e-15 in time.
// False if there is none before t_max.
template <class Rhs, class Guard, class Ahead>
bool IntegrateToEvent(const State& x, Rhs rhs, Guard e, Ahead ahead, double t_max, State* at, double* t) {
  auto stepper = odeint::make_dense_output(1e-13, 1e-13, odeint::runge_kutta_dopri5<State>());
  stepper.initialize(x, 0.0, 1e-3);
  for (int steps = 0; steps < 100000 && stepper.current_time() < t_max; ++steps) {
    stepper.do_step(rhs);
    const State& a = stepper.previous_state();
    const State& b = stepper.current_state();
    if (ahead(b) && e(a) > 0 && e(b) <= 0) {
      double lo = stepper.previous_time(), hi = stepper.current_time();
      for (int it = 0; it < 200 && hi - lo > 1e-15; ++it) {
        const double mid = 0.5 * (lo + hi);
        stepper.calc_state(mid, *at);
        (e(*at) > 0 ? lo : hi) = mid;
      }
      stepper.calc_state(hi, *at);
      *t = hi;
      return true;
    }
  }
  return false;
}

void WalkerRhs(const State& x, State& dx, double) {
  const double a = std::sin(x[0] - kGamma);
  dx = {x[2], x[3], a, a + x[2] * x[2] * std::sin(x[1]) - std::cos(x[0] - kGamma) * std::sin(x[1])};
}

// The stride map on (theta, theta') after heel strike: integrate to the next heel strike (2 theta - phi
// crossing zero downward with theta < 0), located by bisection on the dense output, then the heel strike.
Eigen::Vector2d Stride(const Eigen::Vector2d& z, double* period) {
  const State x = {z(0), 2 * z(0), z(1), (1 - std::cos(2 * z(0))) * z(1)};
  State s;
  if (IntegrateToEvent(x, WalkerRhs, [](const State& y) { return 2 * y[0] - y[1]; },
                       [](const State& y) { return y[0] < 0; }, 1e3, &s, period)) {
    const double c = std::cos(2 * s[0]);
    return {-s[0], c * s[2]};
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
  const Eigen::Vector2cd mu = Eigenvalues(S);

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
  const SpecialPoint* pd = OnlyPeriodDoubling(run.diagram);
  ASSERT_NE(pd, nullptr) << run.diagram.FullReport();
  // "stable when 0 < gamma < 0.015 rad": the bound, to the digits published.
  EXPECT_NEAR(pd->u(p), 0.0151, 5e-5) << pd->BriefReport();
  const FloquetResult at_pd = ComputeFloquet(run.exploration->shooting(), pd->u);
  ASSERT_TRUE(at_pd.ok());
  EXPECT_NEAR(at_pd.nontrivial.front().real(), -1.0, 1e-6);
  // The period-doubled gait: starts at twice the period, is stable at first (the paper's period-two gait).
  DoubledRun doubled = ExplorePeriodDoubled(model, run, *pd, 20);
  const BifurcationDiagram& d2 = doubled.diagram;
  study::ModelExploration& ex2 = *doubled.exploration;
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
  static constexpr int kDimension = 4;  // compiled for this dimension only (model_builder.h)
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
  static constexpr int kDimension = 4;
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


// ---- The compass gait by hand (Goswami et al. 1998; angles from the slope normal, positive forward; legs
// of mass m with their centre at a from the foot and inertia I about it, hip mass mH). Equations derived
// on paper: M(q) q̈ = h with
//     M = [[m a² + (mH + m) l² + I, m l b cos(θs + θw)], [m l b cos(θs + θw), m b² + I]],
//     h = (m l b sin(θs + θw) θ̇w² + g (m a + (mH + m) l) sin(θs + γ),
//          m l b sin(θs + θw) θ̇s² − g m b sin(θw − γ)).
struct CompassGait {
  double gamma = 0.03, m = 5, mH = 10, a = 0.5, b = 0.5, I = 5.0 / 12.0, g = 9.81;
  double l() const { return a + b; }

  void Rhs(const State& x, State& dx) const {
    const double S = std::sin(x[0] + x[1]), C = std::cos(x[0] + x[1]);
    Eigen::Matrix2d M;
    M << m * a * a + (mH + m) * l() * l() + I, m * l() * b * C, m * l() * b * C, m * b * b + I;
    const Eigen::Vector2d h(m * l() * b * S * x[3] * x[3] + g * (m * a + (mH + m) * l()) * std::sin(x[0] + gamma),
                            m * l() * b * S * x[2] * x[2] - g * m * b * std::sin(x[1] - gamma));
    const Eigen::Vector2d acc = M.ldlt().solve(h);
    dx = {x[2], x[3], acc(0), acc(1)};
  }

  // Angular momentum (about `at`) of the bodies listed (0 stance leg, 1 hip, 2 swing leg) at state x with the
  // stance foot at `foot`: Σ m (r − at) × v + I ω, ω = −θ̇s for the stance leg, +θ̇w for the swing leg.
  double AngularMomentum(const State& x, const Eigen::Vector2d& foot, const Eigen::Vector2d& at,
                         std::initializer_list<int> bodies) const {
    const Eigen::Vector2d es(std::sin(x[0]), std::cos(x[0])), ds(std::cos(x[0]), -std::sin(x[0]));
    const Eigen::Vector2d ew(std::sin(x[1]), -std::cos(x[1])), dw(std::cos(x[1]), std::sin(x[1]));
    const Eigen::Vector2d hip = foot + l() * es, v_hip = l() * x[2] * ds;
    const auto cross = [](const Eigen::Vector2d& p, const Eigen::Vector2d& q) { return p(0) * q(1) - p(1) * q(0); };
    double L = 0;
    for (int k : bodies) {
      if (k == 0) L += m * cross(foot + a * es - at, a * x[2] * ds) - I * x[2];
      if (k == 1) L += mH * cross(hip - at, v_hip);
      if (k == 2) L += m * cross(hip + b * ew - at, v_hip + b * x[3] * dw) + I * x[3];
    }
    return L;
  }

  // The plastic heel strike: the whole walker's angular momentum about the new foot and the trailing leg's
  // about the hip are kept; the legs exchange their roles (θs' = −θw, θw' = −θs). Solved for the two new
  // rates from the linear balance, column by column.
  State HeelStrike(const State& x) const {
    const Eigen::Vector2d foot(0, 0);
    const Eigen::Vector2d hip = l() * Eigen::Vector2d(std::sin(x[0]), std::cos(x[0]));
    const Eigen::Vector2d new_foot = hip + l() * Eigen::Vector2d(std::sin(x[1]), -std::cos(x[1]));
    const Eigen::Vector2d before(AngularMomentum(x, foot, new_foot, {0, 1, 2}), AngularMomentum(x, foot, hip, {0}));
    const auto after = [&](double ws, double ww) {
      const State y = {-x[1], -x[0], ws, ww};
      return Eigen::Vector2d(AngularMomentum(y, new_foot, new_foot, {0, 1, 2}),
                             AngularMomentum(y, new_foot, hip, {2}));
    };
    Eigen::Matrix2d A;
    A << after(1, 0), after(0, 1);
    const Eigen::Vector2d w = A.lu().solve(before);
    return {-x[1], -x[0], w(0), w(1)};
  }

  // The stride map on z = (α, θ̇s, θ̇w) right after a heel strike (θs = θw = −α): to the next heel strike
  // (θw − θs crossing zero downward with θs > 0, located by bisection on the dense output), then the strike.
  Eigen::Vector3d Stride(const Eigen::Vector3d& z, double* period) const {
    State x = {-z(0), -z(0), z(1), z(2)};
    State s;
    if (IntegrateToEvent(x, [this](const State& y, State& dy, double) { Rhs(y, dy); },
                         [](const State& y) { return y[1] - y[0]; }, [](const State& y) { return y[0] > 0; }, 10, &s,
                         period)) {
      const State y = HeelStrike(s);
      return {-y[0], y[2], y[3]};
    }
    *period = NAN;
    return Eigen::Vector3d::Constant(NAN);
  }

  Eigen::Matrix3d StrideJacobian(const Eigen::Vector3d& z, double h) const {
    Eigen::Matrix3d J;
    double t;
    for (int j = 0; j < 3; ++j) {
      Eigen::Vector3d zp = z, zm = z;
      zp(j) += h;
      zm(j) -= h;
      J.col(j) = (Stride(zp, &t) - Stride(zm, &t)) / (2 * h);
    }
    return J;
  }

  // Newton on z -> Stride(z) − z with a finite-difference Jacobian.
  Eigen::Vector3d FixedPoint(Eigen::Vector3d z) const {
    double t;
    for (int it = 0; it < 30; ++it) {
      const Eigen::Vector3d r = Stride(z, &t) - z;
      if (r.norm() < 1e-13) break;
      z -= (StrideJacobian(z, 1e-7) - Eigen::Matrix3d::Identity()).lu().solve(r);
    }
    return z;
  }
};

// The state of the compass gait's step right after a heel strike, from the tool's unknowns.
Eigen::Vector3d AfterHeelStrike(const ShootingLayout& layout, const Vector& u, int segment) {
  const int x = layout.state_offset(segment);
  return {-u(x), u(x + 2), u(x + 3)};
}

// The derived heel strike (extended coordinates, e = 0 on the new foot's two constraints, relabelling) is
// the angular-momentum law, at random pre-impact states on the guard, to rounding.
TEST(CompassGait, DerivedHeelStrikeIsTheAngularMomentumLaw) {
  const HybridModel model = Load("compass-gait");
  const CompassGait hand;
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> angle(0.05, 0.5), rate(-2.0, 2.0);
  double worst = 0;
  for (int trial = 0; trial < 20; ++trial) {
    const double alpha = angle(rng);
    const State x = {alpha, alpha, rate(rng), rate(rng)};
    Vector xt = Eigen::Map<const Vector>(x.data(), 4), next;
    model.phase(0).Reset(xt, &next, nullptr);
    const State y = hand.HeelStrike(x);
    for (int k = 0; k < 4; ++k) worst = std::max(worst, std::abs(next(k) - y[k]) / (1 + std::abs(y[k])));
  }
  EXPECT_LT(worst, 1e-13);
  std::printf("compass gait: derived heel strike vs angular-momentum law, worst relative difference %.1e\n", worst);
}

// With the file's uniform-bar legs and with Goswami's point-mass legs (I = 0), from the same shipped starts.
class CompassGaitLegs : public ::testing::TestWithParam<double> {};

TEST_P(CompassGaitLegs, GaitsMultipliersAndPeriodDoublingAgreeWithAnIndependentRootSolve) {
  HybridModel model = Load("compass-gait");
  model.SetParameter("I", GetParam());
  const ParameterRun run = Explore(model);
  ASSERT_EQ(run.diagram.status, ExplorationStatus::kCompleted) << run.diagram.message;
  const ShootingLayout& layout = run.exploration->shooting().layout();
  const int p = layout.parameter_index(0);
  CompassGait hand;
  hand.I = GetParam();
  // Both gaits at gamma = 0.03: the first point of each start's branch.
  int checked = 0;
  for (const Branch& b : run.diagram.branches) {
    if (b.points.empty() || b.direction != 1) continue;
    const Vector& u = b.points.front().u;
    // The start's gamma, up to the rounding of the corrector's last step along the curve (|r| ~ 1e-15 times
    // the condition of dr: 7e-15 for the bars' legs, 6e-14 for point masses).
    ASSERT_NEAR(u(p), 0.03, 1e-13);
    const Eigen::Vector3d tool = AfterHeelStrike(layout, u, 1);
    const Eigen::Vector3d z = hand.FixedPoint(tool + Eigen::Vector3d(1e-3, -2e-3, 2e-3));
    double T;
    hand.Stride(z, &T);
    EXPECT_LT((tool - z).lpNorm<Eigen::Infinity>(), 1e-9) << tool.transpose() << " vs " << z.transpose();
    EXPECT_NEAR(layout.Period(u), T, 1e-9);
    // Multipliers: the stride map's three are the tool's (its fourth, of the section map in the full
    // state, is 0: the heel strike puts θs = θw).
    const Eigen::Vector3cd mu = Eigenvalues(hand.StrideJacobian(z, 1e-6));
    const FloquetResult f = ComputeFloquet(run.exploration->shooting(), u);
    ASSERT_TRUE(f.ok()) << f.message;
    int matched = 0;
    for (const std::complex<double>& m : f.nontrivial) {
      if (std::abs(m) < 1e-9) continue;
      double d = 1e300;
      for (int i = 0; i < 3; ++i) d = std::min(d, std::abs(m - mu(i)));
      EXPECT_LT(d, 1e-6 * (1 + std::abs(m))) << m << " vs " << mu.transpose();
      ++matched;
    }
    EXPECT_EQ(matched, 3);
    std::printf("compass gait (I = %g) at gamma = 0.03: alpha = %.12f, period %.12f (tool - root solve %.1e, %.1e), "
                "multipliers |mu| max %.9f (root solve %.9f)\n",
                hand.I, z(0), T, (tool - z).lpNorm<Eigen::Infinity>(), layout.Period(u) - T, f.max_modulus,
                mu.cwiseAbs().maxCoeff());
    ++checked;
  }
  EXPECT_EQ(checked, 2);

  // The first period doubling, on the long-step gait: the root solve's stride map has the multiplier −1
  // there; its slope, found from the root solve alone by the secant method on that multiplier, agrees.
  const SpecialPoint* pd = OnlyPeriodDoubling(run.diagram);
  ASSERT_NE(pd, nullptr) << run.diagram.FullReport();
  const auto most_negative = [&](double gamma, Eigen::Vector3d* z) {
    hand.gamma = gamma;
    *z = hand.FixedPoint(*z);
    const Eigen::Vector3cd mu = Eigenvalues(hand.StrideJacobian(*z, 1e-6));
    double v = 1e300;
    for (int i = 0; i < 3; ++i) {
      if (std::abs(mu(i).imag()) < 1e-9) v = std::min(v, mu(i).real());
    }
    return v;
  };
  Eigen::Vector3d z = AfterHeelStrike(layout, pd->u, 1);
  double g0 = pd->u(p) - 1e-3, g1 = pd->u(p) + 1e-3;
  double f0 = most_negative(g0, &z) + 1, f1 = most_negative(g1, &z) + 1;
  for (int it = 0; it < 8 && std::abs(g1 - g0) > 1e-12; ++it) {
    const double g2 = g1 - f1 * (g1 - g0) / (f1 - f0);
    g0 = g1, f0 = f1;
    g1 = g2, f1 = most_negative(g1, &z) + 1;
  }
  EXPECT_NEAR(pd->u(p), g1, 1e-7);
  std::printf("compass gait (I = %g): first PD at gamma = %.12f (precision %.1e); root solve's multiplier -1 at %.12f\n",
              hand.I, pd->u(p), pd->precision(), g1);

  // The period-doubled gait beyond it: two different steps, each the root solve's stride of the other.
  DoubledRun doubled = ExplorePeriodDoubled(model, run, *pd, 8);
  const BifurcationDiagram& d2 = doubled.diagram;
  study::ModelExploration& ex2 = *doubled.exploration;
  ASSERT_EQ(d2.status, ExplorationStatus::kCompleted) << d2.message;
  ASSERT_FALSE(d2.branches.empty());
  const ShootingLayout& layout2 = ex2.shooting().layout();
  const Vector& u2 = d2.branches.front().points.back().u;
  hand.gamma = u2(layout2.parameter_index(0));
  EXPECT_GT(std::abs(hand.gamma - pd->u(p)), 1e-3);
  const Eigen::Vector3d z1 = AfterHeelStrike(layout2, u2, 1), z2 = AfterHeelStrike(layout2, u2, 3);
  EXPECT_GT((z1 - z2).norm(), 1e-3);
  double T1, T2;
  EXPECT_LT((hand.Stride(z1, &T1) - z2).lpNorm<Eigen::Infinity>(), 1e-9);
  EXPECT_LT((hand.Stride(z2, &T2) - z1).lpNorm<Eigen::Infinity>(), 1e-9);
  EXPECT_NEAR(layout2.Period(u2), T1 + T2, 1e-9);
  std::printf("compass gait: period-doubled gait at gamma = %.6f, steps alpha = %.9f and %.9f, period %.12f "
              "(root solve %.12f)\n", hand.gamma, z1(0), z2(0), layout2.Period(u2), T1 + T2);
}

INSTANTIATE_TEST_SUITE_P(BarAndPointMassLegs, CompassGaitLegs, ::testing::Values(5.0 / 12.0, 0.0));

// The compiled entry points with the parameters as jets (runs in a parameter) are the interpreter's
// EvaluateWithParameterJets: r and dr, the parameter column included, agree at random points.
TEST(CompassGait, CompiledParameterJetsAreTheInterpreter) {
  ModelFileOptions interpreted;
  interpreted.compile = false;
  const HybridModel plain = LoadModelFile(std::filesystem::path(HYBRIDCONT_SOURCE_DIR) / "models" / "compass-gait.toml",
                                          interpreted);
  const HybridModel compiled = Load("compass-gait");
  ExpectSameMap(compiled, plain, FreeParameters{{"gamma"}, {}}, 0.2, 0.03, 0.01);
}

// A Neimark–Sacker point with a known place: a clock phase whose reset rotates (x, y) by theta and scales
// it by a. The orbit x = y = 0 exists for every a; its return map has the multipliers a e^{±i theta}, so
// the complex pair crosses the unit circle at a = 1 exactly (ns_test = a² − 1 there, floquet.h).
TEST(NeimarkSacker, ComplexPairCrossesTheUnitCircleWhereTheClosedFormSays) {
  const char* text = R"toml(
hybridcont = 1
name = "rotation-map"
conservative = false

[parameters]
a = { value = 0.8, range = "(0, inf)" }
theta = { value = 1.0, range = "(-inf, inf)" }

[[phases]]
name = "tick"
states = ["s", "x", "y"]
typical = [0.5, 0.1, 0.1]
ode = { s = "1", x = "0.1*x*y", y = "-0.1*x*x" }
event = "1 - s"
anchor = "0.5 - s"
reset = { s = "0", x = "a*(cos(theta)*x - sin(theta)*y)", y = "a*(sin(theta)*x + cos(theta)*y)" }

[start]
kind = "guess"
values = { t1 = 0.5, t2 = 0.5, x1_s = 0.5 }

[run]
parameter = "a"
bounds = { a = [0.5, 1.5], period = [0, 10] }
)toml";
  const HybridModel model = BuildExpressionModel(ParseModelText(text, "rotation-map.toml"));
  const ParameterRun run = Explore(model);
  ASSERT_EQ(run.diagram.status, ExplorationStatus::kCompleted) << run.diagram.message;
  const ShootingLayout& layout = run.exploration->shooting().layout();
  std::vector<const SpecialPoint*> ns;
  for (const SpecialPoint& sp : run.diagram.special_points) {
    if (sp.type == SpecialPointType::kNeimarkSacker && sp.duplicate_of < 0) ns.push_back(&sp);
  }
  ASSERT_EQ(ns.size(), 1u) << run.diagram.FullReport();
  EXPECT_EQ(ns[0]->status, LocationStatus::kLocated);
  EXPECT_NEAR(ns[0]->u(layout.parameter_index(0)), 1.0, 1e-10) << ns[0]->BriefReport();
  const FloquetResult f = ComputeFloquet(run.exploration->shooting(), ns[0]->u);
  ASSERT_TRUE(f.ok());
  ASSERT_EQ(f.nontrivial.size(), 2u);
  EXPECT_NEAR(std::abs(f.nontrivial[0]), 1.0, 1e-10);
  EXPECT_NEAR(std::abs(std::arg(f.nontrivial[0])), 1.0, 1e-10);  // the rotation angle theta
  std::printf("rotation map: NS at a = %.13f (exact 1), multipliers %.12f%+.12fi\n",
              ns[0]->u(layout.parameter_index(0)), f.nontrivial[0].real(), f.nontrivial[0].imag());
}

}  // namespace
}  // namespace hybridcont
