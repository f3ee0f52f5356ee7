// ContinuationStepper: one branch point per Step() (continuation.h). The mechanisms live apart:
// predictor.h (tangent, secant, Hermite), step_controller.h (step length), linear_stop.h (stops),
// special_point_detector.h (special points); this file sequences them.
#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>
#include <stdexcept>
#include <utility>

#include "continuation/bordered_solver.h"
#include "continuation/branch_geometry.h"
#include "continuation/jacobian_tolerance_scope.h"
#include "continuation/linear_stop.h"
#include "continuation/predictor.h"
#include "continuation/progress_report.h"
#include "continuation/special_point_detector.h"
#include "continuation/step_controller.h"
#include "hybridcont/continuation.h"
#include "hybridcont/invariant.h"

namespace hybridcont {
using internal::LinearStop;

namespace {

// The options, after checking them against the problem's unknowns (std::invalid_argument otherwise).
const ContinuationOptions& ValidFor(const ContinuationOptions& options, const ZeroProblem& problem) {
  const std::string error = options.ValidateFor(problem.unknown_names());
  if (!error.empty()) throw std::invalid_argument(error);
  return options;
}

// N + 1 − rank dr, singular values below kRankTolerance · max(1, σ_max) counting as zero (the rank
// decision of branch_switching.h).
constexpr double kRankTolerance = 1e-8;
int KernelDimension(const Matrix& dr) {
  const Vector sigma = dr.jacobiSvd().singularValues();
  const double threshold = kRankTolerance * std::max(1.0, sigma.size() > 0 ? sigma(0) : 0.0);
  return static_cast<int>(dr.cols() - (sigma.array() > threshold).count());
}

}  // namespace

class ContinuationStepper::Impl {
 public:
  // The corrector checks its own options first (its message), then the stepper checks the rest.
  Impl(ZeroProblem* problem, const ContinuationOptions& options, int branch_id)
      : problem_(problem),
        corrector_(problem, options.corrector),
        options_(ValidFor(options, *problem)),
        controller_(options_),
        detector_(problem, &corrector_, &solver_, options_),
        stops_(internal::LinearStops(options_, *problem), problem, &corrector_, &solver_, options_),
        progress_(internal::ProgressIndices(options_, *problem)) {
    branch_.id = branch_id;
    branch_.direction = options_.direction;
  }

