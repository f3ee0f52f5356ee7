#include "study/engine/start_carry.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "hybridcont/continuation.h"
#include "hybridcont/corrector.h"
#include "hybridcont/timebased_shooting.h"
#include "study/engine/point_analysis.h"

namespace hybridcont::study {

namespace {

// One parameter carried from `from` to `to` at the level of u (the model's other parameters as set in `model`).
// On success *u is the orbit at `to`; *steps counts the accepted points.
bool CarryOne(const HybridModel& model, const std::string& name, double from, double to,
              const IntegratorOptions& integrator, Vector* u, int* steps, std::string* why) {
  HybridModel at = model.Clone();
  at.SetParameter(name, from);
  const ShootingLayout orbit(at);
  const double level = (*u)(orbit.H_index());
  TimeBasedShooting map(at, integrator, FreeParameters{{name}, {{"H", level}}, {}});
  Vector start(u->size() + 1);
  start << *u, from;
  const int p = static_cast<int>(start.size()) - 1;
  const double delta = std::abs(to - from);
  ContinuationOptions c;
  c.targets = {{name, to}};
  // Beyond the set value by its distance at most: a family that passes it is stopped by the target first.
  c.bounds = {{name, std::min(from, to) - delta, std::max(from, to) + delta}};
  c.turning_point_components = {name};
  c.detect_bifurcations = false;
  c.check_integration_error = false;
  c.initial_step = std::max(1e-3, delta / 50);
  c.max_step = std::max(0.25, delta / 10);
  c.max_points = 400;
  Branch last;
  for (const int direction : {+1, -1}) {  // the orientation of the tangent that moves the parameter toward `to`
    c.direction = direction;
    last = TraceBranch(&map, start, c);
    if (last.points.size() >= 2 && (last.points[1].u(p) - from) * (to - from) > 0) break;
  }
  *steps += static_cast<int>(last.points.size());
  if (last.termination == TerminationReason::kTargetReached && !last.points.empty()) {
    *u = last.points.back().u.head(u->size());
    return true;
  }
  // How far it came toward `to`, and why it did not arrive.
  double farthest = from;
  for (const ContinuationPoint& q : last.points) {
    if ((q.u(p) - farthest) * (to - from) > 0) farthest = q.u(p);
  }
  std::string where;
  for (const SpecialPoint& sp : last.special_points) {
    if (sp.type == SpecialPointType::kTurningPoint && sp.component == name && sp.u.size() > p) {
      where = fmt::format(": its family of orbits at H = {:.10g} turns back at {} = {:.10g} (a fold), so it has no orbit "
                          "at {} = {:.10g} on this side",
                          level, name, sp.u(p), name, to);
      break;
    }
  }
  if (where.empty()) {
    where = fmt::format(": carried to {} = {:.10g} of {:.10g} at H = {:.10g}, then {} ({})", name, farthest, to, level,
                        ToString(last.termination), last.message.empty() ? "no message" : last.message);
  }
  *why = fmt::format("the start could not be carried from {} = {:.10g} to {:.10g}{}", name, from, to, where);
  return false;
}

}  // namespace

CarriedStart CarryStart(const HybridModel& model, const std::vector<NamedValue>& own, const Vector& start,
                        const IntegratorOptions& integrator) {
  CarriedStart out;
  out.u = start;
  // The parameters still at their own values while an earlier one is carried.
  HybridModel at = model.Clone();
  for (const NamedValue& p : own) at.SetParameter(p.name, p.value);
  std::string from_text, to_text;
  for (const NamedValue& p : own) {
    const double to = model.parameter(p.name);
    if (to == p.value) continue;
    if (!CarryOne(at, p.name, p.value, to, integrator, &out.u, &out.steps, &out.why)) return out;
    at.SetParameter(p.name, to);
    from_text += fmt::format("{}{} = {:.6g}", from_text.empty() ? "" : ", ", p.name, p.value);
    to_text += fmt::format("{}{:.6g}", to_text.empty() ? "" : ", ", to);
  }
  out.ok = true;
  const ShootingLayout layout(model);
  out.report = fmt::format("start carried from the model's own {} to {} at H = {:.10g} ({} continuation steps)",
                           from_text, to_text, out.u(layout.H_index()), out.steps);
  return out;
}

CarriedStart CarryGuess(const HybridModel& model, const std::vector<NamedValue>& own, const Vector& guess,
                        const IntegratorOptions& integrator) {
  HybridModel at = model.Clone();
  for (const NamedValue& p : own) at.SetParameter(p.name, p.value);
  const ShootingLayout layout(at);
  TimeBasedShooting map(at, integrator);
  Corrector corrector(&map);
  Vector u;
  const CorrectorResult corrected = corrector.CorrectFixedComponent(guess, layout.H_index(), guess(layout.H_index()), &u);
  if (!corrected.converged() || !IsPhysical(at, u, integrator)) {
    CarriedStart out;
    out.why = corrected.converged() ? "at the model's own parameter values its orbit is not physical either"
                                    : "the guess does not converge at the model's own parameter values either (" +
                                          corrected.message + ")";
    return out;
  }
  return CarryStart(model, own, u, integrator);
}

}  // namespace hybridcont::study
