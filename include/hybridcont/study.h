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

#include "hybridcont/exploration_status.h"
#include "hybridcont/family_ranges.h"
#include "hybridcont/model.h"
#include "hybridcont/orbit_analysis.h"
#include "hybridcont/special_point.h"
#include "hybridcont/study_options.h"

namespace hybridcont {

struct BifurcationDiagram;  // exploration.h: the engine's diagram a study keeps (StudyResult::diagram)

// The version of the library, the tool and the results folders they write.
std::string Version();

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

// One accepted point of a family, analysed.
struct StudyPoint {
  int index = 0;              // in its branch
  Vector u;                   // the branch's layout (time-based; free parameters after the orbit's unknowns)
  double T = 0;               // the period (sum of the durations)
  OrbitAnalysis analysis;     // classification, stability, multipliers, observables, replay error
  int newton_iterations = 0;
  double step = 0;
  bool at_branch_point = false;  // the branch's start at a singular point
  // dT/dc along the branch at the point, c the coordinate it is continued in (H̄ or a parameter): the period's
  // slope, from the branch's tangent (infinite at a turning point in c; NaN where the tangent is unknown).
  double period_slope = std::numeric_limits<double>::quiet_NaN();
  // The model's declared quantities at the point (model_setup.h, "quantities"; NaN where one is undefined).
  std::vector<NamedValue> quantities;
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
  int newton_iterations = 0;               // over its accepted points
  int rejected_steps = 0;
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
  bool started_in_word = false;            // a family of another word, traced from that word's own start

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
  std::string component;     // a boundary's or target's component; an EX point's observable
  // An EX point (options.extrema): +1 where `component` is largest along the family (it rises, then falls, along
  // the branch), -1 where smallest; 0 for every other type.
  int extremum = 0;
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
// (a, p), a the coordinate the study's families are continued in (H̄; with `free`, that parameter at the fixed
// unknown, e.g. k at H̄ = 1.5; without first integral, the model's run parameter) — a fold, a branch point, a
// period doubling or Neimark–Sacker point (the zero of its Floquet test function) — or a boundary of the
// physical families (a duration or a constraint at 0).
struct StudyCurve {
  int id = 0;
  std::string type;         // "fold", "branch-point", "period-doubling", "neimark-sacker", "boundary"
  std::string name;         // a boundary's quantity at 0 ("t2 = 0"); empty otherwise
  int special_point = -1;   // the special point it is continued from (-1 for a boundary)
  std::string status;       // "traced", "start-failed"
  std::string message;      // why it was not traced (or stopped early); may be empty
  // How each end of it stopped (TerminationReason as text): backward, forward; empty for a boundary.
  std::vector<std::string> termination;
  // The codimension-two points found along it: a curve's own folds and branch points, a bracketed end where it
  // leaves the physical region (special_point_curve.h, CodimTwoPoint).
  struct CodimTwo {
    std::string type, name, status;
    double a = 0, p = 0;  // a: the families' coordinate (columns.front()), p: the curves' parameter
    bool operator==(const CodimTwo&) const = default;
  };
  std::vector<CodimTwo> codim_two;
  std::vector<std::string> columns;  // a ("H" or the free parameter), p, then the curve's other unknowns
  std::vector<Vector> points;        // in curve order, each in `columns` order
};

// A region of the plane of a study's curves (options.curves = p): where a family is physical or stable, between
// the curves (or the bound) that end its range at the run's p, over the p both cover.
struct StudyRegion {
  std::string family;
  std::string kind;   // "physical" or "stable"
  int branch = -1;    // the branch whose range it extends
  std::vector<std::pair<double, double>> polygon;  // (p, a) vertices in order, a the families' coordinate
  bool operator==(const StudyRegion&) const = default;
};

// A change of an automaton's phase sequence the study considered (word_change.h): where a physical family of
// a word reached a zero duration, touched a competing guard's surface or ended; the rule that builds the new
// word, accepted or refused with the reason, and the branches it leads to (summary.json's "word_changes").
struct StudyWordChange {
  std::vector<std::string> from_word;  // the modes of the word the family belongs to
  int from_branch = -1;
  std::string at;                      // "t2 = 0", "guard of <transition> touched", "end of a physical family (...)"
  double H = std::numeric_limits<double>::quiet_NaN();  // NaN without a first integral
  // Where an end was only bracketed: the last physical point's H̄ and the first beyond; NaN otherwise.
  double H_physical = std::numeric_limits<double>::quiet_NaN(), H_beyond = std::numeric_limits<double>::quiet_NaN();
  std::string detail;                  // what the first point beyond an end is
  std::string rule;                    // the rule that builds the new word; empty where none was offered
  std::vector<std::string> to_word;    // the new word's modes (with a rule)
  double residual = std::numeric_limits<double>::quiet_NaN();           // the orbit as an orbit of the new word
  double state_difference = std::numeric_limits<double>::quiet_NaN();   // the new word's orbit against the old:
  double period_difference = std::numeric_limits<double>::quiet_NaN();  //   state at the section, period
  bool accepted = false;
  std::string reason;                  // why it was refused, or why an accepted change was not followed
  std::vector<int> to_branches;        // the branches it leads to (explored there, or traced before)
  bool operator==(const StudyWordChange&) const = default;
};

// A word of an automaton the study explored, with its branches (summary.json's "words").
struct StudyWord {
  std::string name;                 // HybridAutomaton::WordName
  std::vector<std::string> modes;
  std::vector<int> branches;
  bool operator==(const StudyWord&) const = default;
};

// How a study in a free parameter found its starts (options.free with fix): the physical families' crossings of
// the fixed value in the ordinary run (summary.json's "starts").
struct StudyParameterStarts {
  int crossings = 0;               // crossings found
  int distinct = 0;                // distinct orbits among them
  int on_traced_branches = 0;      // starts that lay on branches traced from earlier ones
  int ordinary_half_branches = 0;  // half-branches of the ordinary run searched
  bool operator==(const StudyParameterStarts&) const = default;
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

// The file of branch `id` in a results folder (docs/results-format.md): "branch-<id>.csv".
std::string BranchFileName(int id);

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
  // How the study found its start where the caller's parameters needed more than the model's start: "start
  // carried from the model's own k = 25.48 to 30 at H = 1.04 (12 continuation steps)"; empty otherwise.
  std::string start_note;
  // Non-empty when a file of out_dir could not be written (a full disk): the folder keeps what was written,
  // marked as not complete; the result holds the whole study.
  std::string write_error;
  std::vector<StudyWord> words;                 // an automaton's words explored (the study's own first)
  std::vector<StudyWordChange> word_changes;    // every change of word considered; index: handed_over_from
  std::optional<StudyParameterStarts> parameter_starts;  // a study in a free parameter
  std::vector<StudyOrbit> orbits;    // key frames
  std::string curve_parameter;       // p of the curves (options.curves); empty without
  std::vector<StudyCurve> curves;    // id == index
  // Where each family is physical and where stable in the plane of the curves: ParameterRegions (derived from
  // branches and curves, like families).
  std::vector<StudyRegion> regions;
  StudyWork work;
  // The whole saved document (summary.json, docs/results-format.md): beside the typed fields above, the
  // effective options and the model's presentation.
  std::string summary_json;
  // The exploration of the study's own families as the engine gives it (time-based layout, model units): every
  // branch's ContinuationPoint and SpecialPoint with tangents, interval widths and test values, the branch
  // switches and the start's analysis (include exploration.h to read it). Not saved, so not read back by
  // LoadStudy (null there).
  std::shared_ptr<const BifurcationDiagram> diagram;

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
  // How the notes say the options they mention (study_options.h, SayOptions): the command line's flags,
  // Python's keywords; unset: by field.
  std::function<std::string(const std::string& field)> option_words;
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
// study would say (bound widened to a target, no bound), the options they mention said in `words`.
std::vector<std::string> CheckStudyOptions(const StudyOptions& options,
                                           const std::function<std::string(const std::string& field)>& words = {});

// The study saved in a results folder (docs/results-format.md; a folder of an interrupted study too): its
// branches with their analysed points, special points, families, curves and key-frame orbits with their
// samples, the record of its model. Not read back: the engine's diagram (tangents, interval widths, test
// values: StudyResult::diagram is empty). Throws std::invalid_argument naming the file, line and field for a
// folder that is not a saved study.
StudyResult LoadStudy(const std::string& dir);

}  // namespace hybridcont

#endif  // HYBRIDCONT_STUDY_H_
