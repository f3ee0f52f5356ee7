#include "continuation/branch_geometry.h"
#include "continuation/jacobian_tolerance_scope.h"

#include <Eigen/LU>
#include <Eigen/QR>
#include <algorithm>
#include <array>
#include <cstdio>
#include <cmath>
#include <utility>

namespace hybridcont::internal {
namespace {

std::string FormatShort(double value) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.3g", value);
  return text;
}

}  // namespace

Vector KernelByQR(const Matrix& dr) {
  const Eigen::Index n = dr.cols();
  Eigen::HouseholderQR<Matrix> qr(dr.transpose());
  Matrix q = qr.householderQ() * Matrix::Identity(n, n);
  return q.col(n - 1).normalized();
}

double LogRowScale(const Matrix& dr) {
  double log_rows = 0;
  for (Eigen::Index i = 0; i < dr.rows(); ++i) {
    const double norm = dr.row(i).norm();
    if (norm > 0) log_rows += std::log(norm);
  }
  return log_rows;
}

bool InducedTangent(BorderedSolver* solver, const Matrix& dr, const Vector& reference, Vector* tangent,
                    double* sb_own, double* sb_reference, const double* log_row_scale) {
  const Eigen::Index n = dr.cols();
  if (!solver->Factorize(dr, reference)) return false;
  solver->Solve(Vector::Unit(n, n - 1), tangent);
  const double v_norm = tangent->norm();
  if (!(v_norm > 0) || !std::isfinite(v_norm)) return false;
  *tangent /= v_norm;
  // log of the Hadamard bound ∏||rows||; a zero row (possible only at singular points) counts as 1.
  const double log_rows = log_row_scale != nullptr ? *log_row_scale : LogRowScale(dr);
  const double log_reference = std::log(reference.norm());
  const double log_det = solver->LogAbsDeterminant() - log_rows - log_reference;
  const double sign = solver->DeterminantSign();
  // det([dr; τᵀ]) = det([dr; refᵀ]) · ||v|| (Cramer: v = cofactors / det), see special_point.h.
  if (sb_own != nullptr) *sb_own = std::copysign(std::exp(log_det + std::log(v_norm) + log_reference), sign);
  if (sb_reference != nullptr) *sb_reference = std::copysign(std::exp(log_det), sign);
  return true;
}

Segment::Segment(Corrector* corrector, BorderedSolver* solver, ZeroProblem* problem,
                 const ContinuationPoint& a, const ContinuationPoint& b, bool with_sb_test)
    : corrector_(corrector),
      solver_(solver),
      problem_(problem),
      with_sb_test_(with_sb_test),
      a_(a),
      b_(b),
      sigma_b_(a.tangent.dot(b.u - a.u)) {}

