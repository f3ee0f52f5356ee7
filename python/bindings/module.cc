// _hybridcont: the Python package's bridge to the library (pybind11). It exposes the study API (study.h) and
// the model's maps, nothing of its own: the package's Python modules (python/hybridcont/) turn keyword
// arguments into StudyOptions, results folders into DataFrames and SymPy into model text.
//
// Conventions:
//  - Bad input (StudyOptionError, ModelInputError, any std::invalid_argument) arrives as ValueError with the
//    library's message; a numerical failure is a status in what a call returns, never an exception.
//  - The GIL is released while the library computes; the hooks take it back to call Python.
//  - Ctrl-C during a study sets its stop request (a SIGINT handler of its own for the call's duration, the
//    interpreter's restored after): the study ends after its current step with status "cancelled" and keeps
//    the work so far.
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <atomic>
#include <cmath>
#include <limits>
#include <tuple>
#include <variant>
#include <csignal>
#include <mutex>
#include <filesystem>
#include <fstream>
#include <optional>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "hybridcont/continuation.h"
#include "hybridcont/floquet.h"
#include "hybridcont/model_file.h"
#include "hybridcont/models.h"
#include "hybridcont/orbit_trace.h"
#include "hybridcont/setup_evaluation.h"
#include "hybridcont/shooting_layout.h"
#include "hybridcont/study.h"
#include "hybridcont/study_answer.h"
#include "hybridcont/study_report.h"
#include "hybridcont/study_table.h"
#include "hybridcont/timebased_shooting.h"

namespace py = pybind11;

namespace hybridcont::python {

namespace {

// ---- Ctrl-C: a count of SIGINTs, raised by a handler installed while studies run. Each study remembers the
// count it began with, so that a Ctrl-C stops every study running then and no later study forgets it (a
// lock-free atomic: safe in a signal handler).
std::atomic<long> interrupts{0};
static_assert(std::atomic<long>::is_always_lock_free);
extern "C" void OnInterrupt(int) { interrupts.fetch_add(1); }

// Studies may run on several Python threads at once: the handler is installed by the first and the previous
// one restored by the last (a count under a mutex), and a Ctrl-C stops them all. A SIGINT the process ignores
// stays ignored.
class InterruptGuard {
 public:
  InterruptGuard() {
    std::lock_guard<std::mutex> lock(mutex_);
    if (depth_++ > 0) return;
    struct sigaction action {};
    action.sa_handler = OnInterrupt;
    sigemptyset(&action.sa_mask);
    struct sigaction current {};
    installed_ = sigaction(SIGINT, nullptr, &current) == 0 && current.sa_handler != SIG_IGN &&
                 sigaction(SIGINT, &action, &previous_) == 0;
  }
  ~InterruptGuard() {
    std::lock_guard<std::mutex> lock(mutex_);
    if (--depth_ == 0 && installed_) sigaction(SIGINT, &previous_, nullptr), installed_ = false;
  }
  InterruptGuard(const InterruptGuard&) = delete;
  InterruptGuard& operator=(const InterruptGuard&) = delete;

