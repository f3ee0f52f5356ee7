#include "continuation/linear_stop.h"

#include <utility>

#include "continuation/bordered_solver.h"
#include "continuation/branch_geometry.h"
#include "continuation/predictor.h"

namespace hybridcont::internal {
namespace {

// Where the Hermite interpolant between a and b meets the stop (cᵀu = value), by bisection on the
// scalar cubic (it meets it: the stop's sign differs at a and b). Predicts the point on the stop with
// error O(|b − a|⁴) where the chord's is O(|b − a|²), which on strongly curved branches leaves the
// constraint corrector's basin (docs/design/continuation.md, "Stop predictor").
Vector HermiteOnStop(const ContinuationPoint& a, const ContinuationPoint& b, const LinearStop& stop) {
  double lo = 0, hi = 1;
  const bool rising = stop.f(a.u) < stop.f(b.u);
  for (int i = 0; i < 60; ++i) {
    const double mid = 0.5 * (lo + hi);
    ((stop.f(HermitePoint(a, b, mid)) < 0) == rising ? lo : hi) = mid;
  }
  return HermitePoint(a, b, 0.5 * (lo + hi));
}

// u lies between a and b along τ_a (up to 1% of the step): the constraint corrector did not run off.
bool InsideSegment(const ContinuationPoint& a, const ContinuationPoint& b, const Vector& u) {
  const double sigma_b = a.tangent.dot(b.u - a.u);
  const double sigma = a.tangent.dot(u - a.u);
  return sigma >= -0.01 * sigma_b && sigma <= 1.01 * sigma_b;
}

}  // namespace

StopLocator::StopLocator(std::vector<LinearStop> stops, ZeroProblem* problem, Corrector* corrector,
                         BorderedSolver* solver, const ContinuationOptions& options)
    : stops_(std::move(stops)),
      problem_(problem),
      corrector_(corrector),
      solver_(solver),
      min_step_(options.min_step),
      location_tolerance_(options.location_tolerance),
      max_location_iterations_(options.max_location_iterations) {}

const LinearStop* StopLocator::FirstCrossed(const ContinuationPoint& a, const ContinuationPoint& b,
                                            double* theta) const {
  const LinearStop* first = nullptr;
  *theta = 2;
  for (const LinearStop& stop : stops_) {
    const double f_a = stop.f(a.u), f_b = stop.f(b.u);
    if (!stop.Crossed(f_a, f_b)) continue;
    const double crossing = f_a / (f_a - f_b);
    if (crossing < *theta) {
      *theta = crossing;
      first = &stop;
    }
  }
  return first;
}

bool StopLocator::Apply(const ContinuationPoint& a, ContinuationPoint* b, int* newton_iterations,
                        TerminationReason* reason, std::string* message) {
  double first_theta = 2;
  const LinearStop* first = FirstCrossed(a, *b, &first_theta);
  if (first == nullptr) return true;
  if (first->f(a.u) == 0) {
    *reason = first->reason();
    *message = "the branch leaves " + first->label + " at its start point";
    return false;
  }
  ContinuationPoint event;
  // From the Hermite interpolant when the tangents agree in orientation, else from the chord.
  const Vector predictor = a.tangent.dot(b->tangent) > 0 ? HermiteOnStop(a, *b, *first)
                                                         : Vector(a.u + first_theta * (b->u - a.u));
  corrector_->set_max_distance((b->u - a.u).norm() + min_step_);
  const CorrectorResult result = corrector_->CorrectWithConstraint(predictor, first->c, first->value, &event.u);
  *newton_iterations += result.iterations;
  const bool ok = result.converged() && InsideSegment(a, *b, event.u) &&
                  InducedTangent(solver_, corrector_->jacobian(), a.tangent, &event.tangent, &event.sb_test, nullptr);
  if (!ok) LocateByRootFinder(a, *b, *first, &event, message);
  event.step = b->step;
  event.newton_iterations = b->newton_iterations + result.iterations;
  event.contraction = b->contraction;
  event.arclength = a.arclength + (event.u - a.u).norm();
  *b = std::move(event);
  *reason = first->reason();
  message->insert(0, "reached " + first->label);
  return true;
}

void StopLocator::LocateByRootFinder(const ContinuationPoint& a, const ContinuationPoint& b, const LinearStop& stop,
                                     ContinuationPoint* event, std::string* message) {
  Segment segment(corrector_, solver_, problem_, a, b, false);
  const RootLocation root = LocateRoot(
      &segment, [&stop](const Segment::Probe& p) { return stop.f(p.u); }, location_tolerance_,
      max_location_iterations_);
  event->u = root.estimate.u;
  event->tangent = root.estimate.tangent;
  // The probe's test uses τ_a as last row: det([dr; τᵀ]) = det([dr; τ_aᵀ]) / (τ·τ_a).
  event->sb_test = root.estimate.sb_test / a.tangent.dot(event->tangent);
  if (!root.located) message->append(" (stop only bracketed: " + root.message + ")");
  // The located trial point satisfies cᵀu = value to the root finder's tolerance; one constraint
  // correction from there (a step of that size) puts it exactly on the stop.
  ContinuationPoint exact;
  corrector_->set_max_distance(10 * location_tolerance_ * (1 + event->u.norm()));
  if (root.located && corrector_->CorrectWithConstraint(event->u, stop.c, stop.value, &exact.u).converged() &&
      InducedTangent(solver_, corrector_->jacobian(), a.tangent, &exact.tangent, &exact.sb_test, nullptr)) {
    event->u = std::move(exact.u);
    event->tangent = std::move(exact.tangent);
    event->sb_test = exact.sb_test;
  }
}

}  // namespace hybridcont::internal
