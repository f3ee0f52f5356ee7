// The state-based map (paper eq. `statebased`): its zeros are the time-based ones, its Jacobian (the
// saltation chain of eq. `PoincareJacobian`, and the xi-chain) matches finite differences for every
// built-in model, Thm 2.1 holds on computed orbits, it fails where the paper says it must (SLIP start
// point) while the time-based map evaluates, and replay confirms physical orbits.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <random>

#include <Eigen/Dense>

#include "hybridcont/models.h"
#include "hybridcont/replay.h"
#include "hybridcont/statebased_shooting.h"
#include "hybridcont/timebased_shooting.h"
#include "known_orbits.h"
#include "vector_literal.h"

namespace hybridcont {
namespace {

// Tight tolerances for finite-difference checks: central differences of an adaptively integrated map
// carry noise ~tol/h (1e-13 / 1e-4 = 1e-9); Richardson extrapolation (below) makes the truncation O(h^4).
PoincareOptions TightOptions() {
  PoincareOptions o;
  o.event.integrator.rtol = o.event.integrator.atol = 1e-13;
  return o;
}

// Richardson-extrapolated central differences, (4 D(h/2) - D(h)) / 3: truncation O(h^4) instead of O(h^2).
// Near the rocking block's separatrix plain central differences at h = 1e-5 are off by ~5e-7 relative
// (measured: the error falls by 100x per 10x smaller h, towards the analytic value).
template <class Map>
Matrix Richardson(Map&& map, const Vector& u, double h) {
  auto central = [&](double step) {
    Matrix d;
    for (int j = 0; j < u.size(); ++j) {
      Vector up = u, um = u;
      up(j) += step;
      um(j) -= step;
      const Vector col = (map(up) - map(um)) / (2.0 * step);
      if (j == 0) d.resize(col.size(), u.size());
      d.col(j) = col;
    }
    return d;
  };
  return (4.0 * central(h / 2.0) - central(h)) / 3.0;
}

Matrix CentralDifferences(ZeroProblem& problem, const Vector& u, double h) {
  return Richardson(
      [&](const Vector& v) {
        Vector r;
        EXPECT_TRUE(problem.Evaluate(v, &r, nullptr).ok);
        return r;
      },
      u, h);
}

// Newton on [r(u); u_H - H] (square) from u: the state-based orbit at the level H.
bool SolveAtLevel(StateBasedShooting& sb, Vector* u, double H) {
  const int N = sb.num_equations();
  for (int it = 0; it < 20; ++it) {
    Vector r;
    Matrix dr;
    if (!sb.Evaluate(*u, &r, &dr).ok) return false;
    Matrix J(N + 1, N + 1);
    J << dr, Matrix::Zero(1, N + 1);
    J(N, sb.H_index()) = 1.0;
    Vector rhs(N + 1);
    rhs << r, (*u)(sb.H_index()) - H;
    if (rhs.norm() < 1e-12) return true;
    *u -= J.colPivHouseholderQr().solve(rhs);
  }
  return false;
}

TEST(StateBased, UnknownNamesAreThoseOfTheTimeBasedLayout) {
  const HybridModel slip = MakeSlip();
  StateBasedShooting sb(slip, PoincareOptions{});
  const std::vector<std::string> expected = {"x1_alpha", "x1_l", "x1_dalpha", "x1_dl", "xi", "H"};
  EXPECT_EQ(sb.unknown_names(), expected);
  EXPECT_EQ(sb.num_equations(), 5);  // N = n1 + 1
}

TEST(StateBased, BallZerosMatchTheTimeBasedOnesAndThePeriodSqrt8H) {
  const HybridModel ball = MakeBouncingBall();
  const ShootingLayout layout(ball);
  StateBasedShooting sb(ball, PoincareOptions{});
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> noise(-0.02, 0.02);
  for (double H : {0.3, 1.0, 2.5}) {
    const Vector u_tb = BallOrbit(layout, H);
    Vector u = sb.FromTimeBased(u_tb);
    Vector r;
    ASSERT_TRUE(sb.Evaluate(u, &r, nullptr).ok);
    EXPECT_LT(r.norm(), 1e-12) << "H = " << H;  // the flight is a parabola: integration is exact
    EXPECT_NEAR(sb.last_map().period, std::sqrt(8.0 * H), 1e-12);
    // Newton from a perturbed state converges back onto the closed-form orbit.
    Vector guess = u;
    guess(0) += noise(rng);
    guess(1) += noise(rng);
    guess(sb.xi_index()) = 0.01;
    ASSERT_TRUE(SolveAtLevel(sb, &guess, H)) << "H = " << H;
    EXPECT_NEAR(guess(0), H, 1e-12);
    EXPECT_NEAR(guess(1), 0.0, 1e-12);
    EXPECT_NEAR(guess(sb.xi_index()), 0.0, 1e-12);  // Thm 3.1: fixed points of P~ have xi = 0
    EXPECT_NEAR(sb.last_map().period, std::sqrt(8.0 * H), 1e-12);
  }
}

TEST(StateBased, SlipHoppingInPlaceMatchesTheTimeBasedOrbitBothWays) {
  const HybridModel slip = MakeSlip();
  const ShootingLayout layout(slip);
  StateBasedShooting sb(slip, PoincareOptions{});
  TimeBasedShooting tb(slip, IntegratorOptions{});
  for (double H : {1.1, 1.4, 2.0}) {
    const Vector u_tb = SlipHoppingInPlace(slip, layout, H);
    const Vector u = sb.FromTimeBased(u_tb);
    Vector r, r_tb;
    ASSERT_TRUE(sb.Evaluate(u, &r, nullptr).ok);
    ASSERT_TRUE(tb.Evaluate(u_tb, &r_tb, nullptr).ok);
    EXPECT_LT(r.norm(), 1e-9) << "H = " << H;
    EXPECT_LT(r_tb.norm(), 1e-9) << "H = " << H;
    EXPECT_NEAR(sb.last_map().period, layout.Period(u_tb), 1e-9) << "H = " << H;
    // back to the time-based layout: durations and phase starts of the closed form
    Vector u_back;
    ASSERT_TRUE(sb.ToTimeBased(u, &u_back).ok);
    EXPECT_LT((u_back - u_tb).lpNorm<Eigen::Infinity>(), 1e-9) << "H = " << H;
    // and Newton on the state-based map from a perturbed start finds the same x̄_1
    Vector guess = u;
    guess(1) += 0.003;
    guess(3) -= 0.01;
    ASSERT_TRUE(SolveAtLevel(sb, &guess, H)) << "H = " << H;
    EXPECT_LT((guess - u).norm(), 1e-9) << "H = " << H;
  }
}

TEST(StateBased, JacobianMatchesCentralDifferencesAtPhysicalOrbits) {
  // ball and SLIP at their closed-form orbits, with xi = 0 and with xi != 0 (the Psi chain)
  const HybridModel ball = MakeBouncingBall();
  const HybridModel slip = MakeSlip();
  struct Case {
    const HybridModel* model;
    Vector u_tb;
  };
  const std::vector<Case> cases = {{&ball, BallOrbit(ShootingLayout(ball), 0.7)},
                                   {&slip, SlipHoppingInPlace(slip, ShootingLayout(slip), 1.4)},
                                   {&slip, SlipHoppingInPlace(slip, ShootingLayout(slip), 2.0)}};
  for (const Case& c : cases) {
    StateBasedShooting sb(*c.model, TightOptions());
    for (double xi : {0.0, 0.02}) {
      Vector u = sb.FromTimeBased(c.u_tb);
      u(sb.xi_index()) = xi;
      if (c.model == &slip) u(0) = 0.03;  // lean the leg: the alpha-coupling enters dP
      Vector r;
      Matrix dr;
      ASSERT_TRUE(sb.Evaluate(u, &r, &dr).ok) << sb.last_map().message;
      const Matrix fd = CentralDifferences(sb, u, 1e-4);
      const double err = (fd - dr).norm() / dr.norm();
      EXPECT_LT(err, 1e-8) << c.model->name() << " xi = " << xi << "\nanalytic\n" << dr << "\nfd\n" << fd;  // ~1e-10
      // the xi column alone (dP~/dxi through the saltations)
      const double err_xi = (fd.col(sb.xi_index()) - dr.col(sb.xi_index())).norm() / dr.col(sb.xi_index()).norm();
      EXPECT_LT(err_xi, 1e-8) << c.model->name() << " xi = " << xi;
    }
  }
}

TEST(StateBased, PoincareMapDerivativesOfBlockAndRodMatchCentralDifferences) {
  // Not periodic orbits: states on the section from which every event fires; the map's derivative is
  // checked. The rod uses r = 0.3: at the default r = 0.01 an end impact of the thin rod changes mostly
  // its spin, the centre keeps falling after both impacts and from apex states of O(1) height the anchor
  // (apex) is never reached again (kGuardNotReached; its saltations are checked in event_flow_test.cc).
  struct Case {
    std::string model;
    double rod_r;
    Vector x0;
  };
  const std::vector<Case> cases = {{"rocking-block", 0.0, Vec({0.1, 0.0})},
                                   {"rocking-block", 0.0, Vec({0.2, 0.0})},
                                   {"bouncing-rod", 0.3, Vec({0.3, 0.2, 0.0, 0.5})},
                                   {"bouncing-rod", 0.3, Vec({0.6, -0.2, 0.0, 2.0})}};
  for (const Case& c : cases) {
    HybridModel model = MakeBuiltinModel(c.model);
    if (c.rod_r > 0.0) model.SetParameter("r", c.rod_r);
    PoincareMap map(model, TightOptions());
    const int n = static_cast<int>(c.x0.size());
    for (double xi_value : {0.0, 0.01}) {
      PoincareResult res;
      ASSERT_EQ(map.Evaluate(c.x0, Vector::Constant(1, xi_value), true, &res), PoincareStatus::kSuccess)
          << c.model << ": " << res.message;
      // derivative with respect to [x0; xi] at once
      Vector v(n + 1);
      v << c.x0, xi_value;
      const Matrix fd = Richardson(
          [&](const Vector& w) {
            PoincareResult r;
            EXPECT_EQ(map.Evaluate(w.head(n), w.tail(1), false, &r), PoincareStatus::kSuccess) << r.message;
            return r.x;
          },
          v, 1e-4);
      EXPECT_LT((fd.leftCols(n) - res.dP_dx0).norm() / res.dP_dx0.norm(), 1e-8)
          << c.model << " x0 = " << c.x0.transpose() << " xi = " << xi_value << "\nanalytic\n" << res.dP_dx0
          << "\nfd\n" << fd.leftCols(n);
      EXPECT_LT((fd.col(n) - res.dP_dxi).norm() / res.dP_dxi.norm(), 1e-8)
          << c.model << " x0 = " << c.x0.transpose() << " xi = " << xi_value << "\nanalytic " << res.dP_dxi.transpose()
          << "\nfd " << fd.col(n).transpose();
    }
  }
}

TEST(StateBased, LastEventSectionOfAppendixBHasTheDerivativeOfItsMap) {
  // The ball with the section at the impact itself: x0 right after impact, P~ = state right after the next.
  const HybridModel ball = MakeBouncingBall();
  PoincareOptions opts = TightOptions();
  opts.section = PoincareSection::kLastEvent;
  PoincareMap map(ball, opts);
  const Vector x0 = Vec({0.0, 1.3});
  const Vector xi = Vector::Constant(1, 0.05);
  PoincareResult res;
  ASSERT_EQ(map.Evaluate(x0, xi, true, &res), PoincareStatus::kSuccess) << res.message;
  // perturb off the section too: the map is defined for any x0 (Remark `poincareSection`)
  const double h = 1e-5;
  Matrix fd(2, 2);
  for (int j = 0; j < 2; ++j) {
    Vector xp = x0, xm = x0;
    xp(j) += h;
    xm(j) -= h;
    PoincareResult rp, rm;
    ASSERT_TRUE(map.Evaluate(xp, xi, false, &rp) == PoincareStatus::kSuccess) << rp.message;
    ASSERT_TRUE(map.Evaluate(xm, xi, false, &rm) == PoincareStatus::kSuccess) << rm.message;
    fd.col(j) = (rp.x - rm.x) / (2.0 * h);
  }
  EXPECT_LT((fd - res.dP_dx0).norm() / res.dP_dx0.norm(), 1e-7) << "\nanalytic\n" << res.dP_dx0 << "\nfd\n" << fd;
  PoincareResult rp, rm;
  ASSERT_TRUE(map.Evaluate(x0, xi.array() + h, false, &rp) == PoincareStatus::kSuccess);
  ASSERT_TRUE(map.Evaluate(x0, xi.array() - h, false, &rm) == PoincareStatus::kSuccess);
  EXPECT_LT(((rp.x - rm.x) / (2.0 * h) - res.dP_dxi).norm() / res.dP_dxi.norm(), 1e-7);
  // At xi = 0 the orbit from (0, v) returns to (0, v): a fixed point of the last-event map.
  ASSERT_EQ(map.Evaluate(x0, Vector::Zero(1), true, &res), PoincareStatus::kSuccess);
  EXPECT_LT((res.x - x0).norm(), 1e-12);
  EXPECT_NEAR(res.period, 2.6, 1e-12);  // 2 v / g
}

TEST(StateBased, FirstIntegralIsALeftEigenvectorOfTheMapJacobianAtFixedPoints) {
  // Thm 2.1, eq. `leftEigen`: dH_1(x0) dP = dH_1(x0).
  const HybridModel ball = MakeBouncingBall();
  const HybridModel slip = MakeSlip();
  std::vector<std::pair<const HybridModel*, Vector>> orbits;
  for (double H : {0.5, 2.0}) orbits.push_back({&ball, BallOrbit(ShootingLayout(ball), H)});
  for (double H : {1.1, 1.4, 1.8}) orbits.push_back({&slip, SlipHoppingInPlace(slip, ShootingLayout(slip), H)});
  for (const auto& [model, u_tb] : orbits) {
    StateBasedShooting sb(*model, PoincareOptions{});
    const Vector u = sb.FromTimeBased(u_tb);
    Vector r;
    Matrix dr;
    ASSERT_TRUE(sb.Evaluate(u, &r, &dr).ok);
    Vector H;
    Matrix dH;
    model->phase(0).FirstIntegrals(u.head(model->phase(0).dim()), &H, &dH, nullptr);
    const RowVector left = dH.row(0) * sb.last_map().dP_dx0;
    EXPECT_LT((left - dH.row(0)).norm() / dH.row(0).norm(), 1e-8) << model->name() << " H = " << u(sb.H_index());
  }
}

TEST(StateBased, FailsAtTheSlipStartPointWhereTheTimeBasedMapEvaluates) {
  const HybridModel slip = MakeSlip();
  const Vector u0 = BuiltinStartPoint(slip);  // zero flight time, lift-off with dl = 0
  TimeBasedShooting tb(slip, IntegratorOptions{});
  Vector r;
  Matrix dr;
  ASSERT_TRUE(tb.Evaluate(u0, &r, &dr).ok);
  EXPECT_LT(r.norm(), 1e-9);
  StateBasedShooting sb(slip, PoincareOptions{});
  const EvaluationStatus s = sb.Evaluate(sb.FromTimeBased(u0), &r, &dr);
  EXPECT_FALSE(s.ok);
  EXPECT_NE(s.message.find("grazing"), std::string::npos) << s.message;
  EXPECT_NE(s.message.find("phase 'stance'"), std::string::npos) << s.message;
  EXPECT_EQ(sb.last_map().failed_phase, 0);
  EXPECT_EQ(sb.last_map().event_status, EventFlowStatus::kGrazing);
  // the value alone fails the same way (it is the map that does not exist, not its derivative)
  StateBasedShooting value_only(slip, PoincareOptions{});
  EXPECT_FALSE(value_only.Evaluate(value_only.FromTimeBased(u0), &r, nullptr).ok);
}

TEST(Replay, ClosedFormOrbitsReturnToThemselves) {
  const HybridModel ball = MakeBouncingBall();
  const HybridModel slip = MakeSlip();
  for (double H : {0.5, 2.0}) {
    const Vector u = BallOrbit(ShootingLayout(ball), H);
    const ReplayResult rp = ReplayOrbit(ball, u);
    EXPECT_TRUE(rp.physical()) << rp.BriefReport();
    EXPECT_LT(rp.error, 1e-12);
    EXPECT_LT(rp.period_error, 1e-13);
    EXPECT_LT(rp.max_event_time_error, 1e-13);
  }
  for (double H : {1.1, 1.4, 2.0}) {
    const Vector u = SlipHoppingInPlace(slip, ShootingLayout(slip), H);
    const ReplayResult rp = ReplayOrbit(slip, u);
    EXPECT_TRUE(rp.physical()) << rp.BriefReport();
    EXPECT_LT(rp.error, 1e-9) << "H = " << H;
    // dopri5 at rtol 1e-10 against the exact closed form: ~2e-10 measured
    EXPECT_LT(rp.period_error, 1e-9) << "H = " << H;
    EXPECT_LT(rp.max_event_time_error, 1e-9) << "H = " << H;
    EXPECT_EQ(rp.event_times.size(), 3u);
  }
}

TEST(Replay, APerturbedOrbitDoesNotCloseAndAnUnreachableOneFails) {
  const HybridModel slip = MakeSlip();
  const ShootingLayout layout(slip);
  Vector u = SlipHoppingInPlace(slip, layout, 1.4);
  u(layout.state_offset(0) + 0) += 0.05;  // lean the leg at the nadir: the hop no longer repeats
  const ReplayResult rp = ReplayOrbit(slip, u);
  EXPECT_FALSE(rp.physical());
  EXPECT_EQ(rp.status, ReplayStatus::kNotClosed) << rp.BriefReport();
  EXPECT_GT(rp.error, 1e-2);
  // the SLIP start point: lift-off is tangent, the replay cannot run through
  const ReplayResult start = ReplayOrbit(slip, BuiltinStartPoint(slip));
  EXPECT_EQ(start.status, ReplayStatus::kEventFailed);
  EXPECT_NE(start.message.find("grazing"), std::string::npos) << start.message;
}

// Cost of one evaluation of r and dr, state-based vs time-based, at a physical orbit of each model.
// Prints the numbers for the performance notes; asserts only that both evaluate.
TEST(StateBased, CostPerEvaluationAgainstTimeBased) {
  struct Case {
    std::string name;
    HybridModel model;
    Vector u_tb;
  };
  std::vector<Case> cases;
  {
    HybridModel ball = MakeBouncingBall();
    Vector u = BallOrbit(ShootingLayout(ball), 1.0);
    cases.push_back({"bouncing-ball", std::move(ball), u});
    HybridModel slip = MakeSlip();
    u = SlipHoppingInPlace(slip, ShootingLayout(slip), 1.4);
    cases.push_back({"slip", std::move(slip), u});
  }
  for (std::string name : {"rocking-block", "bouncing-rod"}) {
    // a time-based u from a state on the section, via the state-based pass
    HybridModel model = MakeBuiltinModel(name);
    if (name == "bouncing-rod") model.SetParameter("r", 0.3);  // see the derivative test above
    StateBasedShooting sb(model, PoincareOptions{});
    Vector us = Vector::Zero(sb.num_unknowns());
    us.head(model.phase(0).dim()) = name == "rocking-block" ? Vec({0.1, 0.0}) : Vec({0.3, 0.2, 0.0, 0.5});
    Vector u_tb;
    const EvaluationStatus st = sb.ToTimeBased(us, &u_tb);
    ASSERT_TRUE(st.ok) << name << ": " << st.message;
    cases.push_back({name, std::move(model), u_tb});
  }
  for (Case& c : cases) {
    StateBasedShooting sb(c.model, PoincareOptions{});
    TimeBasedShooting tb(c.model, IntegratorOptions{});
    IntegratorOptions dopri5;
    dopri5.method = IntegratorMethod::kDormandPrince54;  // the state-based map's method, for a like comparison
    TimeBasedShooting tb5(c.model, dopri5);
    const Vector us = sb.FromTimeBased(c.u_tb);
    const int reps = 20;
    Vector r;
    Matrix dr;
    auto time = [&](ZeroProblem& p, const Vector& u) {
      const auto start = std::chrono::steady_clock::now();
      for (int i = 0; i < reps; ++i) {
        Vector uu = u;
        uu(uu.size() - 1) += 1e-12 * (i + 1);  // defeat the cache: a new point each time
        EXPECT_TRUE(p.Evaluate(uu, &r, &dr).ok);
      }
      return std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start).count() / reps;
    };
    const double us_sb = time(sb, us);
    const double us_tb = time(tb, c.u_tb);
    const double us_tb5 = time(tb5, c.u_tb);
    std::printf("[cost] %-14s r+dr per point: state-based (dopri5) %6.0f us, %5ld rhs | time-based rkf78 %6.0f us, "
                "%5ld rhs | time-based dopri5 %6.0f us, %5ld rhs\n",
                c.name.c_str(), us_sb, sb.counters().rhs_evaluations / reps, us_tb, tb.counters().rhs_evaluations / reps,
                us_tb5, tb5.counters().rhs_evaluations / reps);
  }
}

}  // namespace
}  // namespace hybridcont