 private:
  static inline std::mutex mutex_;
  static inline int depth_ = 0;
  static inline struct sigaction previous_ {};
  static inline bool installed_ = false;
};

// ---- options: Python's keyword arguments, converted by the library's declaration (study_options.h)

template <class T>
T Get(const py::dict& d, const char* key, T fallback) {
  return d.contains(key) && !d[key].is_none() ? d[key].cast<T>() : fallback;
}

// A Python value of the option's kind (the forms study_options.h lists per OptionKind) as the library's value.
// A value of another shape or a number that is not finite: StudyOptionError naming the option.
StudyOptionValue OptionValueOf(const StudyOptionSpec& spec, const py::handle& v) {
  if (v.is_none()) return std::monostate{};
  const auto refuse = [&](const std::string& expected) {
    return StudyOptionError(spec.field, -1, py::repr(v).cast<std::string>() + ": expected " + expected);
  };
  const auto number = [&](const py::handle x, bool infinite_allowed) {
    if (py::isinstance<py::bool_>(x) || py::isinstance<py::str>(x)) throw refuse("numbers");
    double value;
    try {
      value = py::float_(py::reinterpret_borrow<py::object>(x)).cast<double>();
    } catch (const py::error_already_set&) {
      throw refuse("numbers");
    }
    if (std::isnan(value) || (!infinite_allowed && !std::isfinite(value))) throw refuse("finite numbers");
    return value;
  };
  const auto text = [&](const py::handle x) {
    if (py::isinstance<py::str>(x)) return x.cast<std::string>();
    if (py::hasattr(x, "__fspath__")) return py::module_::import("os").attr("fspath")(x).cast<std::string>();
    throw refuse("a string");
  };
  const auto is_dict = py::isinstance<py::dict>(v);
  const auto items = [&]() -> py::list {  // (name, value) pairs of a dict or a sequence of pairs
    if (is_dict) return py::list(v.cast<py::dict>().attr("items")());
    if (py::isinstance<py::str>(v) || !py::isinstance<py::sequence>(v)) throw refuse("{name: value} or [(name, value)]");
    return py::list(py::reinterpret_borrow<py::object>(v));
  };
  const auto pair = [&](const py::handle item) {
    if (py::isinstance<py::str>(item) || !py::isinstance<py::sequence>(item) || py::len(item) != 2) {
      throw refuse("{name: value} or [(name, value)]");
    }
    return std::make_pair(text(item[py::int_(0)]), py::object(item[py::int_(1)]));
  };
  switch (spec.kind) {
    case OptionKind::kText:
    case OptionKind::kChoice: return text(v);
    case OptionKind::kTexts: {
      if (py::isinstance<py::str>(v)) return std::vector<std::string>{text(v)};
      std::vector<std::string> out;
      for (const py::handle x : v) out.push_back(text(x));
      return out;
    }
    case OptionKind::kNumber: return number(v, false);
    case OptionKind::kCount:
      if (py::isinstance<py::bool_>(v) || !py::isinstance<py::int_>(v)) throw refuse("a whole number");
      return v.cast<int>();
    case OptionKind::kSwitch:
      if (!py::isinstance<py::bool_>(v) && !py::hasattr(v, "dtype")) throw refuse("True or False");
      return v.cast<bool>();
    case OptionKind::kValue:
      if (!is_dict && py::isinstance<py::sequence>(v) && py::len(v) == 2 && py::isinstance<py::str>(v[py::int_(0)])) {
        const auto [name, value] = pair(v);
        return std::vector<NamedValue>{{name, number(value, false)}};
      }
      [[fallthrough]];
    case OptionKind::kValues: {
      std::vector<NamedValue> out;
      for (const py::handle item : items()) {
        const auto [name, value] = pair(item);
        out.push_back({name, number(value, false)});
      }
      return out;
    }
    case OptionKind::kValueLists: {  // {name: value or [values]}
      std::vector<NamedValue> out;
      for (const py::handle item : items()) {
        const auto [name, values] = pair(item);
        if (py::isinstance<py::sequence>(values) || py::hasattr(values, "__array__")) {
          for (const py::handle x : values) out.push_back({name, number(x, false)});
        } else {
          out.push_back({name, number(values, false)});
        }
      }
      return out;
    }
    case OptionKind::kIntervals: {  // {name: (lower, upper)}, None for an open end; or [(name, lower, upper)]
      std::vector<NamedInterval> out;
      const auto end = [&](const py::handle x, double open) { return x.is_none() ? open : number(x, true); };
      const double inf = std::numeric_limits<double>::infinity();
      for (const py::handle item : items()) {
        py::object name, interval;
        if (is_dict) {
          std::tie(name, interval) = std::make_pair(py::object(item[py::int_(0)]), py::object(item[py::int_(1)]));
        } else if (py::isinstance<py::sequence>(item) && py::len(item) == 3) {
          name = item[py::int_(0)];
          interval = py::make_tuple(item[py::int_(1)], item[py::int_(2)]);
        } else {
          throw refuse("{name: (lower, upper)}");
        }
        if (py::isinstance<py::str>(interval) || !py::isinstance<py::sequence>(interval) || py::len(interval) != 2) {
          throw refuse("{name: (lower, upper)}, None for an open end");
        }
        out.push_back({text(name), end(interval[py::int_(0)], -inf), end(interval[py::int_(1)], inf)});
      }
      return out;
    }
  }
  return std::monostate{};
}

// The library's value of an option as Python's keyword takes it: {name: value} for values (ParseStudyOption
// gives each name once), {name: [values]} for value lists, {name: (lower, upper)} (None: open) for intervals.
py::object PythonOf(const StudyOptionSpec& spec, const StudyOptionValue& value) {
  return std::visit(
      [&](const auto& v) -> py::object {
        using T = std::decay_t<decltype(v)>;
        if constexpr (std::is_same_v<T, std::monostate>) {
          return py::none();
        } else if constexpr (std::is_same_v<T, std::vector<NamedValue>>) {
          py::dict out;
          for (const NamedValue& x : v) {
            const py::str name(x.name);
            if (spec.kind != OptionKind::kValueLists) {
              out[name] = x.value;
              continue;
            }
            if (!out.contains(name)) out[name] = py::list();
            out[name].cast<py::list>().append(x.value);
          }
          return out;
        } else if constexpr (std::is_same_v<T, std::vector<NamedInterval>>) {
          py::dict out;
          const auto end = [](double x) { return std::isfinite(x) ? py::object(py::float_(x)) : py::none(); };
          for (const NamedInterval& x : v) out[py::str(x.name)] = py::make_tuple(end(x.lower), end(x.upper));
          return out;
        } else {
          return py::cast(v);
        }
      },
      value);
}

// The options of a study from Python's keyword arguments (and the package's own: model, models_directory,
// model_text). An unknown keyword: TypeError naming it and the known ones.
StudyOptions OptionsOf(const py::dict& d) {
  StudyOptions o;
  for (const auto& [key_handle, value] : d) {
    const std::string key = key_handle.cast<std::string>();
    if (key == "models_directory" || key == "model_text") {
      (key == "model_text" ? o.model_text : o.models_directory) = value.is_none() ? "" : value.cast<std::string>();
      continue;
    }
    const StudyOptionSpec* spec = nullptr;
    for (const StudyOptionSpec& s : StudyOptionSpecs()) {
      if (s.keyword == key) spec = &s;
    }
    if (spec == nullptr) {
      std::string known;
      for (const StudyOptionSpec& s : StudyOptionSpecs()) known += (known.empty() ? "" : ", ") + s.keyword;
      throw py::type_error("unexpected keyword argument '" + key + "' (the options of a study: " + known + ")");
    }
    SetStudyOption(&o, spec->field, OptionValueOf(*spec, value));
  }
  return o;
}

// ---- models
using ModelHandle = std::shared_ptr<HybridModel>;

ModelHandle Share(HybridModel model) { return std::make_shared<HybridModel>(std::move(model)); }

// The map of the model's time-based layout, with `free` parameter(s) held by `fix` (free[i] at fix[i]); a
// model without first integral continued in its parameter has that parameter free and nothing fixed.
struct MapSpec {
  std::vector<std::string> free;
  std::vector<std::pair<std::string, double>> fix;
};

FreeParameters FreeOf(const MapSpec& spec) {
  FreeParameters free;
  free.parameters = spec.free;
  for (const auto& [name, value] : spec.fix) free.fixed.push_back({name, value});
  return free;
}

Vector ToVector(const std::vector<double>& v) { return Eigen::Map<const Vector>(v.data(), static_cast<Eigen::Index>(v.size())); }

py::array_t<double> ToArray(const Vector& v) {
  py::array_t<double> a(v.size());
  for (Eigen::Index i = 0; i < v.size(); ++i) a.mutable_at(i) = v(i);
  return a;
}

py::array_t<double> ToArray(const Matrix& m) {
  py::array_t<double> a({m.rows(), m.cols()});
  for (Eigen::Index i = 0; i < m.rows(); ++i) {
    for (Eigen::Index j = 0; j < m.cols(); ++j) a.mutable_at(i, j) = m(i, j);
  }
  return a;
}

IntegratorOptions IntegratorOf(std::optional<double> rtol, std::optional<double> atol) {
  IntegratorOptions options;
  if (rtol) options.rtol = *rtol;
  if (atol) options.atol = *atol;
  return options;
}

// u must hold one value per unknown of the map.
void CheckSize(const std::vector<double>& u, const TimeBasedShooting& map) {
  if (static_cast<int>(u.size()) != map.num_unknowns()) {
    throw std::invalid_argument("u has " + std::to_string(u.size()) + " entries; the map's unknowns are " +
                                std::to_string(map.num_unknowns()) + " (" + std::to_string(map.num_equations()) +
                                " equations)");
  }
}

py::dict Evaluate(const ModelHandle& model, const std::vector<double>& u, const MapSpec& spec, bool jacobian,
                  std::optional<double> rtol, std::optional<double> atol) {
  TimeBasedShooting map(*model, IntegratorOf(rtol, atol), FreeOf(spec));
  CheckSize(u, map);
  Vector r;
  Matrix dr;
  EvaluationStatus status;
  {
    py::gil_scoped_release release;
    status = map.Evaluate(ToVector(u), &r, jacobian ? &dr : nullptr);
  }
  py::dict out;
  out["ok"] = status.ok;
  out["message"] = status.message;
  out["r"] = status.ok ? py::object(ToArray(r)) : py::none();
  out["dr"] = status.ok && jacobian ? py::object(ToArray(dr)) : py::none();
  out["unknowns"] = map.unknown_names();
  return out;
}

py::dict Floquet(const ModelHandle& model, const std::vector<double>& u, const MapSpec& spec,
                 std::optional<double> rtol, std::optional<double> atol) {
  TimeBasedShooting map(*model, IntegratorOf(rtol, atol), FreeOf(spec));
  CheckSize(u, map);
  FloquetResult f;
  {
    py::gil_scoped_release release;
    f = ComputeFloquet(map, ToVector(u));
  }
  py::dict out;
  out["ok"] = f.ok();
  out["message"] = f.message;
  out["monodromy"] = f.ok() ? py::object(ToArray(f.monodromy)) : py::none();
  out["multipliers"] = f.multipliers;
  out["nontrivial"] = f.nontrivial;
  out["stable"] = f.stable;
  out["stability"] = f.stability.ToString();
  out["bp_test"] = f.bp_test;
  out["pd_test"] = f.pd_test;
  out["multiplier_error"] = f.multiplier_error;
  return out;
}

// One period of the orbit u (model layout, parameters as set on the model): samples t, segment, state.
py::dict Trace(const ModelHandle& model, const std::vector<double>& u, int samples, std::optional<double> rtol,
               std::optional<double> atol) {
  const int expected = ShootingLayout(*model).num_unknowns();
  if (static_cast<int>(u.size()) != expected) {
    throw std::invalid_argument("u has " + std::to_string(u.size()) + " entries; the orbit's unknowns (the model's own "
                                "layout, no free parameters) are " + std::to_string(expected));
  }
  // Every sample becomes Python objects: the bound keeps a mistyped count from exhausting memory.
  constexpr int kMaxSamples = 1000000;
  if (samples < 2 || samples > kMaxSamples) {
    throw std::invalid_argument("samples must lie in [2, " + std::to_string(kMaxSamples) + "], got " +
                                std::to_string(samples));
  }
  std::unique_ptr<OrbitTrace> trace;
  {
    py::gil_scoped_release release;
    trace = std::make_unique<OrbitTrace>(*model, ToVector(u), IntegratorOf(rtol, atol));
  }
  py::dict out;
  out["ok"] = trace->ok();
  out["message"] = trace->message();
  std::vector<double> t;
  std::vector<int> segment;
  std::vector<std::string> phase;
  std::vector<std::vector<double>> x;
  if (trace->ok()) {
    for (const OrbitSample& s : trace->Sample(samples)) {
      t.push_back(s.t);
      segment.push_back(s.segment);
      phase.push_back(model->phase(s.segment % model->num_phases()).name());
      x.emplace_back(s.x.data(), s.x.data() + s.x.size());
    }
  }
  out["t"] = t;
  out["segment"] = segment;
  out["phase"] = phase;
  out["x"] = x;
  return out;
}

// ---- studies
ReportAssets AssetsOf(const py::dict& assets) {
  return ReportAssets{assets["template_html"].cast<std::string>(), assets["viewer_js"].cast<std::string>(),
                      assets["viewer_css"].cast<std::string>(), assets["plotly_js"].cast<std::string>()};
}

// The study's own model (its record, ModelOfStudy) for a report's animations; null, with the reason, where it
// cannot be rebuilt.
std::unique_ptr<HybridModel> ModelForReport(const StudyResult& study, const std::string& models_directory,
                                            std::string* why) {
  try {
    return std::make_unique<HybridModel>(ModelOfStudy(study, models_directory));
  } catch (const std::invalid_argument& e) {
    *why = e.what();
    return nullptr;
  }
}

// The study's families (FoldFamilies): one dict per family and kind of stretch, one entry per interval.
py::list FamiliesOf(const StudyResult& study) {
  py::list out;
  for (const StudyFamily& f : study.families) {
    for (const bool physical : {true, false}) {
      for (const FamilyInterval& i : physical ? f.physical : f.stable) {
        py::dict row;
        row["family"] = f.name;
        row["kind"] = physical ? "physical" : "stable";
        row["continued"] = f.continued;
        row["from"] = i.from;
        row["to"] = i.to;
        row["from_end"] = i.from_end;
        row["to_end"] = i.to_end;
        row["branches"] = f.branches;
        row["special_points"] = f.special_points;
        out.append(row);
      }
    }
  }
  return out;
}

// ---- a study's tables, from its typed result (study.h): the rows Python's DataFrames are made of

// One row per special point that is no duplicate: label (the library's one rule), the record's fields, each
// named unknown (a free parameter, an observable) as a column, the observables as a dict.
py::list SpecialPointRows(const StudyResult& study) {
  py::list rows;
  for (const StudySpecialPoint& sp : study.special_points) {
    if (sp.duplicate_of >= 0) continue;
    py::dict row;
    row["label"] = sp.Label();
    row["id"] = sp.id;
    row["type"] = sp.code;
    row["branch"] = sp.branch;
    row["index"] = sp.index;
    row["H"] = sp.H;
    row["T"] = sp.T;
    row["status"] = sp.status;
    row["precision"] = sp.precision;
    row["precision_arclength"] = sp.precision_arclength;
    row["precision_H"] = sp.precision_H;
    row["residual"] = sp.residual;
    row["component"] = sp.component;
    row["duplicate_of"] = sp.duplicate_of;
    row["message"] = sp.message;
    row["u"] = ToArray(sp.u);
    for (const NamedValue& v : sp.named_unknowns) row[py::str(v.name)] = v.value;
    if (!sp.word.empty()) row["word"] = sp.word;
    if (sp.period_doubled_from >= 0) row["period_doubled_from"] = sp.period_doubled_from;
    if (sp.extremum != 0) row["extremum"] = sp.extremum > 0 ? "maximum" : "minimum";
    if (!sp.observables.empty()) {
      py::dict observables;
      for (const NamedValue& v : sp.observables) observables[py::str(v.name)] = v.value;
      row["observables"] = observables;
    }
    rows.append(row);
  }
  return rows;
}

// One row per branch: id, family, parent (the special point it starts at), direction, depth, points (how
// many), termination, word (its modes joined by " > "), image_of, symmetry, file, and the rest of its record.
py::list BranchRows(const StudyResult& study) {
  py::list rows;
  for (const StudyBranch& b : study.branches) {
    py::dict row;
    row["id"] = b.id;
    row["family"] = b.family;
    row["parent"] = b.parent_special_point;
    row["direction"] = b.direction;
    row["depth"] = b.depth;
    row["points"] = b.points.size();
    row["termination"] = b.termination;
    std::string word;
    for (const std::string& mode : b.word) word += (word.empty() ? "" : " > ") + mode;
    row["word"] = b.word.empty() ? py::object(py::none()) : py::object(py::str(word));
    row["image_of"] = b.image_of;
    row["symmetry"] = b.symmetry;
    row["file"] = BranchFileName(b.id);
    row["message"] = b.message;
    row["model"] = b.model;
    row["origin"] = b.origin;
    row["continued"] = b.continued;
    row["reflected_from"] = b.reflected_from;
    row["period_doubled_from"] = b.period_doubled_from;
    row["handed_over_from"] = b.handed_over_from;
    rows.append(row);
  }
  return rows;
}

// One row per change of word considered (StudyWordChange), NaN for what a change does not have.
py::list WordChangeRows(const StudyResult& study) {
  py::list rows;
  for (const StudyWordChange& c : study.word_changes) {
    py::dict row;
    row["from_word"] = c.from_word;
    row["from_branch"] = c.from_branch;
    row["at"] = c.at;
    row["H"] = c.H;
    row["H_physical"] = c.H_physical;
    row["H_beyond"] = c.H_beyond;
    row["detail"] = c.detail;
    row["rule"] = c.rule;
    row["to_word"] = c.to_word;
    row["residual"] = c.residual;
    row["state_difference"] = c.state_difference;
    row["period_difference"] = c.period_difference;
    row["accepted"] = c.accepted;
    row["reason"] = c.reason;
    row["to_branches"] = c.to_branches;
    rows.append(row);
  }
  return rows;
}

// One row per point of every two-parameter curve: curve (its id), type, name, special_point, status, then the
// curve's columns ("H", the parameter, its other unknowns).
py::list CurveRows(const StudyResult& study) {
  py::list rows;
  for (const StudyCurve& c : study.curves) {
    for (const Vector& point : c.points) {
      py::dict row;
      row["curve"] = c.id;
      row["type"] = c.type;
      row["name"] = c.name;
      row["special_point"] = c.special_point;
      row["status"] = c.status;
      for (std::size_t k = 0; k < c.columns.size() && static_cast<Eigen::Index>(k) < point.size(); ++k) {
        row[py::str(c.columns[k])] = point(static_cast<Eigen::Index>(k));
      }
      rows.append(row);
    }
  }
  return rows;
}

// One row per vertex of every region of the curves' plane (regions.h): region (its index), family, kind,
// branch, then the parameter of the curves and the families' coordinate.
py::list RegionRows(const StudyResult& study) {
  py::list rows;
  const std::string a = study.curves.empty() || study.curves.front().columns.empty() ? std::string("H")
                                                                                     : study.curves.front().columns.front();
  for (std::size_t k = 0; k < study.regions.size(); ++k) {
    const StudyRegion& r = study.regions[k];
    for (const auto& [p, level] : r.polygon) {
      py::dict row;
      row["region"] = static_cast<int>(k);
      row["family"] = r.family;
      row["kind"] = r.kind;
      row["branch"] = r.branch;
      row[py::str(study.curve_parameter)] = p;
      row[py::str(a)] = level;
      rows.append(row);
    }
  }
  return rows;
}

// What Python's Study holds of a study: status, answer, its families' fold, labels and tables.
// The study's points, column by column (study_table.h): numbers as numpy arrays, texts as lists.
py::dict PointColumns(const StudyResult& study) {
  py::dict columns;
  for (StudyColumn& c : StudyPointColumns(study)) {
    if (c.text) columns[py::str(c.name)] = py::cast(c.texts);
    else columns[py::str(c.name)] = py::array_t<double>(static_cast<py::ssize_t>(c.numbers.size()), c.numbers.data());
  }
  return columns;
}

py::dict StudyDict(const StudyResult& study) {
  py::dict out;
  out["status"] = ToString(study.status);
  out["message"] = study.message;
  out["model"] = study.model;
  out["version"] = study.version;
  out["answer"] = OneScreenAnswer(study, study.work.wall_seconds);
  out["families"] = FamiliesOf(study);
  out["unknowns"] = study.unknown_names;
  out["special_points"] = SpecialPointRows(study);
  out["branches"] = BranchRows(study);
  out["word_changes"] = WordChangeRows(study);
  out["curves"] = CurveRows(study);
  out["regions"] = RegionRows(study);
  out["points"] = PointColumns(study);
  out["summary_json"] = study.summary_json;  // the saved document (effective options, presentation)
  out["model_source"] = py::dict(py::arg("kind") = ToString(study.model_source.kind), py::arg("name") = study.model_source.name,
                                 py::arg("path") = study.model_source.path, py::arg("text") = study.model_source.text);
  return out;
}


py::dict RunStudyFromPython(const py::dict& options_dict, const ModelHandle& model, const py::object& on_progress,
                            const py::object& on_point, const py::object& on_note, const py::object& report_assets) {
  const StudyOptions options = OptionsOf(options_dict);
  const std::optional<ReportAssets> assets =
      report_assets.is_none() ? std::nullopt : std::optional<ReportAssets>(AssetsOf(report_assets.cast<py::dict>()));
  StudyHooks hooks;
  // Hooks run on this (the calling) thread while the GIL is released: each takes it to call Python. An
  // exception in a callback ends the study like Ctrl-C and is raised again afterwards.
  std::string callback_error;
  std::atomic<bool> stop_this{false};  // this call's own stop (a callback that failed), beside Ctrl-C's
  // Interrupted: a Ctrl-C since this call began, or a KeyboardInterrupt raised in one of its callbacks.
  const long interrupts_before = interrupts.load();
  std::atomic<bool> interrupted_here{false};
  const auto interrupted = [&] { return interrupted_here.load() || interrupts.load() != interrupts_before; };
  const auto call = [&](const py::object& f, auto&&... args) {
    if (f.is_none() || interrupted() || stop_this) return;
    py::gil_scoped_acquire acquire;
    try {
      f(std::forward<decltype(args)>(args)...);
    } catch (py::error_already_set& e) {
      if (e.matches(PyExc_KeyboardInterrupt)) {
        interrupted_here = true;
      } else {
        callback_error = e.what();
        stop_this = true;
      }
    }
  };
  if (!on_progress.is_none()) {
    hooks.on_progress = [&](const StudyProgress& p) { call(on_progress, p.stage, p.branches, p.points, p.message); };
  }
  if (!on_point.is_none()) {
    hooks.on_point = [&](const StudyPoint& p, const StudyBranch& b) {
      call(on_point, b.id, b.family, p.index, p.T, p.analysis.classification.physical, p.analysis.stability);
    };
  }
  if (!on_note.is_none()) hooks.on_note = [&](const std::string& line) { call(on_note, line); };
  hooks.option_words = OptionKeyword;
  hooks.stop_requested = [&] { return interrupted() || stop_this.load(); };
  StudyResult result;
  std::string report_error, report_note;
  {
    InterruptGuard guard;
    py::gil_scoped_release release;
    result = model ? RunStudy(*model, options, hooks) : RunStudy(options, hooks);
    if (assets && !options.out_dir.empty()) {
      std::string why;
      const std::unique_ptr<HybridModel> built = model ? nullptr : ModelForReport(result, options.models_directory, &why);
      report_error = SaveStudyReport(result, options.out_dir, *assets, model ? model.get() : built.get());
      if (report_error.empty()) report_note = why;  // written, without the orbits' animations
    }
  }
  if (!callback_error.empty()) throw std::runtime_error("a callback of the study failed: " + callback_error);
  py::dict out = StudyDict(result);
  out["report_error"] = report_error;
  out["report_note"] = report_note;
  out["interrupted"] = interrupted();
  out["write_error"] = result.write_error;
  out["wall_seconds"] = result.work.wall_seconds;
  out["report"] = result.report;
  return out;
}

// The saved study as Python's Study holds it (StudyDict; the folder checked as LoadStudy checks it).
py::dict LoadStudyFromPython(const std::string& dir) {
  std::unique_ptr<StudyResult> study_ptr;
  {
    py::gil_scoped_release release;
    study_ptr = std::make_unique<StudyResult>(LoadStudy(dir));
  }
  return StudyDict(*study_ptr);
}

std::string ReportHtml(const std::string& dir, const py::dict& assets, const ModelHandle& model,
                       const std::string& models_directory) {
  const ReportAssets a = AssetsOf(assets);
  if (const std::string missing = a.Missing(); !missing.empty()) {
    throw std::runtime_error("the report's files are missing: " + missing);
  }
  py::gil_scoped_release release;  // reading the folder, building the model (compiled on first use), drawing
  const StudyResult study = LoadStudy(dir);
  std::string why;  // without the model: no animations (Study.report_html's page says nothing of them then)
  const std::unique_ptr<HybridModel> built = model ? nullptr : ModelForReport(study, models_directory, &why);
  return StudyReportHtml(study, a, model ? model.get() : built.get());
}

// ---- point-by-point continuation of one branch of the time-based map
class Continuation {
 public:
  Continuation(const ModelHandle& model, const std::vector<double>& u0, const MapSpec& spec, const py::dict& options)
      : model_(model), map_(*model, IntegratorOf(Get<double>(options, "rtol", 1e-10), Get<double>(options, "atol", 1e-10)),
                            FreeOf(spec)) {
    ContinuationOptions c;
    c.direction = Get<int>(options, "direction", 1);
    c.initial_step = Get<double>(options, "initial_step", c.initial_step);
    c.max_step = Get<double>(options, "max_step", c.max_step);
    c.min_step = Get<double>(options, "min_step", c.min_step);
    c.max_points = Get<int>(options, "max_points", c.max_points);
    if (options.contains("bounds") && !options["bounds"].is_none()) {
      for (const py::handle item : options["bounds"]) {
        const auto b = item.cast<std::tuple<std::string, double, double>>();
        c.bounds.push_back({std::get<0>(b), std::get<1>(b), std::get<2>(b)});
      }
    }
    CheckSize(u0, map_);
    stepper_ = std::make_unique<ContinuationStepper>(&map_, c);
    u0_ = ToVector(u0);
  }

