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
// second call at the same u (e.g. r first, then dr) reuses the cache (STYLE.md practice 8).
//
// Given u, the m+1 segment flows are independent: with many segments (the ball-chain) they are
// integrated on several threads (set_threads), each segment by its own integrator, so r, dr and the
// counters are bitwise those of the serial loop. The threads are a small persistent team that the
// calling thread works in (src/shooting/worker_team.h); they sleep between evaluations.
//
//   TimeBasedShooting shooting(model, IntegratorOptions{});
//   Vector r; Matrix dr;
//   EvaluationStatus s = shooting.Evaluate(u, &r, &dr);
#ifndef HYBRIDCONT_TIMEBASED_SHOOTING_H_
#define HYBRIDCONT_TIMEBASED_SHOOTING_H_

#include <memory>
#include <vector>

#include "hybridcont/flow.h"
#include "hybridcont/shooting_layout.h"
#include "hybridcont/shooting_problem.h"

namespace hybridcont {
namespace internal {
class WorkerTeam;
}

class TimeBasedShooting : public ShootingProblem {
 public:
  // Keeps a reference to model (it must outlive this object).
  TimeBasedShooting(const HybridModel& model, IntegratorOptions options);
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

  // Flow of segment i (0-based) at the last evaluated u (x, Phi, Psi when dr was requested).
  const PhaseFlowResult& segment_flow(int i) const { return flows_[i]; }
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
  // Default kXiHessianTolerance, not 0. Every orbit has ξ* = 0, so at an iterate u the term, ~|ξ|·|∇²H|,
  // is O(|u − u*|): the order by which dr(u) already differs from dr(u*). Newton without it converges
  // quadratically all the same, and the dr of an accepted point (at most max_jacobian_distance =
  // 1e-8·(1 + ||u||) from the solution, corrector.h) errs by ~1e-8 with or without it. Sizable ξ (the
  // at-rest ξ-branches, derivative checks) keeps it. The SB test functions of the root finder, branch
  // switching and the analysis of singular starts (finite differences of dr) ask for 0: with 1e-8 in the
  // SB tests, located SB points of the SLIP moved by up to 4e-12 in H.
  // Measured on the SLIP's complete diagram: the Hessian jets were 17% of the profile; 232 -> 192 ms.
  static constexpr double kXiHessianTolerance = 1e-8;
  void set_jacobian_tolerance(double tolerance) override { jacobian_tolerance_ = tolerance; }
  double jacobian_tolerance() const override { return jacobian_tolerance_; }
  // Segments per thread from which a thread pays. Ball-chain on 2 idle cores, 2 threads against 1: r and
  // dr (a segment ~8 us) x1.19 at 8 segments, x1.34 at 16, x1.67 from 64; r alone (~2 us) x0.72 at 16
  // segments, x1.09 at 24, x1.65 from 128.
  static constexpr int kMinSegmentsPerThreadWithJacobian = 4;
  static constexpr int kMinSegmentsPerThread = 12;

  // Same model, integrator options and fixed levels; one thread (zero_problem.h).
  // The model's symmetries (ModelSymmetry) and their products, on u: states by the phases' signs;
  // durations and ξ change sign under time reversal; H̄ is invariant.
  std::vector<Symmetry> symmetries() const override;
  // Clone, Refined, AddWorkOf, counters(): shooting_problem.h.

 protected:
  std::unique_ptr<ShootingProblem> CopyWithTolerances(double tolerance_factor) const override;

 private:
  EvaluationStatus Integrate(const Vector& u, bool sensitivities);
  // r and the blocks of dr (eq. multishootJacobian) into a sink: dense matrix or triplets.
  template <class Sink>
  EvaluationStatus Assemble(const Vector& u, Vector* r, Sink* dr);

  const HybridModel* model_;
  IntegratorOptions options_;
  int threads_;
  std::unique_ptr<internal::WorkerTeam> team_;  // made at the first evaluation that uses it
  ShootingLayout layout_;
  Vector fixed_levels_;
  std::vector<PhaseFlow> integrators_;
  std::vector<PhaseFlowResult> flows_;
  // cache of the last integrated point
  Vector cached_u_;
  bool cached_sensitivities_ = false;
  double jacobian_tolerance_ = kXiHessianTolerance;
  double cached_jacobian_tolerance_ = 0.0;
  bool cache_valid_ = false;
  EvaluationStatus cached_status_;
  // scratch
  Vector out_, H_;
  Matrix D_, dH_;
  RowVector de_;
  std::vector<Eigen::Triplet<double>> triplets_;
  Matrix block_scratch_;
};

}  // namespace hybridcont

#endif  // HYBRIDCONT_TIMEBASED_SHOOTING_H_
