// A study: the whole of what `hybridcont run MODEL` does, as one library call — the model's families
// explored from its declared start (or from given starts, or from a labelled point of a saved study), every
// accepted point analysed (classification, stability, multipliers, observables, replays), the period-doubled
// families, the families of neighbouring words of an automaton, two-parameter curves, key-frame orbits and
// the ranges where each family is physical and stable. The command line, the Python package and a sweep
// worker all call this; none of them re-implements a step of it.
//
//   StudyOptions options;                 // plain data: copy it, send it to another process
//   options.model = "slip";
//   options.until = {{"H", 1.6}};
//   options.out_dir = "results/slip";     // optional: the results folder (docs/results-format.md), written as
//                                         // it grows; options.resume continues one that was interrupted
//   StudyHooks hooks;                     // kept apart from the options: callbacks of this process
//   hooks.on_point = [](const StudyPoint& p, const StudyBranch& b) { ... };
//   StudyResult study = RunStudy(options, hooks);
//   for (const StudyBranch& b : study.branches) ... b.family, b.ranges, b.points[i].analysis.stability
//
// Contracts:
//  - Options are validated before anything is computed or written; a value the study refuses throws
//    StudyOptionError naming the field ("until[0] 'H=5': ..."), a bad model throws ModelInputError (file,
//    line, field) — both std::invalid_argument. Nothing is written then.
//  - A numerical failure is a status (StudyResult::status, message), never an exception; the work so far is
//    kept (and, with out_dir, saved).
//  - The result owns everything it holds (no reference to a model or map outlives the call).
//  - One thread unless options.threads says otherwise; the result does not depend on the thread count.
//  - A stop request (hooks.stop_requested) ends the study after the current step: status kCancelled, the
//    branches traced so far in the result and the folder.
#ifndef HYBRIDCONT_STUDY_H_
#define HYBRIDCONT_STUDY_H_

#include <functional>
#include <iosfwd>
#include <limits>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "hybridcont/continuation.h"
#include "hybridcont/exploration.h"
#include "hybridcont/family_ranges.h"
#include "hybridcont/model.h"
#include "hybridcont/orbit_analysis.h"
#include "hybridcont/special_point.h"

