#include "study/engine/start_carry.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "hybridcont/corrector.h"
#include "hybridcont/timebased_shooting.h"
#include "study/engine/point_analysis.h"

namespace hybridcont::study {

namespace {

// u (laid out by `from`) laid out by `to`: every unknown by name; those `from` lacks from `extra`.
Vector Relayout(const ShootingLayout& from, const Vector& u, const ShootingLayout& to,
                const std::vector<NamedValue>& extra = {}) {
  Vector out(to.num_unknowns());
  for (int i = 0; i < to.num_unknowns(); ++i) {
    const std::string& name = to.unknown_names()[i];
    const int j = from.UnknownIndex(name);
    if (j >= 0) {
      out(i) = u(j);
      continue;
    }
    const auto it = std::find_if(extra.begin(), extra.end(), [&](const NamedValue& v) { return v.name == name; });
    if (it == extra.end()) throw std::logic_error("carried start: unknown '" + name + "' has no value");
    out(i) = it->value;
  }
  return out;
}

// What one continuation toward the set value gave.
struct Leg {
  bool arrived = false;
  Vector farthest;         // the orbit closest to the set value (the base layout), its parameter value:
  double reached = 0;
  double fold = std::nan("");  // a turning point in the parameter located on the way (NaN: none)
  double level = std::nan("");
  std::string stop;        // why it stopped, where it neither arrived nor folded
  int steps = 0;
};

// One changed parameter carried from `from` to `to` (see start_carry.h), the others as in `model`.
class ParameterCarry {
 public:
  ParameterCarry(const HybridModel& model, std::string name, double from, double to,
                 const IntegratorOptions& integrator, const CarryRoute& route)
      : model_(model), name_(std::move(name)), from_(from), to_(to), integrator_(integrator), route_(route) {
    base_ = route.free;
    base_.observables.clear();  // completed once the start has arrived
    family_parameter_ = std::find(base_.parameters.begin(), base_.parameters.end(), name_) != base_.parameters.end();
  }

  // *u (base layout) at `from_` becomes the orbit at `to_`; *how says which levels it took.
  bool Run(Vector* u, int* steps, std::string* how, std::string* why) {
    Leg best = Trace(*u, from_, /*max_points=*/400);
    *steps += best.steps;
    const double first_level = best.level;
    // What stopped the carry at the first level: a fold, or the end of the physical orbits.
    const std::string obstacle =
        !std::isnan(best.fold)
            ? fmt::format("the family at {} = {:.10g} turns back at {} = {:.6g}", LevelName(), first_level, name_, best.fold)
            : fmt::format("at {} = {:.10g} {}", LevelName(), first_level, best.stop);
    for (int round = 0; round < 3 && !best.arrived && !family_parameter_; ++round) {
      // Along the family: other levels at the farthest value reached, nearest to it first.
      Leg next;
      for (const Vector& v : OtherLevels(best.farthest, best.reached, steps)) {
        Leg leg = Trace(v, best.reached, /*max_points=*/200);
        *steps += leg.steps;
        if (leg.arrived) {
          next = std::move(leg);
          break;
        }
        if (Beyond(leg.reached, next.farthest.size() ? next.reached : best.reached)) next = std::move(leg);
      }
      if (next.farthest.size() == 0) break;
      best = std::move(next);
    }
    if (best.arrived) {
      *u = best.farthest;
      if (best.level != first_level && !std::isnan(first_level)) {
        *how = fmt::format("{}: {}, carried on at {} = {:.10g}", name_, obstacle, LevelName(), best.level);
      }
      return true;
    }
    if (family_parameter_) {
      *why = fmt::format("the start could not be carried from {} = {:.10g} to {:.10g}: it came to {} = {:.10g}, then {}",
                         name_, from_, to_, name_, best.reached, best.stop);
    } else {
      *why = fmt::format("the start could not be carried from {} = {:.10g} to {:.10g}: {}{}, and at the other levels "
                         "tried within the study's bounds it came no farther than {} = {:.10g}",
                         name_, from_, to_, obstacle, std::isnan(best.fold) ? "" : " (a fold)", name_, best.reached);
    }
    return false;
  }

 private:
  bool Beyond(double a, double b) const { return (a - b) * (to_ - from_) > 0; }

