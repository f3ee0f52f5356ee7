// A study's options: what decides its results and how and where it runs (StudyOptions, plain data), and their
// declaration — every option once, with its command-line flag, Python keyword, kind, role and help
// (StudyOptionSpecs). The command line registers its flags from the declaration, Python checks and converts its
// keyword arguments by it, a sweep builds its command line from it, and the resume key is the options whose role
// is kResult (with the model's identity). A new option is one entry of the declaration (src/study/study_options.cc)
// and one member here; no front end lists it again.
//
// Messages about options (StudyOptionError, the study's notes) name the options they mention by field, marked
// (MentionOption), so that each front end says them in its own words: the command line "--fix", Python "fix".
//
//   StudyOptions o;
//   SetStudyOption(&o, "until", ParseStudyOption(*FindStudyOption("until"), {"H=2"}));   // as --until H=2
//   SetStudyOption(&o, "parameters", std::vector<NamedValue>{{"k", 60}});                   // as set={"k": 60}
#ifndef HYBRIDCONT_STUDY_OPTIONS_H_
#define HYBRIDCONT_STUDY_OPTIONS_H_

#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <variant>
#include <vector>

namespace hybridcont {

struct NamedValue {
  std::string name;
  double value = 0;
  bool operator==(const NamedValue&) const = default;
};
struct NamedInterval {
  std::string name;
  double lower = -std::numeric_limits<double>::infinity();
  double upper = std::numeric_limits<double>::infinity();
  bool operator==(const NamedInterval&) const = default;
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

// Everything `hybridcont run` accepts, as plain data (no callbacks): copyable, comparable field by field,
// and written into summary.json as the study's effective options. The members before "how and where it runs"
// decide the results (with the model's identity they are the resume key); the others do not.
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
  std::vector<std::string> extrema;    // observables whose largest and smallest values along each family are located (EX)
  std::optional<double> rtol, atol;    // integrator tolerances (unset: the library's 1e-10)
  std::optional<int> max_branches;     // half-branches traced at most (unset: the model's scenario)
  Formulation formulation = Formulation::kTimeBased;
  bool use_symmetries = true;          // map half-branches that are images under the model's symmetries
  bool follow_word_changes = true;     // an automaton: explore the words its families lead into
  bool period_doubling = false;        // explore the period-doubled family of every located PD point
  std::string free;                    // a parameter continued as an unknown instead of H
  std::optional<NamedValue> fix;       // the unknown held fixed while `free` varies (H=1.5, t2=0, speed=1)
  std::string curves;                  // a parameter: special points continued in (H or `free`, it) after the run
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
  // ---- how and where it runs: not part of the results
  int threads = 1;                     // half-branches traced concurrently (the results do not depend on it)
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
  // The message without its leading field, e.g. "'H=5': ...", its mentions of options said by field.
  const std::string& detail() const { return detail_; }
  // The message with the field and the options it mentions in a front end's words (`words` of a field: the
  // command line's flag, Python's keyword), without the index: "--until 'H=5': ...".
  std::string Say(const std::function<std::string(const std::string& field)>& words) const;

 private:
  std::string field_;
  int index_;
  std::string detail_;  // with its mentions marked
};


// ---- the declaration

// How an option's value is written, as text (the command line) and in Python.
enum class OptionKind {
  kText,         // a word or a path: "k", "results/slip"                        Python: str
  kNumber,       // a finite number (unset: the library's default)                 float or None
  kCount,        // a whole number (unset: the default)                            int or None
  kSwitch,       // on or off: a flag on the command line                          bool
  kChoice,       // one of `choices`                                               str
  kValues,       // NAME=VALUE, repeatable                                         {name: value} or [(name, value)]
  kValueLists,   // NAME=V1,V2,..., repeatable                                     {name: value or [values]}
  kValue,        // one NAME=VALUE (unset: none)                                   {name: value} or (name, value)
  kIntervals,    // NAME=LOWER:UPPER, repeatable; an empty end is unbounded         {name: (lower, upper)}, None open
  kTexts,        // words, repeatable                                              [str] or str
};
// What an option decides: the study's results (part of the resume key), or how and where it runs.
enum class OptionRole { kResult, kRunSetting };

// A value of an option: the alternative its kind holds — std::monostate (unset), bool (kSwitch), int (kCount),
// double (kNumber), std::string (kText, kChoice), std::vector<std::string> (kTexts), std::vector<NamedValue>
// (kValues, kValueLists — one entry per value —, kValue — at most one entry), std::vector<NamedInterval>
// (kIntervals).
using StudyOptionValue = std::variant<std::monostate, bool, int, double, std::string, std::vector<std::string>,
                                      std::vector<NamedValue>, std::vector<NamedInterval>>;

struct StudyOptionSpec {
  std::string field;       // its name in the library's messages and records: a StudyOptions member ("until"),
                           // or a restart's part ("restart.from", "restart.label", "restart.kind")
  std::string flag;        // the command line's: "--until"; "" for the positional model
  std::string keyword;     // Python's keyword argument: "until"
  OptionKind kind = OptionKind::kText;
  OptionRole role = OptionRole::kResult;
  std::string value_name;  // what the value looks like: "NAME=VALUE", "PARAMETER"
  std::string help;        // one paragraph; the options it mentions are marked (MentionOption)
  std::vector<std::string> choices;  // kChoice
  bool sweep = false;      // also an option of `hybridcont sweep`, applied at every grid point
  bool negated = false;    // the flag or keyword turns the member off (--no-symmetry: use_symmetries = false)
  std::function<StudyOptionValue(const StudyOptions&)> get;       // the flag's sense (negated applied)
  std::function<void(StudyOptions*, const StudyOptionValue&)> set;
};

// Every option of a study, in the order the command line's help lists them.
const std::vector<StudyOptionSpec>& StudyOptionSpecs();
// The option of this field, or null.
const StudyOptionSpec* FindStudyOption(const std::string& field);

// The value of an option from its text forms, one per occurrence on a command line (a switch: "true" or
// "false"); an option that is not repeatable given twice is refused. Throws StudyOptionError naming the field,
// the occurrence and the text ("until[1] 'H=abc': value 'abc' is not a number").
StudyOptionValue ParseStudyOption(const StudyOptionSpec& spec, const std::vector<std::string>& texts);
// Sets the option of `field` (a value of its kind's alternative; std::monostate: its default). Throws
// StudyOptionError for an unknown field or a value of another kind.
void SetStudyOption(StudyOptions* options, const std::string& field, const StudyOptionValue& value);
// The words of a field in each front end: the command line's flag ("until" -> "--until") and Python's keyword
// ("bounds" -> "bound"); a group of options by its parts ("restart" -> "--from/--at", "from_/at": the parts that name it);
// a field of no flag or keyword as it is. The `words` SayOptions and StudyOptionError::Say take.
std::string OptionFlag(const std::string& field);
std::string OptionKeyword(const std::string& field);
// Whether the option is repeatable (given once per value).
bool IsRepeatable(OptionKind kind);

// A mention of the option `field` in a message or a help text: said by SayOptions in a front end's words. The
// mention is marked by control characters that no option's value or help holds.
std::string MentionOption(const std::string& field);
// `text` with its mentions said in `words` (the command line's flags, Python's keywords); without `words`, by
// field name.
std::string SayOptions(const std::string& text,
                       const std::function<std::string(const std::string& field)>& words = {});

}  // namespace hybridcont

#endif  // HYBRIDCONT_STUDY_OPTIONS_H_