  // Starts (corrects u0) or adds the next point; returns "continuing" or "finished" (see termination()).
  std::string Step() {
    StepStatus status;
    {
      py::gil_scoped_release release;
      status = started_ ? stepper_->Step() : stepper_->Start(u0_);
    }
    started_ = true;
    return status == StepStatus::kFinished ? "finished" : "continuing";
  }
  bool finished() const { return stepper_->finished(); }
  int num_points() const { return static_cast<int>(stepper_->branch().points.size()); }
  py::dict Point(int i) const {
    const Branch& b = stepper_->branch();
    if (i < 0 || i >= static_cast<int>(b.points.size())) throw py::index_error("no point " + std::to_string(i));
    const ContinuationPoint& p = b.points[i];
    py::dict out;
    out["index"] = i;
    out["u"] = ToArray(p.u);
    out["tangent"] = ToArray(p.tangent);
    out["step"] = p.step;
    out["arclength"] = p.arclength;
    out["newton_iterations"] = p.newton_iterations;
    return out;
  }
  std::string termination() const { return ToString(stepper_->branch().termination); }
  std::string message() const { return stepper_->branch().message; }
  std::vector<std::string> unknowns() const { return map_.unknown_names(); }

 private:
  ModelHandle model_;  // the map refers to it
  TimeBasedShooting map_;
  std::unique_ptr<ContinuationStepper> stepper_;
  Vector u0_;
  bool started_ = false;
};

}  // namespace

}  // namespace hybridcont::python

