#include "hybridcont/event_flow.h"
#include "hybridcont/classification.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "hybridcont/internal/enum_names.h"
#include "hybridcont/orbit_observables.h"

namespace hybridcont {

namespace {

constexpr internal::EnumName<OrbitClass> kOrbitClassNames[] = {
    {OrbitClass::kPhysical, "physical"},
    {OrbitClass::kAtRest, "at-rest"},
    {OrbitClass::kDissipative, "dissipative"},
    {OrbitClass::kReversedTime, "reversed-time"},
    {OrbitClass::kZeroDuration, "zero-duration"},
    {OrbitClass::kWrongDirection, "wrong-direction"},
    {OrbitClass::kGrazing, "grazing"},
    {OrbitClass::kAnchorGrazing, "anchor-grazing"},
    {OrbitClass::kMissedEvent, "missed-event"},
    {OrbitClass::kMissedAnchor, "missed-anchor"},
    {OrbitClass::kIntegrationFailed, "integration-failed"},
    {OrbitClass::kReplayFailed, "replay-failed"},
    {OrbitClass::kConstraintViolated, "constraint-violated"},
};

}  // namespace

std::string ToString(OrbitClass c) { return internal::EnumToString(kOrbitClassNames, c); }

bool FromString(const std::string& text, OrbitClass* c) { return internal::EnumFromString(kOrbitClassNames, text, c); }

namespace {

Classification NonPhysical(OrbitClass reason, const std::string& detail) { return {false, reason, detail}; }

// The scalar guard of segment i (event e_i for i < m, anchor a for the return segment).
double SegmentGuard(const HybridModel& model, int i, const Vector& x, RowVector* grad) {
  if (i < model.num_phases()) return model.phase(i).Event(x, grad);
  return model.anchor().Evaluate(x, grad);
}

// The event of the phase segment i runs in (the return segment m runs in phase 1 up to the anchor).
double PhaseEvent(const HybridModel& model, int i, const Vector& x, RowVector* grad) {
  return model.phase(i % model.num_phases()).Event(x, grad);
}

// The first time inside the segment (before its end) at which the trajectory is beyond its guard: a
// downward crossing (g > 0, then g <= 0), or for an event guard any value g < -penetration, including at
// the start (the end of a rod below the ground right after the other end's impact). Searched on the
// Hermite interpolant of every step. Returns the local time or NaN if none.
double FirstViolation(const HybridModel& model, const OrbitTrace& trace, int i, int samples_per_step,
                      bool forbid_negative, bool from_above,
                      double (*guard)(const HybridModel&, int, const Vector&, RowVector*) = SegmentGuard) {
  const auto& nodes = trace.segment(i);
  const double end = trace.duration(i);
  // Crossings within this fraction of the segment's end are the end crossing itself.
  const double end_slack = 1e-9 * std::max(1.0, std::abs(end));
  // Round-off below zero at the start of a phase (a reset onto its own guard) is not a penetration.
  constexpr double kPenetration = 1e-9;
  double previous = guard(model, i, nodes.front().x, nullptr);
  if (forbid_negative && previous < -kPenetration) return 0.0;
  // An automaton's guard fires where it is crossed from above (observable.h): a phase that begins on it
  // (within kGuardStartTolerance) or below it is not beyond it until it has been above it.
  if (from_above && previous <= kGuardStartTolerance) previous = 0.0;
  for (std::size_t j = 0; j + 1 < nodes.size(); ++j) {
    // Samples follow the motion, not just the steps: an exactly integrable flight (the rod's) is crossed in
    // a few large steps while the guard oscillates (sin of a fast angle). Sub-intervals are short enough
    // that no state component moves by more than kMaxMotion between samples.
    constexpr double kMaxMotion = 0.02;
    constexpr int kMaxSamplesPerStep = 100000;
    const double h = std::abs(nodes[j + 1].t - nodes[j].t);
    const double speed = std::max(nodes[j].f.cwiseAbs().maxCoeff(), nodes[j + 1].f.cwiseAbs().maxCoeff());
    const int samples = static_cast<int>(std::min<double>(
        kMaxSamplesPerStep, std::max<double>(samples_per_step, std::ceil(speed * h / kMaxMotion))));
    for (int s = 1; s <= samples; ++s) {
      const double t = nodes[j].t + (nodes[j + 1].t - nodes[j].t) * s / samples;
      if (std::abs(end - t) <= end_slack) return std::nan("");
      const Vector x = s == samples ? nodes[j + 1].x : trace.Interpolate(i, static_cast<int>(j), t);
      const double g = guard(model, i, x, nullptr);
      if ((previous > 0.0 && g <= 0.0) || (forbid_negative && g < -kPenetration)) return t;
      previous = g;
    }
  }
  return std::nan("");
}

}  // namespace

bool ClassifyByUnknowns(const HybridModel& model, const Vector& u, const ClassificationOptions& options,
                        Classification* result) {
  const ShootingLayout layout(model);
  const int m = model.num_phases();
  std::ostringstream os;
  const int k = layout.num_first_integrals();  // no ξ without a first integral
  const double xi = k > 0 ? u.segment(layout.xi_index(), k).cwiseAbs().maxCoeff() : 0.0;
  const double T = layout.Period(u);
  const double zero_time = options.duration_tolerance * std::max(1.0, std::abs(T));
  bool all_zero = true, any_negative = false, any_zero = false;
  int negative_segment = -1, zero_segment = -1;
  for (int i = 0; i <= m; ++i) {
    const double t = u(layout.time_index(i));
    all_zero = all_zero && std::abs(t) <= zero_time;
    if (t < -zero_time && negative_segment < 0) any_negative = true, negative_segment = i;
    if (std::abs(t) <= zero_time && zero_segment < 0) any_zero = true, zero_segment = i;
  }
  if (xi > options.xi_tolerance) {
    os << "|xi| = " << xi;
    *result = NonPhysical(all_zero ? OrbitClass::kAtRest : OrbitClass::kDissipative, os.str());
  } else if (any_negative) {
    os << "t" << negative_segment + 1 << " = " << u(layout.time_index(negative_segment)) << " < 0";
    *result = NonPhysical(OrbitClass::kReversedTime, os.str());
  } else if (any_zero) {
    os << "t" << zero_segment + 1 << " = " << u(layout.time_index(zero_segment));
    *result = NonPhysical(OrbitClass::kZeroDuration, os.str());
  } else {
    return false;
  }
  return true;
}

Classification ClassifyOrbit(const HybridModel& model, const Vector& u, const OrbitTrace& trace,
                             const ClassificationOptions& options) {
  if (Classification decided; ClassifyByUnknowns(model, u, options, &decided)) return decided;
  const ShootingLayout layout(model);
  const int m = model.num_phases();
  std::ostringstream os;
  if (!trace.ok()) return NonPhysical(OrbitClass::kIntegrationFailed, trace.message());
  // Transversal downward crossing at the end of every segment.
  for (int i = 0; i <= m; ++i) {
    const TraceNode& end = trace.segment(i).back();
    RowVector grad;
    SegmentGuard(model, i, end.x, &grad);
    const double speed = grad.dot(end.f) / std::max(grad.norm() * end.f.norm(), 1e-300);
    if (speed > -options.grazing_tolerance) {
      os << (i < m ? "event of segment " : "anchor at the end of segment ") << i + 1
         << ": normalized crossing speed " << speed;
      if (speed > options.grazing_tolerance) {  // crossed upward: the orbit returns the other way through it
        if (i == m) os << " (the section is crossed upward; the anchor's expression with the opposite sign is crossed downward)";
        return NonPhysical(OrbitClass::kWrongDirection, os.str());
      }
      return NonPhysical(i == m ? OrbitClass::kAnchorGrazing : OrbitClass::kGrazing, os.str());
    }
  }
  // First crossing: the trajectory stays on the positive side of its event inside the phase (no earlier
  // downward crossing, no start beyond it), and the anchor is not crossed earlier in the return segment.
  for (int i = 0; i <= m; ++i) {
    // A phase that ends at a cut of its automaton (hybrid_automaton.h) has a guard that only marks a time.
    const bool cut = model.automaton() && model.automaton()->transitions()[model.word()[i % m]].cut;
    const bool automaton = model.automaton() != nullptr;
    const bool bounds = i < m && !cut && !automaton && model.phase(i).event_bounds_state();
    const double t = FirstViolation(model, trace, i, options.samples_per_step, /*forbid_negative=*/bounds,
                                    /*from_above=*/automaton && i < m);
    if (!std::isnan(t)) {
      os << (i < m ? "event" : "anchor") << " of segment " << i + 1 << " violated at t = " << t << " < "
         << trace.duration(i);
      return NonPhysical(i < m ? OrbitClass::kMissedEvent : OrbitClass::kMissedAnchor, os.str());
    }
  }
  // The return segment runs in phase 1 before its section: phase 1's own event may not be crossed there
  // from above either. A reset may land below it (a walker's swing foot under the ground at the scuffing
  // the model ignores), so there it counts from where it has been above 0, as an automaton's guard does.
  {
    const double t = FirstViolation(model, trace, m, options.samples_per_step, /*forbid_negative=*/false,
                                    /*from_above=*/true, PhaseEvent);
    if (!std::isnan(t)) {
      os << "event of phase 1 violated in segment " << m + 1 << " (before the section) at t = " << t << " < "
         << trace.duration(m);
      return NonPhysical(OrbitClass::kMissedEvent, os.str());
    }
  }
  // Admissibility constraints (observable.h): each minimum >= 0, the first violated one named.
  const std::vector<Observable>& observables = model.observables();
  if (std::any_of(observables.begin(), observables.end(), [](const Observable& o) { return o.constraint; })) {
    ObservableEvaluator evaluator(model, layout, IntegratorOptions{});
    for (int j = 0; j < static_cast<int>(observables.size()); ++j) {
      if (!observables[j].constraint) continue;
      double value = 0.0;
      const EvaluationStatus status = evaluator.Evaluate(j, u, &value, nullptr);
      if (!status.ok) return NonPhysical(OrbitClass::kIntegrationFailed, status.message);
      if (value < -options.constraint_tolerance) {
        os << "constraint '" << observables[j].name << "': minimum " << value << " < 0";
        return NonPhysical(OrbitClass::kConstraintViolated, os.str());
      }
    }
  }
  return {true, OrbitClass::kPhysical, ""};
}

}  // namespace hybridcont
