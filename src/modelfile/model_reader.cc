// The reader's common means: the walk over the top-level tables, messages with file, line and field,
// typed access to TOML nodes, and the symbols of expressions (parameters, definitions, phase states and lets).
#include "model_reader.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace hybridcont::internal {

ExpressionModelSpec Reader::Read() {
  CheckKeys(root_, "", {"hybridcont", "name", "description", "title", "parameters", "definitions", "phases",
                        "symmetries", "start", "run", "families", "quantities", "figures", "drawing",
                        "conservative", "observables", "constraints", "modes", "transitions", "word"});
  ReadVersion();
  conservative_ = OptionalBool(root_, "conservative", "", true);
  if (!conservative_) num_integrals_ = 0;
  spec_.name = RequiredString(root_, "name", "");
  CheckLabel(root_["name"].node(), "name", spec_.name);
  spec_.description = OptionalString(root_, "description", "", "");
  CheckText(root_["description"].node(), "description", spec_.description);
  spec_.setup.title = OptionalString(root_, "title", "", spec_.name);
  CheckText(root_["title"].node(), "title", spec_.setup.title);
  ReadParameters();
  ReadDefinitions();
  ReadPhaseHeaders();
  for (std::size_t i = 0; i < phase_tables_.size(); ++i) ReadPhaseFunctions(static_cast<int>(i));
  ReadSymmetries();
  ReadStart();
  ReadRun();
  ReadFamilies();
  ReadQuantities();
  ReadObservables();
  ReadConstraints();
  for (const FamilyRule& rule : spec_.setup.families) {
    if (rule.word.empty()) {
      CheckSetupValue(rule.when, OrbitSymbols());
    } else {  // another word's rule: its unknowns and period (quantities are the file word's)
      std::vector<std::string> symbols = UnknownNames(rule.word);
      symbols.push_back("T");
      CheckSetupValue(rule.when, symbols);
    }
  }
  ReadFigures();
  ReadDrawing();
  if (!transition_tables_.empty()) {  // an automaton: the catalogue kept, the spec that of the file's word
    automaton_.phases = spec_.phases;
    automaton_.symmetries = spec_.symmetries;
    automaton_.observables = spec_.observables;
    automaton_.setup = spec_.setup;
    spec_.automaton = std::make_shared<const ExpressionAutomatonSpec>(std::move(automaton_));
    ExpressionModelSpec word = ExpressionWordSpec(spec_, spec_.automaton->word);
    word.automaton = spec_.automaton;
    return word;
  }
  if (root_.get("word")) Fail(root_.get("word"), "word", "'word' belongs to an automaton ([[modes]] and [[transitions]])");
  return std::move(spec_);
}

SourceLocation Reader::At(const toml::node* node, const std::string& field) const {
  SourceLocation where;
  where.file = file_;
  where.field = field;
  if (node != nullptr) where.line = static_cast<int>(node->source().begin.line);
  return where;
}

void Reader::Fail(const toml::node* node, const std::string& field, const std::string& what) const {
  throw ModelInputError(At(node, field), what);
}

std::string Reader::Join(const std::string& prefix, const std::string& key) {
  return prefix.empty() ? key : prefix + "." + key;
}

