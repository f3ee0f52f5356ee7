// Event-driven phase integration: event times against closed forms, the trigger rule (start on the guard,
// grazing, guard never reached, NaN), sensitivities at the event, and the saltation matrices of every
// built-in transition against finite differences of the event-driven flow (paper eq. `Saltation`).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "hybridcont/event_flow.h"
#include "hybridcont/models.h"
#include "hybridcont/saltation.h"
#include "known_orbits.h"
#include "vector_literal.h"

namespace hybridcont {
namespace {

TEST(EventFlow, BallFallingFromRestHitsTheGroundAtSqrt2hOverG) {
  HybridModel ball = MakeBouncingBall();
  for (double g : {1.0, 9.81}) {
    ball.SetParameter("g", g);
    EventFlow flow(ball.phase(0), EventFlowOptions{});
    for (double h : {0.8, 2.0, 7.5}) {
      EventFlowResult res;
      ASSERT_EQ(flow.Integrate(Vec({h, 0.0}), Vector::Zero(1), PhaseEventGuard(ball.phase(0)), true, &res),
                EventFlowStatus::kEventReached)
          << res.message;
      const double t = std::sqrt(2.0 * h / g);
      // The flight is a quadratic: Dormand–Prince and its interpolant are exact, so what remains is the
      // root finder's bracket (a few ulps) and round-off.
      EXPECT_NEAR(res.t, t, 1e-13 * std::max(1.0, t)) << "g = " << g << ", h = " << h;
      EXPECT_NEAR(res.x(0), 0.0, 1e-13);
      EXPECT_NEAR(res.x(1), -g * t, 1e-12);
      EXPECT_NEAR(res.Phi(0, 1), t, 1e-12);  // Phi = [[1, t], [0, 1]]
      EXPECT_NEAR(res.Phi(0, 0), 1.0, 1e-12);
      EXPECT_NEAR(res.Phi(1, 0), 0.0, 1e-12);
      EXPECT_NEAR(res.g_dot, -g * t, 1e-12);
      EXPECT_NEAR(res.transversality, g * t / std::hypot(g * t, g), 1e-12);
      EXPECT_GT(res.counters.rhs_evaluations, 0);
      EXPECT_GT(res.counters.steps, 0);
    }
  }
}

TEST(EventFlow, SlipStanceLiftsOffAndTouchesDownToNadirAtTheHarmonicTime) {
  const HybridModel slip = MakeSlip();
  const ShootingLayout layout(slip);
  // The harmonic stance is not a polynomial: the event time is as accurate as the integration and the
  // interpolant. Measured worst case over these H: 1.4e-15 at rtol = atol = 1e-13, 2.6e-13 at the default
  // 1e-10 (next test).
  EventFlowOptions opts;
  opts.integrator.rtol = opts.integrator.atol = 1e-13;
  EventFlow stance(slip.phase(0), opts);
  for (double H : {1.1, 1.4, 2.0}) {
    const Vector u = SlipHoppingInPlace(slip, layout, H);
    const double t_stance = u(layout.time_index(0));
    EventFlowResult res;
    ASSERT_EQ(stance.Integrate(u.segment(layout.state_offset(0), 4), Vector::Zero(1), PhaseEventGuard(slip.phase(0)),
                               true, &res),
              EventFlowStatus::kEventReached)
        << res.message;
    EXPECT_NEAR(res.t, t_stance, 1e-14) << "H = " << H;
    EXPECT_NEAR(res.x(1), 1.0, 1e-13);                                     // l = l0
    EXPECT_NEAR(res.x(3), u(layout.state_offset(1) + 3), 1e-11);           // dl = lift-off speed
    // touch-down -> nadir: the anchor a = -dl
    EventFlowResult ret;
    ASSERT_EQ(stance.Integrate(u.segment(layout.state_offset(2), 4), Vector::Zero(1), AnchorGuard(slip.anchor()), true,
                               &ret),
              EventFlowStatus::kEventReached)
        << ret.message;
    EXPECT_NEAR(ret.t, t_stance, 1e-12) << "H = " << H;
    EXPECT_NEAR(ret.x(1), u(layout.state_offset(0) + 1), 1e-12);  // l_min
  }
}

TEST(EventFlow, DefaultTolerancesLocateTheSlipLiftOffTo1e12) {
  const HybridModel slip = MakeSlip();
  const ShootingLayout layout(slip);
  EventFlow stance(slip.phase(0), EventFlowOptions{});
  for (double H : {1.1, 1.4, 2.0}) {
    const Vector u = SlipHoppingInPlace(slip, layout, H);
    EventFlowResult res;
    ASSERT_EQ(stance.Integrate(u.segment(layout.state_offset(0), 4), Vector::Zero(1), PhaseEventGuard(slip.phase(0)),
                               true, &res),
              EventFlowStatus::kEventReached);
    EXPECT_NEAR(res.t, u(layout.time_index(0)), 1e-12) << "H = " << H;  // measured <= 2.6e-13
  }
}

TEST(EventFlow, SensitivitiesAtTheEventEqualThoseOfTheTimeBasedFlowOverTheEventTime) {
  const HybridModel slip = MakeSlip();
  Vector x0 = Vec({0.05, 0.93, 0.2, 0.4});
  const Vector xi = Vector::Constant(1, 0.03);
  EventFlowOptions opts;
  opts.integrator.rtol = opts.integrator.atol = 1e-12;
  EventFlow ev(slip.phase(0), opts);
  EventFlowResult res;
  ASSERT_EQ(ev.Integrate(x0, xi, PhaseEventGuard(slip.phase(0)), true, &res), EventFlowStatus::kEventReached);
  PhaseFlow flow(slip.phase(0), opts.integrator);
  PhaseFlowResult fixed;
  ASSERT_EQ(flow.Integrate(x0, xi, res.t, true, &fixed), FlowStatus::kSuccess);
  EXPECT_LT((res.x - fixed.x).norm(), 1e-10);
  EXPECT_LT((res.Phi - fixed.Phi).norm(), 1e-9 * fixed.Phi.norm());
  EXPECT_LT((res.Psi - fixed.Psi).norm(), 1e-9 * std::max(1.0, fixed.Psi.norm()));
}

TEST(EventFlow, AStartOnTheGuardMovingUpIsIgnoredMovingDownIsAZeroDurationPhase) {
  const HybridModel ball = MakeBouncingBall();
  EventFlow flow(ball.phase(0), EventFlowOptions{});
  const PhaseEventGuard ground(ball.phase(0));
  EventFlowResult up;
  ASSERT_EQ(flow.Integrate(Vec({0.0, 1.0}), Vector::Zero(1), ground, false, &up), EventFlowStatus::kEventReached);
  EXPECT_NEAR(up.t, 2.0, 1e-13);  // y = t - t^2/2 returns to 0 at t = 2
  EventFlowResult down;
  EXPECT_EQ(flow.Integrate(Vec({0.0, -1.0}), Vector::Zero(1), ground, false, &down), EventFlowStatus::kZeroDuration);
  EXPECT_NE(down.message.find("zero-duration"), std::string::npos) << down.message;
  EXPECT_EQ(down.t, 0.0);
}

TEST(EventFlow, GrazingIsReportedForATouchAndForANearlyTangentCrossing) {
  const HybridModel ball = MakeBouncingBall();  // g = 1
  EventFlow flow(ball.phase(0), EventFlowOptions{});
  const Vector x0 = Vec({0.0, 1.0});  // apex at t = 1, height 0.5
  auto line = [](double level) {
    return FunctionGuard("line y = " + std::to_string(level), [level](const Eigen::Ref<const Vector>& x, RowVector* dg) {
      if (dg) *dg = Eigen::RowVector2d(-1.0, 0.0);
      return level - x(0);  // crossed downward when the ball rises above the line
    });
  };
  EventFlowResult res;
  // Exactly tangent (g = 0.5 - y >= 0, min 0 at the apex): in floating point the apex lands within an
  // ulp or two of the line, on either side; both are grazing. A tangency fixes the time only to
  // ~sqrt(round-off) = 1e-8.
  EXPECT_EQ(flow.Integrate(x0, Vector::Zero(1), line(0.5), false, &res), EventFlowStatus::kGrazing);
  EXPECT_NEAR(res.t, 1.0, 1e-7);
  EXPECT_NE(res.message.find("grazing"), std::string::npos) << res.message;
  // A touch: the minimum g = 1e-11 stays above 0 but within touch_tolerance = 1e-9.
  EXPECT_EQ(flow.Integrate(x0, Vector::Zero(1), line(0.5 + 1e-11), false, &res), EventFlowStatus::kGrazing);
  EXPECT_NEAR(res.t, 1.0, 1e-7);
  EXPECT_NE(res.message.find("touches the guard"), std::string::npos) << res.message;
  // A true downward crossing of g = (0.5 - 1e-15) - y (the ball rising through the line) at the sine
  // sqrt(2e-15) = 4.5e-8 < grazing_tolerance 1e-7, at t = 1 - sqrt(2e-15). Its time is only as good as
  // round-off of y (~1e-16) divided by that slope: ~1e-8.
  EXPECT_EQ(flow.Integrate(x0, Vector::Zero(1), line(0.5 - 1e-15), false, &res), EventFlowStatus::kGrazing);
  EXPECT_NEAR(res.t, 1.0 - std::sqrt(2e-15), 3e-8);
  EXPECT_LT(res.t, 1.0);
  EXPECT_LT(res.transversality, 1e-7);
  EXPECT_NE(res.message.find("grazing crossing"), std::string::npos) << res.message;
  // Further below the apex the same crossing is transversal (sine 1.4e-3): an event at 1 - sqrt(2e-6).
  EXPECT_EQ(flow.Integrate(x0, Vector::Zero(1), line(0.5 - 1e-6), false, &res), EventFlowStatus::kEventReached);
  EXPECT_NEAR(res.t, 1.0 - std::sqrt(2e-6), 1e-12);
}

// A guard reached only from above (an automaton's, from_above) that the phase begins on stays unarmed while
// the trajectory rises above it by no more than touch_tolerance and falls back: the ball leaving the ground at
// speed 1e-5 rises by 5e-11 and sinks below it (the scuffing a model ignores), and the guard is never crossed.
// A guard that counts everywhere calls the same rise a grazing touch; a rise by 5e-7 arms either, and the
// ball's return is the event, at t = 2 v.
TEST(EventFlow, ARiseWithinTouchToleranceLeavesAnUnarmedGuardUnarmed) {
  const HybridModel ball = MakeBouncingBall();  // g = 1
  const PhaseEventGuard ground(ball.phase(0));
  EventFlowOptions above;
  above.from_above = true;
  above.max_duration = 5.0;
  EventFlowResult res;
  EXPECT_EQ(EventFlow(ball.phase(0), above).Integrate(Vec({0.0, 1e-5}), Vector::Zero(1), ground, false, &res),
            EventFlowStatus::kGuardNotReached)
      << res.message;
  EventFlowOptions everywhere;
  everywhere.max_duration = 5.0;
  EXPECT_EQ(EventFlow(ball.phase(0), everywhere).Integrate(Vec({0.0, 1e-5}), Vector::Zero(1), ground, false, &res),
            EventFlowStatus::kGrazing)
      << res.message;
  for (const EventFlowOptions& options : {above, everywhere}) {
    ASSERT_EQ(EventFlow(ball.phase(0), options).Integrate(Vec({0.0, 1e-3}), Vector::Zero(1), ground, false, &res),
              EventFlowStatus::kEventReached)
        << res.message;
    EXPECT_NEAR(res.t, 2e-3, 1e-12);
  }
}

TEST(EventFlow, AGuardThatIsNeverReachedIsAStatusNotAHang) {
  const HybridModel ball = MakeBouncingBall();
  EventFlowOptions opts;
  opts.max_duration = 20.0;
  EventFlow flow(ball.phase(0), opts);
  // Crossed downward only if the ball rose above y = 10; it falls from rest at y = 1 (no ground here).
  const FunctionGuard ceiling("y = 10 from above", [](const Eigen::Ref<const Vector>& x, RowVector* dg) {
    if (dg) *dg = Eigen::RowVector2d(-1.0, 0.0);
    return 10.0 - x(0);
  });
  EventFlowResult res;
  EXPECT_EQ(flow.Integrate(Vec({1.0, 0.0}), Vector::Zero(1), ceiling, false, &res), EventFlowStatus::kGuardNotReached);
  EXPECT_GE(res.t, 20.0);
  EXPECT_NE(res.message.find("max_duration"), std::string::npos) << res.message;
  // A step budget ends a long search as well.
  opts.max_duration = 1e6;
  opts.integrator.max_steps = 50;
  const HybridModel block = MakeRockingBlock();
  EventFlow rocking(block.phase(0), opts);
  const FunctionGuard never("alpha = 10", [](const Eigen::Ref<const Vector>& x, RowVector* dg) {
    if (dg) *dg = Eigen::RowVector2d(-1.0, 0.0);
    return 10.0 - x(0);
  });
  // Without the impact the block swings like a pendulum about alpha = beta - pi: alpha never reaches 10.
  EXPECT_EQ(rocking.Integrate(Vec({-0.05, 0.0}), Vector::Zero(1), never, false, &res), EventFlowStatus::kMaxSteps);
}

TEST(EventFlow, NonFiniteValuesAreAStatusWithTheTime) {
  const HybridModel ball = MakeBouncingBall();
  EventFlow flow(ball.phase(0), EventFlowOptions{});
  const FunctionGuard broken("broken guard", [](const Eigen::Ref<const Vector>& x, RowVector* dg) {
    if (dg) *dg = Eigen::RowVector2d(1.0, 0.0);
    return x(0) < 0.5 ? std::numeric_limits<double>::quiet_NaN() : x(0) + 1.0;
  });
  EventFlowResult res;
  EXPECT_EQ(flow.Integrate(Vec({1.0, 0.0}), Vector::Zero(1), broken, false, &res), EventFlowStatus::kNonFinite);
  EXPECT_NE(res.message.find("phase 'flight'"), std::string::npos) << res.message;
  EXPECT_NE(res.message.find("t = "), std::string::npos) << res.message;
  EXPECT_GT(res.t, 0.9);  // y = 1 - t^2/2 < 0.5 from t = 1
}

TEST(EventFlow, OptionsAreValidated) {
  EventFlowOptions opts;
  opts.grazing_tolerance = 2.0;
  EXPECT_NE(opts.Validate().find("grazing_tolerance"), std::string::npos);
  opts = EventFlowOptions{};
  opts.max_duration = -1.0;
  EXPECT_NE(opts.Validate().find("max_duration = -1"), std::string::npos);
  EXPECT_THROW(EventFlow(MakeBouncingBall().phase(0), opts), std::invalid_argument);
}

// --- saltation matrices against finite differences of the event-driven flow -------------------------

// Start states in phase 1 from which every phase ends in a transversal event (not periodic orbits: the
// derivative of the flow across each transition is what is checked).
Vector StartState(const std::string& model) {
  if (model == "bouncing-ball") return Vec({0.8, 0.3});
  if (model == "rocking-block") return Vec({0.1, 0.05});
  if (model == "bouncing-rod") return Vec({0.8, 0.15, 0.1, 0.6});
  return Vec({0.04, 0.92, 0.15, 0.0});  // slip: near the nadir, leaning slightly
}

struct Transition {
  Vector x_bar;    // start of phase i
  double t_event;  // its event time
};

class SaltationTest : public ::testing::TestWithParam<std::string> {};

// F(x̄_i) = phi_{i+1}(t* - t_E(x̄_i), Delta_i(phi_i(t_E(x̄_i), x̄_i)))  at a fixed global time t* a bit past
// the event; dF/dx̄_i = Phi_{i+1}(t* - t_E) S_i Phi_i(t_E) (eq. `chainedHybridDiff`).
TEST_P(SaltationTest, AcrossEveryTransitionMatchesFiniteDifferencesOfTheEventDrivenFlow) {
  const HybridModel model = MakeBuiltinModel(GetParam());
  const int m = model.num_phases();
  EventFlowOptions opts;
  // Central differences of an adaptively integrated map carry noise ~tol/h; at 1e-13 and h = 1e-5 that
  // is ~1e-8, below the O(h^2) truncation ~1e-10 x third derivatives.
  opts.integrator.rtol = opts.integrator.atol = 1e-13;
  const Vector xi = Vector::Constant(1, 0.02);  // nonzero: the unfolded field, as in P~
  Vector x = StartState(GetParam());
  for (int i = 0; i < m; ++i) {
    const Phase& phase = model.phase(i);
    const Phase& next = model.phase(i + 1);
    EventFlow ev(phase, opts);
    PhaseFlow after(next, opts.integrator);
    EventFlowResult res;
    ASSERT_EQ(ev.Integrate(x, xi, PhaseEventGuard(phase), true, &res), EventFlowStatus::kEventReached)
        << GetParam() << " phase " << i + 1 << ": " << res.message;
    Vector x_plus;
    Matrix D;
    phase.Reset(res.x, &x_plus, &D);
    Vector f_plus;
    next.UnfoldedVectorField(x_plus, xi, &f_plus, nullptr, nullptr);
    Matrix S;
    ASSERT_EQ(Saltation(D, res.f, f_plus, res.dg, &S), SaltationStatus::kSuccess);
    // The paper's identities for S: S f^- = f^+ (flow to flow; exact for any xi).
    EXPECT_LT((S * res.f - f_plus).norm(), 1e-12 * f_plus.norm()) << GetParam() << " phase " << i + 1;

    const double tau = 0.05;  // a bit into the next phase
    const double t_star = res.t + tau;
    PhaseFlowResult nominal;
    ASSERT_EQ(after.Integrate(x_plus, xi, tau, true, &nominal), FlowStatus::kSuccess);
    const Matrix analytic = nominal.Phi * S * res.Phi;

    auto F = [&](const Vector& y) {
      EventFlowResult r;
      EXPECT_EQ(ev.Integrate(y, xi, PhaseEventGuard(phase), false, &r), EventFlowStatus::kEventReached);
      Vector yp;
      phase.Reset(r.x, &yp, nullptr);
      PhaseFlowResult a;
      after.Integrate(yp, xi, t_star - r.t, false, &a);
      return a.x;
    };
    const double h = 1e-5;
    Matrix fd(next.dim(), phase.dim());
    for (int j = 0; j < phase.dim(); ++j) {
      Vector xp = x, xm = x;
      xp(j) += h;
      xm(j) -= h;
      fd.col(j) = (F(xp) - F(xm)) / (2.0 * h);
    }
    const double err = (fd - analytic).norm() / analytic.norm();
    EXPECT_LT(err, 1e-7) << GetParam() << " transition " << i + 1 << " -> " << (i + 1) % m + 1 << "\nanalytic\n"
                         << analytic << "\nfd\n"
                         << fd;
    x = x_plus;
  }
}

INSTANTIATE_TEST_SUITE_P(AllModels, SaltationTest,
                         ::testing::Values("bouncing-ball", "rocking-block", "bouncing-rod", "slip"),
                         [](const auto& info) {
                           std::string s = info.param;
                           for (char& c : s) if (c == '-') c = '_';
                           return s;
                         });

TEST(Saltation, DegenerateAtGrazingAndFirstIntegralIdentity) {
  Matrix D = Matrix::Identity(2, 2);
  Matrix S;
  EXPECT_EQ(Saltation(D, Vec({1.0, 0.0}), Vec({1.0, 0.0}), Eigen::RowVector2d(0.0, 1.0), &S),
            SaltationStatus::kDegenerate);
  EXPECT_EQ(LastSaltation(D, Vec({1.0, 0.0}), Eigen::RowVector2d(0.0, 1.0), &S), SaltationStatus::kDegenerate);
  // Ball impact from y = 0, dy = -2 (g = 1): S = [[-1, 0], [-2 g/dy, -1]] = [[-1, 0], [1, -1]]... check
  // against the formula by hand: f^- = (-2, -1), f^+ = (2, -1), D = diag(1, -1), de = (1, 0):
  // (f^+ - D f^-) = (2 + 2, -1 - 1) = (4, -2); / (de f^-) = -2 -> (-2, 1); S = D + (-2, 1)(1, 0).
  D << 1, 0, 0, -1;
  ASSERT_EQ(Saltation(D, Vec({-2.0, -1.0}), Vec({2.0, -1.0}), Eigen::RowVector2d(1.0, 0.0), &S),
            SaltationStatus::kSuccess);
  Matrix expected(2, 2);
  expected << -1, 0, 1, -1;
  EXPECT_LT((S - expected).norm(), 1e-15);
  // dH(x^-) = dH(x^+) S for H = dy^2/2 + y: dH(x^-) = (1, -2), dH(x^+) = (1, 2).
  EXPECT_LT((Eigen::RowVector2d(1.0, 2.0) * S - Eigen::RowVector2d(1.0, -2.0)).norm(), 1e-15);
}

}  // namespace
}  // namespace hybridcont
