#include "hybridcont/replay.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

#include "hybridcont/shooting_layout.h"

#include "hybridcont/internal/enum_names.h"
#include "hybridcont/internal/options_check.h"

namespace hybridcont {

namespace {

constexpr internal::EnumName<ReplayStatus> kReplayStatusNames[] = {
    {ReplayStatus::kReturned, "returned"},
    {ReplayStatus::kNotClosed, "not closed"},
    {ReplayStatus::kEventFailed, "event failed"},
};

}  // namespace

std::string ReplayOptions::Validate() const {
  return internal::OptionsCheck("ReplayOptions")
      .Nested("poincare", poincare.Validate())
      .Require(poincare.section == PoincareSection::kAnchor, "poincare.section", ToString(poincare.section),
               "must be 'anchor' (a time-based orbit ends at the anchor)")
      .Positive("tolerance", tolerance)
      .message();
}

std::string ToString(ReplayStatus status) { return internal::EnumToString(kReplayStatusNames, status); }

std::string ReplayResult::BriefReport() const {
  std::ostringstream os;
  os << ToString(status);
  if (status == ReplayStatus::kEventFailed) return os.str() + " (" + message + ")";
  os << ": error " << error << ", period " << period << " (relative error " << period_error
     << "), max event time error " << max_event_time_error;
  return os.str();
}

ReplayResult ReplayOrbit(const HybridModel& model, const Vector& u, const ReplayOptions& options) {
  if (const std::string why = options.Validate(); !why.empty()) throw std::invalid_argument(why);
  const ShootingLayout layout(model);
  if (u.size() != layout.num_unknowns()) {
    throw std::invalid_argument("ReplayOrbit: u has " + std::to_string(u.size()) + " entries, the time-based layout has " +
                                std::to_string(layout.num_unknowns()));
  }
  ReplayResult res;
  const Vector x1 = u.segment(layout.state_offset(0), layout.dim(0));
  const Vector xi = u.segment(layout.xi_index(), layout.num_first_integrals());
  PoincareMap map(model, options.poincare);
  PoincareResult pr;
  map.Evaluate(x1, xi, /*with_jacobian=*/false, &pr);
  res.counters = pr.counters;
  res.event_times = pr.durations;
  if (!pr.ok()) {
    res.status = ReplayStatus::kEventFailed;
    res.message = pr.message;
    return res;
  }
  res.x_end = pr.x;
  res.error = (pr.x - x1).norm();
  res.period = pr.period;
  const double T = layout.Period(u);
  const double scale = std::abs(T) > 0.0 ? std::abs(T) : 1.0;
  res.period_error = std::abs(pr.period - T) / scale;
  for (int i = 0; i < layout.num_segments(); ++i) {
    res.event_time_errors.push_back(std::abs(pr.durations[i] - u(layout.time_index(i))) / scale);
    res.max_event_time_error = std::max(res.max_event_time_error, res.event_time_errors.back());
  }
  if (!(res.error <= options.tolerance)) {
    std::ostringstream os;
    os << "replay from x̄_1 ends at distance " << res.error << " > tolerance " << options.tolerance
       << " (period " << pr.period << " vs " << T << ")";
    res.status = ReplayStatus::kNotClosed;
    res.message = os.str();
  }
  return res;
}

}  // namespace hybridcont
