// The exploration of a model's scenario, without any I/O: the engine of a study (study.h) and of the benchmarks.
//
//   ExplorationOptions options = ScenarioExplorationOptions(scenario);   // in the model's units
//   ModelExploration exploration(model, scenario, IntegratorOptions{}, options);  // validates (throws)
//   BifurcationDiagram d = exploration.Run([](const ProgressInfo&, const Vector& u) { ... });
//
// The engine works in scaled unknowns u ./ s (scaled_problem.h, Scenario::unknown_scales); bounds,
// targets and start conditions are converted on the way in and every point on the way out, so callers
// see the model's units only.
#ifndef HYBRIDCONT_STUDY_MODEL_EXPLORATION_H_
#define HYBRIDCONT_STUDY_MODEL_EXPLORATION_H_

#include <functional>
#include <memory>

#include "hybridcont/exploration.h"
#include "hybridcont/floquet_test_functions.h"
#include "hybridcont/scaled_problem.h"
#include "hybridcont/statebased_shooting.h"
#include "hybridcont/timebased_shooting.h"
#include "hybridcont/study.h"
#include "study/io/resume_store.h"
#include "study/engine/scenario.h"

namespace hybridcont::study {


// The work of the Floquet test functions (floquet_test_functions.h) of a run, summed over the copies of
// every stepper: their own maps' (multipliers, PD test) and that of their copies of the engine's problem
// (curve points inside a step, the location of BP and PD points). It is not the continuation's: as the
// Floquet map's was before the test functions moved into the continuation, it is counted on its own.
struct TestFunctionWork {
  FlowCounters counters;
  long evaluations = 0;        // map evaluations, both kinds
  long curve_evaluations = 0;  // of which of the copies of the engine's problem
  long reused_points = 0;      // branch points valued from the corrector's evaluation (none of the above)
};

// Ids of a diagram explored on its own, moved after the run's: branches by branch_offset, special points by
// point_offset (a period-doubled family's, another word's).
void RenumberDiagram(int branch_offset, int point_offset, BifurcationDiagram* d);

// A branch of an exploration (time-based formulation, with the Floquet test functions) that holds no physical
// orbit, nor one on the physical orbits' boundary (zero-duration, grazing), over an arclength of this many of
// the scenario's largest steps (Scenario::max_step: whatever step sizes a caller sets, the same length) is
// abandoned there ("abandoned: no physical orbit over an arclength of 150 ..."): the exploration's families are its
// physical ones, and on every shipped example and the bipedal model at six (k, alpha0) a branch that holds a
// physical orbit has one by its 18th point, and no physical family leaves a special point of a branch before
// that branch's first physical point (bench/README.md, "Branches without physical orbits"). The branches it
// ends are the wandering reversed-time ones that ran to max_points (600) before.
inline constexpr int kStepsWithoutPhysicalOrbit = 150;
// Sooner where every orbit of the branch after its start is one of the unfolded system only (xi != 0, class
// dissipative): no orbit of the model at all, which the unfolding leaves only where a family degenerates (the
// bipedal model's running word has such a branch, 497 points at steps of ~1e-3 before: 4 of its 5.3 s).
inline constexpr int kStepsOfUnfoldedOrbits = 30;

// Bounds, step sizes, depth and branch limits of the scenario.
ExplorationOptions ScenarioExplorationOptions(const Scenario& scenario);

class ModelExploration {
 public:
  // options are in the model's units. Throws std::invalid_argument for options that do not fit the
  // model (unknown component names, invalid values).
  // For the state-based formulation, bounds on components it lacks (durations) are dropped; the start
  // is the first physical point of the time-based scenario (the paper's singular starts with zero
  // durations are out of the state-based map's reach, Table `stateVStime`).
  // With free parameters (time-based formulation only) the map's unknowns end with them and a fixing row
  // holds the fixed unknown (shooting_layout.h, "Free parameters"); the families are explored from given
  // starts (RunFromStarts).
  ModelExploration(const HybridModel& model, const Scenario& scenario, const IntegratorOptions& integrator,
                   ExplorationOptions options, Formulation formulation = Formulation::kTimeBased,
                   FreeParameters free = {}, std::vector<std::pair<std::string, double>> monitors = {});

