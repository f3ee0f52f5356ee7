#include "hybridcont/simulation_start.h"

#include <cmath>
#include <sstream>

#include "hybridcont/shooting_layout.h"

namespace hybridcont {
namespace {

// Integrates `phase` from x until `guard`; a start on the guard moving down is a zero-duration segment.
bool RunSegment(EventFlow& flow, const Vector& x, const Vector& xi, const Guard& guard, double* t, Vector* end,
                std::string* why) {
  EventFlowResult r;
  flow.Integrate(x, xi, guard, false, &r);
  if (r.status == EventFlowStatus::kZeroDuration) {
    *t = 0.0;
    *end = x;
    return true;
  }
  if (!r.ok()) {
    *why = r.message;
    return false;
  }
  *t = r.t;
  *end = r.x;
  return true;
}

}  // namespace

SimulationStartResult SimulateToOrbit(const HybridModel& model, const Vector& x1, const SimulationStartOptions& o) {
  SimulationStartResult res;
  const int m = model.num_phases();
  const ShootingLayout layout(model);
  const Vector xi = Vector::Zero(model.num_first_integrals());
  EventFlowOptions flow_options = o.integrator;
  flow_options.max_duration = o.max_phase_time;
  std::vector<EventFlow> flows;
  for (int i = 0; i < m; ++i) flows.emplace_back(model.phase(i), flow_options);
  const AnchorGuard anchor(model.anchor());
  if (x1.size() != model.phase(0).dim()) {
    res.message = "the start state has " + std::to_string(x1.size()) + " entries, phase '" + model.phase(0).name() +
                  "' " + std::to_string(model.phase(0).dim());
    return res;
  }
  std::string why;
  double t = 0.0;
  Vector x;
  // Onto the Poincaré section first.
  if (!RunSegment(flows[0], x1, xi, anchor, &t, &x, &why)) {
    res.message = "reaching the section from the start state: " + why;
    return res;
  }
  Vector u = Vector::Zero(layout.num_unknowns());
  for (int cycle = 1; cycle <= o.max_cycles; ++cycle) {
    const Vector section = x;
    u.segment(layout.state_offset(0), section.size()) = section;
    Vector state = section;
    for (int i = 0; i < m; ++i) {  // segment i runs phase i to its event, then its reset
      const PhaseEventGuard event(model.phase(i));
      Vector end;
      if (!RunSegment(flows[i], state, xi, event, &t, &end, &why)) {
        res.message = "cycle " + std::to_string(cycle) + ", phase '" + model.phase(i).name() + "': " + why;
        return res;
      }
      u(layout.time_index(i)) = t;
      model.phase(i).Reset(end, &state, nullptr);
      u.segment(layout.state_offset(i + 1), state.size()) = state;
    }
    if (!RunSegment(flows[0], state, xi, anchor, &t, &x, &why)) {  // segment m + 1: back to the section
      res.message = "cycle " + std::to_string(cycle) + ", phase '" + model.phase(0).name() + "' to the section: " + why;
      return res;
    }
    u(layout.time_index(m)) = t;
    res.cycles = cycle;
    res.change = ((x - section).array().abs() / (1.0 + section.array().abs())).maxCoeff();
    if (!std::isfinite(res.change)) {
      res.message = "cycle " + std::to_string(cycle) + ": non-finite state at the section";
      return res;
    }
    if (res.change <= o.tolerance || (!o.require_convergence && cycle == o.max_cycles)) {
      if (layout.num_first_integrals() > 0) {  // a conservative model: its level at the section
        Vector H;
        model.phase(0).FirstIntegrals(section, &H, nullptr, nullptr);
        u(layout.H_index()) = H(0);
      }
      res.converged = true;
      res.u = u;
      std::ostringstream os;
      os.precision(2);
      os << (res.change <= o.tolerance ? "converged after " : "stopped after ") << cycle << " cycles (change "
         << res.change << ")";
      res.message = os.str();
      return res;
    }
  }
  std::ostringstream os;
  os.precision(2);
  os << "no convergence in " << o.max_cycles << " cycles (last change " << res.change
     << "): the orbit the simulation runs into is not attracting enough, or there is none";
  res.message = os.str();
  return res;
}

}  // namespace hybridcont
