// Internal: tangents, the SB test function, and locating a root of a test function between two branch
// points (special points, stops). Shared by the stepper (continuation), branch switching and exploration.
#ifndef HYBRIDCONT_SRC_CONTINUATION_BRANCH_GEOMETRY_H_
#define HYBRIDCONT_SRC_CONTINUATION_BRANCH_GEOMETRY_H_

#include <algorithm>
#include <cmath>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "continuation/bordered_solver.h"
#include "hybridcont/continuation.h"
#include "hybridcont/corrector.h"
#include "hybridcont/types.h"

namespace hybridcont::internal {

// Angle (radians) between two unit vectors, robust to rounding just outside [−1, 1].
inline double AngleBetween(const Vector& a, const Vector& b) { return std::acos(std::clamp(a.dot(b), -1.0, 1.0)); }

// Unit vector spanning the kernel of a full-rank dr (N x (N+1)): last column of Q in drᵀ = QR.
Vector KernelByQR(const Matrix& dr);

// The tangent induced by dr and oriented by `reference` (eq. tangentvector, continuous orientation):
// v = [dr; referenceᵀ]⁻¹ e_{N+1}, τ = v / ||v||, so τ·reference > 0. Also returns the Hadamard-normalized
// determinants with τ and with the reference as last row (special_point.h):
//   own        = det([dr; τᵀ]) / ∏||dr rows||
//   reference  = det([dr; referenceᵀ]) / (∏||dr rows|| ||reference||)  (= own · τ·reference/||reference||)
// With log_row_scale != nullptr, *log_row_scale replaces log ∏||dr rows|| in both normalizations (a
// constant scale along a segment keeps the test function smooth where a row of dr vanishes).
// Returns false if the bordered matrix is singular.
bool InducedTangent(BorderedSolver* solver, const Matrix& dr, const Vector& reference, Vector* tangent,
                    double* sb_own, double* sb_reference, const double* log_row_scale = nullptr);

// log ∏ᵢ ||row i of dr||, a zero row counting as 1.
double LogRowScale(const Matrix& dr);

// The branch between two consecutive points a and b, parametrized by σ = τ_aᵀ(u − u_a) ∈ [0, σ_b].
class Segment {
 public:
  struct Probe {
    Vector u;
    Vector tangent;        // oriented by τ_a
    // det([dr(u); τ_aᵀ]) / ∏||rows of dr(u_a)||: a constant scale, so smooth (≈ linear) in σ, also where
    // a row of dr vanishes at the SB point (N = 1: dr itself vanishes there).
    double sb_test = 0;
    double residual = 0;
    // Set when Evaluate fails although the interpolant's residual is already at the corrector's
    // tolerance: Newton's correction of that residual noise leaves the bracket (next to an SB point).
    bool noise_limited = false;
    // For a noise-limited trial that Newton did correct: how far it moved (the scatter of points that
    // the corrector accepts there, against which the bracket cannot be resolved).
    double scatter = 0;
    // Set when Evaluate fails because the bordered matrix is singular at the trial point itself (before
    // any Newton step): a point exactly on a root of the SB test. Any other failure happens on the way
    // from the interpolant and recurs for trial points half a location tolerance away.
    bool singular_at_trial = false;
  };
  // Absolute part of the largest accepted correction of a trial point, · (1 + ||u||).
  static constexpr double kDistanceFloor = 1e-12;
  // with_sb_test: evaluate dr at a (and b) once for the scale of Probe::sb_test; otherwise sb_test is 0.
  Segment(Corrector* corrector, BorderedSolver* solver, ZeroProblem* problem, const ContinuationPoint& a,
          const ContinuationPoint& b, bool with_sb_test);
  // The point of the curve at σ ∈ (σ_left, σ_right), with its tangent. Predictor: the cubic Hermite
  // interpolant of the two bracketing probes in σ (error O(width⁴); it lies on the hyperplane
  // τ_aᵀ(u − u_a) = σ because the cubic Hermite interpolant of a linear function is exact). Corrector:
  // pseudo-arclength on that hyperplane. Near an SB point the Newton basin shrinks like the distance to
  // it, which a chord predictor (error O(width²)) would miss. A correction longer than a quarter of the
  // bracket width counts as a failure (a jump to the crossing branch). Returns false (and sets *message)
  // if the trial point cannot be corrected; probe->noise_limited then says whether the interpolant's
  // residual was already at the corrector's tolerance (the curve is not resolved on the bracket's scale).
  bool Evaluate(double sigma, const Probe& left, double sigma_left, const Probe& right, double sigma_right,
                Probe* probe, std::string* message);
  // The regular tangents at a and b, linearly interpolated in σ and normalized: accurate to O(σ_b · angle
  // between them). Near an SB point the induced tangent is not (dr has a second singular value near zero,
  // and the computed kernel mixes the two branch directions), so this is the SB point's tangent.
  Vector InterpolatedTangent(double sigma) const;
  // The tangent used by the interpolant at a probe: its own (induced) tangent when it lies in the cone
  // of the interpolated one (half the angle between τ_a and τ_b, plus kTangentNoise), else the
  // interpolated tangent. Only SB segments check; elsewhere every induced tangent is reliable.
  Vector ReliableTangent(const Probe& probe, double sigma) const;
  // Nodes of the interpolant that locates SB points once kNodes corrected points of the segment are known.
  static constexpr size_t kNodes = 4;
  // Largest noise amplification Σ|w_i| of the nodes' Lagrange weights at which that interpolant is used
  // (1 at a node, ~1.2–2 between spread nodes).
  static constexpr double kMaxLebesgue = 4.0;
  // An SB trial point whose interpolant already had a residual at the corrector's tolerance and which
  // Newton moved by more than this fraction of the bracket width is noise, not a correction (Evaluate).
  static constexpr double kResolvedFraction = 1.0 / 16;
  // Angle (radians) by which the integrator noise may turn a correct induced tangent.
  static constexpr double kTangentNoise = 1e-6;
  double sigma_b() const { return sigma_b_; }
  double residual_tolerance() const { return corrector_->options().residual_tolerance; }
  const ContinuationPoint& a() const { return a_; }
  const ContinuationPoint& b() const { return b_; }
  // Probes at the two ends, from the stored points (plus one evaluation of dr for the SB test).
  // Returns false if that evaluation fails.
  bool EndProbe(bool at_b, Probe* probe, std::string* message);
  // The probe at probe.u evaluated again with `refined` (ZeroProblem::Refined): *fine gets the tangent
  // and SB test from the refined dr (same border τ_a, orientation and scale as every probe of this
  // segment), *correction the refined Newton correction −[dr; τ_aᵀ]⁻¹[r; 0]: how far the refined curve
  // lies from probe.u on the probe's hyperplane. False if the evaluation or the bordered matrix fails.
  bool RefinedProbe(ZeroProblem* refined, const Probe& probe, Probe* fine, Vector* correction);
  // The smallest singular value of the bordered matrix [dr; τ_aᵀ] at probe.u, estimated as 1/||B⁻¹||₁
  // (within a factor √n): points that the corrector accepts on the curve (|r| <= residual_tolerance) may
  // lie up to residual_tolerance / σ_min from it.
  // Small where dr loses rank: at an SB point, or where several singular values vanish at once (the
  // SLIP's loop where all phase durations vanish). False if dr cannot be evaluated.
  bool SmallestSingularValue(const Probe& probe, double* sigma_min);

