#include "hybridcont/model_file.h"

#include <toml++/toml.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <functional>
#include <map>
#include <optional>
#include <set>
#include <sstream>

#include "hybridcont/shooting_layout.h"
#include "model_compiler.h"

namespace hybridcont {
namespace {

// A model file is a few kilobytes; a larger one is not a model file (and parsing it would take long).
constexpr std::uintmax_t kMaxModelFileBytes = 4 << 20;

// The reader: walks the parsed TOML tree, checks every field against the format and builds the spec.
class Reader {
 public:
  Reader(const toml::table& root, std::string file) : root_(root), file_(std::move(file)) {}

  ExpressionModelSpec Read() {
    CheckKeys(root_, "", {"hybridcont", "name", "description", "title", "parameters", "definitions", "phases",
                          "symmetries", "start", "run", "families", "quantities", "figures", "drawing"});
    ReadVersion();
    spec_.name = RequiredString(root_, "name", "");
    if (spec_.name.empty() || spec_.name.find_first_of("/\\ \t\n") != std::string::npos) {
      Fail(root_["name"].node(), "name", "a model name must be non-empty without spaces or slashes, got '" +
                                             spec_.name + "'");
    }
    spec_.description = OptionalString(root_, "description", "", "");
    spec_.setup.title = OptionalString(root_, "title", "", spec_.name);
    ReadParameters();
    ReadDefinitions();
    ReadPhaseHeaders();
    for (std::size_t i = 0; i < phase_tables_.size(); ++i) ReadPhaseFunctions(static_cast<int>(i));
    ReadSymmetries();
    ReadStart();
    ReadRun();
    ReadFamilies();
    ReadQuantities();
    for (const FamilyRule& rule : spec_.setup.families) CheckSetupValue(rule.when, OrbitSymbols());
    ReadFigures();
    ReadDrawing();
    return std::move(spec_);
  }

 private:
  // ---- messages
  SourceLocation At(const toml::node* node, const std::string& field) const {
    SourceLocation where;
    where.file = file_;
    where.field = field;
    if (node != nullptr) where.line = static_cast<int>(node->source().begin.line);
    return where;
  }
  [[noreturn]] void Fail(const toml::node* node, const std::string& field, const std::string& what) const {
    throw ModelInputError(At(node, field), what);
  }
  static std::string Join(const std::string& prefix, const std::string& key) {
    return prefix.empty() ? key : prefix + "." + key;
  }
  static std::string TypeName(const toml::node& n) {
    switch (n.type()) {
      case toml::node_type::table: return "a table";
      case toml::node_type::array: return "an array";
      case toml::node_type::string: return "a string";
      case toml::node_type::integer: return "an integer";
      case toml::node_type::floating_point: return "a number";
      case toml::node_type::boolean: return "a boolean";
      default: return "a date or time";
    }
  }

  // Every key of `table` must be one of `known`.
  void CheckKeys(const toml::table& table, const std::string& prefix, std::initializer_list<const char*> known) const {
    for (auto&& [key, node] : table) {
      const std::string k(key.str());
      if (std::none_of(known.begin(), known.end(), [&](const char* n) { return k == n; })) {
        std::string list;
        for (const char* n : known) list += (list.empty() ? "" : ", ") + std::string(n);
        Fail(&node, Join(prefix, k), "unknown field '" + k + "' (expected one of: " + list + ")");
      }
    }
  }

