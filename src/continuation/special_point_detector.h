// Internal: detection and location of the special points of one step of the stepper (special_point.h):
// sign changes of the SB test and of the tangent components τ_k between two consecutive branch points,
// each located by the root finder (branch_geometry.h), its integration error estimated, and a turning
// point at an SB point of the same step given that point's precision; then the zeros of the test
// functions (test_function.h) in that step, also pairs of them inside it. The curve points the test
// functions need (samples inside a step, the location of their zeros) are found on a copy of the problem
// of their own (ZeroProblem::Clone), whose work is handed to the test functions (TestFunctions::
// AddCurveWork) when the detector is done: it is theirs, not the continued problem's.
//
//   SpecialPointDetector detector(&problem, &corrector, &solver, options);
//   detector.Sample(&point);                               // test functions at each branch point
//   detector.Detect(branch.points.size() - 2, false, &branch);  // inserts into branch.special_points
#ifndef HYBRIDCONT_SRC_CONTINUATION_SPECIAL_POINT_DETECTOR_H_
#define HYBRIDCONT_SRC_CONTINUATION_SPECIAL_POINT_DETECTOR_H_

#include <functional>
#include <memory>
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
  // Hands the test functions' copy of the problem to them (TestFunctions::AddCurveWork).
  ~SpecialPointDetector();
  SpecialPointDetector(const SpecialPointDetector&) = delete;
  SpecialPointDetector& operator=(const SpecialPointDetector&) = delete;

  // The test functions at a branch point into point->test_values (left empty without test functions).
  // corrected: the corrector's last evaluation of the problem belongs to this point (its iterate within
  // CorrectorOptions::max_jacobian_distance), and the test functions may take their values from it
  // (TestFunctions::EvaluateAtBranchPoint).
  void Sample(ContinuationPoint* point, bool corrected = false);
  // Locates the sign changes between branch->points[index] and [index + 1] and inserts the special points
  // into branch->special_points in arclength order (ids renumbered: the position). from_singular: the
  // step starts at a bifurcation point, whose SB and turning tests vanish there (not searched), and
  // whose test functions' zeros belong to the parent branch (test_function.h).
  // Returns false when the step does not hold one smooth curve: an SB or turning point's test changes
  // sign across it, but a trial point between its ends cannot be corrected onto any curve, nor is the
  // failure the noise level of a singular place (a step from one branch onto another that passes close
  // by: the stepper rejects it and retries shorter).
  bool Detect(size_t index, bool from_singular, Branch* branch);
  // The test functions' zeros of branch->points from `from` on found again: their values sampled anew
  // and every step from `from` searched. For branches mapped by a symmetry (exploration.h), under which
  // a test function need not be invariant (time reversal turns a physical orbit into a non-physical one).
  void RedetectTestFunctions(size_t from, Branch* branch);
  bool has_test_functions() const { return functions_ != nullptr; }

  // A test function this small at the start of a branch from a bifurcation point, relative to its value
  // at the next sample, vanishes there: the zero is that point, the parent's.
  static constexpr double kStartNoise = 1e-3;
  // A component whose unit tangent entries on both sides of a sign change are at most this is constant along the
  // branch (the hopper's forward speed while it hops in place): its sign changes are rounding, no turning point.
  // A real turning point between two accepted points has |τ_k| ~ h × curvature on at least one side.
  static constexpr double kConstantComponent = 1e-8;
  // Evaluations of the minimization that looks for a pair of zeros at a local minimum of |g|.
  static constexpr int kPairSearchEvaluations = 24;
  // A minimum of |g| this small relative to the samples around it is refined (Brent, up to
  // kTouchEvaluations more evaluations, to location_tolerance in σ) to decide whether g touches zero.
  static constexpr double kTouchCandidate = 1e-4;
  static constexpr int kTouchEvaluations = 60;
  // A refined minimum of |g| of one sign at most this fraction of the samples' largest |g| is a zero that
  // g touches without changing sign (a double zero, e.g. a reciprocal pair of multipliers passing
  // through −1 on the unit circle): for a bowl g ≈ κ(s − s*)² + c it means a miss distance
  // sqrt(c/κ) below 1e-5 of the samples' spread, where the test's own rounding and integration error
  // (relative 1e-13 to 1e-9 on the maps of this library) can no longer tell c from zero.
  static constexpr double kTouchingZero = 1e-10;
  // A local minimum of |g| over the samples whose dip below the lower of its neighbours is at most this
  // fraction of |g| is integration noise, not a bowl that could hold two zeros or touch zero: not refined
  // on the curve. The test functions' relative error is 1e-13 to 1e-9 (above); a real bowl between two
  // steps of the controller dips by far more.
  static constexpr double kNoiseDip = 1e-6;
  // Relative agreement of a branch point's test values with the mapped ones at which a symmetry counts as
  // leaving the test functions invariant (integration noise of the mapped and the image's evaluation).
  static constexpr double kInvariantTolerance = 1e-6;

  // A turning point this close to an SB point of the same step, relative to the step, is taken to be at
  // it (docs/design/continuation.md, "Turning point at an SB point").
  static constexpr double kCoincidence = 1e-4;

 private:
  // A problem with the corrector and solver that find points on its curve.
  struct Curve {
    ZeroProblem* problem;
    Corrector* corrector;
    BorderedSolver* solver;
  };
  // The continued problem's (SB and turning points).
  Curve ContinuationCurve() { return {problem_, corrector_, solver_}; }
  // The test functions' copy, made at its first use; the continued problem's if that has no Clone().
  Curve TestCurve();

  // The special point of `type` where `test` changes sign between a and b (k: the turning component, or
  // −1), as its root finder left it (*bracket_only) and with its integration error (the result).
  SpecialPoint Locate(SpecialPointType type, int k, const Test& test, size_t index, Branch* branch,
                      std::vector<SpecialPoint>* bracket_only);
  // The same between two points a, b of the curve inside step `index` on `curve` (test functions:
  // refined_test evaluates the test with the more accurate copy).
  SpecialPoint LocateOn(const Curve& curve, const ContinuationPoint& a, const ContinuationPoint& b, SpecialPointType type, int k,
                        const Test& test, const Test* refined_test, size_t index, Branch* branch,
                        std::vector<SpecialPoint>* bracket_only);
  // special_point.h, "Integration error": widens point's interval and componentwise widths by the
  // change the problem's refined copy shows at the root, and says so in its message.
  void AddIntegrationError(ZeroProblem* problem, Segment* segment, const RootLocation& root, const Test& test, const Test& refined_test,
                           SpecialPoint* point);
  // A sample of the test functions on the curve: a branch point or a corrected point inside a step.
  struct CurveSample {
    ContinuationPoint point;  // u, tangent, arclength (σ-based inside a step), test_values
    size_t step = 0;          // the step it lies in (its start, for a branch point)
  };
  std::vector<CurveSample> StepSamples(size_t index, const Branch& branch);
  // The point of the curve between samples l and r at parameter σ ∈ (0, σ_r) of that interval.
  bool CurvePoint(const CurveSample& l, const CurveSample& r, double sigma, CurveSample* out);
  void DetectTestFunctions(size_t index, bool from_singular, Branch* branch);
  // Zeros of function j between two samples of opposite sign.
  SpecialPoint LocateTestZero(int j, const CurveSample& l, const CurveSample& r, Branch* branch);
  // The result of minimizing sign·g_j over [l, m] ∪ [m, r] (m: a local minimum of |g_j| among the samples).
  struct CurveMinimum {
    bool other_sign = false;  // `sample` has the other sign: two zeros, one on each side of it
    bool left = false;        // `sample` lies in [l, m], else in [m, r]
    CurveSample sample;       // the sample of the other sign, or the smallest sign·g_j found
    double value = 0;         // sign·g_j at `sample`
    double sigma = 0;         // its σ in its interval
    double bracket = 0;       // width in σ of the final bracket of the minimum
    double miss = 0;          // sqrt(value/κ) for the bowl g ≈ κ(σ − σ*)² + value around it (σ units)
    int evaluations = 0;
  };
  // Golden section on both intervals, then, for a candidate touching zero (kTouchCandidate), Brent's
  // method on the interval that holds the smallest value; stops at the first sample of the other sign.
  CurveMinimum MinimizeOnCurve(int j, double sign, const CurveSample& l, const CurveSample& m, const CurveSample& r);
  // The zero that g_j touches at `minimum` (kTouchingZero), between samples lo and hi.
  SpecialPoint TouchingZero(int j, const CurveSample& lo, const CurveSample& hi, const CurveMinimum& minimum,
                            double scale, Branch* branch);
  double TestValue(int j, const Vector& u);
  // Adds the found points to the branch in arclength order, except zeros of test functions that the
  // functions do not keep (TestFunctions::Keep).
  void Insert(std::vector<SpecialPoint> found, Branch* branch);
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
  bool one_curve_ = true;  // Detect's result: no located SB or turning point failed on an uncorrectable trial
  double location_tolerance_;
  int max_location_iterations_;
  std::unique_ptr<TestFunctions> functions_;  // the options' test functions (own copy), or nullptr
  std::unique_ptr<TestFunctions> refined_functions_;  // made at the first located zero
  CorrectorOptions corrector_options_;
  std::unique_ptr<ZeroProblem> test_problem_;  // the test functions' copy of problem_ (TestCurve)
  std::unique_ptr<Corrector> test_corrector_;
  BorderedSolver test_solver_;
  std::vector<SpecialPointType> function_types_;
};

// SpecialPointDetector::RedetectTestFunctions with a corrector and solver of its own on `problem`, for a
// branch made outside a stepper (a symmetric image, a loop completed by reflection). Nothing without
// options.test_functions.
void RedetectTestFunctions(ZeroProblem* problem, const ContinuationOptions& options, size_t from, Branch* branch);

}  // namespace hybridcont::internal

#endif  // HYBRIDCONT_SRC_CONTINUATION_SPECIAL_POINT_DETECTOR_H_
