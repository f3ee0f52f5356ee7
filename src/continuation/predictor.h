// Internal: the predictors of the stepper (continuation.h, eq. predictor; PredictorType) and the cubic
// Hermite interpolant of two branch points they share with the stop location (linear_stop.h).
//
//   Vector direction = PredictorDirection(type, a, previous);   // τ_a, or the secant's chord
//   Vector predictor = a.u + h * direction, normal = direction;
//   if (type == PredictorType::kHermite && previous != nullptr) HermitePredictor(*previous, a, h, &predictor, &normal);
#ifndef HYBRIDCONT_SRC_CONTINUATION_PREDICTOR_H_
#define HYBRIDCONT_SRC_CONTINUATION_PREDICTOR_H_

#include "hybridcont/continuation.h"
#include "hybridcont/types.h"

namespace hybridcont::internal {

// The direction of the Euler predictor from a: the chord (u_a − u_previous) normalized for kSecant when
// there is a previous point and a chord, τ_a otherwise (also the Hermite predictor's fallback).
Vector PredictorDirection(PredictorType type, const ContinuationPoint& a, const ContinuationPoint* previous);

// The cubic Hermite interpolant p(s) of (u_p, τ_p) at s = −d and (u_a, τ_a) at s = 0, d = |u_a − u_p|
// (chord ≈ arclength), evaluated at s = h: *predictor = p(h), *normal = p'(h) normalized. Leaves both
// unchanged (the tangent predictor) when there is no chord, the tangents disagree in orientation, or
// h > 2d (cubic extrapolation far beyond the data it was fitted to).
void HermitePredictor(const ContinuationPoint& p, const ContinuationPoint& a, double h, Vector* predictor,
                      Vector* normal);

// The cubic Hermite interpolant of (u_a, τ_a) at t = 0 and (u_b, τ_b) at t = 1, the chord length
// standing for the arclength between them.
Vector HermitePoint(const ContinuationPoint& a, const ContinuationPoint& b, double t);

}  // namespace hybridcont::internal

#endif  // HYBRIDCONT_SRC_CONTINUATION_PREDICTOR_H_
