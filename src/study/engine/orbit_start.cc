#include "study/engine/orbit_start.h"

#include <fmt/format.h>

#include <Eigen/LU>

#include <algorithm>

#include "hybridcont/setup_evaluation.h"
#include "hybridcont/simulation_start.h"
#include "hybridcont/timebased_shooting.h"
#include "study/engine/start_carry.h"

namespace hybridcont::study {
namespace {

// Newton on the square system of an orbit at fixed parameters; the residual's max-norm is returned.
// A step never takes a positive duration below half its value: a phase variable (a forcing phase s, an
// angle) makes every orbit recur with durations shifted by whole periods, and full Newton steps from a rough
// guess may land on such an alias with a negative duration (the same states, traversed backwards in time).
// Damped this way Newton stays on the orbit whose durations have the guess's signs; near the solution the
// steps are whole and the convergence quadratic.
bool RefineAtFixedParameters(TimeBasedShooting& shooting, Vector* u, double* residual, int* iterations) {
  const ShootingLayout& layout = shooting.layout();
  Vector r;
  Matrix dr;
  constexpr int kMaxIterations = 60;
  for (*iterations = 0; *iterations < kMaxIterations; ++*iterations) {
    if (!shooting.Evaluate(*u, &r, &dr).ok) return false;
    *residual = r.lpNorm<Eigen::Infinity>();
    if (*residual <= 1e-11) return true;
    const Eigen::PartialPivLU<Matrix> lu(dr);
    const Vector step = -lu.solve(r);
    double lambda = 1.0;
    for (int i = 0; i < layout.num_segments(); ++i) {
      const double t = (*u)(layout.time_index(i)), dt = step(layout.time_index(i));
      if (t > 0 && t + dt < 0.5 * t) lambda = std::min(lambda, 0.5 * t / -dt);
    }
    *u += lambda * step;
    if (!u->allFinite()) return false;
  }
  return shooting.Evaluate(*u, &r, nullptr).ok && (*residual = r.lpNorm<Eigen::Infinity>()) <= 1e-11;
}

// One start: simulated or declared, then refined; false (and why in *report) if it fails.
bool OneStart(const HybridModel& model, const RunSetup& setup, const StartSpec& spec, Vector* u,
              std::string* report) {
  const ShootingLayout base(model);  // the square layout: segments only
  *u = StartPoint(model, spec);
  if (spec.kind == StartSpec::Kind::kSimulation) {
    SimulationStartOptions options;
    options.integrator.integrator = setup.integrator;
    if (spec.cycles > 0) {
      options.max_cycles = spec.cycles;
      options.require_convergence = false;
    }
    const Vector x1 = u->segment(base.state_offset(0), base.dim(0));
    SimulationStartResult s = SimulateToOrbit(model, x1, options);
    if (!s.converged && options.require_convergence && s.cycles >= 1) {
      // The simulation does not settle (the walker falls: the orbit it passed near is unstable, or the start
      // lies outside its basin): the cycle that changed least, closest to a periodic orbit, is Newton's guess
      // instead, as with `cycles`.
      const std::string why = s.message;
      const int cycles = s.cycles;
      options.require_convergence = false;
      SimulationStartResult best;
      for (int k = 1; k <= cycles; ++k) {
        options.max_cycles = k;
        const SimulationStartResult cycle = SimulateToOrbit(model, x1, options);
        if (cycle.converged && (!best.converged || cycle.change < best.change)) best = cycle;
      }
      s = best;
      if (s.converged) {
        *report += fmt::format("event-driven simulation did not settle ({}): cycle {}, which changed least ({:.2g}), "
                               "is the guess; ", why, s.cycles, s.change);
      }
    }
    if (!s.converged) {
      *report += "event-driven simulation did not settle on an orbit: " + s.message;
      return false;
    }
    *u = s.u;
    if (report->empty()) *report += "event-driven simulation from the declared state, " + s.message + "; ";
  } else {
    *report += "the declared orbit; ";
  }
  TimeBasedShooting shooting(model, setup.integrator);
  double residual = 0;
  int iterations = 0;
  if (!RefineAtFixedParameters(shooting, u, &residual, &iterations)) {
    *report += fmt::format("Newton at fixed parameters did not converge (|r| = {:.2e} after {} iterations)", residual,
                           iterations);
    return false;
  }
  *report += fmt::format("refined by Newton at fixed parameters, |r| = {:.1e} after {} iterations", residual,
                         iterations);
  return true;
}

// The start found at `model`'s parameter values, given the free parameters' values (free_layout).
bool StartInLayout(const HybridModel& model, const RunSetup& setup, const StartSpec& spec,
                   const ShootingLayout& free_layout, Vector* point, std::string* report) {
  Vector u;
  if (!OneStart(model, setup, spec, &u, report)) return false;
  *point = Vector::Zero(free_layout.num_unknowns());
  point->head(u.size()) = u;
  for (int p = 0; p < free_layout.num_free_parameters(); ++p) {
    (*point)(free_layout.parameter_index(p)) = model.parameter_value(free_layout.parameter_model_index(p));
  }
  return true;
}

}  // namespace

OrbitStarts FindOrbitStarts(const HybridModel& model, const RunSetup& setup, const ShootingLayout& free_layout) {
  OrbitStarts starts;
  std::vector<StartSpec> specs = {model.setup().start};
  specs.insert(specs.end(), model.setup().more_starts.begin(), model.setup().more_starts.end());
  // At parameters the user set, each start is found at the model's own values and carried (start_carry.h).
  HybridModel own = model.Clone();
  for (const NamedValue& v : setup.own_parameters) own.SetParameter(v.name, v.value);
  const ComponentBound level = LevelBound(setup, free_layout.continued_name());
  for (std::size_t i = 0; i < specs.size(); ++i) {
    Vector point;
    std::string report;
    bool ok = false;
    if (!setup.own_parameters.empty()) {
      std::string own_report;
      if (StartInLayout(own, setup, specs[i], free_layout, &point, &own_report)) {
        const CarriedStart carried =
            CarryStart(model, setup.own_parameters, point, setup.integrator, {setup.free, level});
        ok = carried.ok;
        if (ok) point = carried.u, report = own_report + "; " + carried.report;
        if (!ok) report = carried.why + "; at the values set: ";
      }
    }
    if (!ok) ok = StartInLayout(model, setup, specs[i], free_layout, &point, &report);
    starts.report += fmt::format("  start {}: {}\n", i + 1, report);
    if (ok) starts.points.push_back(point);
  }
  return starts;
}

}  // namespace hybridcont::study