std::string Reader::TypeName(const toml::node& n) {
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

void Reader::CheckKeys(const toml::table& table, const std::string& prefix, std::initializer_list<const char*> known) const {
  for (auto&& [key, node] : table) {
    const std::string k(key.str());
    if (std::none_of(known.begin(), known.end(), [&](const char* n) { return k == n; })) {
      std::string list;
      for (const char* n : known) list += (list.empty() ? "" : ", ") + std::string(n);
      Fail(&node, Join(prefix, k), "unknown field '" + k + "' (expected one of: " + list + ")");
    }
  }
}

const toml::table& Reader::RequiredTable(const toml::table& t, const std::string& key, const std::string& prefix) const {
  const toml::node* n = t.get(key);
  if (n == nullptr) Fail(&t, Join(prefix, key), "missing field '" + key + "'");
  if (!n->is_table()) Fail(n, Join(prefix, key), "expected a table, got " + TypeName(*n));
  return *n->as_table();
}

const toml::table* Reader::OptionalTable(const toml::table& t, const std::string& key, const std::string& prefix) const {
  const toml::node* n = t.get(key);
  if (n == nullptr) return nullptr;
  if (!n->is_table()) Fail(n, Join(prefix, key), "expected a table, got " + TypeName(*n));
  return n->as_table();
}

std::string Reader::RequiredString(const toml::table& t, const std::string& key, const std::string& prefix) const {
  const toml::node* n = t.get(key);
  if (n == nullptr) Fail(&t, Join(prefix, key), "missing field '" + key + "'");
  return AsString(*n, Join(prefix, key));
}

std::string Reader::OptionalString(const toml::table& t, const std::string& key, const std::string& prefix,
                           const std::string& fallback) const {
  const toml::node* n = t.get(key);
  return n == nullptr ? fallback : AsString(*n, Join(prefix, key));
}

std::string Reader::AsString(const toml::node& n, const std::string& field) const {
  if (!n.is_string()) Fail(&n, field, "expected a string, got " + TypeName(n));
  return std::string(n.as_string()->get());
}

double Reader::AsNumber(const toml::node& n, const std::string& field) const {
  double v = 0.0;
  if (n.is_integer()) v = static_cast<double>(n.as_integer()->get());
  else if (n.is_floating_point()) v = n.as_floating_point()->get();
  else Fail(&n, field, "expected a number, got " + TypeName(n));
  if (!std::isfinite(v)) Fail(&n, field, "expected a finite number");
  return v;
}

double Reader::OptionalNumber(const toml::table& t, const std::string& key, const std::string& prefix, double fallback) const {
  const toml::node* n = t.get(key);
  return n == nullptr ? fallback : AsNumber(*n, Join(prefix, key));
}

int Reader::OptionalInteger(const toml::table& t, const std::string& key, const std::string& prefix, int fallback, int lo,
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

bool Reader::OptionalBool(const toml::table& t, const std::string& key, const std::string& prefix, bool fallback) const {
  const toml::node* n = t.get(key);
  if (n == nullptr) return fallback;
  if (!n->is_boolean()) Fail(n, Join(prefix, key), "expected true or false, got " + TypeName(*n));
  return n->as_boolean()->get();
}

const toml::array& Reader::AsArray(const toml::node& n, const std::string& field) const {
  if (!n.is_array()) Fail(&n, field, "expected an array, got " + TypeName(n));
  return *n.as_array();
}

std::vector<std::string> Reader::StringArray(const toml::node& n, const std::string& field) const {
  std::vector<std::string> out;
  const toml::array& a = AsArray(n, field);
  if (a.size() > kMaxListLength) {
    Fail(&n, field, std::to_string(a.size()) + " entries; a list of names has at most " +
                        std::to_string(kMaxListLength));
  }
  for (std::size_t i = 0; i < a.size(); ++i) out.push_back(AsString(*a.get(i), field + "[" + std::to_string(i) + "]"));
  return out;
}

SetupValue Reader::AsSetupValue(const toml::node& n, const std::string& field) const {
  if (n.is_string()) return SetupValue(std::string(n.as_string()->get()), At(&n, field));
  char buffer[40];
  std::snprintf(buffer, sizeof buffer, "%.17g", AsNumber(n, field));
  return SetupValue(buffer, At(&n, field));
}

std::string Reader::ExpressionText(const toml::node& n, const std::string& field) const {
  if (n.is_string()) return std::string(n.as_string()->get());
  return AsSetupValue(n, field).expression;
}

ExprPtr Reader::GlobalSymbol(const std::string& name) {
  if (auto it = parameter_index_.find(name); it != parameter_index_.end()) return MakeParameter(it->second);
  return Definition(name);
}

ExprPtr Reader::Definition(const std::string& name) {
  if (auto it = definitions_.find(name); it != definitions_.end()) return it->second;
  const auto src = definition_sources_.find(name);
  if (src == definition_sources_.end()) return nullptr;
  if (!resolving_.insert("definitions." + name).second) {
    Fail(src->second, "definitions." + name, "'" + name + "' is defined in terms of itself");
  }
  BeginResolving(src->second, "definitions." + name, name);
  const ExprPtr e = ParseExpression(ExpressionText(*src->second, "definitions." + name),
                                    [this](const std::string& s) { return GlobalSymbol(s); },
                                    At(src->second, "definitions." + name));
  if (DependsOnInputs(e)) Fail(src->second, "definitions." + name, "definitions may use parameters only");
  resolving_.erase("definitions." + name);
  resolving_chain_.pop_back();
  definitions_[name] = e;
  return e;
}

void Reader::BeginResolving(const toml::node* n, const std::string& field, const std::string& name) {
  if (resolving_chain_.size() >= kMaxSymbolNesting) {
    std::string chain;
    for (std::size_t i = 0; i < resolving_chain_.size(); ++i) {
      if (i == 3 && resolving_chain_.size() > 5) {
        chain += " uses ... (" + std::to_string(resolving_chain_.size() - 5) + " more)";
        i = resolving_chain_.size() - 2;
      }
      chain += (i == 0 ? "'" : " uses '") + resolving_chain_[i] + "'";
    }
    Fail(n, field, "definitions and let quantities that use one another more than " +
                       std::to_string(kMaxSymbolNesting) + " deep: " + chain + " uses '" + name +
                       "'; a chain that long is refused (resolving it recurses that deep)");
  }
  resolving_chain_.push_back(name);
}

ExprPtr Reader::PhaseSymbol(int phase, const std::string& name) {
  const std::vector<std::string>& states = spec_.phases[phase].state_names;
  if (auto it = std::find(states.begin(), states.end(), name); it != states.end()) {
    return MakeInput(static_cast<int>(it - states.begin()));
  }
  if (phase < static_cast<int>(mechanical_names_.size())) {
    // Pinned coordinates, then their velocities, numbered after the states; elsewhere they are unknown.
    const MechanicalNames& mech = mechanical_names_[phase];
    const int dim = static_cast<int>(states.size()), np = static_cast<int>(mech.pinned.size());
    for (int k = 0; k < np; ++k) {
      for (int which = 0; which < 2; ++which) {
        if (name == (which == 0 ? mech.pinned : mech.pinned_velocities)[k]) {
          return pinned_symbols_phase_ == phase ? MakeInput(dim + which * np + k) : nullptr;
        }
      }
    }
  }
  // A quantity read with the pinned coordinates as symbols is cached apart: elsewhere it is unknown.
  const std::string key = std::to_string(phase) + (pinned_symbols_phase_ == phase ? "+pinned:" : ":") + name;
  if (auto it = lets_.find(key); it != lets_.end()) return it->second;
  const toml::table* transition_let = transition_lets_.empty() ? nullptr : transition_lets_[phase];
  for (const toml::table* let : {transition_let, phase_lets_[phase]}) {
    if (let == nullptr) continue;
    if (const toml::node* n = let->get(name)) {
      const std::string field = (let == transition_let ? TransitionField(phase) : "phases." + spec_.phases[phase].name) +
                                ".let." + name;
      if (!resolving_.insert(field).second) Fail(n, field, "'" + name + "' is defined in terms of itself");
      BeginResolving(n, field, name);
      const ExprPtr e = ParseExpression(ExpressionText(*n, field),
                                        [this, phase](const std::string& s) { return PhaseSymbol(phase, s); },
                                        At(n, field));
      resolving_.erase(field);
      resolving_chain_.pop_back();
      lets_[key] = e;
      return e;
    }
  }
  return GlobalSymbol(name);
}

ExprPtr Reader::ParsePhaseExpression(int phase, const toml::node& n, const std::string& field) {
  return ParseExpression(ExpressionText(n, field), [this, phase](const std::string& s) { return PhaseSymbol(phase, s); },
                         At(&n, field));
}

void Reader::CheckSetupValue(const SetupValue& v, const std::vector<std::string>& extra_symbols) {
  ParseExpression(v.expression,
                  [&](const std::string& s) -> ExprPtr {
                    if (std::find(extra_symbols.begin(), extra_symbols.end(), s) != extra_symbols.end()) {
                      return MakeInput(0);
                    }
                    return GlobalSymbol(s);
                  },
                  v.where);
}

std::vector<std::string> Reader::UnknownNames() const { return UnknownNames(WordPhases()); }

std::vector<std::string> Reader::UnknownNames(const std::vector<int>& word) const {
  std::vector<std::string> names;
  const int m = static_cast<int>(word.size());
  for (int i = 0; i <= m; ++i) names.push_back(std::string("t").append(std::to_string(i + 1)));
  for (int i = 0; i <= m; ++i) {
    for (const std::string& s : spec_.phases[word[i % m]].state_names) names.push_back(std::string("x").append(std::to_string(i + 1)).append("_").append(s));
  }
  if (num_integrals_ == 0) {  // no unfolding, no level: the run's parameter carries the family
    if (!spec_.setup.run.parameter.empty()) names.push_back(spec_.setup.run.parameter);
    return names;
  }
  if (num_integrals_ == 1) {
    names.push_back("xi");
  } else {
    for (int j = 1; j <= num_integrals_; ++j) names.push_back("xi" + std::to_string(j));
  }
  names.push_back("H");
  return names;
}

void Reader::CheckName(const toml::node* n, const std::string& field, const std::string& name) const {
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

namespace {

// The text with every byte that is not printable ASCII written as \xNN (a name in a message).
std::string Escaped(const std::string& text) {
  std::string out;
  for (const unsigned char c : text) {
    if (c >= 0x20 && c < 0x7f) {
      out += static_cast<char>(c);
    } else {
      char buffer[5];
      std::snprintf(buffer, sizeof buffer, "\\x%02x", c);
      out += buffer;
    }
  }
  return out;
}

}  // namespace

void Reader::CheckLabel(const toml::node* n, const std::string& field, const std::string& label) const {
  const bool ok = !label.empty() && label.size() <= kMaxLabelLength && label[0] != '-' &&
                  std::all_of(label.begin(), label.end(), [](char c) {
                    return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-';
                  });
  if (!ok) {
    Fail(n, field, "'" + Escaped(label) + "' is not a label (1 to " + std::to_string(kMaxLabelLength) +
                       " letters, digits, '_' or '-', not starting with '-'): it names files and CSV columns");
  }
}

void Reader::CheckText(const toml::node* n, const std::string& field, const std::string& text) const {
  for (const unsigned char c : text) {
    if (c < 0x20 || c == 0x7f) Fail(n, field, "'" + Escaped(text) + "' holds a control character");
  }
}

std::string Reader::JoinNames(const std::vector<std::string>& names) {
  std::string s;
  for (const std::string& n : names) s += (s.empty() ? "" : ", ") + n;
  return s;
}

void Reader::CheckUnknown(const toml::node* n, const std::string& field, const std::string& name, bool allow_period) const {
  const std::vector<std::string> names = UnknownNames();
  if (allow_period && name == "period") return;
  if (std::find(names.begin(), names.end(), name) == names.end()) {
    Fail(n, field, "'" + name + "' is not an unknown of the model (unknowns: " + JoinNames(names) +
                       (allow_period ? "; or 'period', the sum of all durations" : "") + ")");
  }
}

void Reader::CheckWordUnknown(const toml::node* n, const std::string& field, const std::string& name,
                              const std::vector<int>& word) const {
  const std::vector<std::string> names = UnknownNames(word);
  if (std::find(names.begin(), names.end(), name) == names.end()) {
    Fail(n, field, "'" + name + "' is not an unknown of the start's word (unknowns: " + JoinNames(names) + ")");
  }
}

std::vector<std::string> Reader::OrbitSymbols() const {
  std::vector<std::string> s = UnknownNames();
  s.push_back("T");
  for (const QuantitySpec& q : spec_.setup.quantities) s.push_back(q.name);
  return s;
}

}  // namespace hybridcont::internal
