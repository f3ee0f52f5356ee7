#include "orbit_start.h"

#include <fmt/format.h>

#include <Eigen/LU>

#include "hybridcont/simulation_start.h"
#include "hybridcont/timebased_shooting.h"

namespace hybridcont::app {
namespace {

// Newton on the square system of an orbit at fixed parameters; the residual's max-norm is returned.
bool RefineAtFixedParameters(TimeBasedShooting& shooting, Vector* u, double* residual, int* iterations) {
  Vector r;
  Matrix dr;
  for (*iterations = 0; *iterations < 30; ++*iterations) {
    if (!shooting.Evaluate(*u, &r, &dr).ok) return false;
    *residual = r.lpNorm<Eigen::Infinity>();
    if (*residual <= 1e-11) return true;
    const Eigen::PartialPivLU<Matrix> lu(dr);
    *u -= lu.solve(r);
    if (!u->allFinite()) return false;
  }
  return shooting.Evaluate(*u, &r, nullptr).ok && (*residual = r.lpNorm<Eigen::Infinity>()) <= 1e-11;
}

}  // namespace

OrbitStart FindOrbitStart(const HybridModel& model, const RunSetup& setup, const ShootingLayout& free_layout) {
  OrbitStart start;
  const ShootingLayout base(model);  // the square layout: segments only
  Vector u = setup.scenario.start;
  if (model.setup().start.kind == StartSpec::Kind::kSimulation) {
    SimulationStartOptions options;
    options.integrator.integrator = setup.integrator;
    const Vector x1 = u.segment(base.state_offset(0), base.dim(0));
    const SimulationStartResult s = SimulateToOrbit(model, x1, options);
    if (!s.converged) {
      start.report = "  start: the event-driven simulation did not settle on an orbit: " + s.message + "\n";
      return start;
    }
    u = s.u;
    start.report = "  start: event-driven simulation from the declared state, " + s.message + "\n";
  } else {
    start.report = "  start: the declared orbit\n";
  }
  TimeBasedShooting shooting(model, setup.integrator);
  double residual = 0;
  int iterations = 0;
  if (!RefineAtFixedParameters(shooting, &u, &residual, &iterations)) {
    start.report += fmt::format("  Newton at fixed parameters did not converge (|r| = {:.2e} after {} iterations)\n",
                                residual, iterations);
    return start;
  }
  start.report += fmt::format("  refined by Newton at fixed parameters: |r| = {:.1e} after {} iterations\n", residual,
                              iterations);
  start.u = Vector::Zero(free_layout.num_unknowns());
  start.u.head(base.num_unknowns()) = u;
  for (int i = 0; i < free_layout.num_free_parameters(); ++i) {
    start.u(free_layout.parameter_index(i)) = model.parameter_value(free_layout.parameter_model_index(i));
  }
  start.ok = true;
  return start;
}

}  // namespace hybridcont::app