bool Segment::Evaluate(double sigma, const Probe& left, double sigma_left, const Probe& right,
                       double sigma_right, Probe* probe, std::string* message) {
  const double w = sigma_right - sigma_left;
  const double t = (sigma - sigma_left) / w;
  const double h00 = (1 + 2 * t) * (1 - t) * (1 - t), h10 = t * (1 - t) * (1 - t);
  const double h01 = t * t * (3 - 2 * t), h11 = t * t * (t - 1);
  // du/dσ = τ / (τ_a·τ) along the curve. The interpolant is accurate to O(w⁴): a correction of a quarter
  // of the bracket width is not a correction but a jump — next to an SB point to the crossing branch,
  // which meets the hyperplane close to the parent branch (at distance ~ sqrt(|σ − σ*|) for a pitchfork).
  auto correct = [&](const Vector& tangent_left, const Vector& tangent_right, Vector* predictor) {
    *predictor = h00 * left.u + h01 * right.u + (h10 * w / a_.tangent.dot(tangent_left)) * tangent_left +
                 (h11 * w / a_.tangent.dot(tangent_right)) * tangent_right;
    return CorrectFrom(*predictor, 0.25 * w, probe);
  };
  Vector predictor;
  CorrectorResult result;
  if (with_sb_test_ && nodes_.size() >= kNodes && InterpolateNodes(sigma, &predictor)) {
    result = CorrectFrom(predictor, 0.25 * w, probe);
  } else {
    result = correct(ReliableTangent(left, sigma_left), ReliableTangent(right, sigma_right), &predictor);
  }
  probe->noise_limited = false;
  probe->singular_at_trial = result.status == CorrectorStatus::kSingular && result.iterations == 0;
  if (with_sb_test_ && result.converged() &&
      result.predictor_residual_norm <= corrector_->options().residual_tolerance &&
      result.distance > kResolvedFraction * w) {
    // The interpolant was on the curve to the residual noise already, yet Newton moved it across a
    // sizeable part of the bracket: a correction of noise along the second kernel direction, or a jump
    // to the crossing branch (transcritical: at distance ~|σ − σ*| tan θ, with a test value of the wrong
    // sign for this branch). Either way the curve is not resolved on this scale.
    *message = "trial point at sigma = " + std::to_string(sigma) + ": correction " +
               std::to_string(result.distance) + " of a predictor at the noise level";
    probe->noise_limited = true;
    probe->residual = result.predictor_residual_norm;
    probe->scatter = result.distance;
    return false;
  }
  if (!result.converged()) {
    *message = "trial point at sigma = " + std::to_string(sigma) + " not corrected: " + result.BriefReport();
    // Next to an SB point the bordered matrix is singular for every border (rank dr = N − 1 there), and
    // Newton amplifies the residual noise of a shooting map (~1e-12) along the second kernel direction.
    // When the interpolant's residual is already at the corrector's tolerance, the failure says that the
    // curve cannot be resolved on the scale of the bracket: the bracket is as good as the noise allows.
    // The corrector's first evaluation was at the interpolant itself, where the arclength equation holds:
    // its residual norm is |r| there (unknown only when that very evaluation failed; a later one failing
    // on Newton's jump is the noise-limited case too).
    const bool predictor_evaluated =
        result.evaluations >= 2 || (result.evaluations == 1 && result.status != CorrectorStatus::kEvaluationFailed);
    if (predictor_evaluated && result.predictor_residual_norm <= corrector_->options().residual_tolerance) {
      probe->noise_limited = true;
      probe->residual = result.predictor_residual_norm;
    }
    return false;
  }
  probe->residual = result.residual_norm;
  if (!InducedTangent(solver_, corrector_->jacobian(), a_.tangent, &probe->tangent, nullptr, &probe->sb_test,
                      &log_row_scale_)) {
    // Exactly on a singular point: the test function is zero there, the tangent is the incoming one.
    probe->tangent = a_.tangent;
    probe->sb_test = 0;
  }
  if (with_sb_test_) nodes_.push_back({sigma, probe->u});
  return true;
}

CorrectorResult Segment::CorrectFrom(const Vector& predictor, double max_distance, Probe* probe) {
  const CorrectorOptions saved = corrector_->options();
  corrector_->set_max_distance(max_distance + kDistanceFloor * (1 + predictor.norm()));
  // Trial points next to an SB point: full Newton to a small last step. Accepting on the error estimate
  // would stop before Newton shows that it amplifies residual noise along the second kernel direction
  // (the noise-limited test above), and locate the point inside the noise. Elsewhere (turning points,
  // stops) the curve is regular and the estimate is as good as on branch points.
  if (with_sb_test_) corrector_->set_accept_on_error_estimate(false);
  // and the exact Jacobian: the SB test function is taken from it
  const JacobianToleranceScope exact(problem_, with_sb_test_ ? 0.0 : -1.0, JacobianToleranceScope::Mode::kExactly);
  // dr at the predictor as exact as the later ones: once the bracket is small the interpolant lies on
  // the curve to the rounding level, and the corrector then accepts it after one evaluation
  // (CorrectorOptions::kOnCurveStep) instead of evaluating again one rounding error away.
  corrector_->set_predictor_jacobian_tolerance(0.0);
  const CorrectorResult result = corrector_->CorrectPseudoArclength(predictor, a_.tangent, &probe->u);
  corrector_->set_max_distance(saved.max_distance);
  corrector_->set_accept_on_error_estimate(saved.accept_on_error_estimate);
  corrector_->set_predictor_jacobian_tolerance(saved.predictor_jacobian_tolerance);
  return result;
}

