#include "hybridcont/replay.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include <Eigen/QR>

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

// The finest integration tolerance the examination asks for: below it a double's rounding over the phases
// is no longer small against the requested error.
constexpr double kFinestTolerance = 1e-14;

// The examination of a replay that does not close (replay.h): Newton with minimum-norm steps on the replayed
// map from x̄_1, holding the first integrals at their values at x̄_1 (the rows dH δ = H(x̄_1) − H(x) fix
// the step along the family, where P − I is singular). True when it finds a fixed point within
// options.tolerance of x̄_1, or when P(x̄_1) itself returns within it (res then holds the return and the
// distance); *error is the last |P(x) − x|.
bool FixedPointNear(const Phase& first, PoincareMap& map, const Vector& x1, const Vector& xi,
                    const ReplayOptions& options, ReplayResult* res, double* error) {
  const int n = static_cast<int>(x1.size()), k = first.num_first_integrals();
  Vector H1, H;
  Matrix dH;
  if (k > 0) first.FirstIntegrals(x1, &H1, nullptr, nullptr);
  Vector x = x1;
  PoincareResult pr;
  // One evaluation per iterate: its return decides, and (but after the last step) its Jacobian steps.
  for (int step = 0;; ++step) {
    const bool last = step == options.fixed_point_iterations;
    if (map.Evaluate(x, xi, /*with_jacobian=*/step > 0 && !last, &pr) != PoincareStatus::kSuccess) return false;
    res->counters += pr.counters;
    *error = (pr.x - x).norm();
    if (*error <= options.tolerance) {
      res->x_end = pr.x;
      res->period = pr.period;
      res->event_times = pr.durations;
      return true;
    }
    if (last) return false;
    if (step == 0 && map.Evaluate(x, xi, /*with_jacobian=*/true, &pr) != PoincareStatus::kSuccess) return false;
    if (step == 0) res->counters += pr.counters;
    Matrix A(n + k, n);
    Vector b(n + k);
    A.topRows(n) = pr.dP_dx0 - Matrix::Identity(n, n);
    b.head(n) = pr.x - x;
    if (k > 0) {
      first.FirstIntegrals(x, &H, &dH, nullptr);
      A.bottomRows(k) = dH;
      b.tail(k) = H - H1;
    }
    const Eigen::CompleteOrthogonalDecomposition<Matrix> cod(A);
    x -= cod.solve(b);
    res->fixed_point_steps = step + 1;
    res->fixed_point_distance = (x - x1).norm();
    if (!x.allFinite() || !(res->fixed_point_distance <= options.tolerance)) return false;
  }
}

}  // namespace

std::string ReplayOptions::Validate() const {
  return internal::OptionsCheck("ReplayOptions")
      .Nested("poincare", poincare.Validate())
      .Require(poincare.section == PoincareSection::kAnchor, "poincare.section", ToString(poincare.section),
               "must be 'anchor' (a time-based orbit ends at the anchor)")
      .Positive("tolerance", tolerance)
      .AtLeast("fixed_point_iterations", fixed_point_iterations, 0)
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
  if (res.error <= options.tolerance) return res;
  // The examination (replay.h): the same replay at refined tolerances, then Newton on that map.
  PoincareOptions refined = options.poincare;
  IntegratorOptions& integrator = refined.event.integrator;
  integrator.rtol = std::max(integrator.rtol * options.refined_tolerance_factor, kFinestTolerance);
  integrator.atol = std::max(integrator.atol * options.refined_tolerance_factor, kFinestTolerance);
  PoincareMap fine(model, refined);
  double refined_error = res.error;
  if (FixedPointNear(model.phase(0), fine, x1, xi, options, &res, &refined_error)) {
    std::ostringstream os;
    os << "the replay from x̄_1 ends at distance " << res.error << " at rtol " << options.poincare.event.integrator.rtol
       << ", within " << refined_error << " at rtol " << integrator.rtol;
    if (res.fixed_point_steps > 0) {
      os << " from the replayed map's fixed point, " << res.fixed_point_distance << " from x̄_1 ("
         << res.fixed_point_steps << " Newton steps)";
    }
    os << ": an ill-conditioned orbit";
    res.message = os.str();
    return res;
  }
  std::ostringstream os;
  os << "replay from x̄_1 ends at distance " << res.error << " > tolerance " << options.tolerance << " (period "
     << pr.period << " vs " << T << "); at rtol " << integrator.rtol << " " << refined_error;
  if (res.fixed_point_steps > 0) {
    os << " after " << res.fixed_point_steps << " Newton steps on the replayed map, at distance "
       << res.fixed_point_distance << " from x̄_1";
  }
  res.status = ReplayStatus::kNotClosed;
  res.message = os.str();
  return res;
}

}  // namespace hybridcont
