// The declaration of a study's options (study_options.h): one entry per option, read by every front end.
#include "hybridcont/study_options.h"

#include <algorithm>
#include <cerrno>
#include <climits>
#include <cstdlib>
#include <set>

#include "hybridcont/option_text.h"

namespace hybridcont {

namespace {

// The marks around a mention of an option (MentionOption): ASCII group and record separators, which no
// option's value, help or message holds.
constexpr char kMentionBegin = '\x1d';
constexpr char kMentionEnd = '\x1e';

std::string M(const std::string& field) { return MentionOption(field); }

// The value's alternative, or StudyOptionError naming the field.
template <class T>
const T& As(const std::string& field, const StudyOptionValue& value) {
  if (const T* v = std::get_if<T>(&value)) return *v;
  throw StudyOptionError(field, -1, ": a value of another kind than the option's");
}

// Accessors of the common kinds, by member.
template <class T>
StudyOptionSpec Member(StudyOptionSpec spec, T StudyOptions::*member) {
  spec.get = [member](const StudyOptions& o) -> StudyOptionValue { return o.*member; };
  spec.set = [member, field = spec.field](StudyOptions* o, const StudyOptionValue& v) { o->*member = As<T>(field, v); };
  return spec;
}
template <class T>
StudyOptionSpec Optional(StudyOptionSpec spec, std::optional<T> StudyOptions::*member) {
  spec.get = [member](const StudyOptions& o) -> StudyOptionValue {
    if (!(o.*member)) return std::monostate{};
    return *(o.*member);
  };
  spec.set = [member, field = spec.field](StudyOptions* o, const StudyOptionValue& v) {
    if (std::holds_alternative<std::monostate>(v)) {
      (o->*member).reset();
    } else {
      o->*member = As<T>(field, v);
    }
  };
  return spec;
}
StudyOptionSpec Negated(StudyOptionSpec spec, bool StudyOptions::*member) {
  spec.negated = true;
  spec.get = [member](const StudyOptions& o) -> StudyOptionValue { return !(o.*member); };
  spec.set = [member, field = spec.field](StudyOptions* o, const StudyOptionValue& v) { o->*member = !As<bool>(field, v); };
  return spec;
}

// A part of the restart (RestartSpec): set, it makes the restart; all empty, there is none.
StudyOptionSpec RestartPart(StudyOptionSpec spec, std::string RestartSpec::*member) {
  spec.get = [member](const StudyOptions& o) -> StudyOptionValue { return o.restart ? (*o.restart).*member : ""; };
  spec.set = [member, field = spec.field](StudyOptions* o, const StudyOptionValue& v) {
    const std::string& text = As<std::string>(field, v);
    if (text.empty() && !o->restart) return;
    if (!o->restart) o->restart = RestartSpec{};
    (*o->restart).*member = text;
  };
  return spec;
}

constexpr RestartSpec::Kind kRestartKinds[] = {RestartSpec::Kind::kAuto,          RestartSpec::Kind::kContinue,
                                               RestartSpec::Kind::kSwitch,        RestartSpec::Kind::kPeriodDoubled,
                                               RestartSpec::Kind::kCurve,         RestartSpec::Kind::kFree};

StudyOptionSpec RestartKind(StudyOptionSpec spec) {
  for (const RestartSpec::Kind k : kRestartKinds) spec.choices.push_back(ToString(k));
  spec.get = [](const StudyOptions& o) -> StudyOptionValue {
    return ToString(o.restart ? o.restart->kind : RestartSpec::Kind::kAuto);
  };
  spec.set = [field = spec.field](StudyOptions* o, const StudyOptionValue& v) {
    const std::string& text = As<std::string>(field, v);
    for (const RestartSpec::Kind k : kRestartKinds) {
      if (ToString(k) != text) continue;
      if (k == RestartSpec::Kind::kAuto && !o->restart) return;
      if (!o->restart) o->restart = RestartSpec{};
      o->restart->kind = k;
      return;
    }
    throw StudyOptionError(field, -1, "'" + text + "': not a kind of restart");  // SetStudyOption checks choices
  };
  return spec;
}

StudyOptionSpec FormulationChoice(StudyOptionSpec spec) {
  spec.choices = {ToString(Formulation::kTimeBased), ToString(Formulation::kStateBased)};
  spec.get = [](const StudyOptions& o) -> StudyOptionValue { return ToString(o.formulation); };
  spec.set = [field = spec.field](StudyOptions* o, const StudyOptionValue& v) {
    if (!FromString(As<std::string>(field, v), &o->formulation)) {
      throw StudyOptionError(field, -1, "'" + As<std::string>(field, v) + "': expected 'time' or 'state'");
    }
  };
  return spec;
}

StudyOptionSpec FixedUnknown(StudyOptionSpec spec) {
  spec.get = [](const StudyOptions& o) -> StudyOptionValue {
    return o.fix ? std::vector<NamedValue>{*o.fix} : std::vector<NamedValue>{};
  };
  spec.set = [field = spec.field](StudyOptions* o, const StudyOptionValue& v) {
    if (std::holds_alternative<std::monostate>(v)) return o->fix.reset();
    const auto& values = As<std::vector<NamedValue>>(field, v);
    if (values.size() > 1) {
      throw StudyOptionError(field, 1, "'" + values[1].name + "': one unknown is held fixed, not " +
                                           std::to_string(values.size()));
    }
    o->fix = values.empty() ? std::nullopt : std::optional<NamedValue>(values[0]);
  };
  return spec;
}

StudyOptionSpec Spec(std::string field, std::string flag, std::string keyword, OptionKind kind, OptionRole role,
                     std::string value_name, std::string help, bool sweep) {
  StudyOptionSpec s;
  s.field = std::move(field);
  s.flag = std::move(flag);
  s.keyword = std::move(keyword);
  s.kind = kind;
  s.role = role;
  s.value_name = std::move(value_name);
  s.help = std::move(help);
  s.sweep = sweep;
  return s;
}

constexpr OptionRole kResult = OptionRole::kResult;
constexpr OptionRole kRun = OptionRole::kRunSetting;

std::vector<StudyOptionSpec> Declare() {
  using K = OptionKind;
  using O = StudyOptions;
  return {
      Member(Spec("model", "MODEL", "model", K::kText, kResult, "MODEL",
                  "built-in model name (see `hybridcont list`) or model file (.toml)", false),
             &O::model),
      Member(Spec("parameters", "--set", "set", K::kValues, kResult, "NAME=VALUE",
                  "override a model parameter (repeatable)", true),
             &O::parameters),
      Member(Spec("until", "--until", "until", K::kValues, kResult, "NAME=VALUE",
                  "end every branch exactly where an unknown or an observable of the model reaches a value, e.g. "
                  "H=2 or speed=1 (repeatable)", true),
             &O::until),
      Member(Spec("monitors", "--monitor", "monitor", K::kValueLists, kResult, "NAME=VALUE",
                  "locate the points where an observable of the model reaches a value, e.g. speed=0.5, or several "
                  "values, speed=0.5,0.8 (repeatable; special points UZ)", true),
             &O::monitors),
      Member(Spec("extrema", "--extremum", "extremum", K::kTexts, kResult, "OBSERVABLE",
                  "locate where an observable of the model is largest or smallest along each family, e.g. speed "
                  "(repeatable; special points EX, maxima and minima told apart; with " + M("curves") +
                  " also continued in two parameters: the locus of the best orbits)", true),
             &O::extrema),
      Member(Spec("bounds", "--bound", "bound", K::kIntervals, kResult, "NAME=LOWER:UPPER",
                  "replace the model's bound on an unknown, e.g. H=0:2.7 ('period' is the sum of the durations; an "
                  "empty end is unbounded) (repeatable)", true),
             &O::bounds),
      Optional(Spec("rtol", "--rtol", "rtol", K::kNumber, kResult, "TOL",
                    "integrator relative tolerance (default 1e-10)", true),
               &O::rtol),
      Optional(Spec("atol", "--atol", "atol", K::kNumber, kResult, "TOL",
                    "integrator absolute tolerance (default 1e-10)", true),
               &O::atol),
      Optional(Spec("max_branches", "--max-branches", "max_branches", K::kCount, kResult, "N",
                    "maximum number of half-branches traced (default: the model's scenario)", true),
               &O::max_branches),
      FormulationChoice(Spec("formulation", "--formulation", "formulation", K::kChoice, kResult, "time|state",
                             "time (default: time-based multiple shooting) or state (event-driven Poincare map)",
                             true)),
      Member(Spec("free", "--free", "free", K::kText, kResult, "PARAMETER",
                  "continue the families in a model parameter instead of H, e.g. k (needs " + M("fix") + ")", true),
             &O::free),
      FixedUnknown(Spec("fix", "--fix", "fix", K::kValue, kResult, "NAME=VALUE",
                        "the unknown held fixed while " + M("free") +
                            " varies: H=1.5, a state x2_dx=0.8, a duration t2=0 (where that phase vanishes) or an "
                            "observable speed=1; starts are the physical families' crossings of that value in the "
                            "ordinary run",
                        true)),
      Member(Spec("curves", "--curves", "curves", K::kText, kResult, "PARAMETER",
                  "after the run, continue every turning, SB, PD and NS point and every boundary of the physical "
                  "families in two parameters: (H, PARAMETER), or with " + M("free") + " (PARAMETER of " + M("free") +
                  ", PARAMETER) at the fixed value, e.g. w2 (bounds: " + M("bounds") + " PARAMETER=LO:HI)", false),
             &O::curves),
      Negated(Spec("use_symmetries", "--no-symmetry", "no_symmetry", K::kSwitch, kResult, "",
                   "trace every half-branch, also those that are images of traced ones under the model's symmetries",
                   true),
              &O::use_symmetries),
      Member(Spec("period_doubling", "--period-doubling", "period_doubling", K::kSwitch, kResult, "",
                  "explore the period-doubled family of every located PD point (the phase sequence traversed twice)",
                  true),
             &O::period_doubling),
      Negated(Spec("follow_word_changes", "--one-word", "one_word", K::kSwitch, kResult, "",
                   "a model given as an automaton: follow the start's phase sequence only, not the words its "
                   "families lead into where a phase vanishes or a competing guard is touched", true),
              &O::follow_word_changes),
      RestartPart(Spec("restart.from", "--from", "from_", K::kText, kResult, "FOLDER",
                       "restart from a saved study (a results folder) at the point " + M("restart.label") +
                           " names, instead of the model's start; the new families go to " + M("out_dir"),
                       false),
                  &RestartSpec::from),
      RestartPart(Spec("restart.label", "--at", "at", K::kText, kResult, "LABEL",
                       "with " + M("restart.from") +
                           ": a special point's label (PD4, SB36, TP22: its type and id in that study), a branch's "
                           "end (B5) or one of its points (B5:12)",
                       false),
                  &RestartSpec::label),
      RestartKind(Spec("restart.kind", "--as", "as_", K::kChoice, kResult, "KIND",
                       "with " + M("restart.from") +
                           ": continue (the family beyond the point), switch (every branch through an SB point), "
                           "period-doubled (the family born at a PD point), curve (the point in (H, " + M("curves") +
                           ")), free (the family in " + M("free") +
                           " from the orbit); default auto: what the label's type implies",
                       false)),
      Member(Spec("families_of", "--families-of", "families_of", K::kText, kResult, "FOLDER",
                  "a saved study of this model at nearby parameter values (a results folder): trace only the "
                  "half-branches whose counterparts there led to a family, not the whole exploration (what a sweep "
                  "does from grid point to grid point)", false),
             &O::families_of),
      Member(Spec("families", "--family", "families", K::kTexts, kResult, "NAME",
                  "with " + M("families_of") +
                      ": continue only this family of it (its name, as the answer names it; repeatable)",
                  false),
             &O::families),
      Member(Spec("start_must_converge", "", "start_must_converge", K::kSwitch, kResult, "",
                  "a start that does not converge is bad input (true, the default) or the study's status "
                  "start-failed, the model's starts in other words still explored (false)", false),
             &O::start_must_converge),
      Member(Spec("threads", "--threads", "threads", K::kCount, kRun, "N",
                  "threads tracing half-branches concurrently (default: the machine's cores; 1 = one after the "
                  "other); the results do not depend on it", false),
             &O::threads),
      Member(Spec("out_dir", "--out", "out", K::kText, kRun, "FOLDER", "results folder (default results/MODEL)", false),
             &O::out_dir),
      Member(Spec("overwrite", "--overwrite", "overwrite", K::kSwitch, kRun, "",
                  "replace the results of another model in " + M("out_dir") + " (without it such a folder is refused)",
                  false),
             &O::overwrite),
      Member(Spec("resume", "--resume", "resume", K::kSwitch, kRun, "",
                  "continue the run interrupted in " + M("out_dir") +
                      " (killed, stopped, out of disk): the branches it traced are taken as they are, the rest "
                      "computed; the options must be those of that run",
                  false),
             &O::resume),
  };
}

// The text's refusal from option_text.h ("<option> 'k=abc': ...", asked with an empty option) as the detail of
// a StudyOptionError.
[[noreturn]] void Refuse(const StudyOptionSpec& spec, int index, const std::invalid_argument& e) {
  std::string detail = e.what();
  if (!detail.empty() && detail[0] == ' ') detail.erase(0, 1);
  throw StudyOptionError(spec.field, index, detail);
}

int ParseCount(const StudyOptionSpec& spec, int index, const std::string& text) {
  errno = 0;
  char* end = nullptr;
  const long long value = std::strtoll(text.c_str(), &end, 10);
  if (text.empty() || end != text.c_str() + text.size() || text.find_first_of(" \t") != std::string::npos) {
    throw StudyOptionError(spec.field, index, "'" + text + "': not a whole number");
  }
  if (errno == ERANGE || value < INT_MIN || value > INT_MAX) {
    throw StudyOptionError(spec.field, index, "'" + text + "': out of range");
  }
  return static_cast<int>(value);
}

// The value of one text of the option (occurrence `index`).
StudyOptionValue ParseOne(const StudyOptionSpec& spec, int index, const std::string& text) {
  try {
    switch (spec.kind) {
      case OptionKind::kText:
      case OptionKind::kChoice: return text;
      case OptionKind::kTexts: return std::vector<std::string>{text};
      case OptionKind::kNumber: return ParseFinite(" '" + text + "'", text);
      case OptionKind::kCount: return ParseCount(spec, index, text);
      case OptionKind::kSwitch:
        if (text == "true" || text == "false") return text == "true";
        throw StudyOptionError(spec.field, index, "'" + text + "': expected true or false");
      case OptionKind::kValue:
      case OptionKind::kValues: {
        const auto [name, value] = ParseAssignment("", text);
        return std::vector<NamedValue>{{name, value}};
      }
      case OptionKind::kValueLists: return ParseAssignments("", text);
      case OptionKind::kIntervals: return std::vector<NamedInterval>{ParseBound("", text)};
    }
  } catch (const StudyOptionError&) {
    throw;
  } catch (const std::invalid_argument& e) {
    Refuse(spec, index, e);
  }
  return std::monostate{};
}

// Appends the entries of `more` to the list `into` (both of the option's kind).
template <class List>
bool AppendTo(StudyOptionValue* into, const StudyOptionValue& more) {
  List* list = std::get_if<List>(into);
  const List* tail = std::get_if<List>(&more);
  if (list == nullptr || tail == nullptr) return false;
  list->insert(list->end(), tail->begin(), tail->end());
  return true;
}
void Append(StudyOptionValue* into, StudyOptionValue more) {
  if (std::holds_alternative<std::monostate>(*into)) {
    *into = std::move(more);
    return;
  }
  AppendTo<std::vector<std::string>>(into, more) || AppendTo<std::vector<NamedValue>>(into, more) ||
      AppendTo<std::vector<NamedInterval>>(into, more);
}

// A choice's text, or StudyOptionError (entry `index`) naming the choices.
void CheckChoice(const StudyOptionSpec& spec, int index, const std::string& text) {
  if (std::find(spec.choices.begin(), spec.choices.end(), text) != spec.choices.end()) return;
  std::string expected;
  for (std::size_t c = 0; c < spec.choices.size(); ++c) {
    expected += (c == 0 ? "" : c + 1 == spec.choices.size() ? " or " : ", ") + ("'" + spec.choices[c] + "'");
  }
  throw StudyOptionError(spec.field, index, "'" + text + "': expected " + expected);
}

// The name of an entry that sets one value per name (a parameter, a target, a bound); "" for other kinds.
std::string NameOf(const StudyOptionValue& one) {
  if (const auto* v = std::get_if<std::vector<NamedValue>>(&one)) return v->size() == 1 ? v->front().name : "";
  if (const auto* b = std::get_if<std::vector<NamedInterval>>(&one)) return b->front().name;
  return "";
}

bool HoldsKind(OptionKind kind, const StudyOptionValue& v) {
  if (std::holds_alternative<std::monostate>(v)) return true;
  switch (kind) {
    case OptionKind::kText:
    case OptionKind::kChoice: return std::holds_alternative<std::string>(v);
    case OptionKind::kNumber: return std::holds_alternative<double>(v);
    case OptionKind::kCount: return std::holds_alternative<int>(v);
    case OptionKind::kSwitch: return std::holds_alternative<bool>(v);
    case OptionKind::kTexts: return std::holds_alternative<std::vector<std::string>>(v);
    case OptionKind::kValue:
    case OptionKind::kValues:
    case OptionKind::kValueLists: return std::holds_alternative<std::vector<NamedValue>>(v);
    case OptionKind::kIntervals: return std::holds_alternative<std::vector<NamedInterval>>(v);
  }
  return false;
}

}  // namespace

StudyOptionError::StudyOptionError(std::string field, int index, const std::string& message)
    : std::invalid_argument((index >= 0 ? field + "[" + std::to_string(index) + "]" : field) +
                            (message.rfind(":", 0) == 0 ? "" : " ") + SayOptions(message)),
      field_(std::move(field)), index_(index), detail_(message) {}

std::string StudyOptionError::Say(const std::function<std::string(const std::string& field)>& words) const {
  return (words ? words(field_) : field_) + (detail_.rfind(":", 0) == 0 ? "" : " ") + SayOptions(detail_, words);
}

std::string ToString(RestartSpec::Kind kind) {
  switch (kind) {
    case RestartSpec::Kind::kAuto: return "auto";
    case RestartSpec::Kind::kContinue: return "continue";
    case RestartSpec::Kind::kSwitch: return "switch";
    case RestartSpec::Kind::kPeriodDoubled: return "period-doubled";
    case RestartSpec::Kind::kCurve: return "curve";
    case RestartSpec::Kind::kFree: return "free";
  }
  return "?";
}

const std::vector<StudyOptionSpec>& StudyOptionSpecs() {
  static const std::vector<StudyOptionSpec> specs = Declare();
  return specs;
}

const StudyOptionSpec* FindStudyOption(const std::string& field) {
  for (const StudyOptionSpec& spec : StudyOptionSpecs()) {
    if (spec.field == field) return &spec;
  }
  return nullptr;
}

namespace {
// The words of `field` by `member` of its declaration, or of the parts of a group ("restart": restart.*) that
// name what it is (a choice among its kinds does not: "--from/--at").
std::string WordsOf(const std::string& field, std::string StudyOptionSpec::*member) {
  if (const StudyOptionSpec* spec = FindStudyOption(field)) return (spec->*member).empty() ? field : spec->*member;
  std::string parts;
  for (const StudyOptionSpec& spec : StudyOptionSpecs()) {
    if (spec.field.rfind(field + ".", 0) == 0 && spec.kind != OptionKind::kChoice && !(spec.*member).empty()) {
      parts += (parts.empty() ? "" : "/") + spec.*member;
    }
  }
  return parts.empty() ? field : parts;
}
}  // namespace

std::string OptionFlag(const std::string& field) { return WordsOf(field, &StudyOptionSpec::flag); }
std::string OptionKeyword(const std::string& field) { return WordsOf(field, &StudyOptionSpec::keyword); }

bool IsRepeatable(OptionKind kind) {
  return kind == OptionKind::kValues || kind == OptionKind::kValueLists || kind == OptionKind::kIntervals ||
         kind == OptionKind::kTexts;
}

StudyOptionValue ParseStudyOption(const StudyOptionSpec& spec, const std::vector<std::string>& texts) {
  for (std::size_t i = 0; i < texts.size(); ++i) {
    if (texts[i].empty()) {
      throw StudyOptionError(spec.field, static_cast<int>(i), "'': an empty value (give a value, or leave the option out)");
    }
  }
  if (texts.size() > 1 && !IsRepeatable(spec.kind)) {
    throw StudyOptionError(spec.field, 1, "'" + texts[1] + "': given twice (first '" + texts[0] + "'); give it once");
  }
  StudyOptionValue value;
  std::set<std::string> names;  // one entry per name where the option sets one value per name
  for (std::size_t i = 0; i < texts.size(); ++i) {
    StudyOptionValue one = ParseOne(spec, static_cast<int>(i), texts[i]);
    if (spec.kind == OptionKind::kChoice) CheckChoice(spec, static_cast<int>(i), texts[i]);
    if (spec.kind == OptionKind::kValues || spec.kind == OptionKind::kIntervals) {
      const std::string name = NameOf(one);
      if (!names.insert(name).second) {
        throw StudyOptionError(spec.field, static_cast<int>(i), "'" + texts[i] + "': '" + name + "' is given twice");
      }
    }
    Append(&value, std::move(one));
  }
  return value;
}

void SetStudyOption(StudyOptions* options, const std::string& field, const StudyOptionValue& value) {
  const StudyOptionSpec* spec = FindStudyOption(field);
  if (spec == nullptr) throw StudyOptionError(field, -1, ": not an option of a study");
  if (!HoldsKind(spec->kind, value)) throw StudyOptionError(field, -1, ": a value of another kind than the option's");
  if (std::holds_alternative<std::monostate>(value)) {
    spec->set(options, spec->get(StudyOptions{}));  // its default
    return;
  }
  if (spec->kind == OptionKind::kChoice) CheckChoice(*spec, -1, std::get<std::string>(value));
  spec->set(options, value);
}

std::string MentionOption(const std::string& field) { return kMentionBegin + field + kMentionEnd; }

std::string SayOptions(const std::string& text, const std::function<std::string(const std::string& field)>& words) {
  std::string said;
  std::size_t at = 0;
  while (true) {
    const std::size_t begin = text.find(kMentionBegin, at);
    const std::size_t end = begin == std::string::npos ? std::string::npos : text.find(kMentionEnd, begin);
    if (end == std::string::npos) break;
    const std::string field = text.substr(begin + 1, end - begin - 1);
    said += text.substr(at, begin - at) + (words ? words(field) : field);
    at = end + 1;
  }
  return said + text.substr(at);
}

}  // namespace hybridcont