bool Segment::InterpolateNodes(double sigma, Vector* u_out) const {
  // The kNodes corrected points nearest to σ; Lagrange interpolation in σ (on the hyperplane σ exactly:
  // every node lies on its own hyperplane and interpolation reproduces the linear function τ_aᵀ(u − u_a)).
  std::vector<const std::pair<double, Vector>*> nearest;
  for (const auto& node : nodes_) nearest.push_back(&node);
  const size_t count = std::min<size_t>(kNodes, nearest.size());
  std::partial_sort(nearest.begin(), nearest.begin() + count, nearest.end(), [sigma](const auto* x, const auto* y) {
    return std::abs(x->first - sigma) < std::abs(y->first - sigma);
  });
  std::array<double, kNodes> weights{};
  double lebesgue = 0;
  for (size_t i = 0; i < count; ++i) {
    double weight = 1;
    for (size_t j = 0; j < count; ++j) {
      if (j != i) weight *= (sigma - nearest[j]->first) / (nearest[i]->first - nearest[j]->first);
    }
    weights[i] = weight;
    lebesgue += std::abs(weight);
  }
  // The interpolant amplifies the scatter of its nodes (points accepted inside the noise next to the SB
  // lie ~noise/σ_min off the curve) by Σ|w_i| (the Lebesgue function): clustered nodes, or a trial
  // outside their span, raise it to 1e2–1e3 and the predictor's residual with it.
  // Beyond kMaxLebesgue the Hermite interpolant of the bracketing probes is used instead.
  if (!(lebesgue <= kMaxLebesgue)) return false;
  Vector& u = *u_out;
  u = Vector::Zero(a_.u.size());
  for (size_t i = 0; i < count; ++i) u += weights[i] * nearest[i]->second;
  return true;
}

Vector Segment::ReliableTangent(const Probe& probe, double sigma) const {
  if (!with_sb_test_) return probe.tangent;
  Vector interpolated = InterpolatedTangent(sigma);
  // The tangent of a smooth arc between a and b deviates from the interpolation by far less than half
  // the angle between τ_a and τ_b; a probe tangent outside that cone is the numerical artefact.
  const double cone = 0.5 * AngleBetween(a_.tangent, b_.tangent) + kTangentNoise;
  return AngleBetween(probe.tangent, interpolated) <= cone ? probe.tangent : interpolated;
}

Vector Segment::InterpolatedTangent(double sigma) const {
  const double theta = sigma_b_ != 0 ? std::clamp(sigma / sigma_b_, 0.0, 1.0) : 0.0;
  return ((1 - theta) * a_.tangent + theta * b_.tangent).normalized();
}

bool Segment::EndProbe(bool at_b, Probe* probe, std::string* message) {
  const ContinuationPoint& p = at_b ? b_ : a_;
  probe->u = p.u;
  if (with_sb_test_) nodes_.push_back({at_b ? sigma_b_ : 0.0, p.u});
  probe->tangent = p.tangent;
  probe->sb_test = 0;
  if (!with_sb_test_) return true;
  const JacobianToleranceScope exact(problem_, 0.0, JacobianToleranceScope::Mode::kExactly);
  if (const EvaluationStatus status = problem_->Evaluate(p.u, nullptr, &dr_); !status.ok) {
    *message = "evaluation at a bracketing point failed: " + status.message;
    return false;
  }
  if (!at_b) log_row_scale_ = LogRowScale(dr_);
  // The tangent induced by dr at the point itself: the stored one may come from a Jacobian up to
  // CorrectorOptions::max_jacobian_distance away, and next to an SB point (dr nearly rank-deficient) the
  // induced tangent is sensitive to where dr was taken. The trial points' interpolant starts from it.
  if (!InducedTangent(solver_, dr_, a_.tangent, &probe->tangent, nullptr, &probe->sb_test, &log_row_scale_)) {
    *message = "bracketing point is singular";
    return false;
  }
  return true;
}