namespace hybridcont {

// The version of the library, the tool and the results folders they write.
std::string Version();

struct NamedValue {
  std::string name;
  double value = 0;
};
struct NamedInterval {
  std::string name;
  double lower = -std::numeric_limits<double>::infinity();
  double upper = std::numeric_limits<double>::infinity();
};

// Time-based multiple shooting (the default) or the state-based Poincaré map.
enum class Formulation { kTimeBased, kStateBased };
std::string ToString(Formulation f);
// "time" / "state"; false for anything else.
bool FromString(const std::string& text, Formulation* f);

// Where a restarted study begins: a labelled point of a saved study (docs/results-format.md, "Labels").
//   label "PD4"  (a special point: its code and id)  — kind kPeriodDoubled: the period-doubled family born there;
//                                                      kind kSwitch: every branch through the SB/BP point;
//                                                      kind kCurve: the point continued in (H, curve_parameter);
//   label "B5"   (a branch: its last point)          — kind kContinue: the branch continued beyond its end;
//   label "B5:12" (point 12 of branch 5)             — kind kContinue (both directions) or kFree (--free P).
// kAuto picks what the label's type implies: PD → kPeriodDoubled, SB/BP → kSwitch, TP → kCurve (with
// curves set), a branch or point → kContinue (kFree with free set).
// The study restarted from is a saved one (`from`, its folder) or one in memory (`study`, e.g. the result of
// an earlier RunStudy: no folder needed on either side). The restart's record (summary.json's restarted_from)
// names the folder, or "(a study in memory)".
struct StudyResult;
struct RestartSpec {
  enum class Kind { kAuto, kContinue, kSwitch, kPeriodDoubled, kCurve, kFree };
  std::string from;  // the saved study's folder (read when `study` is null)
  std::string label;
  Kind kind = Kind::kAuto;
  std::shared_ptr<const StudyResult> study;  // a study in memory; `from` is not read then
  // The study restarted from, as a label's message names it: the folder, or "(a study in memory)".
  std::string Source() const { return study ? std::string("(a study in memory)") : from; }
};
std::string ToString(RestartSpec::Kind kind);

// Which model a study was computed on, recorded in its result and its folder ("model_source") so that a
// study read back later draws and evaluates exactly that model, or says why it cannot (ModelOfStudy).
struct StudyModelSource {
  enum class Kind {
    kBuiltin,  // a built-in model, by name
    kFile,     // a model file: its absolute path and the SHA-256 of its text
    kText,     // model-file text (Python's hc.model(text=...), ModelBuilder): the text and its SHA-256
    kCaller,   // a model the caller built in C++ (RunStudy(model, ...)) without text: not rebuildable
    kName,     // a folder written before the record existed: rebuilt by its name, as then
  };
  Kind kind = Kind::kBuiltin;
  std::string name;    // the model's name (HybridModel::name)
  std::string path;    // kFile
  std::string sha256;  // kFile, kText: hex
  std::string text;    // kText
};
std::string ToString(StudyModelSource::Kind kind);
bool FromString(const std::string& text, StudyModelSource::Kind* kind);

// Everything `hybridcont run` accepts, as plain data (no callbacks): copyable, comparable field by field,
// and written into summary.json as the study's effective options.
struct StudyOptions {
  // A built-in model's name or a model file (.toml); a relative file name that does not exist is looked up in
  // models_directory.
  std::string model;
  std::string models_directory;
  // Model-file text: the study's model is made of it (`model` then only names it), or, with a caller's model
  // (RunStudy(model, options)), the text that model was made of. Recorded in the result (StudyModelSource
  // kText) so that its folder rebuilds the model, and part of the resume key. With a caller's model and no
  // text, `model` may name the built-in model or model file it was made from (recorded as such where the
  // model made from there has its name; otherwise it is the caller's own, kCaller).
  std::string model_text;
  std::vector<NamedValue> parameters;  // model parameters set before the study (each name once)
  std::vector<NamedValue> until;       // each branch ends exactly where an unknown or observable reaches the value
  std::vector<NamedInterval> bounds;   // replace the model's bound on an unknown ("period": sum of durations)
  std::vector<NamedValue> monitors;    // observables whose values are located (UZ points)
  std::optional<double> rtol, atol;    // integrator tolerances (unset: the library's 1e-10)
  std::optional<int> max_branches;     // half-branches traced at most (unset: the model's scenario)
  int threads = 1;                     // half-branches traced concurrently
  Formulation formulation = Formulation::kTimeBased;
  bool use_symmetries = true;          // map half-branches that are images under the model's symmetries
  bool follow_word_changes = true;     // an automaton: explore the words its families lead into
  bool period_doubling = false;        // explore the period-doubled family of every located PD point
  std::string free;                    // a parameter continued as an unknown instead of H
  std::optional<NamedValue> fix;       // the unknown held fixed while `free` varies (H=1.5, t2=0, speed=1)
  std::string curves;                  // a parameter: special points continued in (H, it) after the run
  std::optional<RestartSpec> restart;  // begin at a labelled point of a saved study instead of the model's start
  // A saved study of the same model at nearby parameter values (a sweep's neighbouring grid point): trace only
  // the half-branches whose counterpart there led to a family; the others, which found no physical orbit
  // there, are not traced (src/study/stages/family_guide.h says how counterparts are matched). The saved study's
  // families are continued to these parameter values without repeating its whole exploration. Empty: the
  // whole exploration. summary.json's "guided" says what was pruned.
  std::string families_of;
  // The model's start (a guess Newton must correct, a singular start that must be an orbit) failing is bad input
  // (true: ModelInputError before anything runs — the model file's start is wrong where it was written) or the
  // study's status (false: status start-failed for the families from it, the model's starts in other words still
  // explored — a sweep's grid point far from where the start was written).
  bool start_must_converge = true;
  // With families_of: only the half-branches that led to these of its families (by name, as its branches are
  // named) are traced. Empty: every family.
  std::vector<std::string> families;
  // The results folder (docs/results-format.md), written as the study grows; empty: nothing is written.
  std::string out_dir;
  bool overwrite = false;  // replace another model's results in out_dir (refused otherwise)
  // Continue the study saved (possibly interrupted) in out_dir (src/study/io/resume_store.h): branches traced there are taken as they
  // are, the rest computed. The options must be those of the saved study.
  bool resume = false;
};

// A value of StudyOptions the study refuses. field() is the member's name ("until", "bounds", "fix"), index()
// the entry of a list (-1 otherwise); what() begins with both, e.g. "until[0] 'H=5': ...".
class StudyOptionError : public std::invalid_argument {
 public:
  StudyOptionError(std::string field, int index, const std::string& message);
  const std::string& field() const { return field_; }
  int index() const { return index_; }
  // The message without its leading field, e.g. "'H=5': ...".
  const std::string& detail() const { return detail_; }