  using PointCallback = std::function<void(const ProgressInfo& info, const Vector& u)>;
  // Explores from the start point; on_point sees every accepted point in model units and in the layout of
  // the formulation's unknowns (ToTimeBased converts state-based points), its info.tangent in model units in
  // the time-based formulation (empty in the state-based one). A start the model declares as a
  // guess (StartSpec::Kind::kGuess) is first corrected by Newton at its H; if that fails the diagram's
  // status is kStartFailed with the corrector's message.
  BifurcationDiagram Run(const PointCallback& on_point = PointCallback());

  // Branches of an interrupted study (resume_store.h): each exploration of this object takes the branches
  // `store` holds under their ids in the study (this exploration's ids plus `offset`) instead of tracing them,
  // and stores the branches it merges. Null: none.
  void set_branch_store(ResumeStore* store, int offset = 0) { store_ = store, store_offset_ = offset; }

  // Asked before every step of every branch and before launching one (ContinuationOptions::cancel): true
  // ends the exploration with the branches traced so far (status kCancelled).
  void set_cancel(std::function<bool()> cancel) { options_.continuation.cancel = std::move(cancel); }

  // Half-branches not to trace (ExplorationOptions::known_ray) of the explorations Run, RunFromStarts and
  // RunFromPoint: asked with the switch point u and the direction v in model units (the time-based layout),
  // on the exploring thread. A study guided by a saved one's families (family_guide.h) prunes with it.
  void set_ray_filter(std::function<bool(const Vector& u, const Vector& v)> filter) { ray_filter_ = std::move(filter); }
  // The typical magnitude of each unknown (the engine's scaling, scaled_problem.h).
  const Vector& unknown_scales() const { return scaled_->scales(); }

  // The start of Run, checked before anything runs (Run does it when it was not called): a singular start
  // must be an orbit (r = 0 to SingularStartTolerance), a guess must converge under Newton at its level H.
  // False with the reason in *why, which names every part of the cycle that does not close and the unknowns
  // the start leaves unset (start_check.h). start_report() then says how far Newton moved a guess ("" when
  // it did not move it beyond the corrector's tolerance).
  bool PrepareStart(std::string* why);
  const std::string& start_report() const { return start_report_; }
  // The start PrepareStart corrected (time-based layout, model units); empty before or when it failed.
  Vector prepared_start() const { return start_prepared_ && start_failure_.empty() ? prepared_start_ : Vector(); }
  // Run explores from the orbit u (time-based layout, model units: a start found otherwise, start_carry.h)
  // instead of the scenario's start; `report` is its start_report().
  void SetStart(const Vector& u, const std::string& report) {
    start_prepared_ = true;
    prepared_start_ = u;
    start_failure_.clear();
    start_report_ = report;
  }
  // Run has no start: it ends with kStartFailed and `why`.
  void SetStartFailure(const std::string& why) {
    start_prepared_ = true;
    start_failure_ = why;
  }

  // Explores from each of `starts` (regular points, model units) in turn, one diagram: a start that lies on
  // a branch traced (or mapped) from an earlier one, or whose image under one of the problem's symmetries
  // does (with use_symmetries), is skipped (counted in *skipped): its families are already in the diagram,
  // or are images of families in it. Branch and special-point ids run on from one start's exploration to the
  // next, as on_point sees them; max_branches bounds the total. No starts, or none that converges, is
  // kStartFailed.
  BifurcationDiagram RunFromStarts(const std::vector<Vector>& starts, const PointCallback& on_point,
                                   int* skipped);

  // The family through the regular point u (model units, time-based) in the direction of `tangent` only (a
  // branch continued beyond its end), and every branch reachable from it.
  BifurcationDiagram RunFromPoint(const Vector& u, const Vector& tangent, const PointCallback& on_point);

  // The period-doubled family born at the PD point u_pd (model units, the parent's layout `parent`) of the
  // parent of this exploration's model, RepeatedModel(parent, 2) (time-based formulation):
  // ExplorePeriodDoubled on the scaled problem, points reported and returned as by Run.
  BifurcationDiagram RunPeriodDoubled(const ShootingLayout& parent, const Vector& u_pd,
                                      const PointCallback& on_point = PointCallback());

