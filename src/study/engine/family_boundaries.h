// Where the physical families of a diagram meet the boundary of the physical orbits, as the stages after the
// exploration need it (word_families.h: where a phase sequence may change; parameter_curves.h: the curves
// of those boundaries in two parameters):
//  - a phase duration through 0 between two consecutive points of a branch with a physical end;
//  - the observable (a constraint, a competing guard) that vanishes at a located CB point;
//  - whether a point lies on a polyline (a boundary already traced, a branch already known).
#ifndef HYBRIDCONT_STUDY_FAMILY_BOUNDARIES_H_
#define HYBRIDCONT_STUDY_FAMILY_BOUNDARIES_H_

#include <algorithm>
#include <functional>
#include <vector>

#include "hybridcont/exploration.h"
#include "hybridcont/model.h"
#include "hybridcont/orbit_observables.h"
#include "hybridcont/shooting_layout.h"

namespace hybridcont::study {

// A duration at most this is 0 (a branch point on a zero-duration family, a start with zero durations).
inline constexpr double kZeroDuration = 1e-12;

// A duration t<segment+1> through 0 between points `point` and `point + 1` of `branch`, one of them physical.
struct DurationCrossing {
  int branch = -1;
  int point = -1;
  int segment = -1;
  Vector u;              // the linear interpolant at t = 0, or the point itself where its duration is 0
  bool at_point = false; // an end point has the zero duration (|t| <= kZeroDuration)
  Vector u_run;          // the same in the layout of d's points (`free`): with the free parameters' values
};

// The crossings on the branches of d that are not images (an image's are its source's images), in the
// model's own layout (u's head); d's points are in the layout of `free` (the run's free parameters, fixed
// unknowns and observables), and each point is classified at its own parameter values. With `zero_points`,
// an end point whose duration is already 0 counts too (not where both ends are 0: a family with that
// duration 0 throughout); else only strict sign changes.
std::vector<DurationCrossing> DurationCrossings(const HybridModel& model, const BifurcationDiagram& d,
                                                const IntegratorOptions& integrator, bool zero_points,
                                                const FreeParameters& free = {});

// The observable accepted by `wanted` whose value at u is closest to 0 and below 1e-6 in size, or -1; for
// an extremum, interior_only asks that the extremum lie inside its interval (the constraint's boundary, not
// its end). evaluator is left at that observable's evaluation, so last_extremum_segment()/time() are its.
int VanishingObservable(const HybridModel& model, ObservableEvaluator& evaluator, const Vector& u,
                        const std::function<bool(const Observable&)>& wanted, bool interior_only);

// Distance from x to the segment [a, b].
template <typename V>
double DistanceToSegment(const V& x, const V& a, const V& b) {
  const V d = b - a;
  const double length2 = d.squaredNorm();
  const double s = length2 > 0 ? std::clamp((x - a).dot(d) / length2, 0.0, 1.0) : 0.0;
  return (a + s * d - x).norm();
}

}  // namespace hybridcont::study

#endif  // HYBRIDCONT_STUDY_FAMILY_BOUNDARIES_H_
