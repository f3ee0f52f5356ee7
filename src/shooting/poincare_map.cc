#include "hybridcont/poincare_map.h"

#include <sstream>
#include <stdexcept>

#include "hybridcont/internal/enum_names.h"

namespace hybridcont {

namespace {

constexpr internal::EnumName<PoincareSection> kPoincareSectionNames[] = {
    {PoincareSection::kAnchor, "anchor"},
    {PoincareSection::kLastEvent, "last-event"},
};

constexpr internal::EnumName<PoincareStatus> kPoincareStatusNames[] = {
    {PoincareStatus::kSuccess, "success"},
    {PoincareStatus::kEventFailed, "event failed"},
    {PoincareStatus::kNonFinite, "non-finite value"},
};

}  // namespace

std::string ToString(PoincareSection section) { return internal::EnumToString(kPoincareSectionNames, section); }

bool FromString(const std::string& name, PoincareSection* section) {
  return internal::EnumFromString(kPoincareSectionNames, name, section);
}

std::string ToString(PoincareStatus status) { return internal::EnumToString(kPoincareStatusNames, status); }

std::string PoincareResult::BriefReport() const {
  std::ostringstream os;
  os << ToString(status);
  if (!ok()) os << " (" << message << ")";
  os << ": period " << period << ", " << counters.steps << " steps, " << counters.rhs_evaluations
     << " rhs evaluations";
  return os.str();
}

PoincareMap::PoincareMap(const HybridModel& model, PoincareOptions options) : model_(&model), options_(options) {
  if (const std::string why = options.Validate(); !why.empty()) throw std::invalid_argument(why);
  const int m = model.num_phases();
  EventFlowOptions event = options.event;
  event.from_above = model.automaton() != nullptr;  // guards of an automaton fire when crossed from above
  for (int i = 0; i <= m; ++i) flows_.emplace_back(model.phase(i), event);
}

PoincareStatus PoincareMap::Evaluate(const Eigen::Ref<const Vector>& x0, const Eigen::Ref<const Vector>& xi,
                                     bool with_jacobian, PoincareResult* result) {
  const int m = model_->num_phases();
  const int n1 = model_->phase(0).dim();
  const int k = model_->num_first_integrals();
  if (x0.size() != n1 || xi.size() != k) {
    throw std::invalid_argument("PoincareMap::Evaluate: x0 has " + std::to_string(x0.size()) + " entries (expected " +
                                std::to_string(n1) + "), xi has " + std::to_string(xi.size()) + " (expected " +
                                std::to_string(k) + ")");
  }
  PoincareResult& res = *result;
  res = PoincareResult();
  const bool last_event = options_.section == PoincareSection::kLastEvent;
  auto fail = [&](PoincareStatus status, int phase, std::string why) {
    res.status = status;
    res.failed_phase = phase;
    res.message = std::move(why);
    return status;
  };

  Vector x = x0;
  Matrix Phi_bar, Psi_bar;  // fixed-global-time sensitivities at the start of the current phase
  if (with_jacobian) {
    Phi_bar.setIdentity(n1, n1);
    Psi_bar.setZero(n1, k);
  }
  res.starts.push_back(x);
  for (int i = 0; i < m; ++i) {
    const Phase& phase = model_->phase(i);
    EventFlowResult& ev = phase_result_;
    flows_[i].Integrate(x, xi, PhaseEventGuard(phase), with_jacobian, &ev);
    res.counters += ev.counters;
    if (!ev.ok()) {
      res.event_status = ev.status;
      return fail(PoincareStatus::kEventFailed, i, "phase " + std::to_string(i + 1) + ": " + ev.message);
    }
    res.durations.push_back(ev.t);
    res.transversalities.push_back(ev.transversality);
    phase.Reset(ev.x, &x_next_, with_jacobian ? &D_ : nullptr);
    if (!x_next_.allFinite()) {
      return fail(PoincareStatus::kNonFinite, i, "phase " + std::to_string(i + 1) + " ('" + phase.name() +
                                                     "'): reset map returned a non-finite value");
    }
    if (with_jacobian) {
      const bool last = last_event && i == m - 1;
      SaltationStatus s;
      if (last) {
        s = LastSaltation(D_, ev.f, ev.dg, &S_);
      } else {
        model_->phase(i + 1).UnfoldedVectorField(x_next_, xi, &f_plus_, nullptr, nullptr);
        s = Saltation(D_, ev.f, f_plus_, ev.dg, &S_);
      }
      if (s != SaltationStatus::kSuccess) {
        res.event_status = EventFlowStatus::kGrazing;
        return fail(PoincareStatus::kEventFailed, i, "phase " + std::to_string(i + 1) + " ('" + phase.name() +
                                                         "'): saltation matrix " + ToString(s));
      }
      Psi_bar = S_ * (ev.Phi * Psi_bar + ev.Psi);
      Phi_bar = S_ * (ev.Phi * Phi_bar);
      res.saltations.push_back(S_);
    }
    x = x_next_;
    res.starts.push_back(x);
  }

  if (last_event) {
    res.x = x;
    if (with_jacobian) {
      res.dP_dx0 = Phi_bar;
      res.dP_dxi = Psi_bar;
    }
  } else {
    EventFlowResult& ev = phase_result_;
    flows_[m].Integrate(x, xi, AnchorGuard(model_->anchor()), with_jacobian, &ev);
    res.counters += ev.counters;
    if (!ev.ok()) {
      res.event_status = ev.status;
      return fail(PoincareStatus::kEventFailed, m, "return to the section (phase 1): " + ev.message);
    }
    res.durations.push_back(ev.t);
    res.transversalities.push_back(ev.transversality);
    res.x = ev.x;
    if (with_jacobian) {
      if (SectionProjection(ev.f, ev.dg, &Pi_) != SaltationStatus::kSuccess) {
        res.event_status = EventFlowStatus::kGrazing;
        return fail(PoincareStatus::kEventFailed, m, "return to the section: the flow is tangent to the anchor");
      }
      res.Phi = ev.Phi * Phi_bar;
      res.dP_dx0 = Pi_ * res.Phi;
      res.dP_dxi = Pi_ * (ev.Phi * Psi_bar + ev.Psi);
    }
  }
  for (double t : res.durations) res.period += t;
  return res.status;
}

}  // namespace hybridcont
