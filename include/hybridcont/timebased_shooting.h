// The time-based multiple-shooting map r: R^{N+1} -> R^N of paper eq. `timebased` and its Jacobian
// (eq. `multishootJacobian`), as a ZeroProblem for the continuation engine.
//
// Phase durations t_i are unknowns (they may be zero or negative); events and anchor become equations.
// Residual blocks, in the order of the layout (shooting_layout.h):
//   r_p  = phi_1(t_{m+1}, x̄_{m+1}; xi) - x̄_1            periodicity
//   r_a  = a(phi_1(t_{m+1}, x̄_{m+1}; xi))                anchor
//   r_s,i = Delta_i(phi_i(t_i, x̄_i; xi)) - x̄_{i+1}        shooting, i = m..1
//   r_e,i = e_i(phi_i(t_i, x̄_i; xi))                      event, i = m..1
//   r_i  = H_1(x̄_1) - H̄                                   first integral
// followed by the fixing rows and the observables' equations o_j − g_j(u) (shooting_layout.h).
//
// Jacobian (columns grouped as u, rows as r; f~ = f~(phi_i), Phi_i, Psi_i at the end of phase i):
//
//          t_{m+1},x̄_{m+1}  t_m,x̄_m   ...   t_1,x̄_1     xi        H̄
//   m+1  [ R_{m+1}          0          ...   C           Xi_{m+1}   0 ]
//   m    [ C                R_m        ...   0           Xi_m       0 ]
//   ...  [        ...             ...                     ...         ]
//   1    [ 0                ...    C         R_1         Xi_1       0 ]
//   H    [ 0                ...    0         h_1          0        -1 ]
//
//   R_i = [ D_i f~   D_i Phi_i ]     Xi_i = [ D_i Psi_i  ]     C = [ 0  -I ]     h_1 = [ 0  dH_1(x̄_1) ]
//         [ de_i f~  de_i Phi_i]            [ de_i Psi_i ]         [ 0   0 ]
// with D_{m+1} = I and de_{m+1} = da. No saltation matrices are needed (paper §3.4).
//
// One integration of every phase per evaluation point: r and dr are read from the same flows, and a
// second call at the same u (e.g. r first, then dr) reuses the cache (conventions §8).
//
// Given u, the m+1 segment flows are independent: with many segments (the ball-chain) they are
// integrated on several threads (set_threads), each segment by its own integrator, so r, dr and the
// counters are bitwise those of the serial loop. The threads are a small persistent team that the
// calling thread works in (src/shooting/worker_team.h); they sleep between evaluations.
//
//   TimeBasedShooting shooting(model, IntegratorOptions{});
//   Vector r; Matrix dr;
//   EvaluationStatus s = shooting.Evaluate(u, &r, &dr);
//
// A model without first integral has no ξ and H̄ columns nor first-integral rows; it is continued with one
// free parameter (shooting_layout.h). Without one its map is square (dr is N × N): an orbit at fixed
// parameters, for Newton's method (a start), not a ZeroProblem to continue.
#ifndef HYBRIDCONT_TIMEBASED_SHOOTING_H_
#define HYBRIDCONT_TIMEBASED_SHOOTING_H_

#include <memory>
#include <vector>

#include "hybridcont/flow.h"
#include "hybridcont/invariant.h"
#include "hybridcont/shooting_layout.h"
#include "hybridcont/shooting_problem.h"

namespace hybridcont {
namespace internal {
class WorkerTeam;
}
class ObservableEvaluator;

class TimeBasedShooting : public ShootingProblem {
 public:
  // Keeps a reference to model (it must outlive this object). With free parameters (shooting_layout.h,
  // "Free parameters") the map evaluates on its own copy of the model (HybridModel::Clone), on which it sets
  // the parameters from u before each evaluation; the model must then have parameter derivatives and be
  // cloneable (throws std::invalid_argument naming the model otherwise, or for a bad FreeParameters). A
  // parameter value outside its range is an evaluation failure naming it, not an exception.
  TimeBasedShooting(const HybridModel& model, IntegratorOptions options, FreeParameters free = {});
  ~TimeBasedShooting() override;
  TimeBasedShooting(TimeBasedShooting&&) noexcept;
  TimeBasedShooting& operator=(TimeBasedShooting&&) noexcept;

  int num_equations() const override { return layout_.num_equations(); }
  std::vector<std::string> unknown_names() const override { return layout_.unknown_names(); }
  EvaluationStatus Evaluate(const Vector& u, Vector* r, Matrix* dr) override;
  // From kSparseFrom unknowns on (the bordered solver's sparse threshold), dr is assembled as triplets.
  static constexpr int kSparseFrom = 150;
  bool prefers_sparse_jacobian() const override { return num_unknowns() >= kSparseFrom; }
  EvaluationStatus EvaluateSparse(const Vector& u, Vector* r, SparseMatrix* dr) override;

  const ShootingLayout& layout() const { return layout_; }
  const HybridModel& model() const { return *model_; }
  const IntegratorOptions& integrator_options() const { return options_; }

  // Fixed levels H̄_j of first integrals j = 2..k (size k-1); zero by default.
  void SetFixedLevels(const Vector& levels);
  const FreeParameters& free_parameters() const { return free_; }
  // u without the observables' entries (num_unknowns() − layout().num_observables() values) completed with
  // their values at u: a start point of a map whose observables joined the unknowns. NaN where one cannot
  // be evaluated (a correction from there then fails with the evaluation's message).
  Vector CompleteUnknowns(const Vector& u);
  // The value the i-th fixed unknown is held at (FreeParameters::fixed).
  void SetFixedValue(int i, double value);