  // The coordinate the family is followed in (held while the parameter moves).
  std::string LevelName() const { return ShootingLayout(model_, base_).continued_name(); }

  HybridModel At(double value) const {
    HybridModel at = model_.Clone();
    at.SetParameter(name_, value);
    return at;
  }

  // The carry's free parameters: the base's with the carried one joining, the family's coordinate held.
  FreeParameters CarryFree(const Vector& u) const {
    if (family_parameter_) return base_;
    const ShootingLayout base(model_, base_);
    FreeParameters carry = base_;
    const int held = base.continued_index();
    carry.parameters.push_back(name_);
    carry.fixed.emplace_back(base.unknown_names()[held], u(held));
    return carry;
  }

  // Continuation from the orbit u (base layout) at parameter value `value` toward to_, in whichever
  // orientation moves the parameter that way.
  Leg Trace(const Vector& u, double value, int max_points) const {
    const HybridModel at = At(value);
    const ShootingLayout base(at, base_);
    const FreeParameters free = CarryFree(u);
    TimeBasedShooting map(at, integrator_, free);
    const ShootingLayout& layout = map.layout();
    const Vector start = Relayout(base, u, layout, {{name_, value}});
    const int p = layout.UnknownIndex(name_);
    const double delta = std::abs(to_ - value);
    ContinuationOptions c;
    c.targets = {{name_, to_}};
    // Beyond the set value by its distance at most: a family that passes it is stopped by the target first.
    c.bounds = {{name_, std::min(value, to_) - delta, std::max(value, to_) + delta}};
    if (family_parameter_ && !route_.level_bound.component.empty()) c.bounds.push_back(route_.level_bound);
    c.turning_point_components = {name_};
    c.detect_bifurcations = false;
    c.check_integration_error = false;
    c.initial_step = std::max(1e-3, delta / 50);
    c.max_step = std::max(0.25, delta / 10);
    c.max_points = max_points;
    Branch last;
    for (const int direction : {+1, -1}) {
      c.direction = direction;
      last = TraceBranch(&map, start, c);
      if (last.points.size() >= 2 && (last.points[1].u(p) - value) * (to_ - value) > 0) break;
    }
    Leg leg;
    leg.steps = static_cast<int>(last.points.size());
    leg.reached = value;
    leg.farthest = u;
    if (!family_parameter_) leg.level = u(base.continued_index());
    // The points that moved toward to_, up to the farthest; the family may leave the physical orbits on the
    // way (a flight shrinking to nothing): the carry ends at the last physical one.
    std::vector<const ContinuationPoint*> path;
    for (const ContinuationPoint& q : last.points) {
      if (Beyond(q.u(p), leg.reached)) leg.reached = q.u(p), path.push_back(&q);
    }
    leg.arrived = last.termination == TerminationReason::kTargetReached && !last.points.empty();
    if (leg.arrived && (path.empty() || path.back() != &last.points.back())) path.push_back(&last.points.back());
    const ShootingLayout plain(at);
    const auto physical = [&](const ContinuationPoint* q) {
      const HybridModel there = At(q->u(p));
      return IsPhysical(there, Relayout(layout, q->u, plain), integrator_);
    };
    if (!path.empty() && !physical(path.back())) {
      // Physical at the leg's start, not at its end: the last physical point by bisection over the path.
      int lo = -1, hi = static_cast<int>(path.size()) - 1;  // path[lo] physical (lo = -1: the start), path[hi] not
      while (hi - lo > 1) {
        const int mid = (lo + hi) / 2;
        (physical(path[mid]) ? lo : hi) = mid;
      }
      leg.arrived = false;
      leg.reached = lo >= 0 ? path[lo]->u(p) : value;
      leg.stop = fmt::format("its orbits are no longer physical beyond {} = {:.10g}", name_, leg.reached);
      path.resize(lo + 1);
    }
    if (!path.empty()) leg.farthest = Relayout(layout, path.back()->u, base);
    if (leg.arrived) leg.reached = to_;
    for (const SpecialPoint& sp : last.special_points) {
      if (!leg.stop.empty()) break;  // the physical orbits ended before any fold
      if (sp.type == SpecialPointType::kTurningPoint && sp.component == name_ && sp.u.size() > p) {
        leg.fold = sp.u(p);
        break;
      }
    }
    if (leg.stop.empty()) {
      leg.stop = fmt::format("{} ({})", ToString(last.termination), last.message.empty() ? "no message" : last.message);
    }
    return leg;
  }