  // ---- typed access
  const toml::table& RequiredTable(const toml::table& t, const std::string& key, const std::string& prefix) const {
    const toml::node* n = t.get(key);
    if (n == nullptr) Fail(&t, Join(prefix, key), "missing field '" + key + "'");
    if (!n->is_table()) Fail(n, Join(prefix, key), "expected a table, got " + TypeName(*n));
    return *n->as_table();
  }
  const toml::table* OptionalTable(const toml::table& t, const std::string& key, const std::string& prefix) const {
    const toml::node* n = t.get(key);
    if (n == nullptr) return nullptr;
    if (!n->is_table()) Fail(n, Join(prefix, key), "expected a table, got " + TypeName(*n));
    return n->as_table();
  }
  std::string RequiredString(const toml::table& t, const std::string& key, const std::string& prefix) const {
    const toml::node* n = t.get(key);
    if (n == nullptr) Fail(&t, Join(prefix, key), "missing field '" + key + "'");
    return AsString(*n, Join(prefix, key));
  }
  std::string OptionalString(const toml::table& t, const std::string& key, const std::string& prefix,
                             const std::string& fallback) const {
    const toml::node* n = t.get(key);
    return n == nullptr ? fallback : AsString(*n, Join(prefix, key));
  }
  std::string AsString(const toml::node& n, const std::string& field) const {
    if (!n.is_string()) Fail(&n, field, "expected a string, got " + TypeName(n));
    return std::string(n.as_string()->get());
  }
  double AsNumber(const toml::node& n, const std::string& field) const {
    double v = 0.0;
    if (n.is_integer()) v = static_cast<double>(n.as_integer()->get());
    else if (n.is_floating_point()) v = n.as_floating_point()->get();
    else Fail(&n, field, "expected a number, got " + TypeName(n));
    if (!std::isfinite(v)) Fail(&n, field, "expected a finite number");
    return v;
  }
  double OptionalNumber(const toml::table& t, const std::string& key, const std::string& prefix, double fallback) const {
    const toml::node* n = t.get(key);
    return n == nullptr ? fallback : AsNumber(*n, Join(prefix, key));
  }
  int OptionalInteger(const toml::table& t, const std::string& key, const std::string& prefix, int fallback, int lo,
                      int hi) const {
    const toml::node* n = t.get(key);
    if (n == nullptr) return fallback;
    if (!n->is_integer()) Fail(n, Join(prefix, key), "expected an integer, got " + TypeName(*n));
    const std::int64_t v = n->as_integer()->get();
    if (v < lo || v > hi) {
      Fail(n, Join(prefix, key), std::to_string(v) + " is outside [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
    }
    return static_cast<int>(v);
  }
  bool OptionalBool(const toml::table& t, const std::string& key, const std::string& prefix, bool fallback) const {
    const toml::node* n = t.get(key);
    if (n == nullptr) return fallback;
    if (!n->is_boolean()) Fail(n, Join(prefix, key), "expected true or false, got " + TypeName(*n));
    return n->as_boolean()->get();
  }
  const toml::array& AsArray(const toml::node& n, const std::string& field) const {
    if (!n.is_array()) Fail(&n, field, "expected an array, got " + TypeName(n));
    return *n.as_array();
  }
  std::vector<std::string> StringArray(const toml::node& n, const std::string& field) const {
    std::vector<std::string> out;
    const toml::array& a = AsArray(n, field);
    for (std::size_t i = 0; i < a.size(); ++i) out.push_back(AsString(*a.get(i), field + "[" + std::to_string(i) + "]"));
    return out;
  }
  // A set-up value: a number or an expression string (checked later against its symbols).
  SetupValue AsSetupValue(const toml::node& n, const std::string& field) const {
    if (n.is_string()) return SetupValue(std::string(n.as_string()->get()), At(&n, field));
    char buffer[40];
    std::snprintf(buffer, sizeof buffer, "%.17g", AsNumber(n, field));
    return SetupValue(buffer, At(&n, field));
  }
  // An expression string (numbers are accepted and written as constants).
  std::string ExpressionText(const toml::node& n, const std::string& field) const {
    if (n.is_string()) return std::string(n.as_string()->get());
    return AsSetupValue(n, field).expression;
  }

  // ---- symbols
  // Parameters and [definitions] (definitions are expressions over parameters and other definitions).
  ExprPtr GlobalSymbol(const std::string& name) {
    if (auto it = parameter_index_.find(name); it != parameter_index_.end()) return MakeParameter(it->second);
    return Definition(name);
  }
  ExprPtr Definition(const std::string& name) {
    if (auto it = definitions_.find(name); it != definitions_.end()) return it->second;
    const auto src = definition_sources_.find(name);
    if (src == definition_sources_.end()) return nullptr;
    if (!resolving_.insert("definitions." + name).second) {
      Fail(src->second, "definitions." + name, "'" + name + "' is defined in terms of itself");
    }
    const ExprPtr e = ParseExpression(ExpressionText(*src->second, "definitions." + name),
                                      [this](const std::string& s) { return GlobalSymbol(s); },
                                      At(src->second, "definitions." + name));
    if (DependsOnInputs(e)) Fail(src->second, "definitions." + name, "definitions may use parameters only");
    resolving_.erase("definitions." + name);
    definitions_[name] = e;
    return e;
  }
  // A phase's states, its `let` quantities, then the global symbols.
  ExprPtr PhaseSymbol(int phase, const std::string& name) {
    const std::vector<std::string>& states = spec_.phases[phase].state_names;
    if (auto it = std::find(states.begin(), states.end(), name); it != states.end()) {
      return MakeInput(static_cast<int>(it - states.begin()));
    }
    const std::string key = std::to_string(phase) + ":" + name;
    if (auto it = lets_.find(key); it != lets_.end()) return it->second;
    if (const toml::table* let = phase_lets_[phase]) {
      if (const toml::node* n = let->get(name)) {
        const std::string field = "phases." + spec_.phases[phase].name + ".let." + name;
        if (!resolving_.insert(field).second) Fail(n, field, "'" + name + "' is defined in terms of itself");
        const ExprPtr e = ParseExpression(ExpressionText(*n, field),
                                          [this, phase](const std::string& s) { return PhaseSymbol(phase, s); },
                                          At(n, field));
        resolving_.erase(field);
        lets_[key] = e;
        return e;
      }
    }
    return GlobalSymbol(name);
  }
  ExprPtr ParsePhaseExpression(int phase, const toml::node& n, const std::string& field) {
    return ParseExpression(ExpressionText(n, field), [this, phase](const std::string& s) { return PhaseSymbol(phase, s); },
                           At(&n, field));
  }
  // Checks a set-up value against its symbols now, so that a typo is reported before anything runs.
  void CheckSetupValue(const SetupValue& v, const std::vector<std::string>& extra_symbols) {
    ParseExpression(v.expression,
                    [&](const std::string& s) -> ExprPtr {
                      if (std::find(extra_symbols.begin(), extra_symbols.end(), s) != extra_symbols.end()) {
                        return MakeInput(0);
                      }
                      return GlobalSymbol(s);
                    },
                    v.where);
  }
  // Names of the time-based layout's unknowns: t1..t<m+1>, x<i>_<state>, xi (xi1.. for k > 1), H.
  std::vector<std::string> UnknownNames() const {
    std::vector<std::string> names;
    const int m = static_cast<int>(spec_.phases.size());
    for (int i = 0; i <= m; ++i) names.push_back("t" + std::to_string(i + 1));
    for (int i = 0; i <= m; ++i) {
      for (const std::string& s : spec_.phases[i % m].state_names) names.push_back("x" + std::to_string(i + 1) + "_" + s);
    }
    if (num_integrals_ <= 1) {
      names.push_back("xi");
    } else {
      for (int j = 1; j <= num_integrals_; ++j) names.push_back("xi" + std::to_string(j));
    }
    names.push_back("H");
    return names;
  }

  // ---- sections
  void ReadVersion() {
    const toml::node* n = root_.get("hybridcont");
    if (n == nullptr) {
      Fail(&root_, "hybridcont", "missing field 'hybridcont' (the format version; write `hybridcont = " +
                                      std::to_string(kModelFileFormatVersion) + "` on the first line)");
    }
    if (!n->is_integer()) Fail(n, "hybridcont", "expected the format version as an integer, got " + TypeName(*n));
    const std::int64_t v = n->as_integer()->get();
    if (v < 1 || v > kModelFileFormatVersion) {
      Fail(n, "hybridcont", "format version " + std::to_string(v) + " is not supported (this hybridcont reads 1 to " +
                                std::to_string(kModelFileFormatVersion) + ")");
    }
  }

  ParameterRange ParseRange(const toml::node& n, const std::string& field) const {
    const std::string text = AsString(n, field);
    const auto bad = [&](const std::string& why) {
      Fail(&n, field, "range '" + text + "': " + why + " (write it as an interval: \"(0, inf)\", \"[0, 1]\")");
    };
    std::string s = text;
    s.erase(std::remove_if(s.begin(), s.end(), [](char c) { return std::isspace(static_cast<unsigned char>(c)); }), s.end());
    if (s.size() < 5) bad("too short");
    ParameterRange r;
    if (s.front() != '(' && s.front() != '[') bad("expected '(' or '[' first");
    if (s.back() != ')' && s.back() != ']') bad("expected ')' or ']' last");
    r.lower_closed = s.front() == '[';
    r.upper_closed = s.back() == ']';
    const std::size_t comma = s.find(',');
    if (comma == std::string::npos || s.find(',', comma + 1) != std::string::npos) bad("expected two ends separated by one comma");
    const auto end = [&](const std::string& e, double infinity) {
      if (e == "inf" || e == "+inf") return std::numeric_limits<double>::infinity();
      if (e == "-inf") return -std::numeric_limits<double>::infinity();
      const ExprPtr x = ParseExpression(e, nullptr, At(&n, field));
      ExpressionProgram p({x}, 0, false, {});
      const double v = p.EvaluateScalar(nullptr, nullptr);
      if (!std::isfinite(v)) bad("end '" + e + "' is not finite");
      (void)infinity;
      return v;
    };
    r.lower = end(s.substr(1, comma - 1), -1);
    r.upper = end(s.substr(comma + 1, s.size() - comma - 2), 1);
    if (!(r.lower < r.upper)) bad("the lower end must be below the upper end");
    if ((std::isinf(r.lower) && r.lower_closed) || (std::isinf(r.upper) && r.upper_closed)) bad("an infinite end must be open");
    return r;
  }

  void ReadParameters() {
    const toml::table* t = OptionalTable(root_, "parameters", "");
    if (t == nullptr) return;
    for (auto&& [key, node] : *t) {
      const std::string name(key.str());
      const std::string field = "parameters." + name;
      CheckName(&node, field, name);
      ParameterInfo info{name, 0.0, "", {}};
      if (node.is_table()) {
        const toml::table& p = *node.as_table();
        CheckKeys(p, field, {"value", "range", "description"});
        const toml::node* v = p.get("value");
        if (v == nullptr) Fail(&node, field + ".value", "missing field 'value'");
        info.default_value = AsNumber(*v, field + ".value");
        info.description = OptionalString(p, "description", field, "");
        if (const toml::node* r = p.get("range")) info.range = ParseRange(*r, field + ".range");
        if (!info.range.Contains(info.default_value)) {
          Fail(v, field + ".value", "value " + AsSetupValue(*v, field).expression + " is outside the range " +
                                        info.range.ToString());
        }
      } else {
        info.default_value = AsNumber(node, field);
      }
      parameter_index_[name] = static_cast<int>(spec_.parameters.size());
      spec_.parameters.push_back(info);
    }
  }

  void ReadDefinitions() {
    const toml::table* t = OptionalTable(root_, "definitions", "");
    if (t == nullptr) return;
    for (auto&& [key, node] : *t) {
      const std::string name(key.str());
      CheckName(&node, "definitions." + name, name);
      if (parameter_index_.count(name)) Fail(&node, "definitions." + name, "'" + name + "' is also a parameter");
      definition_sources_[name] = &node;
    }
    for (const auto& [name, node] : definition_sources_) {
      Definition(name);
      spec_.setup.definitions.push_back({name, AsSetupValue(*node, "definitions." + name)});
    }
  }

  // A symbol name must be an identifier that is not a function or a reserved name.
  void CheckName(const toml::node* n, const std::string& field, const std::string& name) const {
    static const std::set<std::string> kReserved = {"pi",   "X",    "T",    "sin",  "cos",  "tan",   "asin", "acos",
                                                    "atan", "sinh", "cosh", "tanh", "exp",  "log",   "sqrt", "abs",
                                                    "atan2", "pow", "min",  "max"};
    const bool identifier = !name.empty() && (std::isalpha(static_cast<unsigned char>(name[0])) || name[0] == '_') &&
                            std::all_of(name.begin(), name.end(), [](char c) {
                              return std::isalnum(static_cast<unsigned char>(c)) || c == '_';
                            });
    if (!identifier) Fail(n, field, "'" + name + "' is not a name (letters, digits, '_'; not starting with a digit)");
    if (kReserved.count(name)) Fail(n, field, "'" + name + "' is reserved (a function or a built-in symbol)");
  }

  void ReadPhaseHeaders() {
    const toml::node* n = root_.get("phases");
    if (n == nullptr) Fail(&root_, "phases", "missing field 'phases' (at least one [[phases]] table)");
    const toml::array& a = AsArray(*n, "phases");
    if (a.empty()) Fail(n, "phases", "a model needs at least one phase");
    std::set<std::string> names;
    for (std::size_t i = 0; i < a.size(); ++i) {
      const std::string field = "phases[" + std::to_string(i) + "]";
      if (!a.get(i)->is_table()) Fail(a.get(i), field, "expected a [[phases]] table, got " + TypeName(*a.get(i)));
      const toml::table& t = *a.get(i)->as_table();
      CheckKeys(t, field, {"name", "states", "typical", "let", "ode", "energy", "integrals", "event", "reset", "anchor"});
      ExpressionPhaseSpec p;
      p.name = RequiredString(t, "name", field);
      if (p.name.empty() || !names.insert(p.name).second) {
        Fail(t.get("name"), field + ".name", "phase name '" + p.name + "' is empty or used twice");
      }
      const std::string pf = "phases." + p.name;
      const toml::node* states = t.get("states");
      if (states == nullptr) Fail(&t, pf + ".states", "missing field 'states'");
      p.state_names = StringArray(*states, pf + ".states");
      if (p.state_names.empty() || static_cast<int>(p.state_names.size()) > kMaxPhaseDim) {
        Fail(states, pf + ".states", std::to_string(p.state_names.size()) + " states, expected 1 to " +
                                         std::to_string(kMaxPhaseDim));
      }
      std::set<std::string> seen;
      for (const std::string& s : p.state_names) {
        CheckName(states, pf + ".states", s);
        if (!seen.insert(s).second) Fail(states, pf + ".states", "state '" + s + "' listed twice");
        if (parameter_index_.count(s) || definition_sources_.count(s)) {
          Fail(states, pf + ".states", "state '" + s + "' is also a parameter or definition");
        }
      }
      const int dim = static_cast<int>(p.state_names.size());
      p.typical_state.resize(dim);
      if (const toml::node* typ = t.get("typical")) {
        const toml::array& v = AsArray(*typ, pf + ".typical");
        if (static_cast<int>(v.size()) != dim) {
          Fail(typ, pf + ".typical", std::to_string(v.size()) + " values for " + std::to_string(dim) + " states");
        }
        for (int k = 0; k < dim; ++k) p.typical_state(k) = AsNumber(*v.get(k), pf + ".typical");
      } else {
        // A generic state away from the zeros where expressions such as 1/l are singular.
        for (int k = 0; k < dim; ++k) p.typical_state(k) = 0.3 + 0.1 * k;
      }
      if (i > 0 && t.get("anchor")) Fail(t.get("anchor"), pf + ".anchor", "only the first phase carries the anchor");
      spec_.phases.push_back(std::move(p));
      phase_tables_.push_back(&t);
      phase_lets_.push_back(OptionalTable(t, "let", pf));
    }
  }

  void ReadPhaseFunctions(int i) {
    const toml::table& t = *phase_tables_[i];
    ExpressionPhaseSpec& p = spec_.phases[i];
    const std::string pf = "phases." + p.name;
    const int dim = static_cast<int>(p.state_names.size());
    if (const toml::table* let = phase_lets_[i]) {
      for (auto&& [key, node] : *let) {
        const std::string name(key.str());
        CheckName(&node, pf + ".let." + name, name);
        if (std::find(p.state_names.begin(), p.state_names.end(), name) != p.state_names.end() ||
            parameter_index_.count(name)) {
          Fail(&node, pf + ".let." + name, "'" + name + "' is also a state or a parameter");
        }
        PhaseSymbol(i, name);  // parse now: errors in unused quantities are errors too
      }
    }
    // ode: one expression per state, keyed by the state's name.
    const toml::table& ode = RequiredTable(t, "ode", pf);
    std::vector<ExprPtr> f(dim);
    std::vector<SourceLocation> f_where(dim);
    for (auto&& [key, node] : ode) {
      const std::string name(key.str());
      const auto it = std::find(p.state_names.begin(), p.state_names.end(), name);
      if (it == p.state_names.end()) {
        Fail(&node, pf + ".ode." + name, "'" + name + "' is not a state of phase '" + p.name + "'");
      }
      const int k = static_cast<int>(it - p.state_names.begin());
      f[k] = ParsePhaseExpression(i, node, pf + ".ode." + name);
      f_where[k] = At(&node, pf + ".ode." + name);
    }
    for (int k = 0; k < dim; ++k) {
      if (!f[k]) Fail(&ode, pf + ".ode", "missing the rate of state '" + p.state_names[k] + "'");
    }
    p.vector_field = ExpressionProgram(f, dim, true, f_where);
    // First integrals: `energy` (one) or `integrals` (several).
    const toml::node* energy = t.get("energy");
    const toml::node* integrals = t.get("integrals");
    if ((energy == nullptr) == (integrals == nullptr)) {
      Fail(integrals ? integrals : &t, pf + ".energy",
           "give exactly one of 'energy' (the first integral) or 'integrals' (several)");
    }
    std::vector<ExprPtr> h;
    std::vector<SourceLocation> h_where;
    if (energy) {
      h.push_back(ParsePhaseExpression(i, *energy, pf + ".energy"));
      h_where.push_back(At(energy, pf + ".energy"));
    } else {
      const toml::array& a = AsArray(*integrals, pf + ".integrals");
      if (a.empty()) Fail(integrals, pf + ".integrals", "at least one first integral");
      for (std::size_t k = 0; k < a.size(); ++k) {
        const std::string field = pf + ".integrals[" + std::to_string(k) + "]";
        h.push_back(ParsePhaseExpression(i, *a.get(k), field));
        h_where.push_back(At(a.get(k), field));
      }
    }
    if (i == 0) num_integrals_ = static_cast<int>(h.size());
    if (static_cast<int>(h.size()) != num_integrals_) {
      Fail(energy ? energy : integrals, pf, "phase '" + p.name + "' has " + std::to_string(h.size()) +
                                                " first integrals, the first phase " + std::to_string(num_integrals_) +
                                                " (every phase has the same number)");
    }
    p.integrals = ExpressionProgram(h, dim, true, h_where);
    const toml::node* event = t.get("event");
    if (event == nullptr) Fail(&t, pf + ".event", "missing field 'event' (the phase ends at its downward zero crossing)");
    p.event = ExpressionProgram({ParsePhaseExpression(i, *event, pf + ".event")}, dim, true, {At(event, pf + ".event")});
    // reset: the next phase's states by name (the next phase may have another dimension).
    const int m = static_cast<int>(spec_.phases.size());
    const ExpressionPhaseSpec& next = spec_.phases[(i + 1) % m];
    const toml::table& reset = RequiredTable(t, "reset", pf);
    std::vector<ExprPtr> r(next.state_names.size());
    std::vector<SourceLocation> r_where(next.state_names.size());
    for (auto&& [key, node] : reset) {
      const std::string name(key.str());
      const auto it = std::find(next.state_names.begin(), next.state_names.end(), name);
      if (it == next.state_names.end()) {
        Fail(&node, pf + ".reset." + name, "'" + name + "' is not a state of the next phase '" + next.name +
                                               "' (its states: " + JoinNames(next.state_names) + ")");
      }
      const int k = static_cast<int>(it - next.state_names.begin());
      r[k] = ParsePhaseExpression(i, node, pf + ".reset." + name);
      r_where[k] = At(&node, pf + ".reset." + name);
    }
    for (std::size_t k = 0; k < r.size(); ++k) {
      if (!r[k]) {
        Fail(&reset, pf + ".reset", "missing the value of state '" + next.state_names[k] + "' of the next phase '" +
                                        next.name + "' (the reset gives all " + std::to_string(r.size()) + " of them)");
      }
    }
    p.reset = ExpressionProgram(r, dim, true, r_where);
    if (i == 0) {
      const toml::node* anchor = t.get("anchor");
      if (anchor == nullptr) {
        Fail(&t, pf + ".anchor", "missing field 'anchor' in the first phase (the Poincaré section: its downward zero crossing)");
      }
      spec_.anchor = ExpressionProgram({ParsePhaseExpression(0, *anchor, pf + ".anchor")}, dim, true,
                                       {At(anchor, pf + ".anchor")});
    }
  }

  static std::string JoinNames(const std::vector<std::string>& names) {
    std::string s;
    for (const std::string& n : names) s += (s.empty() ? "" : ", ") + n;
    return s;
  }

  void ReadSymmetries() {
    const toml::node* n = root_.get("symmetries");
    if (n == nullptr) return;
    const toml::array& a = AsArray(*n, "symmetries");
    for (std::size_t i = 0; i < a.size(); ++i) {
      const std::string field = "symmetries[" + std::to_string(i) + "]";
      if (!a.get(i)->is_table()) Fail(a.get(i), field, "expected a [[symmetries]] table");
      const toml::table& t = *a.get(i)->as_table();
      CheckKeys(t, field, {"name", "reverses_time", "flip"});
      ModelSymmetry s;
      s.name = RequiredString(t, "name", field);
      if (s.name.empty()) Fail(t.get("name"), field + ".name", "a symmetry needs a name");
      s.reverses_time = OptionalBool(t, "reverses_time", field, false);
      const toml::table* flip = OptionalTable(t, "flip", field);
      for (const ExpressionPhaseSpec& p : spec_.phases) s.state_signs.push_back(Vector::Ones(p.state_names.size()));
      if (flip) {
        for (auto&& [key, node] : *flip) {
          const std::string phase(key.str());
          const std::string ff = field + ".flip." + phase;
          const auto it = std::find_if(spec_.phases.begin(), spec_.phases.end(),
                                       [&](const ExpressionPhaseSpec& p) { return p.name == phase; });
          if (it == spec_.phases.end()) Fail(&node, ff, "'" + phase + "' is not a phase");
          const int k = static_cast<int>(it - spec_.phases.begin());
          for (const std::string& state : StringArray(node, ff)) {
            const auto st = std::find(it->state_names.begin(), it->state_names.end(), state);
            if (st == it->state_names.end()) Fail(&node, ff, "'" + state + "' is not a state of phase '" + phase + "'");
            s.state_signs[k](st - it->state_names.begin()) = -1.0;
          }
        }
      }
      for (const ModelSymmetry& known : spec_.symmetries) {
        if (known.name == s.name) Fail(t.get("name"), field + ".name", "symmetry '" + s.name + "' declared twice");
      }
      const bool flips = std::any_of(s.state_signs.begin(), s.state_signs.end(),
                                     [](const Vector& signs) { return (signs.array() < 0.0).any(); });
      if (!flips && !s.reverses_time) {
        Fail(flip ? static_cast<const toml::node*>(flip) : &t, field + ".flip",
             "symmetry '" + s.name + "' flips no state and does not reverse time (it is the identity)");
      }
      spec_.symmetries.push_back(std::move(s));
    }
  }

  void CheckUnknown(const toml::node* n, const std::string& field, const std::string& name, bool allow_period) const {
    const std::vector<std::string> names = UnknownNames();
    if (allow_period && name == "period") return;
    if (std::find(names.begin(), names.end(), name) == names.end()) {
      Fail(n, field, "'" + name + "' is not an unknown of the model (unknowns: " + JoinNames(names) +
                         (allow_period ? "; or 'period', the sum of all durations" : "") + ")");
    }
  }

  void ReadStart() {
    const toml::table* t = OptionalTable(root_, "start", "");
    if (t == nullptr) Fail(&root_, "start", "missing table [start] (where the exploration begins)");
    CheckKeys(*t, "start", {"kind", "values", "conditions"});
    const std::string kind = OptionalString(*t, "kind", "start", "singular");
    if (kind == "singular") spec_.setup.start.kind = StartSpec::Kind::kSingular;
    else if (kind == "guess") spec_.setup.start.kind = StartSpec::Kind::kGuess;
    else Fail(t->get("kind"), "start.kind", "'" + kind + "': expected 'singular' or 'guess'");
    if (const toml::table* values = OptionalTable(*t, "values", "start")) {
      for (auto&& [key, node] : *values) {
        const std::string name(key.str());
        CheckUnknown(&node, "start.values." + name, name, false);
        SetupValue v = AsSetupValue(node, "start.values." + name);
        CheckSetupValue(v, {});
        spec_.setup.start.values.push_back({name, v});
      }
    }
    if (const toml::node* c = t->get("conditions")) {
      const toml::array& a = AsArray(*c, "start.conditions");
      for (std::size_t i = 0; i < a.size(); ++i) {
        const std::string field = "start.conditions[" + std::to_string(i) + "]";
        if (!a.get(i)->is_table()) Fail(a.get(i), field, "expected a table { terms = {...}, description = \"...\" }");
        const toml::table& ct = *a.get(i)->as_table();
        CheckKeys(ct, field, {"terms", "description"});
        StartSpec::Condition cond;
        const toml::table& terms = RequiredTable(ct, "terms", field);
        for (auto&& [key, node] : terms) {
          const std::string name(key.str());
          CheckUnknown(&node, field + ".terms." + name, name, false);
          cond.terms.push_back({name, AsNumber(node, field + ".terms." + name)});
        }
        if (cond.terms.empty()) Fail(&terms, field + ".terms", "a condition needs at least one term");
        cond.description = OptionalString(ct, "description", field, "");
        spec_.setup.start.conditions.push_back(cond);
      }
    }
  }

  void ReadRun() {
    RunSpec& run = spec_.setup.run;
    // Without a [run] table: |xi| <= 1 and the defaults of RunSpec; a model file should bound H.
    run.bounds.push_back({"xi", "-1", "1"});
    const toml::table* t = OptionalTable(root_, "run", "");
    if (t == nullptr) return;
    CheckKeys(*t, "run", {"bounds", "scales", "max_branches", "max_depth", "max_points", "initial_step", "max_step",
                          "keyframes"});
    if (const toml::table* b = OptionalTable(*t, "bounds", "run")) {
      for (auto&& [key, node] : *b) {
        const std::string name(key.str());
        const std::string field = "run.bounds." + name;
        CheckUnknown(&node, field, name, true);
        const toml::array& a = AsArray(node, field);
        if (a.size() != 2) Fail(&node, field, "expected [lower, upper]");
        BoundSpec bound{name, AsSetupValue(*a.get(0), field + "[0]"), AsSetupValue(*a.get(1), field + "[1]")};
        CheckSetupValue(bound.lower, {});
        CheckSetupValue(bound.upper, {});
        std::erase_if(run.bounds, [&](const BoundSpec& x) { return x.component == name; });
        run.bounds.push_back(bound);
      }
    }
    if (const toml::table* s = OptionalTable(*t, "scales", "run")) {
      for (auto&& [key, node] : *s) {
        const std::string name(key.str());
        CheckUnknown(&node, "run.scales." + name, name, false);
        SetupValue v = AsSetupValue(node, "run.scales." + name);
        CheckSetupValue(v, {});
        run.scales.push_back({name, v});
      }
    }
    run.max_branches = OptionalInteger(*t, "max_branches", "run", run.max_branches, 1, 100000);
    run.max_depth = OptionalInteger(*t, "max_depth", "run", run.max_depth, 0, 100);
    run.max_points = OptionalInteger(*t, "max_points", "run", run.max_points, 2, 10000000);
    run.initial_step = OptionalNumber(*t, "initial_step", "run", run.initial_step);
    run.max_step = OptionalNumber(*t, "max_step", "run", run.max_step);
    if (!(run.initial_step > 0)) Fail(t->get("initial_step"), "run.initial_step", "must be positive");
    if (!(run.max_step >= run.initial_step)) Fail(t->get("max_step"), "run.max_step", "must be at least initial_step");
    if (const toml::table* k = OptionalTable(*t, "keyframes", "run")) {
      CheckKeys(*k, "run.keyframes", {"component", "value", "orbits"});
      run.keyframe_component = OptionalString(*k, "component", "run.keyframes", "H");
      if (run.keyframe_component != "H" && run.keyframe_component != "T") {
        Fail(k->get("component"), "run.keyframes.component", "expected \"H\" or \"T\"");
      }
      if (const toml::node* v = k->get("value")) run.keyframe_value = AsSetupValue(*v, "run.keyframes.value");
      CheckSetupValue(run.keyframe_value, {});
      run.keyframe_orbits = OptionalInteger(*k, "orbits", "run.keyframes", run.keyframe_orbits, 0, 100);
    }
  }

  std::vector<std::string> OrbitSymbols() const {
    std::vector<std::string> s = UnknownNames();
    s.push_back("T");
    for (const QuantitySpec& q : spec_.setup.quantities) s.push_back(q.name);
    return s;
  }

  void ReadFamilies() {
    const toml::node* n = root_.get("families");
    if (n == nullptr) return;
    const toml::array& a = AsArray(*n, "families");
    for (std::size_t i = 0; i < a.size(); ++i) {
      const std::string field = "families[" + std::to_string(i) + "]";
      if (!a.get(i)->is_table()) Fail(a.get(i), field, "expected a [[families]] table");
      const toml::table& t = *a.get(i)->as_table();
      CheckKeys(t, field, {"name", "when"});
      FamilyRule rule;
      rule.name = RequiredString(t, "name", field);
      const toml::node* when = t.get("when");
      rule.when = when ? AsSetupValue(*when, field + ".when") : SetupValue("1", At(&t, field));
      spec_.setup.families.push_back(rule);
    }
  }

  void ReadQuantities() {
    const toml::table* t = OptionalTable(root_, "quantities", "");
    if (t == nullptr) return;
    const std::vector<std::string> unknowns = UnknownNames();
    for (auto&& [key, node] : *t) {
      const std::string name(key.str());
      const std::string field = "quantities." + name;
      CheckName(&node, field, name);
      if (std::find(unknowns.begin(), unknowns.end(), name) != unknowns.end() || parameter_index_.count(name)) {
        Fail(&node, field, "'" + name + "' is also an unknown or a parameter");
      }
      QuantitySpec q;
      q.name = name;
      if (node.is_table()) {
        CheckKeys(*node.as_table(), field, {"expression", "description"});
        const toml::node* e = node.as_table()->get("expression");
        if (e == nullptr) Fail(&node, field + ".expression", "missing field 'expression'");
        q.expression = AsSetupValue(*e, field + ".expression");
        q.description = OptionalString(*node.as_table(), "description", field, "");
      } else {
        q.expression = AsSetupValue(node, field);
      }
      spec_.setup.quantities.push_back(q);
    }
    // Quantities may use one another only through the unknowns: check each against the unknowns.
    for (const QuantitySpec& q : spec_.setup.quantities) {
      std::vector<std::string> symbols = UnknownNames();
      symbols.push_back("T");
      CheckSetupValue(q.expression, symbols);
    }
  }

  void ReadFigures() {
    const toml::node* n = root_.get("figures");
    if (n == nullptr) return;
    const toml::array& a = AsArray(*n, "figures");
    std::vector<std::string> columns = OrbitSymbols();
    for (std::size_t i = 0; i < a.size(); ++i) {
      const std::string field = "figures[" + std::to_string(i) + "]";
      if (!a.get(i)->is_table()) Fail(a.get(i), field, "expected a [[figures]] table");
      const toml::table& t = *a.get(i)->as_table();
      CheckKeys(t, field, {"file", "title", "x", "y", "zoom"});
      FigureSpec f;
      f.file = RequiredString(t, "file", field);
      const bool safe = f.file.size() > 4 && f.file.substr(f.file.size() - 4) == ".png" &&
                        std::all_of(f.file.begin(), f.file.end(), [](char c) {
                          return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.';
                        });
      if (!safe) Fail(t.get("file"), field + ".file", "'" + f.file + "': a plain file name ending in .png");
      f.title = OptionalString(t, "title", field, "");
      f.x = RequiredString(t, "x", field);
      const toml::node* y = t.get("y");
      if (y == nullptr) Fail(&t, field + ".y", "missing field 'y'");
      f.y = y->is_string() ? std::vector<std::string>{AsString(*y, field + ".y")} : StringArray(*y, field + ".y");
      for (const std::string& c : f.y) {
        if (std::find(columns.begin(), columns.end(), c) == columns.end()) {
          Fail(y, field + ".y", "'" + c + "' is not a column (an unknown, T, or a quantity)");
        }
      }
      if (std::find(columns.begin(), columns.end(), f.x) == columns.end()) {
        Fail(t.get("x"), field + ".x", "'" + f.x + "' is not a column (an unknown, T, or a quantity)");
      }
      f.zoom_special_points = OptionalBool(t, "zoom", field, false);
      spec_.setup.figures.push_back(f);
    }
  }

  void ReadDrawing() {
    const toml::table* t = OptionalTable(root_, "drawing", "");
    if (t == nullptr) return;
    DrawingSpec& d = spec_.setup.drawing;
    for (auto&& [key, node] : *t) {
      const std::string k(key.str());
      if (k == "ground") {
        d.ground = OptionalBool(*t, "ground", "drawing", true);
        continue;
      }
      if (k == "mass_radius") {
        d.mass_radius = OptionalNumber(*t, "mass_radius", "drawing", d.mass_radius);
        if (!(d.mass_radius > 0)) Fail(&node, "drawing.mass_radius", "must be positive");
        continue;
      }
      const auto it = std::find_if(spec_.phases.begin(), spec_.phases.end(),
                                   [&](const ExpressionPhaseSpec& p) { return p.name == k; });
      if (it == spec_.phases.end()) {
        Fail(&node, "drawing." + k, "'" + k + "' is neither a phase nor one of: ground, mass_radius");
      }
      const int phase = static_cast<int>(it - spec_.phases.begin());
      const std::string field = "drawing." + k;
      if (!node.is_table()) Fail(&node, field, "expected a table");
      const toml::table& pt = *node.as_table();
      CheckKeys(pt, field, {"x_velocity", "points", "lines", "masses"});
      DrawingSpec::PhaseDrawing pd;
      pd.phase = k;
      const auto check = [&](const toml::node& n, const std::string& f) {
        SetupValue v = AsSetupValue(n, f);
        // The symbols OrbitPresentation gives a drawing: the phase's states, X, parameters, definitions
        // (not the phase's let quantities, which the run would refuse after compiling the model).
        const std::vector<std::string>& states = spec_.phases[phase].state_names;
        ParseExpression(v.expression,
                        [&](const std::string& s) -> ExprPtr {
                          if (s == "X" || std::find(states.begin(), states.end(), s) != states.end()) return MakeInput(0);
                          return GlobalSymbol(s);
                        },
                        v.where);
        return v;
      };
      if (const toml::node* v = pt.get("x_velocity")) pd.x_velocity = check(*v, field + ".x_velocity");
      std::set<std::string> point_names;
      if (const toml::table* pts = OptionalTable(pt, "points", field)) {
        for (auto&& [pk, pn] : *pts) {
          const std::string name(pk.str());
          const std::string pf = field + ".points." + name;
          const toml::array& xy = AsArray(pn, pf);
          if (xy.size() != 2) Fail(&pn, pf, "expected [x, y]");
          pd.points.push_back({name, check(*xy.get(0), pf + "[0]"), check(*xy.get(1), pf + "[1]")});
          point_names.insert(name);
        }
      }
      const auto check_point = [&](const toml::node* n, const std::string& f, const std::string& name) {
        if (!point_names.count(name)) Fail(n, f, "'" + name + "' is not a point of drawing." + k);
      };
      if (const toml::node* lines = pt.get("lines")) {
        const toml::array& a = AsArray(*lines, field + ".lines");
        for (std::size_t i = 0; i < a.size(); ++i) {
          const std::string lf = field + ".lines[" + std::to_string(i) + "]";
          std::vector<std::string> line = StringArray(*a.get(i), lf);
          if (line.size() < 2) Fail(a.get(i), lf, "a line needs at least two points");
          for (const std::string& p : line) check_point(a.get(i), lf, p);
          pd.lines.push_back(line);
        }
      }
      if (const toml::node* masses = pt.get("masses")) {
        for (const std::string& p : StringArray(*masses, field + ".masses")) check_point(masses, field + ".masses", p);
        pd.masses = StringArray(*masses, field + ".masses");
      }
      d.phases.push_back(pd);
    }
  }

  const toml::table& root_;
  std::string file_;
  ExpressionModelSpec spec_;
  std::map<std::string, int> parameter_index_;
  std::map<std::string, const toml::node*> definition_sources_;
  std::map<std::string, ExprPtr> definitions_;
  std::map<std::string, ExprPtr> lets_;
  std::set<std::string> resolving_;
  std::vector<const toml::table*> phase_tables_;
  std::vector<const toml::table*> phase_lets_;
  int num_integrals_ = 1;
};

}  // namespace

namespace {

// Longest chain of dotted keys the reader accepts (the format's deepest is 3: `[drawing.flight]` plus a
// key). toml++ builds and destroys dotted keys recursively: `[a.a.a...]` 100000 deep overflows the stack
// before any field is checked, so such a chain is refused before parsing.
constexpr int kMaxKeyDepth = 32;

// Throws ModelInputError at the first chain of more than kMaxKeyDepth dotted keys outside strings and
// comments (a key's parts may be quoted strings: `"a"."b"`).
void CheckKeyDepth(const std::string& text, const std::string& file_name) {
  int line = 1, dots = 0;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (c == '\n') {
      ++line, dots = 0;
    } else if (c == '#') {
      while (i + 1 < text.size() && text[i + 1] != '\n') ++i;
    } else if (c == '"' || c == '\'') {  // a string: skipped, it is one part of a key at most
      const bool multi = text.compare(i, 3, std::string(3, c)) == 0;
      const std::string close = multi ? std::string(3, c) : std::string(1, c);
      std::size_t j = i + close.size();
      while (j < text.size() && text.compare(j, close.size(), close) != 0) {
        if (c == '"' && text[j] == '\\') ++j;  // escapes only in basic strings
        else if (!multi && text[j] == '\n') break;  // unterminated: the TOML parser reports it
        if (j < text.size() && text[j] == '\n') ++line;
        ++j;
      }
      const bool closed = j < text.size() && text.compare(j, close.size(), close) == 0;
      i = closed ? j + close.size() - 1 : j - 1;  // unterminated: resume at the line's end
    } else if (c == '.') {
      if (++dots > kMaxKeyDepth) {
        throw ModelInputError(SourceLocation{file_name, line, ""},
                              "keys nested more than " + std::to_string(kMaxKeyDepth) + " deep (a.b.c...)");
      }
    } else if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == ' ' || c == '\t' ||
                 c == '+')) {
      dots = 0;  // anything else ends a dotted key
    }
  }
}

}  // namespace

