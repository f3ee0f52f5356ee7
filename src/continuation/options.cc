// Enum strings, option validation and reports of continuation.h.
#include <algorithm>
#include <cmath>
#include <sstream>

#include "hybridcont/continuation.h"
#include "hybridcont/internal/enum_names.h"
#include "hybridcont/internal/options_check.h"

namespace hybridcont {

namespace {

constexpr internal::EnumName<TerminationReason> kTerminationReasonNames[] = {
    {TerminationReason::kNotFinished, "not-finished"},
    {TerminationReason::kMaxPoints, "max-points"},
    {TerminationReason::kTargetReached, "target-reached"},
    {TerminationReason::kBoundReached, "bound-reached"},
    {TerminationReason::kUserStop, "user-stop"},
    {TerminationReason::kAbandoned, "abandoned"},
    {TerminationReason::kStepTooSmall, "step-too-small"},
    {TerminationReason::kClosedLoop, "closed-loop"},
    {TerminationReason::kKnownBranch, "known-branch"},
    {TerminationReason::kStartFailed, "start-failed"},
};

constexpr internal::EnumName<PredictorType> kPredictorTypeNames[] = {
    {PredictorType::kTangent, "tangent"},
    {PredictorType::kSecant, "secant"},
    {PredictorType::kHermite, "hermite"},
};

// A value as an options message prints it (the default stream format).
std::string Text(double value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

}  // namespace

std::string ToString(TerminationReason reason) { return internal::EnumToString(kTerminationReasonNames, reason); }

std::string ToString(PredictorType type) { return internal::EnumToString(kPredictorTypeNames, type); }

bool FromString(const std::string& text, PredictorType* type) {
  return internal::EnumFromString(kPredictorTypeNames, text, type);
}

std::string ContinuationOptions::Validate() const {
  internal::OptionsCheck check("ContinuationOptions");
  check.Positive("initial_step", initial_step)
      .Positive("min_step", min_step)
      .Positive("max_step", max_step)
      .Positive("nominal_contraction", nominal_contraction)
      .Positive("nominal_distance", nominal_distance)
      .Positive("nominal_angle", nominal_angle)
      .Positive("max_corrector_distance", max_corrector_distance)
      .Positive("location_tolerance", location_tolerance)
      .Require(min_step <= max_step, "min_step", min_step, "must be <= max_step = " + Text(max_step))
      .Require(initial_step >= min_step && initial_step <= max_step, "initial_step", initial_step,
               "must lie in [min_step, max_step] = [" + Text(min_step) + ", " + Text(max_step) + "]")
      .Require(direction == 1 || direction == -1, "direction", direction, "must be +1 or -1")
      .AtLeast("max_points", max_points, 1)
      .AtLeast("max_location_iterations", max_location_iterations, 1)
      .Nested("corrector", corrector.Validate());
  for (const ComponentBound& bound : bounds) {
    check.Require(bound.lower < bound.upper, "bounds[" + bound.component + "]: lower = " + Text(bound.lower) +
                                                 " must be < upper = " + Text(bound.upper));
  }
  for (const SumBound& bound : sum_bounds) {
    check.Require(!bound.components.empty(), "sum_bounds: components must not be empty")
        .Require(bound.lower < bound.upper,
                 "sum_bounds: lower = " + Text(bound.lower) + " must be < upper = " + Text(bound.upper));
  }
  for (const ComponentTarget& target : targets) {
    check.Require(std::isfinite(target.value),
                  "targets[" + target.component + "]: value = " + Text(target.value) + " must be finite");
  }
  return check.message();
}

std::string ContinuationOptions::ValidateFor(const std::vector<std::string>& unknown_names) const {
  if (std::string error = Validate(); !error.empty()) return error;
  internal::OptionsCheck check("ContinuationOptions");
  auto known = [&unknown_names, &check](const std::string& field, const std::string& name) {
    const bool found = std::find(unknown_names.begin(), unknown_names.end(), name) != unknown_names.end();
    check.Require(found, field + ": \"" + name + "\" is not an unknown of the problem");
  };
  for (const std::string& name : turning_point_components) known("turning_point_components", name);
  for (const ComponentBound& bound : bounds) known("bounds", bound.component);
  for (const ComponentTarget& target : targets) known("targets", target.component);
  for (const SumBound& bound : sum_bounds) {
    for (const std::string& name : bound.components) known("sum_bounds", name);
  }
  for (const std::string& name : progress_components) known("progress_components", name);
  return check.message();
}

std::string Branch::BriefReport() const {
  std::ostringstream out;
  out << "Branch " << id << ": " << points.size() << " points, " << special_points.size()
      << " special points, " << ToString(termination) << ", " << newton_iterations << " Newton iterations, "
      << rejected_steps << " rejected steps";
  if (image_of >= 0) out << ", image of branch " << image_of << " under " << symmetry;
  if (reflected_from >= 0) out << ", points from " << reflected_from << " on reflected under " << symmetry;
  return out.str();
}

std::string Branch::FullReport(const std::vector<std::string>& unknown_names) const {
  std::ostringstream out;
  out << BriefReport() << "\n";
  out << "  direction " << direction << ", depth " << depth << ", parent special point " << parent_special_point
      << "\n";
  if (!points.empty()) {
    out << "  arclength " << points.back().arclength << ", mean Newton iterations per point "
        << (points.size() > 1 ? static_cast<double>(newton_iterations) / (points.size() - 1) : 0.0) << "\n";
  }
  if (!message.empty()) out << "  termination: " << message << "\n";
  for (const SpecialPoint& point : special_points) out << "  " << point.BriefReport(unknown_names) << "\n";
  return out.str();
}

}  // namespace hybridcont