bool Segment::RefinedProbe(ZeroProblem* refined, const Probe& probe, Probe* fine, Vector* correction) {
  Vector r;
  if (!refined->Evaluate(probe.u, &r, &dr_).ok) return false;
  fine->u = probe.u;
  fine->residual = r.norm();
  // InducedTangent leaves [dr; τ_aᵀ] factorized: the correction is one more solve.
  if (!InducedTangent(solver_, dr_, a_.tangent, &fine->tangent, nullptr, &fine->sb_test, &log_row_scale_)) {
    return false;
  }
  Vector rhs = Vector::Zero(r.size() + 1);
  rhs.head(r.size()) = -r;
  solver_->Solve(rhs, correction);
  return correction->allFinite();
}

bool Segment::SmallestSingularValue(const Probe& probe, double* sigma_min) {
  const JacobianToleranceScope exact(problem_, 0.0, JacobianToleranceScope::Mode::kExactly);
  if (!problem_->Evaluate(probe.u, nullptr, &dr_).ok) return false;
  const Eigen::Index n = dr_.cols();
  Matrix bordered(n, n);
  bordered.topRows(n - 1) = dr_;
  bordered.row(n - 1) = a_.tangent.transpose();
  if (!bordered.allFinite()) return false;
  // 1/||B⁻¹||₁ from the LU's condition estimate (Hager–Higham: a few solves, no SVD), within a factor √n
  // of σ_min = 1/||B⁻¹||₂: what is asked is an order of magnitude.
  const Eigen::PartialPivLU<Matrix> lu(bordered);
  const double norm_1 = bordered.cwiseAbs().colwise().sum().maxCoeff();
  *sigma_min = lu.rcond() * norm_1;
  return std::isfinite(*sigma_min);
}

namespace {

// The bracket of LocateRoot: its ends in σ, their probes and test values, and the Illinois state.
struct Bracket {
  double lo = 0, hi = 0;
  Segment::Probe lo_probe, hi_probe;
  double g_lo = 0, g_hi = 0;  // the test at the ends
  double f_lo = 0, f_hi = 0;  // Illinois factors: the value of an end retained twice is halved
  int side = 0;               // the end kept last time
  int last_side = 0;          // the end that moved last

  // *out completed from the bracket. The estimate is a bracket end: with |test| smaller, or the most
  // recent one on a tie (a test function that jumps at its root has equal |test| on both sides).
  RootLocation Finish(RootLocation* out, bool located) const {
    out->located = located;
    out->lo = lo;
    out->hi = hi;
    const bool use_hi = std::abs(g_hi) < std::abs(g_lo) || (std::abs(g_hi) == std::abs(g_lo) && last_side == +1);
    out->estimate = use_hi ? hi_probe : lo_probe;
    out->sigma = use_hi ? hi : lo;
    out->test = use_hi ? g_hi : g_lo;
    out->u_lo = lo_probe.u;
    out->u_hi = hi_probe.u;
    // The flatter of the segment's secant and the final bracket's (RootLocation::slope).
    if (hi > lo && g_lo != 0 && g_hi != 0 && std::signbit(g_lo) != std::signbit(g_hi)) {
      const double local = (g_hi - g_lo) / (hi - lo);
      if (std::abs(local) < std::abs(out->slope)) out->slope = local;
    }
    return *out;
  }

