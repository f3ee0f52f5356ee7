#include "continuation/step_controller.h"

#include <algorithm>
#include <cmath>

#include "continuation/branch_geometry.h"

namespace hybridcont::internal {

StepController::StepController(const ContinuationOptions& options)
    : min_step_(options.min_step),
      max_step_(options.max_step),
      nominal_contraction_(options.nominal_contraction),
      nominal_distance_(options.nominal_distance),
      nominal_angle_(options.nominal_angle),
      residual_tolerance_(options.corrector.residual_tolerance),
      h_(options.initial_step) {}

double StepController::DecelerationFactor(const CorrectorResult& result, const Vector& tangent_a,
                                          const Vector& tangent_b) const {
  return std::max({std::sqrt(ContractionSignal(result) / nominal_contraction_),
                   std::sqrt(result.distance / nominal_distance_),
                   AngleBetween(tangent_a, tangent_b) / nominal_angle_});
}

void StepController::Reject(double factor) {
  h_ = at_min_step() ? h_ * factor : std::max(h_ * factor, min_step_);
}

void StepController::CorrectorFailed(double arclength) {
  failed_step_ = std::min(failed_step_, h_);
  failed_size_ = failed_step_;
  failed_at_ = arclength;
  Reject(0.5);
}

double StepController::NextStep(double f, double arclength, bool rejected_this_step) {
  // No growth right after a rejection: the step that just failed would be proposed again. And no growth
  // back to a step at which the corrector failed recently: the deceleration factor measures the step
  // just taken, not the basin of the one twice as long.
  double growth_limit = rejected_this_step ? h_ : max_step_;
  if (arclength - failed_at_ > kFailedStepMemory * failed_size_) failed_step_ = kNoFailure;
  growth_limit = std::max(h_, std::min(growth_limit, kFailedStepMargin * failed_step_));
  failed_step_ *= kFailedStepRelease;
  return std::clamp(std::min(h_ / std::max(f, 0.5), growth_limit), min_step_, max_step_);
}

double StepController::ContractionSignal(const CorrectorResult& result) const {
  if (result.predictor_residual_norm <= residual_tolerance_) return 0.0;
  return std::min(result.contraction, result.residual_contraction);
}

}  // namespace hybridcont::internal
