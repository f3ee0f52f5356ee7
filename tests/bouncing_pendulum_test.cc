// The pendulum on a bouncing slider (models/bouncing-pendulum.toml): a model with two massive degrees of
// freedom and an elastic impact, written from T, V and the impact law. Checked against what does not come
// from the shooting code:
//   - the vertical bouncing in closed form (a ball of mass m1 + m2: period 2 v/g, v = sqrt(2 H/(m1 + m2)))
//     and its period doubling at H = (m1 + m2) g l / 2, where the pendulum's multipliers, the roots of
//     mu^2 - (2 - 4 v^2/(g l)) mu + 1, meet at -1;
//   - every orbit of the diagram, the period-doubled swinging families included, replayed by an
//     event-driven simulation written here from the hand-derived equations of motion and the impact law
//     solved with Eigen (its own integrator, events located by bisection on dense output);
//   - the energy along every orbit, integrated by the library's flow, stays at H̄.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <boost/numeric/odeint.hpp>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "hybridcont/exploration.h"
#include "hybridcont/flow.h"
#include "hybridcont/model_file.h"
#include "hybridcont/period_doubling.h"
#include "hybridcont/shooting_layout.h"
#include "study/engine/model_exploration.h"
#include "study_fixture.h"
#include "study/engine/scenario.h"