  StepStatus Start(const Vector& u0, const Vector* hint) {
    HYBRIDCONT_DEMAND(u0.size() == problem_->num_unknowns());
    HYBRIDCONT_DEMAND(hint == nullptr || hint->size() == problem_->num_unknowns());
    Vector u = u0;
    Matrix dr;
    if (options_.correct_start_point) {
      // With the exact Jacobian: an exploration analyses its start's kernel with it first (branch_switching.h),
      // which leaves it in the problem's cache, while a worker thread's copy of the problem starts from none;
      // both then correct the start the same way, to the bit.
      const internal::JacobianToleranceScope exact(problem_, 0.0, internal::JacobianToleranceScope::Mode::kExactly);
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
    return Begin(std::move(start), false, options_.correct_start_point);
  }

  StepStatus StartAtSingularPoint(const Vector& u0, const Vector& tangent) {
    HYBRIDCONT_DEMAND(u0.size() == problem_->num_unknowns());
    HYBRIDCONT_DEMAND(tangent.size() == problem_->num_unknowns());
    if (!(tangent.norm() > 0)) throw std::invalid_argument("StartAtSingularPoint: tangent is zero");
    ContinuationPoint start;
    start.u = u0;
    start.tangent = tangent.normalized();
    start.sb_test = 0;
    return Begin(std::move(start), true, false);
  }

  // Predictor and corrector until a step is accepted; then the stops, the closed loop, the special
  // points of the new interval, the user's stop and max_points.
  StepStatus Step() {
    if (finished()) return StepStatus::kFinished;
    if (options_.cancel && options_.cancel()) return Finish(TerminationReason::kUserStop, "cancelled");
    for (int retry = 0;; ++retry) {
      const ContinuationPoint& a = branch_.points.back();
      ContinuationPoint b;
      double next_h = 0;
      if (const std::optional<StepStatus> given_up = Advance(a, &b, &next_h)) return *given_up;
      b.arclength = a.arclength + (b.u - a.u).norm();

      TerminationReason reason = TerminationReason::kNotFinished;
      std::string message;
      if (!stops_.stops().empty() && !stops_.Apply(a, &b, &branch_.newton_iterations, &reason, &message)) {
        return Finish(reason, message);
      }
      if (reason == TerminationReason::kNotFinished && options_.detect_closed_loop && ClosesLoop(a, b)) {
        CloseLoop(a, &b);
        reason = TerminationReason::kClosedLoop;
        message = "the branch returned to its start point";
      }
      if (reason != TerminationReason::kClosedLoop) detector_.Sample(&b, true);  // a closed loop's b is its start
      const bool may_retry = reason == TerminationReason::kNotFinished && retry < kOneCurveRetries &&
                             !controller_.at_min_step();
      std::vector<SpecialPoint> before;
      if (may_retry) before = branch_.special_points;
      branch_.points.push_back(std::move(b));  // a is invalid from here on
      const size_t count = branch_.points.size();
      // The first interval of a branch from a singular point starts at the bifurcation point itself.
      const bool from_singular = start_singular_ && (count == 2 || reason == TerminationReason::kClosedLoop);
      if (!detector_.Detect(count - 2, from_singular, &branch_) && may_retry) {
        // The step left its branch for another one passing close by (special_point_detector.h): the
        // point and what was found on the step are dropped, and the step is taken again at half length.
        branch_.points.pop_back();
        branch_.special_points = std::move(before);
        Reject(0.5);
        continue;
      }
      controller_.set_h(next_h);
      if (reason == TerminationReason::kNotFinished) {
        std::string why;
        if (options_.stop_predicate && options_.stop_predicate(branch_.points.back().u)) {
          reason = TerminationReason::kUserStop;
          message = "stop_predicate returned true";
        } else if (options_.abandon && !(why = options_.abandon(branch_)).empty()) {
          reason = TerminationReason::kAbandoned;
          message = std::move(why);
        } else if (static_cast<int>(count) >= options_.max_points) {
          reason = TerminationReason::kMaxPoints;
          message = "max_points = " + std::to_string(options_.max_points) + " reached";
        }
      }
      Report();
      if (reason != TerminationReason::kNotFinished) return Finish(reason, message);
      return StepStatus::kContinuing;
    }
  }

  void Terminate(TerminationReason reason, const std::string& message) { Finish(reason, message); }
  bool finished() const { return branch_.termination != TerminationReason::kNotFinished; }
  double step_size() const { return controller_.h(); }
  const Branch& branch() const { return branch_; }
  Branch TakeBranch() {
    if (!finished()) Finish(TerminationReason::kUserStop, "branch taken from the stepper before it finished");
    return std::move(branch_);
  }

 private:
  // corrected: the corrector's last evaluation is the start's (SpecialPointDetector::Sample).
  StepStatus Begin(ContinuationPoint start, bool singular, bool corrected) {
    HYBRIDCONT_DEMAND(branch_.points.empty());  // one Start* per stepper
    start_singular_ = singular;
    detector_.Sample(&start, corrected);
    branch_.points.push_back(std::move(start));
    Report();
    for (const LinearStop& stop : stops_.stops()) {
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

  // Predicts from a with the controller's h and corrects, shrinking h after every failure, until the
  // deceleration factor accepts the step: *b is the new point (without its arclength), *next_h the step
  // proposed after it. Returns kFinished when the branch ends instead (step too small, or a start along
  // a curve of singular points).
  static constexpr std::size_t kJumpHistory = 8;  // accepted steps that size a jump across a singular point
  // Times a step whose special points show that it left its branch is halved and taken again (Step);
  // after that it is kept, with its special point bracketed only.
  static constexpr int kOneCurveRetries = 3;

  std::optional<StepStatus> Advance(const ContinuationPoint& a, ContinuationPoint* b, double* next_h) {
    const ContinuationPoint* previous = branch_.points.size() >= 2 ? &branch_.points[branch_.points.size() - 2] : nullptr;
    const Vector direction = internal::PredictorDirection(options_.predictor, a, previous);
    double sb_reference = 0;
    std::string last_failure;
    const int rejected_before = branch_.rejected_steps;
    bool jumping = false;
    Vector jump_direction;
    for (;;) {
      const double h = controller_.h();
      if (controller_.below_min_step()) {
        // Next to a singular point (an SB point, a turning point that is one) Newton's basin shrinks with
        // the distance to it, so steps that halve towards it fail down to min_step (and the accepted ones
        // before them shrink as they close in). Before giving up, one step across it: four times the
        // largest of the last kJumpHistory steps (at most max_step), accepted whatever its deceleration
        // factor; the special points inside are located as on any step (docs/design/continuation.md,
        // "Jump across a singular point").
        // Its direction is the secant over those steps: the tangents next to the singular point are set
        // by noise.
        double recent = 0;
        std::size_t back = branch_.points.size() - 1;
        for (std::size_t n = 0; back > 0 && n < kJumpHistory; ++n, --back) {
          recent = std::max(recent, branch_.points[back].step);
        }
        const Vector secant = a.u - branch_.points[back].u;
        if (!jumping && recent > 0 && secant.norm() > 0) {
          jumping = true;
          jump_direction = secant.normalized();
          last_failure += " (then a jump across: ";
          controller_.set_h(std::min(options_.max_step, 4 * recent));
          continue;
        }
        return Finish(TerminationReason::kStepTooSmall,
                      "step fell below min_step = " + std::to_string(options_.min_step) + "; last failure: " +
                          last_failure + (jumping ? ")" : ""));
      }
      Vector predictor = a.u + h * direction;
      Vector normal = direction;
      if (jumping) {
        predictor = a.u + h * jump_direction;
        normal = jump_direction;
      } else if (options_.predictor == PredictorType::kHermite && previous != nullptr) {
        internal::HermitePredictor(*previous, a, h, &predictor, &normal);
      }
      corrector_.set_max_distance(options_.max_corrector_distance * h);
      const CorrectorResult result = corrector_.Correct(options_.corrector_type, predictor, normal, &b->u);
      branch_.newton_iterations += result.iterations;
      if (!result.converged()) {
        last_failure = "h = " + std::to_string(h) + ": " + result.BriefReport();
        if (const std::optional<StepStatus> status = NotASimpleCurve(predictor, result)) return status;
        ++branch_.rejected_steps;
        controller_.CorrectorFailed(a.arclength);
        continue;
      }
      if (!internal::InducedTangent(&solver_, corrector_.jacobian(), a.tangent, &b->tangent, &b->sb_test,
                                    &sb_reference)) {
        last_failure = "h = " + std::to_string(h) + ": corrected point is singular";
        Reject(0.5);
        continue;
      }
      const double f = controller_.DecelerationFactor(result, a.tangent, b->tangent);
      if (f > 2 && !controller_.at_min_step() && !jumping) {
        last_failure = "h = " + std::to_string(h) + ": step control rejected (f = " + std::to_string(f) + ")";
        Reject(std::max(0.5 / (f / 2), 0.25));  // h / f, but never below h / 4
        continue;
      }
      *next_h = controller_.NextStep(f, a.arclength, branch_.rejected_steps > rejected_before);
      b->step = h;
      b->newton_iterations = result.iterations;
      b->contraction = result.contraction;
      return std::nullopt;
    }
  }

  // [dr; pᵀ] singular at the very predictor of a branch started at a singular point: along a curve of
  // singular points halving h cannot help. Ends the branch when dr at the predictor, evaluated to the
  // problem's own accuracy (the corrector's was taken with predictor_jacobian_tolerance), has a kernel
  // of dimension >= 2; said once instead of ~20 rejected steps.
  std::optional<StepStatus> NotASimpleCurve(const Vector& predictor, const CorrectorResult& result) {
    if (!(start_singular_ && branch_.points.size() == 1 && result.status == CorrectorStatus::kSingular &&
          result.iterations == 0)) {
      return std::nullopt;
    }
    Matrix dr;
    if (const int k = problem_->Evaluate(predictor, nullptr, &dr).ok ? KernelDimension(dr) : 0; k >= 2) {
      return Finish(TerminationReason::kStartFailed,
                    "dr has a kernel of dimension " + std::to_string(k) +
                        " along this direction: not a simple curve (at h = " + std::to_string(controller_.h()) + ")");
    }
    return std::nullopt;
  }

  // Shrinks h and counts the rejected step.
  void Reject(double factor) {
    ++branch_.rejected_steps;
    controller_.Reject(factor);
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

  // *b becomes the start point, so the curve closes exactly, with the arclength and step to it from a.
  void CloseLoop(const ContinuationPoint& a, ContinuationPoint* b) const {
    const double arclength = a.arclength + (branch_.points.front().u - a.u).norm();
    const double step = b->step;
    *b = branch_.points.front();
    b->arclength = arclength;
    b->step = step;
  }

  void Report() const {
    if (!options_.progress) return;
    ProgressInfo info = internal::PointProgress(branch_.points.back(), branch_.id,
                                                static_cast<int>(branch_.points.size()) - 1, progress_,
                                                controller_.h(), branch_.rejected_steps);
    info.at_singular_point = start_singular_ && branch_.points.size() == 1;
    options_.progress(info);
  }

  ZeroProblem* problem_;
  Corrector corrector_;
  ContinuationOptions options_;
  internal::BorderedSolver solver_;
  internal::StepController controller_;
  internal::SpecialPointDetector detector_;
  internal::StopLocator stops_;
  std::vector<int> progress_;
  Branch branch_;
  bool start_singular_ = false;
};

ContinuationStepper::ContinuationStepper(ZeroProblem* problem, const ContinuationOptions& options, int branch_id) {
  HYBRIDCONT_DEMAND(problem != nullptr);
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