 private:
  std::string field_;
  int index_;
  std::string detail_;
};

// One accepted point of a family, analysed.
struct StudyPoint {
  int index = 0;              // in its branch
  Vector u;                   // the branch's layout (time-based; free parameters after the orbit's unknowns)
  double T = 0;               // the period (sum of the durations)
  OrbitAnalysis analysis;     // classification, stability, multipliers, observables, replay error
  int newton_iterations = 0;
  double step = 0;
  bool at_branch_point = false;  // the branch's start at a singular point
};

// One half-branch of the study, with what the study knows about it.
struct StudyBranch {
  int id = 0;
  std::string model;                       // the model its points are orbits of (a period-doubled family's)
  // "" for the study's own families; "period-doubled" for a period-doubled family; an automaton's word name
  // for a family of another word.
  std::string origin;
  std::vector<std::string> unknown_names;  // the layout of u
  std::string continued;                   // the coordinate its family is continued in (H or a parameter)
  std::vector<std::string> word;           // an automaton's word (its modes); empty otherwise
  int direction = +1;
  int parent_special_point = -1;
  int depth = 0;
  int image_of = -1;
  std::string symmetry;
  int reflected_from = -1;
  std::string termination;                 // TerminationReason as text; "running" while it is traced
  std::string message;
  std::vector<StudyPoint> points;
  // Named by the model's family rules at the middle of its first physical stretch; empty without physical
  // orbits.
  std::string family;
  BranchRanges ranges;                     // where its orbits are physical and stable (family_ranges.h)
  int period_doubled_from = -1;            // the PD point a period-doubled family is born at
  int handed_over_from = -1;               // the word change it begins at (StudyResult::word_changes)