ExpressionModelSpec ParseModelText(const std::string& text, const std::string& file_name) {
  CheckKeyDepth(text, file_name);
  toml::table root;
  try {
    root = toml::parse(text, file_name);
  } catch (const toml::parse_error& e) {
    SourceLocation where;
    where.file = file_name;
    where.line = static_cast<int>(e.source().begin.line);
    throw ModelInputError(where, "TOML syntax: " + std::string(e.description()) + " (column " +
                                     std::to_string(e.source().begin.column) + ")");
  }
  return Reader(root, file_name).Read();
}

ExpressionModelSpec ReadModelFile(const std::filesystem::path& path) {
  const auto fail = [&](const std::string& why) { throw ModelInputError(SourceLocation{path.string(), 0, ""}, why); };
  // Checked before opening: a FIFO or a device would block or never end (`z.toml -> /dev/zero`).
  std::error_code ec;
  const std::filesystem::file_status status = std::filesystem::status(path, ec);
  if (ec || !std::filesystem::exists(status)) {
    fail("cannot read the model file (" + (ec ? ec.message() : std::string("no such file")) + ")");
  }
  if (std::filesystem::is_directory(status)) fail("cannot read the model file: it is a folder");
  if (!std::filesystem::is_regular_file(status)) fail("cannot read the model file: not a regular file");
  const std::uintmax_t size = std::filesystem::file_size(path, ec);
  if (!ec && size > kMaxModelFileBytes) {
    fail("the model file has " + std::to_string(size) + " bytes; a model file has at most " +
         std::to_string(kMaxModelFileBytes) + " bytes");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) fail("cannot read the model file (" + std::string(std::strerror(errno)) + ")");
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) fail("cannot read the model file (read error)");
  return ParseModelText(text.str(), path.string());
}

HybridModel LoadModelFile(const std::filesystem::path& path, const ModelFileOptions& options) {
  ExpressionModelSpec spec = ReadModelFile(path);
  std::shared_ptr<const CompiledPrograms> compiled;
  if (options.compile) compiled = internal::CompileModel(spec, options);
  try {
    return BuildExpressionModel(std::move(spec), std::move(compiled));
  } catch (const ModelInputError&) {
    throw;
  } catch (const std::invalid_argument& e) {
    throw ModelInputError(SourceLocation{path.string(), 0, ""}, e.what());
  }
}

bool IsModelFilePath(const std::string& name_or_path) {
  return name_or_path.size() > 5 && name_or_path.substr(name_or_path.size() - 5) == ".toml";
}

}  // namespace hybridcont