namespace hybridcont {
namespace {

namespace odeint = boost::numeric::odeint;

constexpr double m1 = 1.0, m2 = 1.0, l = 1.0, g = 1.0, M = m1 + m2;

HybridModel LoadPendulum() {
  ModelFileOptions options;
  options.cache_dir = std::filesystem::temp_directory_path() / "hybridcont-test-cache";
  return LoadModelFile(std::filesystem::path(HYBRIDCONT_SOURCE_DIR) / "models" / "bouncing-pendulum.toml", options);
}

BifurcationDiagram Explore(const HybridModel& model) { return *StudyOf(model).diagram; }

// ---- the independent simulation: state (y, theta, dy, dtheta)
using State = std::array<double, 4>;

Eigen::Matrix2d MassMatrix(double theta) {
  Eigen::Matrix2d A;
  A << M, m2 * l * std::sin(theta), m2 * l * std::sin(theta), m2 * l * l;
  return A;
}

void Rhs(const State& x, State& dx, double /*t*/) {
  const double s = std::sin(x[1]), c = std::cos(x[1]);
  const Eigen::Vector2d h(-m2 * l * c * x[3] * x[3] - M * g, -m2 * g * l * s);
  const Eigen::Vector2d acc = MassMatrix(x[1]).ldlt().solve(h);
  dx = {x[2], x[3], acc(0), acc(1)};
}

// Newton's law with e = 1 at the contact y = 0 (G = (1, 0)), from M and G directly.
void Impact(State* x) {
  const Eigen::RowVector2d G(1.0, 0.0);
  const Eigen::Vector2d v((*x)[2], (*x)[3]);
  const Eigen::Vector2d w = MassMatrix((*x)[1]).ldlt().solve(G.transpose());
  const Eigen::Vector2d after = v - 2.0 * w * (G * v)(0) / (G * w)(0);
  (*x)[2] = after(0);
  (*x)[3] = after(1);
}

double Energy(const State& x) {
  const double s = std::sin(x[1]), c = std::cos(x[1]);
  return 0.5 * M * x[2] * x[2] + m2 * l * s * x[2] * x[3] + 0.5 * m2 * l * l * x[3] * x[3] + M * g * x[0] +
         m2 * g * l * (1 - c);
}

// From x0 (at the slider's apex) through `impacts` impacts to the next apex; returns the state there and
// the elapsed time in *time. Events (y through 0 downward; dy through 0 downward) located by bisection
// on the dense output to 1e-14 in time.
State Simulate(State x, int impacts, double* time) {
  auto stepper = odeint::make_dense_output(1e-13, 1e-13, odeint::runge_kutta_dopri5<State>());
  double t = 0.0;
  const auto locate = [&](int component) {
    double a = stepper.previous_time(), b = stepper.current_time();
    State xm;
    for (int it = 0; it < 100 && b - a > 1e-14; ++it) {
      const double mid = 0.5 * (a + b);
      stepper.calc_state(mid, xm);
      (xm[component] > 0.0 ? a : b) = mid;
    }
    stepper.calc_state(b, xm);
    return std::pair{b, xm};
  };
  // Leave the apex (dy = 0 there) before looking for the next one.
  bool past_apex = false;
  int done = 0;
  stepper.initialize(x, t, 1e-3);
  for (int steps = 0; steps < 1000000; ++steps) {
    stepper.do_step(Rhs);
    const State& prev = stepper.previous_state();
    const State& cur = stepper.current_state();
    if (done < impacts && prev[0] > 0.0 && cur[0] <= 0.0) {
      auto [te, xe] = locate(0);
      xe[0] = 0.0;
      Impact(&xe);
      ++done;
      stepper.initialize(xe, te, 1e-3);
      past_apex = false;
      continue;
    }
    if (done == impacts && past_apex && prev[2] > 0.0 && cur[2] <= 0.0) {
      auto [te, xe] = locate(2);
      *time = te;
      return xe;
    }
    if (cur[2] > 0.0) past_apex = true;  // rising after the last impact
  }
  *time = NAN;
  return x;
}

TEST(BouncingPendulum, VerticalBouncingAndItsPeriodDoublingInClosedForm) {
  const HybridModel model = LoadPendulum();
  const ShootingLayout layout(model);
  const BifurcationDiagram d = Explore(model);
  const int iH = layout.H_index();
  int points = 0;
  double max_dT = 0;
  for (const Branch& b : d.branches) {
    for (const ContinuationPoint& p : b.points) {
      const double H = p.u(iH), v = std::sqrt(2 * H / M);
      EXPECT_NEAR(layout.Period(p.u), 2 * v / g, 1e-10) << "H = " << H;
      EXPECT_NEAR(p.u(layout.state_offset(0) + 1), 0.0, 1e-12);  // theta = 0 at the apex
      max_dT = std::max(max_dT, std::abs(layout.Period(p.u) - 2 * v / g));
      ++points;
    }
  }
  EXPECT_GT(points, 30);
  int pd = 0;
  for (const SpecialPoint& p : d.special_points) {
    if (p.type != SpecialPointType::kPeriodDoubling) continue;
    ++pd;
    EXPECT_EQ(p.status, LocationStatus::kLocated) << p.BriefReport();
    EXPECT_NEAR(p.u(iH), 0.5 * M * g * l, 1e-9) << p.BriefReport();
    EXPECT_LT(p.precision(), 1e-9) << p.BriefReport();
  }
  EXPECT_EQ(pd, 1) << d.FullReport();
  std::printf("vertical bouncing: %d points, max |T - 2v/g| = %.2g\n", points, max_dT);
}

TEST(BouncingPendulum, EveryOrbitConfirmedByAnEventDrivenSimulationAndKeepsItsEnergy) {
  const HybridModel model = LoadPendulum();
  const ShootingLayout parent(model);
  const BifurcationDiagram d = Explore(model);
  const SpecialPoint* pd = nullptr;
  for (const SpecialPoint& p : d.special_points) {
    if (p.type == SpecialPointType::kPeriodDoubling) pd = &p;
  }
  ASSERT_NE(pd, nullptr);
  // The period-doubled families: the phase sequence traversed twice.
  const HybridModel doubled = RepeatedModel(model, 2);
  const study::Scenario scenario = study::DefaultScenario(doubled);
  ExplorationOptions options = study::ScenarioExplorationOptions(scenario);
  options.threads = 1;
  options.start_conditions.clear();
  study::ModelExploration exploration(doubled, scenario, IntegratorOptions{}, options);
  const BifurcationDiagram dd = exploration.RunPeriodDoubled(parent, pd->u);
  const ShootingLayout layout2(doubled);

  double max_state = 0, max_time = 0, max_drift = 0, max_drift_sim = 0, max_swing = 0;
  int orbits = 0;
  const auto check = [&](const HybridModel& m, const ShootingLayout& layout, const Vector& u, int impacts) {
    const double H = u(layout.H_index()), T = layout.Period(u);
    // The library's flow: the energy along every segment.
    for (int s = 0; s < layout.num_segments(); ++s) {
      const Phase& phase = m.phase(s % m.num_phases());
      PhaseFlow flow(phase, IntegratorOptions{});
      PhaseFlowResult result;
      double drift = 0;
      flow.Integrate(u.segment(layout.state_offset(s), layout.dim(s)), Vector::Zero(1), u(layout.time_index(s)),
                     false, &result, [&](double, const Eigen::Ref<const Vector>& x) {
                       Vector E;
                       phase.FirstIntegrals(x, &E, nullptr, nullptr);
                       drift = std::max(drift, std::abs(E(0) - H));
                     });
      EXPECT_TRUE(result.ok()) << result.message;
      max_drift = std::max(max_drift, drift);
    }
    // The independent simulation from the apex state x1.
    State x0;
    for (int k = 0; k < 4; ++k) x0[k] = u(layout.state_offset(0) + k);
    double t = 0;
    const State x1 = Simulate(x0, impacts, &t);
    double dx = 0;
    for (int k = 0; k < 4; ++k) dx = std::max(dx, std::abs(x1[k] - x0[k]));
    max_state = std::max(max_state, dx);
    max_time = std::max(max_time, std::abs(t - T));
    max_drift_sim = std::max(max_drift_sim, std::abs(Energy(x1) - H));
    max_swing = std::max(max_swing, std::abs(x0[1]));
    EXPECT_LE(dx, 1e-7) << "H = " << H << ", T = " << T;
    EXPECT_NEAR(t, T, 1e-7) << "H = " << H;
    ++orbits;
  };
  for (const Branch& b : d.branches) {
    for (const ContinuationPoint& p : b.points) check(model, parent, p.u, 1);
  }
  int swinging = 0;
  for (const Branch& b : dd.branches) {
    for (const ContinuationPoint& p : b.points) {
      check(doubled, layout2, p.u, 2);
      swinging += std::abs(p.u(layout2.state_offset(0) + 1)) > 1e-3 ? 1 : 0;
    }
  }
  EXPECT_GT(swinging, 50);
  EXPECT_LE(max_drift, 1e-8);
  std::printf("%d orbits (%d swinging, |theta| up to %.2f at the apex): event-driven simulation returns to the "
              "start within %.2g (state) and %.2g (period); energy drift along the orbits %.2g (library flow), "
              "%.2g (simulation)\n",
              orbits, swinging, max_swing, max_state, max_time, max_drift, max_drift_sim);
}

}  // namespace
}  // namespace hybridcont