  // Whether a special point after point `index` lies on (or at an end of) one of its physical stretches.
  bool OnPhysicalStretch(int index) const;
};

// A located (or bracketed) special point of the study, in the layout of its branch.
struct StudySpecialPoint {
  int id = 0;
  SpecialPointType type = SpecialPointType::kTurningPoint;
  std::string code;          // "TP", "SB", "PD", ... (special_point.h, Code)
  int branch = -1;
  int index = 0;             // the branch point after which it lies
  double H = 0, T = 0;       // NaN where the model has no first integral
  std::string status;        // LocationStatus as text
  double precision = 0;      // width of the interval holding it (model units)
  double precision_arclength = 0;  // the same interval along the branch, in the engine's scaled arclength
  double precision_H = 0;          // its width in H̄ (NaN without a first integral or widths)
  double residual = 0;
  std::string component;     // a boundary's or target's component
  int duplicate_of = -1;
  std::string message;
  Vector u;
  std::vector<std::string> word;   // an automaton's word; empty otherwise
  int period_doubled_from = -1;
  // The free parameters and observables among the unknowns at the point, by name (also in u).
  std::vector<NamedValue> named_unknowns;
  // The model's observables and constraints at the point (observable.h; NaN where one is undefined). Empty where
  // they were not evaluated (a model without observables, a period-doubled family's point).
  std::vector<NamedValue> observables;
  // The label of a restart (RestartSpec::label): code and id, "PD4".
  std::string Label() const { return code + std::to_string(id); }
};

// A sampled orbit drawn as a key frame.
struct StudyOrbit {
  int branch = -1, index = 0;
  std::string family;
  double H = 0, T = 0;
  std::vector<double> t;               // sample times
  std::vector<int> segment;            // 0-based segment of each sample
  std::vector<Vector> x;               // the state at each sample
  // Φ_T, the monodromy matrix of the orbit at the start of its first phase (floquet.h); empty where it
  // could not be computed.
  Matrix monodromy;
};

// A two-parameter curve of the study (options.curves = p): a special point of a physical family continued in
// (H̄, p) — a fold, a branch point, a period doubling or Neimark–Sacker point (the zero of its Floquet test
// function) — or a boundary of the physical families (a duration or a constraint at 0).
struct StudyCurve {
  int id = 0;
  std::string type;         // "fold", "branch-point", "period-doubling", "neimark-sacker", "boundary"
  std::string name;         // a boundary's quantity at 0 ("t2 = 0"); empty otherwise
  int special_point = -1;   // the special point it is continued from (-1 for a boundary)
  std::string status;       // "traced", "start-failed"
  std::vector<std::string> columns;  // "H", p, then the curve's other unknowns
  std::vector<Vector> points;        // in curve order, each in `columns` order
};

// A stretch of the continued coordinate: from <= to, each end said as the answer says it — a special point's
// label ("PD4"; ", not located" where it was only bracketed) or how the end is known ("end of the branch,
// bound-reached").
struct FamilyInterval {
  double from = 0, to = 0;
  std::string from_end, to_end;
  bool operator==(const FamilyInterval&) const = default;
};

// One family of the study, over every branch that holds its orbits (both directions from a start, the images
// under symmetries, families reached by switching, restarts, period doubling, other words): where its orbits
// are physical and where stable, as the union of its branches' ranges. Disjoint stretches stay disjoint.
struct StudyFamily {
  std::string name;                      // as the model's family rules name it (StudyBranch::family)
  std::string continued;                 // the coordinate of its intervals (H or a free parameter)
  std::vector<int> branches;             // the branches with a stretch of it, ascending
  std::vector<FamilyInterval> physical;  // ascending, disjoint
  std::vector<FamilyInterval> stable;    // ascending, disjoint
  std::vector<std::string> special_points;  // labels of the located special points on its physical stretches
  bool operator==(const StudyFamily&) const = default;  // exact: a study and the same study read back agree
};

// The families of a study's branches, in the order they are first met (StudyBranch::ranges, each range's
// family). The one fold of ranges that every front end shows.
std::vector<StudyFamily> FoldFamilies(const std::vector<StudyBranch>& branches,
                                      const std::vector<StudySpecialPoint>& special_points);

struct StudyWork {
  long rhs_evaluations = 0;          // the continuation's
  long map_evaluations = 0;
  long analysis_rhs_evaluations = 0; // Floquet multipliers of the accepted points
  long analysis_map_evaluations = 0;
  long test_rhs_evaluations = 0;     // Floquet test functions
  long test_map_evaluations = 0;
  double wall_seconds = 0;
  int resumed_branches = 0;          // taken from an interrupted study (resume)
};

struct StudyResult {
  std::string version;               // of the library that computed (or wrote) it
  std::string model;
  StudyModelSource model_source;       // which model it is (ModelOfStudy rebuilds it)
  std::vector<NamedValue> parameters;  // the model's parameter values
  std::vector<std::string> unknown_names;
  std::vector<StudyBranch> branches;   // id == index
  std::vector<StudySpecialPoint> special_points;  // id == index
  std::vector<StudyFamily> families;   // FoldFamilies(branches, special_points)
  ExplorationStatus status = ExplorationStatus::kCompleted;
  std::string message;               // why it did not complete
  std::string report;                // the study's report in words
  // Non-empty when a file of out_dir could not be written (a full disk): the folder keeps what was written,
  // marked as not complete; the result holds the whole study.
  std::string write_error;
  std::vector<StudyOrbit> orbits;    // key frames
  std::string curve_parameter;       // p of the curves (options.curves); empty without
  std::vector<StudyCurve> curves;    // id == index
  StudyWork work;
  // The whole saved document (summary.json, docs/results-format.md): the effective options, word changes
  // ("word_changes", "words"), curves ("curves"), starts, presentation. The typed fields above are read from
  // it and the point tables.
  std::string summary_json;
  // The exploration of the study's own families as the engine gives it (time-based layout, model units): every
  // branch's ContinuationPoint and SpecialPoint with tangents, interval widths and test values, the branch
  // switches and the start's analysis. Not saved, so not read back by LoadStudy (empty there).
  BifurcationDiagram diagram;

