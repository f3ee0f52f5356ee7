// Enum strings, option validation and reports of continuation.h.
#include <algorithm>
#include <cmath>
#include <sstream>

#include "hybridcont/continuation.h"

namespace hybridcont {

std::string ToString(TerminationReason reason) {
  switch (reason) {
    case TerminationReason::kNotFinished: return "not-finished";
    case TerminationReason::kMaxPoints: return "max-points";
    case TerminationReason::kTargetReached: return "target-reached";
    case TerminationReason::kBoundReached: return "bound-reached";
    case TerminationReason::kUserStop: return "user-stop";
    case TerminationReason::kStepTooSmall: return "step-too-small";
    case TerminationReason::kClosedLoop: return "closed-loop";
    case TerminationReason::kKnownBranch: return "known-branch";
    case TerminationReason::kStartFailed: return "start-failed";
  }
  return "unknown";
}

std::string ToString(PredictorType type) {
  switch (type) {
    case PredictorType::kTangent: return "tangent";
    case PredictorType::kSecant: return "secant";
    case PredictorType::kHermite: return "hermite";
  }
  return "unknown";
}

bool StringToPredictorType(const std::string& text, PredictorType* type) {
  if (text == "tangent") {
    *type = PredictorType::kTangent;
  } else if (text == "secant") {
    *type = PredictorType::kSecant;
  } else if (text == "hermite") {
    *type = PredictorType::kHermite;
  } else {
    return false;
  }
  return true;
}

std::string ContinuationOptions::Validate() const {
  std::ostringstream out;
  auto positive = [&out](const char* field, double value) {
    if (!(value > 0) || !std::isfinite(value)) {
      out << "ContinuationOptions::" << field << " = " << value << " must be finite and > 0";
      return false;
    }
    return true;
  };
  if (!positive("initial_step", initial_step) || !positive("min_step", min_step) ||
      !positive("max_step", max_step) || !positive("nominal_contraction", nominal_contraction) ||
      !positive("nominal_distance", nominal_distance) || !positive("nominal_angle", nominal_angle) ||
      !positive("max_corrector_distance", max_corrector_distance) ||
      !positive("location_tolerance", location_tolerance)) {
    return out.str();
  }
  if (min_step > max_step) {
    out << "ContinuationOptions::min_step = " << min_step << " must be <= max_step = " << max_step;
  } else if (initial_step < min_step || initial_step > max_step) {
    out << "ContinuationOptions::initial_step = " << initial_step << " must lie in [min_step, max_step] = ["
        << min_step << ", " << max_step << "]";
  } else if (direction != 1 && direction != -1) {
    out << "ContinuationOptions::direction = " << direction << " must be +1 or -1";
  } else if (max_points < 1) {
    out << "ContinuationOptions::max_points = " << max_points << " must be >= 1";
  } else if (max_location_iterations < 1) {
    out << "ContinuationOptions::max_location_iterations = " << max_location_iterations << " must be >= 1";
  } else if (const std::string corrector_error = corrector.Validate(); !corrector_error.empty()) {
    out << "ContinuationOptions::corrector: " << corrector_error;
  } else {
    for (const ComponentBound& bound : bounds) {
      if (!(bound.lower < bound.upper)) {
        out << "ContinuationOptions::bounds[" << bound.component << "]: lower = " << bound.lower
            << " must be < upper = " << bound.upper;
        break;
      }
    }
    for (const SumBound& bound : sum_bounds) {
      if (bound.components.empty()) {
        out << "ContinuationOptions::sum_bounds: components must not be empty";
      } else if (!(bound.lower < bound.upper)) {
        out << "ContinuationOptions::sum_bounds: lower = " << bound.lower << " must be < upper = " << bound.upper;
      }
    }
    for (const ComponentTarget& target : targets) {
      if (!std::isfinite(target.value)) {
        out << "ContinuationOptions::targets[" << target.component << "]: value = " << target.value
            << " must be finite";
      }
    }
  }
  return out.str();
}

std::string ContinuationOptions::ValidateFor(const std::vector<std::string>& unknown_names) const {
  std::string error = Validate();
  if (!error.empty()) return error;
  auto check = [&unknown_names, &error](const std::string& field, const std::string& name) {
    if (error.empty() && std::find(unknown_names.begin(), unknown_names.end(), name) == unknown_names.end()) {
      error = "ContinuationOptions::" + field + ": \"" + name + "\" is not an unknown of the problem";
    }
  };
  for (const std::string& name : turning_point_components) check("turning_point_components", name);
  for (const ComponentBound& bound : bounds) check("bounds", bound.component);
  for (const ComponentTarget& target : targets) check("targets", target.component);
  for (const SumBound& bound : sum_bounds) {
    for (const std::string& name : bound.components) check("sum_bounds", name);
  }
  for (const std::string& name : progress_components) check("progress_components", name);
  return error;
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
