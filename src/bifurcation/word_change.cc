#include "hybridcont/word_change.h"

#include <fmt/format.h>

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <functional>

#include "hybridcont/automaton_words.h"
#include "hybridcont/corrector.h"
#include "hybridcont/shooting_layout.h"
#include "hybridcont/timebased_shooting.h"

namespace hybridcont {
namespace {

// Smallest singular value of the new word's Jacobian, relative to the largest, below which the orbit is a
// singular point of its map (a branch point): ~1e-16/1e-10 precision of the located orbit times the scale.
constexpr double kSingularRatio = 1e-9;

// Times closer than this (relative) are one instant: an extremum located next to a segment's end, where the
// guard's rate vanishes too, is that end.
constexpr double kSameInstant = 1e-9;

// One shooting segment of the new word: its duration and start state.
struct Piece {
  double t = 0;
  Vector x;
};

// The old orbit's segments.
std::vector<Piece> Pieces(const ShootingLayout& layout, const Vector& u) {
  std::vector<Piece> pieces;
  for (int s = 0; s < layout.num_segments(); ++s) {
    pieces.push_back({u(layout.time_index(s)), u.segment(layout.state_offset(s), layout.dim(s))});
  }
  return pieces;
}

// The state of segment s of u after time t.
bool FlowTo(const HybridModel& model, const ShootingLayout& layout, const Vector& u, int s, double t,
            const IntegratorOptions& integrator, Vector* x, std::string* why) {
  PhaseFlow flow(model.phase(s), integrator);
  PhaseFlowResult res;
  const int k = layout.num_first_integrals();
  const Vector xi = k > 0 ? Vector(u.segment(layout.xi_index(), k)) : Vector();
  flow.Integrate(u.segment(layout.state_offset(s), layout.dim(s)), xi, t, false, &res);
  if (!res.ok()) {
    *why = "integrating segment " + std::to_string(s + 1) + " failed: " + res.message;
    return false;
  }
  *x = res.x;
  return true;
}

// Builds the new word's unknowns from `pieces`, evaluates its map there, names the worst block when the
// residual is too large, and corrects the orbit in the new word.
WordChange Check(const HybridModel& model, const Vector& u, Word word, const std::string& rule,
                 const std::function<bool(const HybridModel&, std::vector<Piece>*, std::string*)>& build,
                 const IntegratorOptions& integrator) {
  WordChange c;
  c.word = word;
  c.rule = rule;
  const HybridAutomaton& a = *model.automaton();
  HybridModel next = WordModelAt(model, word);
  std::vector<Piece> pieces;
  if (!build(next, &pieces, &c.reason)) return c;
  const ShootingLayout old_layout(model);
  TimeBasedShooting map(next, integrator);
  const ShootingLayout& layout = map.layout();
  HYBRIDCONT_DEMAND(static_cast<int>(pieces.size()) == layout.num_segments());
  c.u_mapped = Vector::Zero(layout.num_unknowns());
  for (int s = 0; s < layout.num_segments(); ++s) {
    HYBRIDCONT_DEMAND(pieces[s].x.size() == layout.dim(s));
    c.u_mapped(layout.time_index(s)) = pieces[s].t;
    c.u_mapped.segment(layout.state_offset(s), layout.dim(s)) = pieces[s].x;
  }
  const int k = layout.num_first_integrals();
  for (int j = 0; j < k; ++j) c.u_mapped(layout.xi_index(j)) = u(old_layout.xi_index(j));
  if (layout.has_level()) c.u_mapped(layout.H_index()) = u(old_layout.H_index());
  Vector r;
  Matrix dr;  // for the correction below; the same evaluation gives the residual
  const EvaluationStatus status = map.Evaluate(c.u_mapped, &r, &dr);
  if (!status.ok) {
    c.reason = "the new word's map fails there: " + status.message;
    return c;
  }
  c.residual = r.norm();
  if (!(c.residual <= kWordChangeResidual)) {
    // The block that fails: a transition's reset rows or its guard row, the anchor, the first integrals.
    const int m = next.num_phases();
    double worst = -1;
    for (int s = 0; s <= m; ++s) {
      const int rows = layout.dim((s + 1) % (m + 1) == 0 ? 0 : s + 1);
      const double reset = r.segment(layout.block_row(s), rows).norm();
      const double guard = std::abs(r(layout.block_row(s) + rows));
      if (s == m) {
        if (std::max(reset, guard) > worst) {
          worst = std::max(reset, guard);
          c.reason = fmt::format("the orbit does not return to the section in the new word (mismatch {:.2e})", worst);
        }
        continue;
      }
      const std::string& name = a.transitions()[word[s]].name;
      if (guard > worst) {
        worst = guard;
        c.reason = fmt::format("the guard of '{}' is {:.3e} where phase {} ({}) ends, not 0", name, r(layout.block_row(s) + rows),
                               s + 1, next.phase(s).name());
      }
      if (reset > worst) {
        worst = reset;
        c.reason = fmt::format("the reset of '{}' gives another state than the phase sequence it replaces (difference "
                               "{:.3e})", name, reset);
      }
    }
    const double integrals = r.segment(layout.first_integral_row(), k).norm();
    if (integrals > worst) c.reason = fmt::format("the first integrals differ by {:.3e}", integrals);
    c.reason += fmt::format(" (residual {:.2e})", c.residual);
    return c;
  }
  // Corrected in the new word from the kernel direction of its Jacobian (regular at a fold in H̄ too).
  Eigen::JacobiSVD<Matrix> svd(dr, Eigen::ComputeFullV);
  const Vector tau = svd.matrixV().col(dr.cols() - 1);
  const double smallest = svd.singularValues()(svd.singularValues().size() - 1);
  c.singular = !(smallest > kSingularRatio * svd.singularValues()(0));
  if (c.singular) {
    // A branch point of the new word (where families of it cross): the mapped orbit is its zero already.
    c.u = c.u_mapped;
  } else {
    Corrector corrector(&map);
    const CorrectorResult result = corrector.CorrectMoorePenrose(c.u_mapped, tau, &c.u);
    if (result.status != CorrectorStatus::kConverged) {
      c.reason = "the new word's corrector did not converge (" + ToString(result.status) + ")";
      return c;
    }
  }
  c.state_difference =
      (c.u.segment(layout.state_offset(0), layout.dim(0)) - u.segment(old_layout.state_offset(0), old_layout.dim(0)))
          .norm();
  c.period_difference = std::abs(layout.Period(c.u) - old_layout.Period(u));
  c.accepted = true;
  return c;
}

Vector ResetOf(const HybridModel& model, int phase, const Vector& x) {
  Vector next;
  model.phase(phase).Reset(x, &next, nullptr);
  return next;
}

}  // namespace

std::vector<WordChange> WordsWithoutPhase(const HybridModel& model, const Vector& u, int segment,
                                          const IntegratorOptions& integrator, std::string* why) {
  std::vector<WordChange> out;
  HYBRIDCONT_DEMAND(model.automaton() != nullptr);
  const HybridAutomaton& a = *model.automaton();
  const Word& w = model.word();
  const int m = static_cast<int>(w.size());
  if (segment < 1 || segment >= m) {
    *why = "the zero duration is the anchor mode's (the section's phase stays in every word)";
    return out;
  }
  const AutomatonTransition& before = a.transitions()[w[segment - 1]];
  const AutomatonTransition& after = a.transitions()[w[segment]];
  const ShootingLayout layout(model);
  for (std::size_t tau = 0; tau < a.transitions().size(); ++tau) {
    const AutomatonTransition& t = a.transitions()[tau];
    if (t.from != before.from || t.to != after.to) continue;
    Word next = w;
    next[segment - 1] = static_cast<int>(tau);
    next.erase(next.begin() + segment);
    const std::string rule = fmt::format("phase {} ({}) removed: {} then {} replaced by {}", segment + 1,
                                         a.modes()[before.to].name, before.name, after.name, t.name);
    out.push_back(Check(model, u, next, rule,
                        [&](const HybridModel&, std::vector<Piece>* pieces, std::string*) {
                          *pieces = Pieces(layout, u);
                          pieces->erase(pieces->begin() + segment);
                          return true;
                        },
                        integrator));
  }
  // The zero-duration phase traded for one of another mode between the same neighbours (a running stride's
  // flight of zero duration is a double support of zero duration where both legs meet the ground at once):
  // τ1 into that mode, at once τ2 out of it. The new word's map decides whether the guards and resets agree.
  if (std::none_of(out.begin(), out.end(), [](const WordChange& c) { return c.accepted; })) {
    for (int tau1 : a.TransitionsFrom(before.from)) {
      const AutomatonTransition& t1 = a.transitions()[tau1];
      if (t1.to == before.to || t1.cut) continue;
      for (int tau2 : a.TransitionsFrom(t1.to)) {
        const AutomatonTransition& t2 = a.transitions()[tau2];
        if (t2.to != after.to || t2.cut) continue;
        Word next = w;
        next[segment - 1] = tau1;
        next[segment] = tau2;
        const std::string rule =
            fmt::format("phase {} ({}) of zero duration traded for one in '{}': {} then {} replaced by {} then {}",
                        segment + 1, a.modes()[before.to].name, a.modes()[t1.to].name, before.name, after.name,
                        t1.name, t2.name);
        out.push_back(Check(model, u, next, rule,
                            [&](const HybridModel& nm, std::vector<Piece>* pieces, std::string* failure) {
                              *pieces = Pieces(layout, u);
                              // The new mode's state: τ1's reset of the state where phase `segment` began.
                              const Piece& last = (*pieces)[segment - 1];
                              Vector x_end;
                              if (!FlowTo(model, layout, u, segment - 1, last.t, integrator, &x_end, failure)) {
                                return false;
                              }
                              (*pieces)[segment] = {0.0, ResetOf(nm, segment - 1, x_end)};
                              return true;
                            },
                            integrator));
      }
    }
  }
  if (out.empty()) {
    *why = fmt::format("no transition from mode '{}' to mode '{}' takes the place of phase {} ({}), nor a pair "
                       "through another mode",
                       a.modes()[before.from].name, a.modes()[after.to].name, segment + 1, a.modes()[before.to].name);
  }
  return out;
}

std::vector<WordChange> WordsWithTransition(const HybridModel& model, const Vector& u, int transition, int segment,
                                            double t, const IntegratorOptions& integrator, std::string* why) {
  std::vector<WordChange> out;
  HYBRIDCONT_DEMAND(model.automaton() != nullptr);
  const HybridAutomaton& a = *model.automaton();
  const Word& w = model.word();
  const int m = static_cast<int>(w.size());
  const ShootingLayout layout(model);
  const AutomatonTransition& tau = a.transitions()[transition];
  const int mode = a.transitions()[w[segment % m]].from;
  HYBRIDCONT_DEMAND(tau.from == mode);
  double t_s = u(layout.time_index(segment));
  if (std::abs(t) <= kSameInstant * (1 + std::abs(t_s))) {
    // Where the segment begins: the end of the one before, when a cut (the same state) separates them.
    if (segment == 0 || !a.transitions()[w[segment - 1]].cut) {
      *why = segment == 0 ? "the guard is touched at the section"
                          : "the guard is touched where the phase begins, right after a transition that is not a cut";
      return out;
    }
    --segment;
    t = t_s = u(layout.time_index(segment));
  }
  const bool at_end = std::abs(t - t_s) <= kSameInstant * (1 + std::abs(t_s));
  if (at_end && segment == m) {
    *why = "the guard is touched at the section";
    return out;
  }
  Vector x_star;
  if (!FlowTo(model, layout, u, segment, t, integrator, &x_star, why)) return out;
  // Where the inserted transitions lead back to: the rest of the segment's mode, or (at its end) the mode
  // its own transition leads into.
  const int back = at_end ? a.transitions()[w[segment]].to : mode;
  std::vector<int> returns;  // -1: τ leads there itself
  if (tau.to == back) returns.push_back(-1);
  for (int sigma : a.TransitionsFrom(tau.to)) {
    if (a.transitions()[sigma].to == back && tau.to != back) returns.push_back(sigma);
  }
  if (returns.empty()) {
    *why = fmt::format("no transition from mode '{}' back to mode '{}'", a.modes()[tau.to].name, a.modes()[back].name);
    return out;
  }
  for (int sigma : returns) {
    std::vector<int> inserted = {transition};
    if (sigma >= 0) inserted.push_back(sigma);
    Word next(w.begin(), w.begin() + std::min(segment, m));
    next.insert(next.end(), inserted.begin(), inserted.end());
    if (!at_end && segment < m) next.push_back(w[segment]);
    if (segment < m) next.insert(next.end(), w.begin() + segment + 1, w.end());
    const int first = std::min(segment, m);  // the new word's index of τ
    std::string rule = at_end ? fmt::format("{} replaced by {}", a.transitions()[w[segment]].name, tau.name)
                              : fmt::format("{} inserted in phase {} ({}) at t = {:.10g}", tau.name,
                                            segment % m + 1, a.modes()[mode].name, t);
    if (sigma >= 0) rule += fmt::format(" with a phase of zero duration in '{}' and {}", a.modes()[tau.to].name,
                                        a.transitions()[sigma].name);
    out.push_back(Check(model, u, next, rule,
                        [&](const HybridModel& nm, std::vector<Piece>* pieces, std::string*) {
                          const std::vector<Piece> old = Pieces(layout, u);
                          pieces->assign(old.begin(), old.begin() + segment);
                          pieces->push_back({t, old[segment].x});
                          Vector x = ResetOf(nm, first, x_star);
                          if (sigma >= 0) {
                            pieces->push_back({0.0, x});
                            x = ResetOf(nm, first + 1, x);
                          }
                          if (!at_end) pieces->push_back({t_s - t, x});
                          pieces->insert(pieces->end(), old.begin() + segment + 1, old.end());
                          return true;
                        },
                        integrator));
  }
  return out;
}

}  // namespace hybridcont