 private:
  Corrector* corrector_;
  BorderedSolver* solver_;
  ZeroProblem* problem_;
  bool with_sb_test_;
  double log_row_scale_ = 0;
  // SB segments: (σ, u) of every corrected point (ends and trial points). Next to the SB the induced
  // tangents of the probes are unreliable, so the interpolant is built from the points alone: Lagrange
  // through the kNodes nearest ones, error ~ |u⁗| Π|σ − σ_i|, below the Hermite interpolant's with
  // interpolated tangents (error ~ width · tangent error) as soon as the bracket is small.
  std::vector<std::pair<double, Vector>> nodes_;
  CorrectorResult CorrectFrom(const Vector& predictor, double max_distance, Probe* probe);
  // The Lagrange interpolant at sigma; false (nothing written) when it would amplify the nodes' scatter
  // by more than kMaxLebesgue.
  bool InterpolateNodes(double sigma, Vector* u) const;
  Matrix dr_;
  const ContinuationPoint& a_;
  const ContinuationPoint& b_;
  double sigma_b_;
};

// Bracket widths by which a location to the noise level widens its bracket on each side (LocateRoot).
inline constexpr double kNoiseMargin = 4.0;

struct RootLocation {
  bool located = false;       // bracket narrower than the tolerance (or exact zero)
  double lo = 0, hi = 0;      // final bracket in σ
  double sigma = 0;           // σ of the estimate
  Segment::Probe estimate;    // the trial point with the smallest |test|
  Vector u_lo, u_hi;          // curve points at the bracket ends
  double test = 0;
  // What turns an error of the test function into an error of the root (stepper, "Integration error" in
  // special_point.h): the flatter of the test's secant slopes over the whole segment and over the final
  // bracket (from the test's values at the ends). The segment's alone understates the error where the test is
  // flatter at its root than across the step (docs/design/continuation.md, "Slope of a located root").
  // 0 when the end probes failed.
  double slope = 0;
  int iterations = 0;
  // Located to the noise level: a trial point inside the bracket had a residual at the corrector's
  // tolerance already, yet Newton's correction of it left the bracket (Segment::Evaluate). The bracket,
  // between corrected points with test values of opposite sign, is then the honest precision.
  bool noise_limited = false;
  // Noise-limited by the conditioning: the largest residual_tolerance / σ_min at the bracket ends
  // (Segment::SmallestSingularValue); 0 otherwise.
  double conditioning_scatter = 0;
  // Not located because a trial point could not be corrected (not for the noise level): the bracket
  // may not hold one smooth curve.
  bool uncorrectable = false;
  std::string message;        // why only bracketed
};

// Safeguarded Illinois iteration for test(σ) = 0 on [0, σ_b], given test values of opposite sign at the
// ends. Illinois (regula falsi with halving of a retained end value) converges superlinearly from both
// sides; a bisection every third iteration without halving of the bracket guards against stagnation.
RootLocation LocateRoot(Segment* segment, const std::function<double(const Segment::Probe&)>& test,
                        double tolerance, int max_iterations);

}  // namespace hybridcont::internal

#endif  // HYBRIDCONT_SRC_CONTINUATION_BRANCH_GEOMETRY_H_