  // The corrected trial point at x with test value g != 0 replaces the end of its sign.
  void Replace(double x, double g, Segment::Probe probe) {
    if (std::signbit(g) == std::signbit(g_lo)) {
      lo = x;
      g_lo = f_lo = g;
      lo_probe = std::move(probe);
      last_side = -1;
      if (side == -1) f_hi *= 0.5;
      side = -1;
    } else {
      hi = x;
      g_hi = f_hi = g;
      hi_probe = std::move(probe);
      last_side = +1;
      if (side == +1) f_lo *= 0.5;
      side = +1;
    }
  }
};

// A trial point of one LocateRoot iteration, corrected onto the curve, and what its failures said.
struct Trial {
  bool corrected = false;
  double x = 0;                // where it was corrected
  Segment::Probe probe;
  bool noise_limited = false;  // a failed attempt was limited by the noise
  double scatter = 0;          // the largest correction of such an attempt
};

// A trial point exactly on the root of the SB test is exactly singular (regula falsi hits it for a linear
// test function): retried half a tolerance to either side, which still brackets the root. With a noisy map
// the points within ~noise/slope of an SB cannot be corrected at all: then retried halfway to either
// bracket end, which still halves the bracket.
Trial CorrectTrial(Segment* segment, const Bracket& bracket, double x0, double margin, double tolerance,
                   std::string* message) {
  const double lo = bracket.lo, hi = bracket.hi;
  Trial trial;
  trial.x = x0;
  bool retry_nearby = false;
  const std::array<double, 5> trials = {x0, x0 + 0.5 * tolerance, x0 - 0.5 * tolerance, 0.5 * (lo + x0), 0.5 * (x0 + hi)};
  for (size_t attempt = 0; attempt < trials.size(); ++attempt) {
    // The retries half a tolerance away only for a trial exactly on the root: any other failure (a jump
    // along the nearly singular direction, a poor interpolant) recurs half a tolerance away.
    if ((attempt == 1 || attempt == 2) && !retry_nearby) continue;
    const double x = std::clamp(trials[attempt], lo + margin, hi - margin);
    if (segment->Evaluate(x, bracket.lo_probe, lo, bracket.hi_probe, hi, &trial.probe, message)) {
      trial.x = x;
      trial.corrected = true;
      break;
    }
    if (attempt == 0) retry_nearby = trial.probe.singular_at_trial;
    trial.noise_limited = trial.noise_limited || trial.probe.noise_limited;
    if (trial.probe.noise_limited) trial.scatter = std::max(trial.scatter, trial.probe.scatter);
  }
  return trial;
}

// A trial point that could not be corrected, in a bracket at whose ends the points the corrector accepts
// may lie farther from the curve than kResolvedFraction of its width (residual_tolerance / σ_min,
// Segment::SmallestSingularValue): the curve is not resolved on the bracket's scale, and the failure says
// so, whatever Newton did (it diverges, or jumps along the nearly singular direction from an interpolant
// built on scattered ends).
bool IllConditioned(Segment* segment, const Bracket& bracket, RootLocation* out) {
  const double residual_tolerance = segment->residual_tolerance();
  double scatter = 0;
  for (const Segment::Probe* end : {&bracket.lo_probe, &bracket.hi_probe}) {
    double sigma_min = 0;
    if (!segment->SmallestSingularValue(*end, &sigma_min)) return false;
    scatter = std::max(scatter, residual_tolerance / sigma_min);
  }
  if (!(scatter >= Segment::kResolvedFraction * (bracket.hi - bracket.lo))) return false;
  out->conditioning_scatter = scatter;
  return true;
}

// Located to the noise level. The bracket ends are themselves points accepted inside the noise: near the
// SB they scatter across both branches, and an end on the crossing branch carries a test value of the
// wrong sign. The SB is then only known to lie within a few bracket widths (or the scatter) of the
// bracket: kNoiseMargin (docs/design/continuation.md, "Location to the noise level").
RootLocation NoiseLimited(const Bracket& bracket, const Trial& trial, double sigma_b, RootLocation* out) {
  out->noise_limited = true;
  if (out->conditioning_scatter > 0) {
    out->message = "located to the noise level: at the bracket (width " + FormatShort(bracket.hi - bracket.lo) +
                   ") the bordered Jacobian is so nearly singular that points accepted at the residual " +
                   "tolerance may lie " + FormatShort(out->conditioning_scatter) + " off the curve, and a trial " +
                   "point inside it could not be corrected (the precision is the bracket widened by four times " +
                   "its width on both sides: an estimate, not a bound)";
  } else {
    out->message = "located to the noise level: a trial point inside the bracket has |r| = " +
                   FormatShort(trial.probe.residual) + " before any correction, and Newton's correction of that " +
                   "noise is not small against the bracket (the precision is the bracket widened by " +
                   "four times its width, or that correction if larger, on both sides: an estimate, not a bound)";
  }
  RootLocation located = bracket.Finish(out, true);
  const double margin = std::max(trial.scatter, kNoiseMargin * (bracket.hi - bracket.lo));
  const double lowest = std::min(0.0, sigma_b), highest = std::max(0.0, sigma_b);
  located.lo = std::max(lowest, bracket.lo - margin);
  located.hi = std::min(highest, bracket.hi + margin);
  return located;
}

}  // namespace