  // Flow of segment i (0-based) at the last evaluated u (x, Phi, Psi when dr was requested).
  const PhaseFlowResult& segment_flow(int i) const {
    HYBRIDCONT_DEMAND(i >= 0 && i < static_cast<int>(flows_.size()));
    return flows_[i];
  }
  // Whether the last integration was at exactly u (same bits), succeeded, and holds the sensitivities at
  // least as exact as `jacobian_tolerance` asks (set_jacobian_tolerance): Evaluate(u, r, dr) then integrates
  // nothing and counts no evaluation, and segment_flow(i) is u's. A caller that finds the map a continuation
  // has just evaluated takes its r, dr and flows without integrating again (FloquetTestFunctions).
  bool HoldsEvaluation(const Vector& u, double jacobian_tolerance) const {
    return cache_valid_ && cached_status_.ok && cached_sensitivities_ && cached_u_.size() == u.size() &&
           cached_u_ == u && cached_jacobian_tolerance_ <= jacobian_tolerance;
  }
  // Threads integrating the segments of one evaluation, the calling thread included; 1 integrates on the
  // calling thread alone. Only as many as get the minimum number of segments below take part (waking a
  // thread costs more than it saves on fewer). Default: the machine's cores. Throws
  // std::invalid_argument for < 1.
  void set_threads(int threads);
  int threads() const { return threads_; }
  // ZeroProblem::set_jacobian_tolerance: the ξ·∇²H term of the segments' sensitivities is left out where
  // its relative size is below it. A cached evaluation serves a later request only if it was at least
  // as exact.
  //
  // Default kXiHessianTolerance, not 0: on every orbit ξ* = 0, so the term is O(|u − u*|) at an iterate,
  // the order by which dr(u) already differs from dr(u*); Newton converges quadratically without it.
  // Callers that difference dr (SB tests, branch switching) ask for 0. docs/design/shooting.md, "The ξ·∇²H
  // term".
  static constexpr double kXiHessianTolerance = 1e-8;
  void set_jacobian_tolerance(double tolerance) override { jacobian_tolerance_ = tolerance; }
  double jacobian_tolerance() const override { return jacobian_tolerance_; }
  // Segments per thread from which a thread pays for its hand-over (docs/design/shooting.md, "Segments per
  // thread"): fewer with a Jacobian, whose segments cost four times as much.
  static constexpr int kMinSegmentsPerThreadWithJacobian = 4;
  static constexpr int kMinSegmentsPerThread = 12;

  // Same model, integrator options and fixed levels; one thread (zero_problem.h).
  // The model's symmetries (ModelSymmetry) and their products, on u: states by the phases' signs;
  // durations and ξ change sign under time reversal; H̄ is invariant. None when observables joined the
  // unknowns (how an observable transforms is not declared).
  std::vector<Symmetry> symmetries() const override;
  // "H", or the first free parameter when there are any (its families are traced at fixed values).
  std::string family_parameter() const override {
    return layout_.num_free_parameters() > 0 ? layout_.unknown_names()[layout_.parameter_index(0)] : "H";
  }
  // Clone, Refined, AddWorkOf, counters(): shooting_problem.h.

 protected:
  std::unique_ptr<ShootingProblem> CopyWithTolerances(double tolerance_factor) const override;

 private:
  EvaluationStatus Integrate(const Vector& u, bool sensitivities);
  // r and the blocks of dr (eq. multishootJacobian) into a sink: dense matrix or triplets.
  template <class Sink>
  EvaluationStatus Assemble(const Vector& u, Vector* r, Sink* dr);
  // The first-integral rows (models with k > 0).
  template <class Sink>
  void AssembleFirstIntegrals(const Vector& u, Vector* r, Sink* dr);

  // Sets the free parameters of own_model_ from u; a failure when a value lies outside its range.
  EvaluationStatus SetParameters(const Vector& u);

  std::unique_ptr<HybridModel> own_model_;  // with free parameters: the copy evaluated on
  const HybridModel* model_;
  IntegratorOptions options_;
  FreeParameters free_;
  int threads_;
  std::unique_ptr<internal::WorkerTeam> team_;  // made at the first evaluation that uses it
  ShootingLayout layout_;
  Vector fixed_levels_;
  std::vector<PhaseFlow> integrators_;
  std::vector<PhaseFlowResult> flows_;
  // observables joining the unknowns: their evaluator, values and gradients at the cached point
  std::unique_ptr<ObservableEvaluator> observables_;
  Vector observable_values_;
  Matrix observable_gradients_;
  // cache of the last integrated point
  Vector cached_u_;
  bool cached_sensitivities_ = false;
  double jacobian_tolerance_ = kXiHessianTolerance;
  double cached_jacobian_tolerance_ = 0.0;
  bool cache_valid_ = false;
  EvaluationStatus cached_status_;
  // scratch
  Vector out_, H_, dp_out_, dp_H_;
  Matrix D_, dH_;
  RowVector de_;
  std::vector<Eigen::Triplet<double>> triplets_;
  Matrix block_scratch_;
};

}  // namespace hybridcont

#endif  // HYBRIDCONT_TIMEBASED_SHOOTING_H_
