// Phase flows with sensitivities (paper eqs. `hybridDynamicsNum`, `diffState`, `diffParam`).
//
// For a phase with unfolded vector field f~(x, xi) = f(x) + xi·dH(x)^T, PhaseFlow integrates over a
// duration t (positive, zero or negative) the augmented system
//     x'   = f~(x, xi),                       x(0)   = x0,
//     Phi' = A(x, xi) Phi,                    Phi(0) = I      (A = df~/dx),
//     Psi' = A(x, xi) Psi + dH(x)^T,          Psi(0) = 0      (n x k, k first integrals),
// so that x(t) = phi(t, x0; xi), Phi = dphi/dx0 and Psi = dphi/dxi. With free model parameters p
// (set_free_parameters) Psi has q more columns, dphi/dp, from Psi_p' = A Psi_p + df~/dp, Psi_p(0) = 0. t = 0 is the identity without any
// integration; t < 0 integrates backward in time (the paper's reversed-time, non-physical orbits).
//
//   PhaseFlow flow(model.phase(0), IntegratorOptions{});
//   PhaseFlowResult res;
//   flow.Integrate(x0, xi, /*t=*/0.7, /*with_sensitivities=*/true, &res);  // res.x, res.Phi, res.Psi
//
// Stepping is Boost.Odeint's controlled embedded Runge–Kutta (Dormand–Prince 5(4) or Fehlberg 7(8)),
// driven by our own loop so that the last step lands exactly on t, non-finite values from the model are
// caught (with phase and time) and the work is counted. The error control covers the whole augmented
// state, so Phi and Psi are as accurate as x: the Newton corrector then converges quadratically.
#ifndef HYBRIDCONT_FLOW_H_
#define HYBRIDCONT_FLOW_H_

#include <memory>
#include <string>
#include <vector>

#include "hybridcont/model.h"

namespace hybridcont {

enum class IntegratorMethod {
  kDormandPrince54,  // the paper's ode45-type method; cheap per step, fine for rtol >= 1e-9
  kFehlberg78,       // 8th order: far fewer steps at the tight tolerances used by default
};
std::string ToString(IntegratorMethod method);
// Parses "dopri5" / "rkf78"; returns false for an unknown name.
bool FromString(const std::string& name, IntegratorMethod* method);

struct IntegratorOptions {
  // Fehlberg 7(8): at rtol = 1e-10 it takes ~5x fewer steps than Dormand–Prince on the examples; tight
  // tolerances are what let special points be located to ~1e-10 in H.
  IntegratorMethod method = IntegratorMethod::kFehlberg78;
  // Relative tolerance per component of the augmented state. 1e-10 (not the paper's 1e-7): residuals of
  // the shooting map then reach ~1e-10, which the continuation needs to locate bifurcations sharply.
  double rtol = 1e-10;
  // Absolute tolerance; states are O(1) in the normalized units (m = l0 = g = 1).
  double atol = 1e-10;
  // First trial step; the controller adapts it at once.
  double initial_step = 1e-2;
  // A step below this (in absolute time) is a failure: the solution is singular or the model is stiff.
  double min_step = 1e-12;
  // Accepted + rejected steps per phase before giving up (guards against a runaway integration).
  int max_steps = 200000;

  // Empty if valid; otherwise names the field, its value and the violated constraint.
  std::string Validate() const;
};

enum class FlowStatus {
  kSuccess,
  kNonFinite,     // the model returned NaN/Inf (message: phase, time)
  kStepTooSmall,  // step size fell below IntegratorOptions::min_step
  kMaxSteps,      // IntegratorOptions::max_steps exhausted
};
std::string ToString(FlowStatus status);

// Work counters; they feed the performance notes (RHS evaluations per accepted point).
struct FlowCounters {
  long rhs_evaluations = 0;
  long steps = 0;
  long rejected_steps = 0;
  FlowCounters& operator+=(const FlowCounters& o) {
    rhs_evaluations += o.rhs_evaluations;
    steps += o.steps;
    rejected_steps += o.rejected_steps;
    return *this;
  }
};

struct PhaseFlowResult {
  FlowStatus status = FlowStatus::kSuccess;
  std::string message;  // empty on success
  Vector x;             // phi(t, x0; xi)
  Matrix Phi;           // dphi/dx0, n x n (only with sensitivities)
  Matrix Psi;           // [dphi/dxi, dphi/dp], n x (k + q) (only with sensitivities)
  FlowCounters counters;
  // The ξ·∇²H term was left out of the sensitivities only because of set_jacobian_tolerance: Phi and Psi
  // are then exact only to that relative tolerance.
  bool jacobian_relaxed = false;
  bool ok() const { return status == FlowStatus::kSuccess; }
};

class PhaseFlow {
 public:
  PhaseFlow(const Phase& phase, IntegratorOptions options);
  ~PhaseFlow();
  PhaseFlow(PhaseFlow&&) noexcept;
  PhaseFlow& operator=(PhaseFlow&&) noexcept;

  // Integrates from x0 over duration t with unfolding parameters xi (size k). Fills *result; returns
  // result->status. Never throws for numerical outcomes.
  FlowStatus Integrate(const Eigen::Ref<const Vector>& x0, const Eigen::Ref<const Vector>& xi, double t,
                       bool with_sensitivities, PhaseFlowResult* result);

  // Same, also calling observer(t, x) at the start and after every accepted step (for dense sampling of
  // a trajectory: figures, physical classification).
  using Observer = std::function<void(double, const Eigen::Ref<const Vector>&)>;
  FlowStatus Integrate(const Eigen::Ref<const Vector>& x0, const Eigen::Ref<const Vector>& xi, double t,
                       bool with_sensitivities, PhaseFlowResult* result, const Observer& observer);

  const Phase& phase() const { return *phase_; }
  const IntegratorOptions& options() const { return options_; }
  // Relative size below which the ξ·∇²H term of A = df~/dx may be left out of the sensitivities
  // (ZeroProblem::set_jacobian_tolerance); 0, the default, keeps it unless it is below 1e-3 rtol.
  void set_jacobian_tolerance(double tolerance) { jacobian_tolerance_ = tolerance; }
  // Model parameters (indices into HybridModel::parameters()) whose sensitivities are integrated as the
  // last columns of Psi. The phase must have parameter derivatives (Phase::has_parameter_derivatives).
  void set_free_parameters(std::vector<int> parameters);

 private:
  struct Steppers;
  const Phase* phase_;
  IntegratorOptions options_;
  double jacobian_tolerance_ = 0.0;
  std::unique_ptr<Steppers> steppers_;
};

}  // namespace hybridcont

#endif  // HYBRIDCONT_FLOW_H_