RootLocation LocateRoot(Segment* segment, const std::function<double(const Segment::Probe&)>& test,
                        double tolerance, int max_iterations) {
  RootLocation out;
  Bracket bracket;
  std::string message;
  double& lo = bracket.lo;
  double& hi = bracket.hi;
  hi = segment->sigma_b();
  if (!segment->EndProbe(false, &bracket.lo_probe, &message) || !segment->EndProbe(true, &bracket.hi_probe, &message)) {
    out.message = message;
    out.lo = lo;
    out.hi = hi;
    out.estimate = segment->sigma_b() > 0 ? bracket.hi_probe : bracket.lo_probe;
    out.u_lo = segment->a().u;
    out.u_hi = segment->b().u;
    return out;
  }
  bracket.g_lo = test(bracket.lo_probe), bracket.g_hi = test(bracket.hi_probe);
  if (hi > lo) out.slope = (bracket.g_hi - bracket.g_lo) / (hi - lo);
  bracket.f_lo = bracket.g_lo, bracket.f_hi = bracket.g_hi;
  double width_at_check = hi - lo;
  if (bracket.g_lo != 0 && bracket.g_hi != 0 && std::signbit(bracket.g_lo) == std::signbit(bracket.g_hi)) {
    // The end probes recompute the SB test from dr at the points themselves, while the sign change was
    // seen in the values stored with the points (from dr up to CorrectorOptions::max_jacobian_distance
    // away): the crossing lies within that distance of an end, or is not there. Not a root to locate.
    out.message = "no sign change between the bracketing points when the test is re-evaluated there (" +
                  FormatShort(bracket.g_lo) + ", " + FormatShort(bracket.g_hi) + ")";
    return bracket.Finish(&out, false);
  }
  for (int it = 1; it <= max_iterations; ++it) {
    const double width = hi - lo;
    if (width <= tolerance) return bracket.Finish(&out, true);
    double x = (lo * bracket.f_hi - hi * bracket.f_lo) / (bracket.f_hi - bracket.f_lo);
    if (it % 3 == 0) {  // a bisection every third iteration without halving of the bracket
      if (width > 0.5 * width_at_check) x = 0.5 * (lo + hi);
      width_at_check = width;
    }
    // Keep every trial point strictly inside, at least tolerance/4 from the ends, so the bracket shrinks.
    const double margin = std::min(0.25 * tolerance, 0.25 * width);
    if (!std::isfinite(x)) x = 0.5 * (lo + hi);
    x = std::clamp(x, lo + margin, hi - margin);
    Trial trial = CorrectTrial(segment, bracket, x, margin, tolerance, &message);
    out.iterations = it;
    if (!trial.corrected) {
      if (trial.noise_limited) return NoiseLimited(bracket, trial, segment->sigma_b(), &out);
      if (IllConditioned(segment, bracket, &out)) return NoiseLimited(bracket, trial, segment->sigma_b(), &out);
      out.uncorrectable = true;
      out.message = message;
      return bracket.Finish(&out, false);
    }
    x = trial.x;
    const double g = test(trial.probe);
    if (g == 0) {
      // Exactly on the root: the slope from the bracket just before (RootLocation::slope), then a
      // one-point bracket whose test value is that 0.
      for (const auto& [end, value] : {std::pair{lo, bracket.g_lo}, std::pair{hi, bracket.g_hi}}) {
        const double local = value / (end - x);
        if (end != x && std::abs(local) < std::abs(out.slope)) out.slope = local;
      }
      lo = hi = x;
      bracket.g_lo = bracket.g_hi = 0;
      bracket.lo_probe = bracket.hi_probe = trial.probe;
      return bracket.Finish(&out, true);
    }
    bracket.Replace(x, g, std::move(trial.probe));
  }
  out.message = "root finder budget of " + std::to_string(max_iterations) + " iterations spent";
  return bracket.Finish(&out, hi - lo <= tolerance);
}

}  // namespace hybridcont::internal
