// Derivative checks: every derivative the library uses is compared with central finite differences.
//
//   DerivativeCheckReport report = CheckDerivatives(model, DerivativeCheckOptions{});
//   std::cout << report.Table();          // worst relative error per derivative, with its threshold
//   if (!report.passed()) ...
//
// Checked, at num_points random (seeded) points per phase: df/dx, de/dx, dDelta/dx, dH/dx (against FD
// of H), d2H/dx2 (against FD of dH), the anchor's da/dx, the flow sensitivities Phi = dphi/dx0 and
// Psi = dphi/dxi (durations drawn from [-max_duration, max_duration], xi != 0), the Jacobian dr of
// the time-based shooting map at random u, and every declared symmetry S of the model at the same u:
// |r(S u)| = |r(u)| and |dr(S u) S| = |dr(u)| componentwise (model.h, ModelSymmetry), and the gradient of
// every observable and constraint (observable.h) at random u. States are drawn around each phase's
// typical state.
//
// Error measure per derivative and point: max_ij |J_ij - FD_ij| / max(max_ij |J_ij|, 1e-8), i.e.
// relative to the largest entry, so that structurally small entries (r^2 terms of the rod) still count
// against the scale of the matrix they belong to. The worst over points is reported. A parameter's column
// dr/dp of the shooting map is measured in relative units of p and of the unknowns (each column times
// max(1, |value|)) against the larger of its own largest entry and the map's largest such entry over the
// unknowns: a derivative that is exactly zero (a parameter that cancels) is then compared with differences
// that are integration noise on the map's own scale, not on the scale of a zero column.
#ifndef HYBRIDCONT_DERIVATIVE_CHECK_H_
#define HYBRIDCONT_DERIVATIVE_CHECK_H_

#include <string>
#include <vector>

#include "hybridcont/flow.h"
#include "hybridcont/model.h"

namespace hybridcont {

struct DerivativeCheckOptions {
  // Random points per phase (and for the shooting map); several, so one lucky point cannot hide a bug.
  int num_points = 5;
  // Seed of the point generator: checks are reproducible.
  unsigned seed = 20251122;
  // Central-difference step for model functions (relative to 1 + |x_i|): truncation ~h^2, round-off ~eps/h.
  double model_step = 1e-6;
  // Step for differences of integrated flows: larger, since the integrator's error (~rtol) divided by the
  // step is the noise floor.
  double flow_step = 1e-5;
  // Thresholds on the relative error (see header comment).
  double model_tolerance = 1e-6;
  double flow_tolerance = 1e-5;
  // Largest |duration| of the sampled flows and of the sampled shooting-map times.
  double max_duration = 0.6;
  // Largest |xi| sampled: xi != 0 exercises the Hessian term of df~/dx.
  double max_xi = 0.3;
  // Integrator for the flow checks: tight, so that finite differences of flows are meaningful.
  IntegratorOptions integrator = {IntegratorMethod::kFehlberg78, 1e-13, 1e-13, 1e-2, 1e-14, 1000000};

  std::string Validate() const;
};

struct DerivativeCheckEntry {
  std::string what;          // e.g. "phase 'stance': df/dx"
  double worst_error = 0.0;  // worst relative error over the points
  double tolerance = 0.0;
  std::string note;  // non-empty when an evaluation failed (message)
  // Points drawn again, not failures: where the integration failed (the sampled state or duration leaves the
  // model's domain), or where the function is not differentiable within the difference stencil (an
  // observable's minimum switching place, a guard arming): central differences at two steps disagree there.
  int redrawn_unintegrable = 0;
  int redrawn_not_differentiable = 0;
  bool passed() const { return note.empty() && worst_error <= tolerance; }
};

struct DerivativeCheckReport {
  std::string model;
  std::vector<DerivativeCheckEntry> entries;
  bool passed() const;
  // Fixed-width table: derivative, worst relative error, threshold, verdict.
  std::string Table() const;
};

// Throws std::invalid_argument for invalid options.
DerivativeCheckReport CheckDerivatives(const HybridModel& model, const DerivativeCheckOptions& options);

}  // namespace hybridcont

#endif  // HYBRIDCONT_DERIVATIVE_CHECK_H_
