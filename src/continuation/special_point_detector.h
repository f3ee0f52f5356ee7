// Internal: detection and location of the special points of one step of the stepper (special_point.h):
// sign changes of the SB test and of the tangent components τ_k between two consecutive branch points,
// each located by the root finder (branch_geometry.h), its integration error estimated, and a turning
// point at an SB point of the same step given that point's precision.
//
//   SpecialPointDetector detector(&problem, &corrector, &solver, options);
//   detector.Detect(branch.points.size() - 2, &branch);   // appends to branch.special_points
#ifndef HYBRIDCONT_SRC_CONTINUATION_SPECIAL_POINT_DETECTOR_H_
#define HYBRIDCONT_SRC_CONTINUATION_SPECIAL_POINT_DETECTOR_H_

#include <functional>
#include <string>
#include <vector>

#include "continuation/branch_geometry.h"
#include "hybridcont/continuation.h"
#include "hybridcont/corrector.h"
#include "hybridcont/special_point.h"

namespace hybridcont::internal {

class SpecialPointDetector {
 public:
  using Test = std::function<double(const Segment::Probe&)>;

  // The pointers must outlive the detector; they are the stepper's own. options must be valid for the
  // problem (ContinuationOptions::ValidateFor).
  SpecialPointDetector(ZeroProblem* problem, Corrector* corrector, BorderedSolver* solver,
                       const ContinuationOptions& options);

  // Locates the sign changes between branch->points[index] and [index + 1] and appends the special points
  // to branch->special_points in arclength order, with ids continuing the branch's.
  void Detect(size_t index, Branch* branch);

  // A turning point this close to an SB point of the same step, relative to the step, is taken to be at
  // it (docs/design/continuation.md, "Turning point at an SB point").
  static constexpr double kCoincidence = 1e-4;

 private:
  // The special point of `type` where `test` changes sign between a and b (k: the turning component, or
  // −1), as its root finder left it (*bracket_only) and with its integration error (the result).
  SpecialPoint Locate(SpecialPointType type, int k, const Test& test, size_t index, Branch* branch,
                      std::vector<SpecialPoint>* bracket_only);
  // special_point.h, "Integration error": widens point's interval and componentwise widths by the
  // change the problem's refined copy shows at the root, and says so in its message.
  void AddIntegrationError(Segment* segment, const RootLocation& root, const Test& test, SpecialPoint* point);
  // A turning point at an SB point of the same step keeps its root finder's bracket (bracket_only) and
  // takes the SB point's interval and their distance on both sides instead of its own estimate.
  static void PlaceTurningPointsAtSbPoints(double step, const std::vector<SpecialPoint>& bracket_only,
                                           std::vector<SpecialPoint>* found);

  ZeroProblem* problem_;
  Corrector* corrector_;
  BorderedSolver* solver_;
  std::vector<std::string> names_;
  std::vector<int> turning_;  // indices of the turning-point components
  bool detect_bifurcations_;
  bool check_integration_error_;
  double location_tolerance_;
  int max_location_iterations_;
};

}  // namespace hybridcont::internal

#endif  // HYBRIDCONT_SRC_CONTINUATION_SPECIAL_POINT_DETECTOR_H_
