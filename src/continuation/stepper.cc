// ContinuationStepper: predictor, corrector, step control, stops, special points (continuation.h).
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "continuation/bordered_solver.h"
#include "continuation/branch_geometry.h"
#include "continuation/linear_stop.h"
#include "continuation/progress_report.h"
#include "hybridcont/continuation.h"

namespace hybridcont {
using internal::LinearStop;

class ContinuationStepper::Impl {
 public:
  Impl(ZeroProblem* problem, const ContinuationOptions& options, int branch_id)
      : problem_(problem), options_(options), corrector_(problem, options.corrector), h_(options.initial_step) {
    names_ = problem_->unknown_names();
    const std::string error = options_.ValidateFor(names_);
    if (!error.empty()) throw std::invalid_argument(error);
    branch_.id = branch_id;
    branch_.direction = options_.direction;
    std::vector<std::string> turning = options_.turning_point_components;
    if (turning.empty() && problem_->UnknownIndex("H") >= 0) turning.push_back("H");
    for (const std::string& name : turning) turning_.push_back(problem_->UnknownIndex(name));
    progress_ = internal::ProgressIndices(options_, *problem_);
    stops_ = internal::LinearStops(options_, *problem_);
  }

  StepStatus Start(const Vector& u0, const Vector* hint) {
    CheckSize(u0, "start point");
    if (hint != nullptr) CheckSize(*hint, "direction hint");
    Vector u = u0;
    Matrix dr;
    if (options_.correct_start_point) {
      if (const EvaluationStatus status = problem_->Evaluate(u0, nullptr, &dr); !status.ok) {
        return Finish(TerminationReason::kStartFailed, "evaluation at the start point failed: " + status.message);
      }
      const CorrectorResult result = corrector_.CorrectMoorePenrose(u0, internal::KernelByQR(dr), &u);
      branch_.newton_iterations += result.iterations;
      if (!result.converged()) {
        return Finish(TerminationReason::kStartFailed, "start point not corrected: " + result.BriefReport());
      }
      dr = corrector_.jacobian();
    } else if (const EvaluationStatus status = problem_->Evaluate(u0, nullptr, &dr); !status.ok) {
      return Finish(TerminationReason::kStartFailed, "evaluation at the start point failed: " + status.message);
    }
    ContinuationPoint start;
    start.u = u;
    const Vector reference = hint != nullptr ? *hint : internal::KernelByQR(dr);
    if (!internal::InducedTangent(&solver_, dr, reference, &start.tangent, &start.sb_test, nullptr)) {
      return Finish(TerminationReason::kStartFailed,
                    "dr is singular at the start point (kernel dimension >= 2): use BranchDirectionsAt and "
                    "StartAtSingularPoint");
    }
    if (hint == nullptr) {
      // Paper's convention det([dr; τᵀ]) > 0, then the direction d of eq. IVP.
      const double sign = (std::signbit(start.sb_test) ? -1.0 : 1.0) * options_.direction;
      start.tangent *= sign;
      start.sb_test *= sign;
    }
    return Begin(std::move(start), false);
  }

  StepStatus StartAtSingularPoint(const Vector& u0, const Vector& tangent) {
    CheckSize(u0, "start point");
    CheckSize(tangent, "tangent");
    if (!(tangent.norm() > 0)) throw std::invalid_argument("StartAtSingularPoint: tangent is zero");
    ContinuationPoint start;
    start.u = u0;
    start.tangent = tangent.normalized();
    start.sb_test = 0;
    return Begin(std::move(start), true);
  }