  // The time-based map (also used by the state-based formulation to find its start).
  TimeBasedShooting& shooting() { return shooting_; }
  ZeroProblem& problem();
  Formulation formulation() const { return formulation_; }
  // A point of the formulation's layout as a time-based u (identity for the time-based formulation).
  EvaluationStatus ToTimeBased(const Vector& u, Vector* u_time);
  const Vector& scales() const { return scaled_->scales(); }
  // Work of the formulation's map (RHS evaluations, map evaluations).
  // The id of a branch of d that u (model units) lies on: within the chord sag of one of its segments
  // (scaled); -1 for none.
  int BranchThrough(const BifurcationDiagram& d, const Vector& u) const;
  bool OnBranch(const BifurcationDiagram& d, const Vector& u) const { return BranchThrough(d, u) >= 0; }

  // What the Floquet test functions learnt of the orbit at the accepted point u (time-based layout, model
  // units, the exact u the point callback got): its class, replay, multipliers and residual (the point's
  // analysis then integrates nothing again). Empty where they did not evaluate that point (a mapped
  // image's, a state-based point's, a start at a singular point's).
  std::optional<FloquetTestFunctions::BranchPointAnalysis> KnownBranchPointAnalysis(const Vector& u);
  // Drops them all (after an exploration: the points of its traces are analysed).
  void ForgetBranchPointAnalyses();

  FlowCounters counters() const;
  long num_evaluations() const;
  // Work of the Floquet test functions so far (complete once Run has returned).
  TestFunctionWork test_function_work() const;

  class TestWorkSink;  // where the test functions' copies leave their work (model_exploration.cc)
  // A branch taken from the store (ExplorationOptions::recorded_branch), in the engine's units: what the test
  // functions learnt at each of its points is learnt again where it was not the point's own evaluation
  // (KnownBranchPointAnalysis then gives what it gave for the traced branch): from the map at the corrector's
  // iterate (evaluated_at), and on a mapped branch's images from their preimages (EvaluateAtImage).
  void RelearnRecordedPoints(const Branch& branch);

 private:
  // The run's options in scaled units with the callbacks converting to model units.
  ExplorationOptions EngineOptions(const PointCallback& on_point, int branch_offset = 0);
  // The diagram's points and special points from scaled to model units.
  void ToModelUnits(BifurcationDiagram* diagram) const;
  // Whether the singular start (an orbit) has branch directions under the start conditions; if not, false with
  // the kernel of dr there in *why.
  bool SingularStartHasDirections(std::string* why);
  // PrepareStart's work: checks (and corrects) the start into prepared_start_.
  bool CheckAndCorrectStart(std::string* why);
  // The first physical point of the time-based scenario, or an empty vector (message in *why).
  Vector FindPhysicalStart(std::string* why);

  const HybridModel& model_;
  Scenario scenario_;
  IntegratorOptions integrator_;
  Formulation formulation_;
  TimeBasedShooting shooting_;
  std::unique_ptr<StateBasedShooting> state_;
  std::unique_ptr<ScaledProblem> scaled_;
  ExplorationOptions options_;  // in scaled units
  std::function<bool(const Vector& u, const Vector& v)> ray_filter_;  // model units
  ExplorationOptions time_options_;  // the time-based scenario's (model units), to find a state start
  std::shared_ptr<TestWorkSink> test_work_;
  // Branches without a physical orbit over an arclength of kStepsWithoutPhysicalOrbit largest steps (or of
  // kStepsOfUnfoldedOrbits, orbits of the unfolded system only) are abandoned there (EngineOptions); off for the
  // search of a physical start (FindPhysicalStart), which walks such branches.
  bool abandon_without_physical_ = true;
  bool start_prepared_ = false;
  Vector prepared_start_;        // the time-based start (model units), a guess corrected
  std::string start_failure_;    // why the prepared start failed (empty: it did not)
  std::string start_report_;
  ResumeStore* store_ = nullptr;
  int store_offset_ = 0;
};

}  // namespace hybridcont::study

#endif  // HYBRIDCONT_STUDY_MODEL_EXPLORATION_H_