namespace hybridcont::python {
namespace {

// Models and their maps: NativeModel (a HybridModel shared with Python), MapSpec, and the ways to make one.
void BindModels(py::module_& m) {
  py::class_<MapSpec>(m, "MapSpec", "Free parameters of a map and the unknowns that hold them.")
      .def(py::init<>())
      .def(py::init<std::vector<std::string>, std::vector<std::pair<std::string, double>>>(), py::arg("free"),
           py::arg("fix"))
      .def_readwrite("free", &MapSpec::free)
      .def_readwrite("fix", &MapSpec::fix);

  py::class_<HybridModel, ModelHandle>(m, "NativeModel", "A hybrid model of the library (HybridModel).")
      .def_property_readonly("name", &HybridModel::name)
      .def_property_readonly("description", &HybridModel::description)
      .def_property_readonly("num_first_integrals", &HybridModel::num_first_integrals)
      .def_property_readonly("parameters",
                             [](const HybridModel& model) {
                               py::dict out;
                               for (std::size_t i = 0; i < model.parameters().size(); ++i) {
                                 out[py::str(model.parameters()[i].name)] = model.parameter_value(static_cast<int>(i));
                               }
                               return out;
                             })
      .def_property_readonly("phases",
                             [](const HybridModel& model) {
                               std::vector<std::pair<std::string, std::vector<std::string>>> out;
                               for (int i = 0; i < model.num_phases(); ++i) {
                                 out.push_back({model.phase(i).name(), model.phase(i).state_names()});
                               }
                               return out;
                             })
      .def_property_readonly("family_names",
                             [](const HybridModel& model) { return OrbitPresentation(model).family_names(); })
      .def("set_parameter", &HybridModel::SetParameter, py::arg("name"), py::arg("value"))
      .def("clone", [](const HybridModel& model) { return Share(model.Clone()); })
      .def("unknowns",
           [](const ModelHandle& model, const MapSpec& spec) {
             return TimeBasedShooting(*model, IntegratorOptions{}, FreeOf(spec)).unknown_names();
           })
      .def("evaluate", &Evaluate, py::arg("u"), py::arg("spec") = MapSpec{}, py::arg("jacobian") = true,
           py::arg("rtol") = py::none(), py::arg("atol") = py::none())
      .def("floquet", &Floquet, py::arg("u"), py::arg("spec") = MapSpec{}, py::arg("rtol") = py::none(),
           py::arg("atol") = py::none())
      .def("trace", &Trace, py::arg("u"), py::arg("samples") = 400, py::arg("rtol") = py::none(),
           py::arg("atol") = py::none());

  m.def(
      "make_model",
      [](const std::string& name, const std::vector<std::pair<std::string, double>>& parameters,
         const std::string& models_directory, bool compile) {
        std::vector<NamedValue> values;
        for (const auto& [n, v] : parameters) values.push_back({n, v});
        py::gil_scoped_release release;  // a model file is compiled on first use (seconds)
        return Share(MakeStudyModel(name, values, models_directory, nullptr, compile));
      },
      py::arg("name"), py::arg("parameters"), py::arg("models_directory"), py::arg("compile") = true,
      "A built-in model, a model file, or a shipped model file by its name.");
  m.def(
      "model_from_text",
      [](const std::string& text, const std::string& source, bool compile) {
        ModelFileOptions options;
        options.compile = compile;
        py::gil_scoped_release release;
        return Share(LoadModelText(text, source, options));
      },
      py::arg("text"), py::arg("source"), py::arg("compile") = true, "A model from model-file text.");
}

// Studies: run, load, their models and reports, and the text forms of their options.
void BindStudies(py::module_& m) {
  m.def("run_study", &RunStudyFromPython, py::arg("options"), py::arg("model") = ModelHandle(),
        py::arg("on_progress") = py::none(), py::arg("on_point") = py::none(), py::arg("on_note") = py::none(),
        py::arg("report_assets") = py::none());
  m.def("load_study", &LoadStudyFromPython, py::arg("dir"));
  m.def(
      "study_options",
      [] {
        py::list out;
        for (const StudyOptionSpec& spec : StudyOptionSpecs()) {
          py::dict d;
          d["field"] = spec.field;
          d["flag"] = spec.flag;
          d["keyword"] = spec.keyword;
          d["value_name"] = spec.value_name;
          d["help"] = SayOptions(spec.help, OptionKeyword);
          d["flag_help"] = SayOptions(spec.help, OptionFlag);
          d["choices"] = spec.choices;
          d["switch"] = spec.kind == OptionKind::kSwitch;
          d["repeatable"] = IsRepeatable(spec.kind);
          d["decides_results"] = spec.role == OptionRole::kResult;
          d["sweep"] = spec.sweep;
          d["default"] = PythonOf(spec, spec.get(StudyOptions{}));
          out.append(d);
        }
        return out;
      },
      "The options of a study as the library declares them: field, flag, keyword, value_name, help (in keywords), "
      "flag_help (in flags), choices, switch, repeatable, decides_results, sweep, default.");
  m.def(
      "parse_option",
      [](const std::string& field, const std::vector<std::string>& texts) {
        const StudyOptionSpec* spec = FindStudyOption(field);
        if (spec == nullptr) throw std::invalid_argument("'" + field + "': not an option of a study");
        try {
          return PythonOf(*spec, ParseStudyOption(*spec, texts));
        } catch (const StudyOptionError& e) {
          throw std::invalid_argument(e.Say(OptionFlag));  // a command line's text: said with its flags
        }
      },
      py::arg("field"), py::arg("texts"),
      "An option's value from its command-line texts (one per occurrence) in the form its keyword takes, checked "
      "as `hybridcont run` checks it (ValueError naming the flag and the text).");
  m.def(
      "model_of_study",
      [](const std::string& dir, const std::string& models_directory) {
        py::gil_scoped_release release;  // reading the folder, building (compiling) the model
        const StudyResult study = LoadStudy(dir);
        return Share(ModelOfStudy(study, models_directory));
      },
      py::arg("dir"), py::arg("models_directory") = "",
      "The model a saved study was computed on, at its parameter values, rebuilt from its record "
      "(ValueError saying why it cannot: its model file is gone or has changed, or the model was built by the "
      "caller).");
  m.def(
      "check_options",
      [](const py::dict& options) {
        const StudyOptions o = OptionsOf(options);
        py::gil_scoped_release release;  // builds (compiles) the model
        return CheckStudyOptions(o, OptionKeyword);
      },
      py::arg("options"), "Validates study options against the model without computing; returns its notes.");
  m.def("report_html", &ReportHtml, py::arg("dir"), py::arg("assets"), py::arg("model") = ModelHandle(),
        py::arg("models_directory") = "");
}

// Point-by-point continuation of one branch.
void BindContinuation(py::module_& m) {
  py::class_<Continuation>(m, "NativeContinuation")
      .def(py::init<const ModelHandle&, const std::vector<double>&, const MapSpec&, const py::dict&>(),
           py::arg("model"), py::arg("u0"), py::arg("spec"), py::arg("options"))
      .def("step", &Continuation::Step)
      .def_property_readonly("finished", &Continuation::finished)
      .def_property_readonly("num_points", &Continuation::num_points)
      .def("point", &Continuation::Point)
      .def_property_readonly("termination", &Continuation::termination)
      .def_property_readonly("message", &Continuation::message)
      .def_property_readonly("unknowns", &Continuation::unknowns);
}

}  // namespace
}  // namespace hybridcont::python

PYBIND11_MODULE(_hybridcont, m) {
  using namespace hybridcont;
  using namespace hybridcont::python;
  m.doc() = "hybridcont's C++ library (study API, model maps); use the package `hybridcont`, not this module.";
  m.attr("__version__") = Version();
  m.def("builtin_model_names", &BuiltinModelNames, "The names of the built-in C++ models.");

  // A refused option in Python's words: its keyword and the keywords it mentions ("fix {'H': 1}: needs ...").
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const StudyOptionError& e) {
      PyErr_SetString(PyExc_ValueError, e.Say(OptionKeyword).c_str());
    } catch (const py::cast_error& e) {
      // An argument of another type than the function takes (a string where a number belongs): bad input.
      PyErr_SetString(PyExc_ValueError, (std::string("an argument of the wrong type: ") + e.what()).c_str());
    }
  });
  BindModels(m);
  BindStudies(m);
  BindContinuation(m);
}
