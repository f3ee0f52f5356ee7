// Internal: the step-length control of the stepper (continuation.h, "step size"): the Allgower–Georg
// deceleration factor, rejection, and the memory of steps at which the corrector failed.
//
//   StepController control(options);
//   const double f = control.DecelerationFactor(result, a.tangent, b.tangent);
//   if (f > 2 && !control.at_min_step()) control.Reject(...);            // retry with a shorter h
//   else next_h = control.NextStep(f, a.arclength, rejected_this_step);  // accepted
//
// The controller owns h; the stepper counts the rejections (Branch::rejected_steps).
#ifndef HYBRIDCONT_SRC_CONTINUATION_STEP_CONTROLLER_H_
#define HYBRIDCONT_SRC_CONTINUATION_STEP_CONTROLLER_H_

#include <limits>

#include "hybridcont/continuation.h"
#include "hybridcont/corrector.h"
#include "hybridcont/types.h"

namespace hybridcont::internal {

class StepController {
 public:
  // options must be valid (ContinuationOptions::Validate); h starts at options.initial_step.
  explicit StepController(const ContinuationOptions& options);

  double h() const { return h_; }
  void set_h(double h) { h_ = h; }
  // h fell below min_step (up to rounding): the branch is given up (kStepTooSmall).
  bool below_min_step() const { return h_ < min_step_ * (1 - 1e-12); }
  // h is min_step (up to rounding): the step is accepted whatever the deceleration factor says.
  bool at_min_step() const { return h_ <= min_step_ * (1 + 1e-12); }

  // The deceleration factor f = max(sqrt(κ/κ̃), sqrt(δ/δ̃), α/α̃) of the step just corrected, κ from
  // ContractionSignal, α the angle between the tangents at its two ends.
  double DecelerationFactor(const CorrectorResult& result, const Vector& tangent_a, const Vector& tangent_b) const;
  // Shrinks h by `factor`; the last try before giving up is made with exactly min_step.
  void Reject(double factor);
  // The corrector failed at h for a step from the point at `arclength`: h is remembered as failed and
  // halved.
  void CorrectorFailed(double arclength);
  // The step h proposed after accepting a step from the point at `arclength` with deceleration factor f:
  // h / max(f, 1/2), clamped to [min_step, max_step], not above h after a rejection in this step, and
  // not back up to a step at which the corrector failed recently.
  double NextStep(double f, double arclength, bool rejected_this_step);

  // The Newton contraction the controller reads: the smaller of κ = ||Δ₁||/||Δ₀|| and the residual
  // contraction ||F(u₁)||/||F(u₀)||; 0 when the predictor's residual is already at the corrector's
  // tolerance (the ratios are then ratios of noise). docs/design/continuation.md, "Contraction signal".
  double ContractionSignal(const CorrectorResult& result) const;

  // Steps grow to at most kFailedStepMargin times the smallest step at which the corrector failed; that
  // cap is released by kFailedStepRelease per accepted point and forgotten kFailedStepMemory failed steps
  // further along the branch, where the difficulty need not persist (docs/design/continuation.md,
  // "Failed-step memory").
  static constexpr double kFailedStepMargin = 0.75;
  static constexpr double kFailedStepRelease = 1.1;
  static constexpr double kFailedStepMemory = 4;

 private:
  static constexpr double kNoFailure = std::numeric_limits<double>::infinity();
  double min_step_;
  double max_step_;
  double nominal_contraction_;
  double nominal_distance_;
  double nominal_angle_;
  double residual_tolerance_;
  double h_;
  double failed_step_ = kNoFailure;  // smallest failed h, released per accepted point; ∞ before any failure
  double failed_size_ = 0;           // failed_step_ when it was last set (before any release)
  double failed_at_ = 0;             // arclength of the point the last failed step started from
};

}  // namespace hybridcont::internal

#endif  // HYBRIDCONT_SRC_CONTINUATION_STEP_CONTROLLER_H_