  // Orbits of the family through u (base layout) at parameter value `value` at other levels, within the
  // study's bound of the level: a few along each direction, nearest first, the physical ones of each direction
  // before the others.
  std::vector<Vector> OtherLevels(const Vector& u, double value, int* steps) const {
    const HybridModel at = At(value);
    TimeBasedShooting map(at, integrator_, base_);
    const ShootingLayout& layout = map.layout();
    ContinuationOptions c;
    if (route_.level_bound.component == layout.continued_name()) c.bounds = {route_.level_bound};
    c.detect_bifurcations = false;
    c.check_integration_error = false;
    c.max_points = 120;
    std::vector<std::vector<Vector>> sides;
    for (const int direction : {+1, -1}) {
      c.direction = direction;
      const Branch b = TraceBranch(&map, u, c);
      *steps += static_cast<int>(b.points.size());
      std::vector<Vector> side;
      const ShootingLayout plain(at);
      // Near levels first, then farther ones (indices growing geometrically along the trace).
      for (const std::size_t i : {2, 5, 10, 20, 40, 80, 119}) {
        if (i >= b.points.size()) break;
        side.push_back(b.points[i].u);
      }
      std::stable_partition(side.begin(), side.end(),
                            [&](const Vector& v) { return IsPhysical(at, Relayout(layout, v, plain), integrator_); });
      sides.push_back(std::move(side));
    }
    std::vector<Vector> out;
    for (std::size_t k = 0; k < 7; ++k) {
      for (const std::vector<Vector>& side : sides) {
        if (k < side.size()) out.push_back(side[k]);
      }
    }
    return out;
  }

  const HybridModel& model_;
  std::string name_;
  double from_, to_;
  const IntegratorOptions& integrator_;
  const CarryRoute& route_;
  FreeParameters base_;
  bool family_parameter_ = false;
};

}  // namespace

CarriedStart CarryStart(const HybridModel& model, const std::vector<NamedValue>& own, const Vector& start,
                        const IntegratorOptions& integrator, const CarryRoute& route) {
  CarriedStart out;
  // The parameters still at their own values while an earlier one is carried.
  HybridModel at = model.Clone();
  for (const NamedValue& p : own) at.SetParameter(p.name, p.value);
  const ShootingLayout given(model, route.free);
  FreeParameters base_free = route.free;
  base_free.observables.clear();
  const ShootingLayout base(model, base_free);
  Vector u = Relayout(given, start, base);
  std::string from_text, to_text, how;
  for (const NamedValue& p : own) {
    const double to = model.parameter(p.name);
    if (to == p.value) continue;
    std::string leg_how;
    if (!ParameterCarry(at, p.name, p.value, to, integrator, route).Run(&u, &out.steps, &leg_how, &out.why)) return out;
    at.SetParameter(p.name, to);
    from_text += fmt::format("{}{} = {:.6g}", from_text.empty() ? "" : ", ", p.name, p.value);
    to_text += fmt::format("{}{:.6g}", to_text.empty() ? "" : ", ", to);
    if (!leg_how.empty()) how += "; " + leg_how;
  }
  if (given.num_observables() > 0) {
    // The base layout is the given one without its observables, which come last: completed with their values.
    TimeBasedShooting map(model, integrator, route.free);
    out.u = map.CompleteUnknowns(u);
  } else {
    out.u = Relayout(base, u, given, {});
  }
  out.ok = true;
  if (from_text.empty()) {
    out.report = "the start at the model's own values is the start at the values set";
    return out;
  }
  const std::string level =
      base.has_level() && base.UnknownIndex("H") >= 0 ? fmt::format(" at H = {:.10g}", u(base.H_index())) : "";
  out.report = fmt::format("start carried from the model's own {} to {}{} ({} continuation steps{})", from_text, to_text,
                           level, out.steps, how);
  return out;
}

CarriedStart CarryGuess(const HybridModel& model, const std::vector<NamedValue>& own, const Vector& guess,
                        const IntegratorOptions& integrator, const CarryRoute& route) {
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
  return CarryStart(model, own, u, integrator, route);
}

}  // namespace hybridcont::study