  StepStatus Step() {
    if (finished()) return StepStatus::kFinished;
    const ContinuationPoint& a = branch_.points.back();
    const ContinuationPoint* previous = branch_.points.size() >= 2 ? &branch_.points[branch_.points.size() - 2] : nullptr;
    Vector direction = a.tangent;
    if (options_.predictor == PredictorType::kSecant && previous != nullptr) {
      const Vector chord = a.u - previous->u;
      if (chord.norm() > 0) direction = chord.normalized();
    }
    ContinuationPoint b;
    double next_h = h_;
    double sb_reference = 0;
    std::string last_failure;
    const int rejected_before = branch_.rejected_steps;
    for (;;) {
      if (h_ < options_.min_step * (1 - 1e-12)) {
        return Finish(TerminationReason::kStepTooSmall,
                      "step fell below min_step = " + std::to_string(options_.min_step) + "; last failure: " +
                          last_failure);
      }
      Vector predictor = a.u + h_ * direction;
      Vector normal = direction;
      if (options_.predictor == PredictorType::kHermite && previous != nullptr) {
        HermitePredictor(*previous, a, h_, &predictor, &normal);
      }
      corrector_.set_max_distance(options_.max_corrector_distance * h_);
      const CorrectorResult result = corrector_.Correct(options_.corrector_type, predictor, normal, &b.u);
      branch_.newton_iterations += result.iterations;
      if (!result.converged()) {
        last_failure = "h = " + std::to_string(h_) + ": " + result.BriefReport();
        if (start_singular_ && branch_.points.size() == 1 && result.status == CorrectorStatus::kSingular &&
            result.iterations == 0) {
          // [dr; pᵀ] singular at the very predictor: along a curve of singular points (e.g. the rod's
          // at-rest ξ-line) halving h cannot help. Said once, instead of ~20 rejected steps.
          // dr at the predictor to the problem's own accuracy (the corrector's was taken with
          // predictor_jacobian_tolerance).
          Matrix dr;
          if (const int k = problem_->Evaluate(predictor, nullptr, &dr).ok ? KernelDimension(dr) : 0; k >= 2) {
            return Finish(TerminationReason::kStartFailed,
                          "dr has a kernel of dimension " + std::to_string(k) +
                              " along this direction: not a simple curve (at h = " + std::to_string(h_) + ")");
          }
        }
        failed_step_ = std::min(failed_step_, h_);
        failed_size_ = failed_step_;
        failed_at_ = a.arclength;
        Reject(0.5);
        continue;
      }
      if (!internal::InducedTangent(&solver_, corrector_.jacobian(), a.tangent, &b.tangent, &b.sb_test,
                                    &sb_reference)) {
        last_failure = "h = " + std::to_string(h_) + ": corrected point is singular";
        Reject(0.5);
        continue;
      }
      // Allgower–Georg deceleration factor (continuation.h), with the contraction of ContractionSignal.
      const double f = std::max({std::sqrt(ContractionSignal(result) / options_.nominal_contraction),
                                 std::sqrt(result.distance / options_.nominal_distance),
                                 internal::AngleBetween(a.tangent, b.tangent) / options_.nominal_angle});
      const bool at_min_step = h_ <= options_.min_step * (1 + 1e-12);
      if (f > 2 && !at_min_step) {
        last_failure = "h = " + std::to_string(h_) + ": step control rejected (f = " + std::to_string(f) + ")";
        Reject(std::max(0.5 / (f / 2), 0.25));  // h / f, but never below h / 4
        continue;
      }
      // No growth right after a rejection: the step that just failed would be proposed again. And no
      // growth back to a step at which the corrector failed recently (failed_step_, released by
      // kFailedStepRelease per accepted step and forgotten kFailedStepMemory failed steps further along
      // the branch, where the difficulty need not persist): the deceleration factor measures the step
      // just taken, not the basin of the one twice as long. Without this memory the bouncing rod's
      // symmetric family alternated failure at 2h and success at h for 30 steps (136 rejected steps in
      // 354 points).
      double growth_limit = branch_.rejected_steps > rejected_before ? h_ : options_.max_step;
      if (a.arclength - failed_at_ > kFailedStepMemory * failed_size_) failed_step_ = kNoFailure;
      growth_limit = std::max(h_, std::min(growth_limit, kFailedStepMargin * failed_step_));
      failed_step_ *= kFailedStepRelease;
      next_h = std::clamp(std::min(h_ / std::max(f, 0.5), growth_limit), options_.min_step, options_.max_step);
      b.step = h_;
      b.newton_iterations = result.iterations;
      b.contraction = result.contraction;
      break;
    }
    b.arclength = a.arclength + (b.u - a.u).norm();

    TerminationReason reason = TerminationReason::kNotFinished;
    std::string message;
    if (!stops_.empty() && !ApplyStops(a, &b, &reason, &message)) return StepStatus::kFinished;
    if (reason == TerminationReason::kNotFinished && options_.detect_closed_loop && ClosesLoop(a, b)) {
      const double arclength = a.arclength + (branch_.points.front().u - a.u).norm();
      b = branch_.points.front();
      b.arclength = arclength;
      b.step = h_;
      reason = TerminationReason::kClosedLoop;
      message = "the branch returned to its start point";
    }
    branch_.points.push_back(std::move(b));
    const size_t count = branch_.points.size();
    const bool from_singular = (count == 2 && start_singular_) ||
                               (reason == TerminationReason::kClosedLoop && start_singular_);
    if (!from_singular) DetectSpecialPoints(count - 2);
    h_ = next_h;
    const ContinuationPoint& added = branch_.points.back();
    if (reason == TerminationReason::kNotFinished) {
      if (options_.stop_predicate && options_.stop_predicate(added.u)) {
        reason = TerminationReason::kUserStop;
        message = "stop_predicate returned true";
      } else if (static_cast<int>(count) >= options_.max_points) {
        reason = TerminationReason::kMaxPoints;
        message = "max_points = " + std::to_string(options_.max_points) + " reached";
      }
    }
    Report();
    if (reason != TerminationReason::kNotFinished) return Finish(reason, message);
    return StepStatus::kContinuing;
  }

