// Internal: the stops that are level sets of a linear functional cᵀu (ContinuationOptions' targets,
// bounds and sum bounds), shared by the stepper (which locates them, StopLocator) and the exploration
// (which names the stop an image of a branch ends on).
//
//   StopLocator locator(LinearStops(options, problem), &problem, &corrector, &solver, options);
//   if (!locator.Apply(a, &b, &newton_iterations, &reason, &message)) ...  // the branch ends at a
//   // otherwise b is the point exactly on the first stop crossed in (a, b], or unchanged
#ifndef HYBRIDCONT_SRC_CONTINUATION_LINEAR_STOP_H_
#define HYBRIDCONT_SRC_CONTINUATION_LINEAR_STOP_H_

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "hybridcont/continuation.h"
#include "hybridcont/corrector.h"
#include "hybridcont/scaled_problem.h"
#include "hybridcont/zero_problem.h"

namespace hybridcont::internal {

class BorderedSolver;

struct LinearStop {
  enum class Kind { kTarget, kLower, kUpper };
  Vector c;
  double value = 0;
  Kind kind = Kind::kTarget;
  std::string label;  // e.g. "H <= 2", "t1+t2+t3 >= -20", "H = 1.5", in the problem's own units

  double f(const Vector& u) const { return c.dot(u) - value; }
  bool Crossed(double f_a, double f_b) const {
    switch (kind) {
      case Kind::kTarget: return f_a != 0 && (f_b == 0 || std::signbit(f_a) != std::signbit(f_b));
      case Kind::kLower: return f_a >= 0 && f_b < 0;
      case Kind::kUpper: return f_a <= 0 && f_b > 0;
    }
    return false;
  }
  bool Violated(double f_u) const {
    return (kind == Kind::kLower && f_u < 0) || (kind == Kind::kUpper && f_u > 0);
  }
  TerminationReason reason() const {
    return kind == Kind::kTarget ? TerminationReason::kTargetReached : TerminationReason::kBoundReached;
  }
};

// Targets, then bounds, then sum bounds (finite sides only), in the order of the options. Values are in
// the problem's unknowns; labels show them in the user's (a ScaledProblem's scales undone), with the
// shortest decimal that reads back.
inline std::vector<LinearStop> LinearStops(const ContinuationOptions& options, const ZeroProblem& problem) {
  const int n = problem.num_unknowns();
  const auto* scaled = dynamic_cast<const ScaledProblem*>(&problem);
  const auto shown = [&](const Vector& c, double value) {
    int k = 0;
    c.cwiseAbs().maxCoeff(&k);
    const double v = scaled ? value * scaled->scales()(k) : value;
    char buffer[32];
    for (int digits = 6; digits <= 17; ++digits) {
      std::snprintf(buffer, sizeof buffer, "%.*g", digits, v);
      if (std::strtod(buffer, nullptr) == v) break;
    }
    return std::string(buffer);
  };
  std::vector<LinearStop> stops;
  for (const ComponentTarget& target : options.targets) {
    const Vector c = Vector::Unit(n, problem.UnknownIndex(target.component));
    stops.push_back({c, target.value, LinearStop::Kind::kTarget, target.component + " = " + shown(c, target.value)});
  }
  auto add_bounds = [&](const Vector& c, double lower, double upper, const std::string& label) {
    if (std::isfinite(lower)) stops.push_back({c, lower, LinearStop::Kind::kLower, label + " >= " + shown(c, lower)});
    if (std::isfinite(upper)) stops.push_back({c, upper, LinearStop::Kind::kUpper, label + " <= " + shown(c, upper)});
  };
  for (const ComponentBound& bound : options.bounds) {
    add_bounds(Vector::Unit(n, problem.UnknownIndex(bound.component)), bound.lower, bound.upper, bound.component);
  }
  for (const SumBound& bound : options.sum_bounds) {
    Vector c = Vector::Zero(n);
    std::string label;
    for (const std::string& name : bound.components) {
      c(problem.UnknownIndex(name)) += 1.0;
      label += (label.empty() ? "" : "+") + name;
    }
    add_bounds(c, bound.lower, bound.upper, label);
  }
  return stops;
}

// Locates the stops on the branch: the point exactly on a crossed stop, found by the linear-constraint
// corrector [r(u); cᵀu − value] = 0 from the cubic Hermite interpolant of the step (the chord where the
// tangents disagree in orientation), and where that fails by the special points' root finder on
// cᵀu − value along the step, corrected onto the stop from there.
class StopLocator {
 public:
  // The pointers must outlive the locator; they are the stepper's own.
  StopLocator(std::vector<LinearStop> stops, ZeroProblem* problem, Corrector* corrector, BorderedSolver* solver,
              const ContinuationOptions& options);

  const std::vector<LinearStop>& stops() const { return stops_; }
  // The earliest stop crossed in (a, b]: *b is replaced by the point exactly on it, *reason and the start
  // of *message name the stop, *newton_iterations counts the corrector's work. Returns false, with *reason
  // and *message set, if the branch ends at a (a stop crossed right at the start point).
  bool Apply(const ContinuationPoint& a, ContinuationPoint* b, int* newton_iterations, TerminationReason* reason,
             std::string* message);

 private:
  // The stop crossed first in (a, b] and the chord fraction θ where it crosses; nullptr if none is.
  const LinearStop* FirstCrossed(const ContinuationPoint& a, const ContinuationPoint& b, double* theta) const;
  // Where the constraint corrector failed: the root of cᵀu − value along the step, then one constraint
  // correction onto the stop. Appends to *message when the root is only bracketed.
  void LocateByRootFinder(const ContinuationPoint& a, const ContinuationPoint& b, const LinearStop& stop,
                          ContinuationPoint* event, std::string* message);

  std::vector<LinearStop> stops_;
  ZeroProblem* problem_;
  Corrector* corrector_;
  BorderedSolver* solver_;
  double min_step_;
  double location_tolerance_;
  int max_location_iterations_;
};

}  // namespace hybridcont::internal

#endif  // HYBRIDCONT_SRC_CONTINUATION_LINEAR_STOP_H_