  // The special point with this label ("PD4"), or null.
  const StudySpecialPoint* FindSpecialPoint(const std::string& label) const;
  // Index out of range: std::out_of_range.
  const StudyBranch& branch(int id) const;
};

struct StudyProgress {
  std::string stage;    // "start", "exploration", "period-doubled families", "words", "curves", "key frames"
  int branches = 0;     // half-branches begun so far
  int points = 0;       // accepted points so far
  std::string message;  // what begins, in words ("word stance > flight from t2 = 0:"); may be empty
};

// Callbacks of the calling process, kept apart from the options. Called on the calling thread, in the
// serial order of the study (whatever options.threads); stop_requested may be called from worker threads.
struct StudyHooks {
  // Each accepted point, analysed, of branch `branch` (the id it has in the result; its summary so far, without
  // its points: they come one by one).
  std::function<void(const StudyPoint& point, const StudyBranch& branch)> on_point;
  // Each finished branch.
  std::function<void(const StudyBranch& branch)> on_branch;
  // Stage changes and counts.
  std::function<void(const StudyProgress& progress)> on_progress;
  // Messages the study says before it runs (what it changed that the caller did not write) and as it goes
  // (how far Newton moved a start, a model file compiled); one line each.
  std::function<void(const std::string& line)> on_note;
  // True ends the study at the next step (status kCancelled).
  std::function<bool()> stop_requested;
};

// The model a study of `model` runs on (StudyOptions::model, parameters, models_directory): a built-in model, a
// model file, or a shipped model file by its name alone ("compass-gait" for <models_directory>/compass-gait.toml,
// where no built-in model has that name), compiled unless `compile` is false (then interpreted); notes on
// compiling go to `log`.
// Throws as RunStudy does.
HybridModel MakeStudyModel(const std::string& model, const std::vector<NamedValue>& parameters = {},
                           const std::string& models_directory = "", std::ostream* log = nullptr,
                           bool compile = true);
// Where MakeStudyModel finds `model`: a built-in model, or a model file (its absolute path; sha256 is left
// empty: the study takes the digest of the file it has read, so that nothing else is ever read).
StudyModelSource FindStudyModel(const std::string& model, const std::string& models_directory = "");

// The model a study was computed on, rebuilt from its record (StudyResult::model_source) at the study's
// parameter values: the built-in model; the model file, if it is still there with the same text; the model
// text. Throws std::invalid_argument saying why it cannot (the file is gone or has changed since; a model the
// caller built) — never another model of the same name. `models_directory` serves folders written before the
// record existed (rebuilt by name).
HybridModel ModelOfStudy(const StudyResult& study, const std::string& models_directory = "", std::ostream* log = nullptr);

// Validates the options (throws StudyOptionError / ModelInputError), prepares out_dir, runs the study.
StudyResult RunStudy(const StudyOptions& options, const StudyHooks& hooks = {});
// The study of a model the caller built (a model of its own, a clone with edited parameters): run on a copy,
// so `model` need not outlive the call; options.parameters are set on the copy, and options.model, when set,
// names what the model was made from (StudyOptions::model_text says how it is recorded).
StudyResult RunStudy(const HybridModel& model, const StudyOptions& options, const StudyHooks& hooks = {});

// Validates the options against the model without computing or writing anything; returns the notes the
// study would say (bound widened to a target, no bound).
std::vector<std::string> CheckStudyOptions(const StudyOptions& options);

// The study saved in a results folder (docs/results-format.md; a folder of an interrupted study too): its
// branches with their analysed points, special points, families, curves and key-frame orbits with their
// samples, the record of its model. Not read back: the engine's diagram (tangents, interval widths, test
// values: StudyResult::diagram is empty). Throws std::invalid_argument naming the file, line and field for a
// folder that is not a saved study.
StudyResult LoadStudy(const std::string& dir);

}  // namespace hybridcont

#endif  // HYBRIDCONT_STUDY_H_