  void Terminate(TerminationReason reason, const std::string& message) { Finish(reason, message); }
  bool finished() const { return branch_.termination != TerminationReason::kNotFinished; }
  double step_size() const { return h_; }
  const Branch& branch() const { return branch_; }
  Branch TakeBranch() {
    if (!finished()) Finish(TerminationReason::kUserStop, "branch taken from the stepper before it finished");
    return std::move(branch_);
  }

 private:
  void CheckSize(const Vector& v, const char* what) const {
    if (v.size() != problem_->num_unknowns()) {
      throw std::invalid_argument(std::string("ContinuationStepper: ") + what + " has size " +
                                  std::to_string(v.size()) + ", expected num_unknowns() = " +
                                  std::to_string(problem_->num_unknowns()));
    }
  }

  StepStatus Begin(ContinuationPoint start, bool singular) {
    if (!branch_.points.empty()) throw std::invalid_argument("ContinuationStepper: already started");
    start_singular_ = singular;
    branch_.points.push_back(std::move(start));
    Report();
    for (const LinearStop& stop : stops_) {
      if (stop.Violated(stop.f(branch_.points.front().u))) {
        return Finish(TerminationReason::kBoundReached, "start point violates " + stop.label);
      }
    }
    if (options_.max_points <= 1) return Finish(TerminationReason::kMaxPoints, "max_points = 1");
    return StepStatus::kContinuing;
  }

  StepStatus Finish(TerminationReason reason, const std::string& message) {
    if (!finished()) {
      branch_.termination = reason;
      branch_.message = message;
    }
    return StepStatus::kFinished;
  }

  // N + 1 − rank dr, singular values below kRankTolerance · max(1, σ_max) counting as zero (the rank
  // decision of branch_switching.h).
  static int KernelDimension(const Matrix& dr) {
    const Vector sigma = dr.jacobiSvd().singularValues();
    const double threshold = kRankTolerance * std::max(1.0, sigma.size() > 0 ? sigma(0) : 0.0);
    return static_cast<int>(dr.cols() - (sigma.array() > threshold).count());
  }
  static constexpr double kRankTolerance = 1e-8;

