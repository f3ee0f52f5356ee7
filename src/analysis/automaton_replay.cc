#include "hybridcont/event_flow.h"
#include "hybridcont/automaton_replay.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "hybridcont/shooting_layout.h"

namespace hybridcont {
namespace {

// Bisection steps refining a crossing time between two accepted steps: 2^-60 of a step, below the
// integrator's accuracy.
constexpr int kBisections = 60;
// A leg is first integrated over its duration in the word times 1 + kLegMargin (plus kLegMargin): the
// automaton's crossing of a physical orbit lies at that duration, up to the integration error.
constexpr double kLegMargin = 0.05;

// A state of a leg's trajectory at time t since the leg began.
struct Sample {
  double t;
  Vector y;
};

// One leg of the replay, in one mode: the flow of the mode's phase and the functions watched along it, the
// guards of the transitions out of the mode (out) and, on the last leg, the anchor (index out.size()).
struct WatchedLeg {
  const HybridModel& model;
  const HybridAutomaton& a;
  const std::vector<int>& out;
  const Vector& p;  // the model's parameter values
  const Vector& xi;
  const Phase& ph;
  bool last;
  PhaseFlow& flow;

  // The watched functions at y.
  std::vector<double> Values(const Eigen::Ref<const Vector>& y) const {
    std::vector<double> v;
    for (int t : out) v.push_back(a.transitions()[t].guard->Evaluate(y, p, nullptr, nullptr));
    if (last) v.push_back(model.anchor().Evaluate(y, nullptr));
    return v;
  }
  // Their rates along the flow at y, ġ = ∇g · f.
  std::vector<double> Rates(const Eigen::Ref<const Vector>& y) const {
    Vector f;
    ph.UnfoldedVectorField(y, xi, &f, nullptr, nullptr);
    std::vector<double> v;
    RowVector dg;
    for (int t : out) a.transitions()[t].guard->Evaluate(y, p, &dg, nullptr), v.push_back(dg.dot(f));
    if (last) model.anchor().Evaluate(y, &dg), v.push_back(dg.dot(f));
    return v;
  }
  // The state the flow reaches from `from` after time t; empty if the integration fails.
  Vector StateAt(const Vector& from, double t) const {
    PhaseFlowResult r;
    flow.Integrate(from, xi, t, false, &r);
    return r.ok() ? r.x : Vector();
  }
};

// The first downward crossing among a leg's watched functions: its index (-1: none), time and state.
struct LegCrossing {
  int first = -1;
  double t = std::numeric_limits<double>::infinity();
  Vector x;
};

// Scans consecutive samples of a leg for downward crossings of the watched functions, up to the first pair
// of samples between which one is found, and keeps in *crossing the earliest (when earlier than the one it
// holds). A crossing is located by bisection in time, integrating from the earlier sample of its pair.
//
// The integrator's steps may step over a shallow dip of a guard (a swing foot that grazes the ground): where
// a guard positive at both ends of a step has its rate go from negative to positive, its minimum in between
// is located (bisection on the rate) and, if it is <= 0, the crossing lies before it. Likewise a shallow
// bump above 0 of a guard negative at both ends arms it, and the crossing lies after its maximum.
void ScanForFirstCrossing(const WatchedLeg& watched, const std::vector<Sample>& samples, LegCrossing* crossing) {
  int& first = crossing->first;
  double& t_cross = crossing->t;
  Vector& x_cross = crossing->x;
  std::vector<double> before = watched.Values(samples[0].y), rate_before = watched.Rates(samples[0].y);
  if (samples[0].t == 0) {
    for (double& v : before) v = v > kGuardStartTolerance ? v : 0.0;  // on or below a guard: not above it
  }
  for (std::size_t s = 1; s < samples.size() && first < 0; ++s) {
    const Vector& y0 = samples[s - 1].y;
    const std::vector<double> after = watched.Values(samples[s].y), rate_after = watched.Rates(samples[s].y);
    for (std::size_t j = 0; j < after.size(); ++j) {
      double hi = samples[s].t - samples[s - 1].t;
      Vector y_hi = samples[s].y;
      double lo = 0;
      if (before[j] > 0 && after[j] > 0 && rate_before[j] < 0 && rate_after[j] > 0) {
        for (int b = 0; b < kBisections; ++b) {  // the minimum: the rate's zero
          const double mid = 0.5 * (lo + hi);
          const Vector y = watched.StateAt(y0, mid);
          if (y.size() == 0) break;
          if (watched.Rates(y)[j] < 0) lo = mid;
          else hi = mid, y_hi = y;
        }
        if (!(watched.Values(y_hi)[j] <= 0)) continue;
        lo = 0;
      } else if (before[j] <= 0 && after[j] <= 0 && rate_before[j] > 0 && rate_after[j] < 0) {
        // A bump above 0 between the samples (a foot that barely clears the ground) arms the guard, and
        // it is crossed on the way down after the maximum; one by no more than the event flow's touch
        // tolerance does not (a foot that starts on the ground and sinks into it at once, rising by
        // rounding first), as in the replay of the word (event_flow.h).
        double top = hi;
        Vector y_top = y_hi;
        for (int b = 0; b < kBisections; ++b) {  // the maximum: the rate's zero
          const double mid = 0.5 * (lo + top);
          const Vector y = watched.StateAt(y0, mid);
          if (y.size() == 0) break;
          if (watched.Rates(y)[j] > 0) lo = mid;
          else top = mid, y_top = y;
        }
        if (!(watched.Values(y_top)[j] > EventFlowOptions{}.touch_tolerance)) continue;
        lo = top;
      } else if (!(before[j] > 0 && after[j] <= 0)) {
        continue;
      }
      // Bisection in [t_{s-1} + lo, t_{s-1} + hi], integrating from sample s-1.
      for (int b = 0; b < kBisections; ++b) {
        const double mid = 0.5 * (lo + hi);
        const Vector y = watched.StateAt(y0, mid);
        if (y.size() == 0) break;
        if (watched.Values(y)[j] > 0) lo = mid;
        else hi = mid, y_hi = y;
      }
      if (samples[s - 1].t + hi < t_cross) t_cross = samples[s - 1].t + hi, first = static_cast<int>(j), x_cross = y_hi;
    }
    before = after;
    rate_before = rate_after;
  }
}

}  // namespace

AutomatonReplayResult ReplayAutomaton(const HybridModel& model, const Vector& u, const IntegratorOptions& integrator) {
  HYBRIDCONT_DEMAND(model.automaton() != nullptr);
  AutomatonReplayResult result;
  const HybridAutomaton& a = *model.automaton();
  const Word& word = model.word();
  const int m = static_cast<int>(word.size());
  const ShootingLayout layout(model);
  const int k = layout.num_first_integrals();
  const Vector xi = k > 0 ? Vector(u.segment(layout.xi_index(), k)) : Vector();
  Vector p(model.parameters().size());
  for (int j = 0; j < p.size(); ++j) p(j) = model.parameter_value(j);
  // A phase of the word per mode (its flow) and per transition (its reset); -1: not in the word.
  std::vector<int> phase_of_mode(a.modes().size(), -1), phase_of_transition(a.transitions().size(), -1);
  for (int i = m - 1; i >= 0; --i) {
    phase_of_mode[a.transitions()[word[i]].from] = i;
    phase_of_transition[word[i]] = i;
  }
  const Vector x1 = u.segment(layout.state_offset(0), layout.dim(0));
  const double horizon = 2 * std::abs(layout.Period(u)) + 1.0;
  Vector x = x1;
  int mode = a.anchor_mode();
  double elapsed = 0;
  for (int leg = 0; leg <= m; ++leg) {
    const int phase = phase_of_mode[mode];
    HYBRIDCONT_DEMAND(phase >= 0);  // modes are entered by transitions of the word only
    const std::vector<int> out = a.TransitionsFrom(mode);
    const bool last = leg == m;
    const Phase& ph = model.phase(phase);
    std::vector<Sample> samples;
    PhaseFlow flow(model.phase(phase), integrator);
    PhaseFlowResult res;
    const WatchedLeg watched{model, a, out, p, xi, ph, last, flow};
    // The word's own duration of this leg, with a margin, first; the rest of the horizon only when no guard is
    // crossed within it (the orbit is not one of the automaton then, or leaves the word later).
    const double expected = std::abs(u(layout.time_index(leg))) * (1 + kLegMargin) + kLegMargin;
    const auto integrate = [&](const Vector& from, double t0, double duration) {
      flow.Integrate(from, xi, duration, false, &res, [&](double t, const Eigen::Ref<const Vector>& y) {
        if (t > 0 || samples.empty()) samples.push_back({t0 + t, y});
      });
      return res.ok() || samples.size() >= 2;
    };
    if (!integrate(x, 0, std::min(expected, horizon - elapsed))) {
      result.message = fmt::format("integrating mode '{}' failed: {}", a.modes()[mode].name, res.message);
      return result;
    }
    // The first downward crossing among the watched functions in the samples so far.
    LegCrossing crossing;
    ScanForFirstCrossing(watched, samples, &crossing);
    if (crossing.first < 0 && samples.back().t < horizon - elapsed) {  // not within the expected duration: the rest
      const Sample last_sample = samples.back();
      samples.erase(samples.begin(), samples.end() - 1);
      if (integrate(last_sample.y, last_sample.t, horizon - elapsed - last_sample.t)) {
        ScanForFirstCrossing(watched, samples, &crossing);
      }
    }
    if (crossing.first < 0) {
      result.message = fmt::format("no guard out of mode '{}' is crossed within t = {:.6g}", a.modes()[mode].name,
                                   horizon - elapsed);
      return result;
    }
    elapsed += crossing.t;
    if (last && crossing.first == static_cast<int>(out.size())) {  // back at the section
      result.ok = true;
      result.same_word = result.taken == word;
      result.return_error = (crossing.x - x1).norm();
      return result;
    }
    const int tau = out[crossing.first];
    result.taken.push_back(tau);
    if (phase_of_transition[tau] < 0 || leg == m) {
      result.ok = true;
      result.message = fmt::format("the automaton takes '{}' (at t = {:.10g}), which the word does not take there",
                                   a.transitions()[tau].name, elapsed);
      return result;
    }
    model.phase(phase_of_transition[tau]).Reset(crossing.x, &x, nullptr);
    mode = a.transitions()[tau].to;
  }
  HYBRIDCONT_UNREACHABLE();
}

}  // namespace hybridcont
