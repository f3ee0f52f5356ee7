// A downstream program of the installed package: the closed-form bouncing-ball orbit is a zero of the
// time-based shooting map r (paper eq. `timebased`), and a perturbed point is not. Exits 1 otherwise.
//
// The ball (paper §4.1) at level H: apex height h = H / (m g), impact speed v = sqrt(2 g h), fall and rise
// times v / g. Segment 1 starts at the apex, x = [h, 0]; segment 2 right after the impact, x = [0, +v].
#include <hybridcont/family_ranges.h>
#include <hybridcont/models.h>
#include <hybridcont/shooting_layout.h>
#include <hybridcont/timebased_shooting.h>

#include <cmath>
#include <iostream>

int main() {
  using namespace hybridcont;
  const HybridModel ball = MakeBuiltinModel("bouncing-ball");
  TimeBasedShooting shooting(ball, IntegratorOptions{});
  const ShootingLayout& layout = shooting.layout();
  if (layout.num_segments() != 2) {
    std::cerr << "bouncing-ball: expected 2 segments, got " << layout.num_segments() << "\n";
    return 1;
  }

  const double H = 0.5, g = ball.parameter("g"), m = ball.parameter("m");
  const double h = H / (m * g), v = std::sqrt(2.0 * g * h), t = v / g;
  Vector u = Vector::Zero(layout.num_unknowns());
  u(layout.time_index(0)) = t;
  u(layout.state_offset(0)) = h;
  u(layout.time_index(1)) = t;
  u(layout.state_offset(1) + 1) = v;
  u(layout.H_index()) = H;

  // The integrator is exact on the ball's quadratic flight up to rounding.
  const auto residual = [&shooting](const Vector& at) {
    Vector r;
    const EvaluationStatus status = shooting.Evaluate(at, &r, nullptr);
    if (!status.ok) std::cerr << "evaluation failed: " << status.message << "\n";
    return status.ok ? r.lpNorm<Eigen::Infinity>() : -1.0;
  };
  const double on_orbit = residual(u);
  Vector off = u;
  off(layout.time_index(0)) += 1e-3;
  const double off_orbit = residual(off);
  std::cout << "bouncing-ball, H = " << H << ": |r| = " << on_orbit << " on the orbit, " << off_orbit
            << " with t1 + 1e-3\n";
  // Reports the library formats (fmt, a private dependency of the core library): a family's range on a
  // one-branch diagram, written as the report writes it.
  Branch branch;
  for (int i = 0; i < 3; ++i) {
    ContinuationPoint point;
    point.u = u;
    point.arclength = 0.1 * i;
    branch.points.push_back(point);
  }
  const BranchRanges ranges = RangesOnBranch(branch, {true, true, true}, {true, true, true}, {false, false, false},
                                             layout.H_index());
  const std::string range = ranges.physical.empty() ? "" : ToString(ranges.physical.front().from);
  std::cout << "range starts at " << range << "\n";
  const bool ok = on_orbit >= 0.0 && on_orbit < 1e-10 && off_orbit > 1e-6 && range.rfind("0.5 (start", 0) == 0;
  if (!ok) std::cerr << "FAILED: expected |r| < 1e-10 on the orbit and > 1e-6 off it\n";
  return ok ? 0 : 1;
}