  // The Newton contraction the step controller reads: the smaller of κ = ||Δ₁||/||Δ₀|| and the residual
  // contraction ||F(u₁)||/||F(u₀)||. Both estimate the Kantorovich quantity of the predictor (affine
  // covariant and contravariant); where they disagree, κ ≈ 1 with a small residual contraction, the first
  // Newton step overshot along a nearly singular direction of the bordered matrix and the second one took
  // it back, a transient that does not limit the basin (the bouncing rod's symmetric family, next to the
  // non-symmetric one: κ stayed ~0.3 for h from 1e-3 to 1e-2 and pinned h at 8e-4). Zero when the
  // predictor's residual is already at the corrector's tolerance: the ratios are then ratios of noise.
  double ContractionSignal(const CorrectorResult& result) const {
    if (result.predictor_residual_norm <= options_.corrector.residual_tolerance) return 0.0;
    return std::min(result.contraction, result.residual_contraction);
  }

  // The cubic Hermite interpolant p(s) of (u_p, τ_p) at s = −d and (u_a, τ_a) at s = 0, d = |u_a − u_p|
  // (chord ≈ arclength), evaluated at s = h: *predictor = p(h), *normal = p'(h) normalized. Left as the
  // tangent predictor when there is no chord, the tangents disagree in orientation, or h > 2d (cubic
  // extrapolation far beyond the data it was fitted to).
  static void HermitePredictor(const ContinuationPoint& p, const ContinuationPoint& a, double h, Vector* predictor,
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

  // The cubic Hermite interpolant of (u_a, τ_a) at t = 0 and (u_b, τ_b) at t = 1, the chord length
  // standing for the arclength between them.
  static Vector HermitePoint(const ContinuationPoint& a, const ContinuationPoint& b, double t) {
    const double d = (b.u - a.u).norm();
    const double t2 = t * t, t3 = t2 * t;
    const double h00 = 2 * t3 - 3 * t2 + 1, h10 = t3 - 2 * t2 + t, h01 = -2 * t3 + 3 * t2, h11 = t3 - t2;
    return h00 * a.u + h01 * b.u + (h10 * d) * a.tangent + (h11 * d) * b.tangent;
  }

  // Where the Hermite interpolant between a and b meets the stop (cᵀu = value), by bisection on the
  // scalar cubic (it meets it: the stop's sign differs at a and b). Predicts the point on the stop with
  // error O(|b − a|⁴) where the chord's is O(|b − a|²): on the bouncing rod's curved families the chord
  // predictor's residual was 5–24 and every stop fell back to the root finder.
  static Vector HermiteOnStop(const ContinuationPoint& a, const ContinuationPoint& b, const LinearStop& stop) {
    double lo = 0, hi = 1;
    const bool rising = stop.f(a.u) < stop.f(b.u);
    for (int i = 0; i < 60; ++i) {
      const double mid = 0.5 * (lo + hi);
      ((stop.f(HermitePoint(a, b, mid)) < 0) == rising ? lo : hi) = mid;
    }
    return HermitePoint(a, b, 0.5 * (lo + hi));
  }

  // Shrinks h; the last try before giving up is made with exactly min_step.
  void Reject(double factor) {
    ++branch_.rejected_steps;
    const bool at_min_step = h_ <= options_.min_step * (1 + 1e-12);
    h_ = at_min_step ? h_ * factor : std::max(h_ * factor, options_.min_step);
  }

  // The earliest linear stop crossed in (a, b]: b is replaced by the point exactly on it. Returns false if
  // the branch ends at a (stop crossed right at the start point).
  bool ApplyStops(const ContinuationPoint& a, ContinuationPoint* b, TerminationReason* reason,
                  std::string* message) {
    const LinearStop* first = nullptr;
    double first_theta = 2;
    for (const LinearStop& stop : stops_) {
      const double f_a = stop.f(a.u), f_b = stop.f(b->u);
      if (!stop.Crossed(f_a, f_b)) continue;
      const double theta = f_a / (f_a - f_b);
      if (theta < first_theta) {
        first_theta = theta;
        first = &stop;
      }
    }
    if (first == nullptr) return true;
    if (first->f(a.u) == 0) {
      Finish(first->reason(), "the branch leaves " + first->label + " at its start point");
      return false;
    }
    ContinuationPoint event;
    // From the Hermite interpolant when the tangents agree in orientation, else from the chord.
    const Vector predictor = a.tangent.dot(b->tangent) > 0 ? HermiteOnStop(a, *b, *first)
                                                           : Vector(a.u + first_theta * (b->u - a.u));
    corrector_.set_max_distance((b->u - a.u).norm() + options_.min_step);
    const CorrectorResult result = corrector_.CorrectWithConstraint(predictor, first->c, first->value, &event.u);
    branch_.newton_iterations += result.iterations;
    bool ok = result.converged() &&
              InsideSegment(a, *b, event.u) &&
              internal::InducedTangent(&solver_, corrector_.jacobian(), a.tangent, &event.tangent,
                                       &event.sb_test, nullptr);
    if (!ok) {
      // Fallback: root of cᵀu − value along the branch by the special-point root finder.
      internal::Segment segment(&corrector_, &solver_, problem_, a, *b, false);
      const internal::RootLocation root = internal::LocateRoot(
          &segment, [first](const internal::Segment::Probe& p) { return first->f(p.u); },
          options_.location_tolerance, options_.max_location_iterations);
      event.u = root.estimate.u;
      event.tangent = root.estimate.tangent;
      // The probe's test uses τ_a as last row: det([dr; τᵀ]) = det([dr; τ_aᵀ]) / (τ·τ_a).
      event.sb_test = root.estimate.sb_test / a.tangent.dot(event.tangent);
      if (!root.located) message->append(" (stop only bracketed: " + root.message + ")");
      // The located trial point satisfies cᵀu = value to the root finder's tolerance; one constraint
      // correction from there (a step of that size) puts it exactly on the stop.
      ContinuationPoint exact;
      corrector_.set_max_distance(10 * options_.location_tolerance * (1 + event.u.norm()));
      if (root.located && corrector_.CorrectWithConstraint(event.u, first->c, first->value, &exact.u).converged() &&
          internal::InducedTangent(&solver_, corrector_.jacobian(), a.tangent, &exact.tangent, &exact.sb_test,
                                   nullptr)) {
        event.u = std::move(exact.u);
        event.tangent = std::move(exact.tangent);
        event.sb_test = exact.sb_test;
      }
    }
    event.step = b->step;
    event.newton_iterations = b->newton_iterations + result.iterations;
    event.contraction = b->contraction;
    event.arclength = a.arclength + (event.u - a.u).norm();
    *b = std::move(event);
    *reason = first->reason();
    message->insert(0, "reached " + first->label);
    return true;
  }

  // u lies between a and b along τ_a (up to 1% of the step): the constraint corrector did not run off.
  static bool InsideSegment(const ContinuationPoint& a, const ContinuationPoint& b, const Vector& u) {
    const double sigma_b = a.tangent.dot(b.u - a.u);
    const double sigma = a.tangent.dot(u - a.u);
    return sigma >= -0.01 * sigma_b && sigma <= 1.01 * sigma_b;
  }

  // The start point lies on the chord a–b (within the chord sag of the arc) and the tangents agree.
  bool ClosesLoop(const ContinuationPoint& a, const ContinuationPoint& b) const {
    if (branch_.points.size() < 3) return false;
    const ContinuationPoint& start = branch_.points.front();
    const Vector chord = b.u - a.u;
    const double length = chord.norm();
    if (!(length > 0) || a.arclength < 2 * length) return false;
    const double t = chord.dot(start.u - a.u) / (length * length);
    if (t < 0 || t > 1) return false;
    const double distance = (a.u + t * chord - start.u).norm();
    const double sag = length * (internal::AngleBetween(a.tangent, b.tangent) / 4 + 1e-3) + 1e-9 * (1 + start.u.norm());
    return distance <= sag && start.tangent.dot(chord) > 0.9 * length;
  }

  // Sign changes of the SB test and of τ_k between points [index] and [index + 1], each located.
  void DetectSpecialPoints(size_t index) {
    const ContinuationPoint& a = branch_.points[index];
    const ContinuationPoint& b = branch_.points[index + 1];
    std::vector<SpecialPoint> found;
    std::vector<SpecialPoint> bracket_only;  // each found point as its root finder left it
    auto locate = [&](SpecialPointType type, int k, const std::function<double(const internal::Segment::Probe&)>& test) {
      internal::Segment segment(&corrector_, &solver_, problem_, a, b, type == SpecialPointType::kSimpleBifurcation);
      const internal::RootLocation root =
          internal::LocateRoot(&segment, test, options_.location_tolerance, options_.max_location_iterations);
      SpecialPoint point;
      point.type = type;
      point.status = root.located ? LocationStatus::kLocated : LocationStatus::kBracketed;
      point.branch_id = branch_.id;
      point.index = static_cast<int>(index);
      point.arclength = a.arclength + root.sigma;
      point.component_index = k;
      if (k >= 0) point.component = names_[k];
      point.u = root.estimate.u;
      point.tangent = root.estimate.tangent;
      if (type == SpecialPointType::kSimpleBifurcation) {
        // The induced tangent is undefined at an SB point, and next to it can be numerically meaningless
        // (dr has a second near-zero singular value, so a noisy dr mixes both branch directions in the
        // computed kernel). Kept only inside the cone of the bracketing points' regular tangents.
        point.tangent = segment.ReliableTangent(root.estimate, root.sigma);
      }
      point.tangent_before = a.tangent;
      point.tangent_after = b.tangent;
      point.test_value = root.test;
      point.interval_lo = a.arclength + root.lo;
      point.interval_hi = a.arclength + root.hi;
      point.interval_width = (root.u_hi - root.u_lo).cwiseAbs();
      point.residual_norm = root.estimate.residual;
      point.iterations = root.iterations;
      point.message = root.message;
      // An interval wider than the bracket (noise-limited locations widen it, AddIntegrationError may):
      // the components vary over all of it.
      const auto cover = [](SpecialPoint* p) {
        p->interval_width = p->interval_width.cwiseMax(p->tangent.cwiseAbs() * p->precision());
      };
      cover(&point);
      bracket_only.push_back(point);
      if (options_.check_integration_error) AddIntegrationError(&segment, root, test, &point);
      cover(&point);
      branch_.located_iterations += root.iterations;
      found.push_back(std::move(point));
    };
    if (options_.detect_bifurcations && a.sb_test != 0 && b.sb_test != 0 &&
        std::signbit(a.sb_test) != std::signbit(b.sb_test)) {
      locate(SpecialPointType::kSimpleBifurcation, -1, [](const internal::Segment::Probe& p) { return p.sb_test; });
    }
    for (const int k : turning_) {
      if (a.tangent(k) * b.tangent(k) < 0) {
        locate(SpecialPointType::kTurningPoint, k, [k](const internal::Segment::Probe& p) { return p.tangent(k); });
      }
    }
    // A turning point at an SB point of the same step cannot be told apart from it: the tangent, and so
    // τ_k, is undefined at the SB point and next to it set by the noise, and so is the turning point's
    // own integration-error estimate (on the SLIP with w2 = 12 the refined τ flipped and claimed an error
    // of 2 in arclength). "At" means inside the SB point's interval or closer than kCoincidence of the
    // step (SLIP: on branch 18, where the branch passes the zero-duration family, the turning point lands
    // 1.2e-9 before the SB point or on it, depending on the tolerances, and at rtol 1e-12 the SB's
    // interval is narrower than that; at the closed loop's reflection midpoint the two are 1.9e-6 apart,
    // 1e-5 of the step, with H̄ equal to 1e-13). Such a turning point keeps its root finder's bracket and
    // takes the SB point's interval and their distance on both sides instead of its own estimate.
    const double step = b.arclength - a.arclength;
    for (const SpecialPoint& sb : found) {
      if (sb.type != SpecialPointType::kSimpleBifurcation) continue;
      for (size_t i = 0; i < found.size(); ++i) {
        SpecialPoint& tp = found[i];
        const double distance = std::abs(tp.arclength - sb.arclength);
        const bool inside = tp.arclength >= sb.interval_lo && tp.arclength <= sb.interval_hi;
        if (tp.type != SpecialPointType::kTurningPoint || !(inside || distance <= kCoincidence * step)) continue;
        const SpecialPoint& bracket = bracket_only[i];
        tp.interval_lo = std::min({bracket.interval_lo, sb.interval_lo, tp.arclength - distance});
        tp.interval_hi = std::max({bracket.interval_hi, sb.interval_hi, tp.arclength + distance});
        if (bracket.interval_width.size() == sb.interval_width.size() && tp.u.size() == sb.u.size()) {
          tp.interval_width = bracket.interval_width.cwiseMax(sb.interval_width + 2 * (tp.u - sb.u).cwiseAbs());
        }
        std::ostringstream text;
        text.precision(12);
        text << "at the simple bifurcation point at s = " << sb.arclength << " (";
        if (inside) {
          text << "inside its interval";
        } else {
          text << "closer than " << kCoincidence << " of the step";
        }
        text << "), where the tangent is undefined: located as well as that point, its own integration-error "
             << "estimate is meaningless there";
        tp.message = bracket.message.empty() ? text.str() : bracket.message + "; " + text.str();
      }
    }
    std::sort(found.begin(), found.end(),
              [](const SpecialPoint& x, const SpecialPoint& y) { return x.arclength < y.arclength; });
    for (SpecialPoint& point : found) {
      point.id = static_cast<int>(branch_.special_points.size());
      branch_.special_points.push_back(std::move(point));
    }
  }

  // special_point.h, "Integration error". The estimate evaluated again with the problem's refined copy:
  // with the error of an evaluation proportional to the tolerances, the change Δ of a quantity is
  // (1 − factor) of its error at the problem's own tolerances. The test function's error over its slope
  // is how far the exact root may lie from the computed one (δs, along the branch), the refined Newton
  // correction how far the exact curve may lie from the point (δu). Where δs or δu exceed the bracket,
  // the interval and the componentwise widths grow to cover them, and the message says so.
  void AddIntegrationError(internal::Segment* segment, const internal::RootLocation& root,
                           const std::function<double(const internal::Segment::Probe&)>& test, SpecialPoint* point) {
    constexpr double kFactor = ContinuationOptions::kIntegrationErrorFactor;
    constexpr double kScale = ContinuationOptions::kIntegrationErrorScale;
    const std::unique_ptr<ZeroProblem> refined = problem_->Refined(kFactor);
    if (refined == nullptr) return;  // exact to rounding: the bracket is the precision
    const auto not_estimated = [point](const std::string& why) {
      if (!point->message.empty()) point->message += "; ";
      point->message += "integration error not estimated (" + why + "): the precision is the bracket's";
    };
    if (root.estimate.u.size() != problem_->num_unknowns() || !(root.slope != 0)) {
      return not_estimated("no test function slope");
    }
    internal::Segment::Probe fine;
    Vector du;
    const bool ok = segment->RefinedProbe(refined.get(), root.estimate, &fine, &du);
    problem_->AddWorkOf(*refined);
    if (!ok) return not_estimated("the evaluation at 0.1x the tolerances failed");
    const double change = std::abs(test(fine) - root.test), refined_step = du.norm();
    du *= kScale;
    const double ds = kScale * change / std::abs(root.slope);
    if (!std::isfinite(ds)) return not_estimated("not finite");
    const Vector tangent = point->tangent.size() == du.size() ? point->tangent : root.estimate.tangent;
    const Vector spread = 2 * (tangent.cwiseAbs() * ds + du.cwiseAbs());
    const double bracket = point->precision();
    // The arclength interval also takes the point's distance from the exact curve: one number that
    // bounds how far the exact special point may be from u, along the branch or off it.
    const double reach = ds + du.norm();
    point->interval_lo = std::min(point->interval_lo, point->arclength - reach);
    point->interval_hi = std::max(point->interval_hi, point->arclength + reach);
    if (point->interval_width.size() == spread.size()) point->interval_width = point->interval_width.cwiseMax(spread);
    if (point->precision() > bracket) {
      char text[640];
      std::snprintf(text, sizeof(text),
                    "integration error: evaluated with %gx the tolerances the test function moves by %.2g "
                    "(slope %.2g along the branch) and Newton by %.2g, so the root may lie %.2g away along "
                    "the branch and the point %.2g off it (twice the estimate; precision %.2g, the bracket was %.2g)",
                    kFactor, change, std::abs(root.slope), refined_step, ds, du.norm(), point->precision(), bracket);
      if (!point->message.empty()) point->message += "; ";
      point->message += text;
    }
  }

  void Report() const {
    if (!options_.progress) return;
    options_.progress(internal::PointProgress(branch_.points.back(), branch_.id,
                                              static_cast<int>(branch_.points.size()) - 1, progress_, h_,
                                              branch_.rejected_steps));
  }

  ZeroProblem* problem_;
  ContinuationOptions options_;
  Corrector corrector_;
  internal::BorderedSolver solver_;
  std::vector<std::string> names_;
  std::vector<int> turning_;
  std::vector<int> progress_;
  std::vector<LinearStop> stops_;
  Branch branch_;
  double h_;
  // Smallest step at which the corrector failed, growing by kFailedStepRelease per accepted point
  // (infinite before any failure); steps grow to at most kFailedStepMargin times it.
  static constexpr double kNoFailure = std::numeric_limits<double>::infinity();
  double failed_step_ = kNoFailure;
  double failed_size_ = 0;  // failed_step_ when it was last set (before any release)
  double failed_at_ = 0;    // arclength of the point the last failed step started from
  static constexpr double kFailedStepMargin = 0.75;
  static constexpr double kFailedStepRelease = 1.1;
  static constexpr double kFailedStepMemory = 4;
  // A turning point this close to an SB point of the same step, relative to the step, is taken to be at
  // it (DetectSpecialPoints).
  static constexpr double kCoincidence = 1e-4;
  bool start_singular_ = false;
};

ContinuationStepper::ContinuationStepper(ZeroProblem* problem, const ContinuationOptions& options, int branch_id) {
  if (problem == nullptr) throw std::invalid_argument("ContinuationStepper: problem is null");
  impl_ = std::make_unique<Impl>(problem, options, branch_id);
}
ContinuationStepper::~ContinuationStepper() = default;
ContinuationStepper::ContinuationStepper(ContinuationStepper&&) noexcept = default;
ContinuationStepper& ContinuationStepper::operator=(ContinuationStepper&&) noexcept = default;

StepStatus ContinuationStepper::Start(const Vector& u0) { return impl_->Start(u0, nullptr); }
StepStatus ContinuationStepper::Start(const Vector& u0, const Vector& direction_hint) {
  return impl_->Start(u0, &direction_hint);
}
StepStatus ContinuationStepper::StartAtSingularPoint(const Vector& u0, const Vector& tangent) {
  return impl_->StartAtSingularPoint(u0, tangent);
}
StepStatus ContinuationStepper::Step() { return impl_->Step(); }
void ContinuationStepper::Terminate(TerminationReason reason, const std::string& message) {
  impl_->Terminate(reason, message);
}
bool ContinuationStepper::finished() const { return impl_->finished(); }
double ContinuationStepper::step_size() const { return impl_->step_size(); }
const Branch& ContinuationStepper::branch() const { return impl_->branch(); }
Branch ContinuationStepper::TakeBranch() { return impl_->TakeBranch(); }

Branch TraceBranch(ZeroProblem* problem, const Vector& u0, const ContinuationOptions& options) {
  ContinuationStepper stepper(problem, options);
  for (StepStatus status = stepper.Start(u0); status == StepStatus::kContinuing; status = stepper.Step()) {
  }
  return stepper.TakeBranch();
}

}  // namespace hybridcont
