// Branch switching on a badly conditioned map: the state-based (single-shooting) map of the bouncing rod
// at its SB point, where the largest Floquet multiplier is ~5e2 and dr has norm ~2e7. Second derivatives
// by differences with the default step fail there (the perturbed rod misses its apex); the confirmed
// smaller step must give the direction that the time-based map gives, projected on the state-based
// unknowns (an independent computation: another map, exact there with the default step).
#include <cmath>

#include <Eigen/SVD>
#include <gtest/gtest.h>

#include "hybridcont/branch_switching.h"
#include "hybridcont/models.h"
#include "hybridcont/scaled_problem.h"
#include "hybridcont/statebased_shooting.h"
#include "hybridcont/timebased_shooting.h"

namespace hybridcont {
namespace {

// The unit vector of ker dr(u) (2-dimensional at an SB point) closest to `hint`.
Vector KernelDirectionClosestTo(ZeroProblem& problem, const Vector& u, const Vector& hint) {
  Vector r;
  Matrix dr;
  EXPECT_TRUE(problem.Evaluate(u, &r, &dr).ok);
  Eigen::JacobiSVD<Matrix> svd(dr, Eigen::ComputeFullV);
  const Matrix kernel = svd.matrixV().rightCols(2);
  return (kernel * (kernel.transpose() * hint)).normalized();
}

double LineAngle(const Vector& a, const Vector& b) {
  return std::acos(std::min(1.0, std::abs(a.normalized().dot(b.normalized()))));
}

TEST(StateBasedSwitch, TheRodsSwitchAgreesWithTheTimeBasedDirection) {
  const HybridModel rod = MakeBouncingRod();
  IntegratorOptions integrator;  // defaults: rtol = atol = 1e-10
  TimeBasedShooting time_based(rod, integrator);
  // The SB point of the symmetric family, as `hybridcont run bouncing-rod` locates it (H = 0.51540794).
  Vector u_time(17);
  u_time << 0.12453090392603691, 0.49989998999439594, -1.5507949928611513, 0.12453090392603688,
      12.45309352112467, 0.24906186593585944, 0.49989998999439594, 1.5507949928611513, 0.12453093296792943,
      -12.453090616935365, 0.12453090392603643, 0.5076539630107136, 2.971948711854069e-15,
      -6.919448268366226e-34, 12.45309352112467, 3.6576177456790275e-16, 0.5154079399230074;
  Vector time_scales = Vector::Ones(17);  // the model's scales: dalpha ~ l0/r
  for (const char* name : {"x1_dalpha", "x2_dalpha", "x3_dalpha"}) time_scales(time_based.UnknownIndex(name)) = 100;
  ScaledProblem scaled_time(&time_based, time_scales);

  // Incoming tangent: along the symmetric family (t2 = t1 + t3), i.e. the kernel direction closest to it.
  Vector along = Vector::Zero(17);
  along(time_based.UnknownIndex("t1")) = along(time_based.UnknownIndex("t3")) = 1;
  along(time_based.UnknownIndex("t2")) = 2;
  along(time_based.UnknownIndex("H")) = 1;
  SpecialPoint sb_time;
  sb_time.u = scaled_time.ToScaled(u_time);
  sb_time.tangent = sb_time.tangent_before = sb_time.tangent_after =
      KernelDirectionClosestTo(scaled_time, sb_time.u, along);
  const BranchSwitch time_switch = SwitchDirectionAt(&scaled_time, sb_time, BranchSwitchOptions());
  ASSERT_EQ(time_switch.status, BranchSwitchStatus::kOk) << time_switch.BriefReport();
  EXPECT_TRUE(time_switch.message.empty()) << "the time-based map is confirmed at the default step";

  PoincareOptions poincare;
  poincare.event.integrator = integrator;
  StateBasedShooting state_based(rod, poincare);
  Vector state_scales = Vector::Ones(6);
  state_scales(state_based.UnknownIndex("x1_dalpha")) = 100;
  ScaledProblem scaled_state(&state_based, state_scales);
  // The state-based unknowns are a linear projection of the time-based ones, so are the directions.
  const Vector expected = scaled_state.ToScaled(state_based.FromTimeBased(scaled_time.FromScaled(time_switch.direction)));
  SpecialPoint sb_state;
  sb_state.u = scaled_state.ToScaled(state_based.FromTimeBased(u_time));
  sb_state.tangent = sb_state.tangent_before = sb_state.tangent_after = KernelDirectionClosestTo(
      scaled_state, sb_state.u, scaled_state.ToScaled(state_based.FromTimeBased(scaled_time.FromScaled(sb_time.tangent))));

  const BranchSwitch state_switch = SwitchDirectionAt(&scaled_state, sb_state, BranchSwitchOptions());
  ASSERT_EQ(state_switch.status, BranchSwitchStatus::kOk) << state_switch.BriefReport();
  // The default step is not confirmed (the rod perturbed by 1e-4 along the kernel misses its apex), nor are
  // 1e-5 and 1e-6; 1e-7 agrees with 1e-8.
  EXPECT_NE(state_switch.message.find("second derivatives by differences with step 1e-07"), std::string::npos)
      << state_switch.message;
  EXPECT_NE(state_switch.message.find("step 0.0001: "), std::string::npos) << state_switch.message;
  // Measured 4.3e-6 rad; the families cross at 0.0122 rad in these unknowns, so 1e-4 tells them apart.
  EXPECT_LT(LineAngle(state_switch.direction, expected), 1e-4);
  EXPECT_GT(LineAngle(state_switch.direction, sb_state.tangent), 1e-2);
}

}  // namespace
}  // namespace hybridcont
