#include "continuation/predictor.h"

namespace hybridcont::internal {

Vector PredictorDirection(PredictorType type, const ContinuationPoint& a, const ContinuationPoint* previous) {
  Vector direction = a.tangent;
  if (type == PredictorType::kSecant && previous != nullptr) {
    const Vector chord = a.u - previous->u;
    if (chord.norm() > 0) direction = chord.normalized();
  }
  return direction;
}

void HermitePredictor(const ContinuationPoint& p, const ContinuationPoint& a, double h, Vector* predictor,
                      Vector* normal) {
  const double d = (a.u - p.u).norm();
  if (!(d > 0) || h > 2 * d || p.tangent.dot(a.tangent) <= 0) return;
  const double t = 1 + h / d;  // t = 0 at u_p, 1 at u_a
  *predictor = HermitePoint(p, a, t);
  const double t2 = t * t;
  const double d00 = 6 * t2 - 6 * t, d10 = 3 * t2 - 4 * t + 1, d01 = -6 * t2 + 6 * t, d11 = 3 * t2 - 2 * t;
  const Vector slope = (d00 / d) * p.u + (d01 / d) * a.u + d10 * p.tangent + d11 * a.tangent;
  if (slope.norm() > 0) *normal = slope.normalized();
}

Vector HermitePoint(const ContinuationPoint& a, const ContinuationPoint& b, double t) {
  const double d = (b.u - a.u).norm();
  const double t2 = t * t, t3 = t2 * t;
  const double h00 = 2 * t3 - 3 * t2 + 1, h10 = t3 - 2 * t2 + t, h01 = -2 * t3 + 3 * t2, h11 = t3 - t2;
  return h00 * a.u + h01 * b.u + (h10 * d) * a.tangent + (h11 * d) * b.tangent;
}

}  // namespace hybridcont::internal
