// Reading the format version, [parameters], [definitions], [start], [run], [[families]] and [quantities].
#include "model_reader.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>

#include "hybridcont/hybrid_automaton.h"

namespace hybridcont::internal {

void Reader::ReadVersion() {
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

ParameterRange Reader::ParseRange(const toml::node& n, const std::string& field) const {
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

void Reader::ReadParameters() {
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

void Reader::ReadDefinitions() {
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

void Reader::ReadStart() {
  const toml::node* n = root_.get("start");
  if (n == nullptr) Fail(&root_, "start", "missing table [start] (where the exploration begins)");
  if (const toml::array* a = n->as_array(); a != nullptr && !transition_tables_.empty()) {
    ReadWordStarts(*a);
    return;
  }
  if (const toml::array* a = n->as_array()) {  // [[start]]: several starts, one family each
    if (conservative_) {
      Fail(n, "start", "several starts ([[start]]) are for models without first integral (conservative = false); "
                       "a conservative model's exploration branches from its one start");
    }
    if (a->empty()) Fail(n, "start", "at least one start");
    for (std::size_t i = 0; i < a->size(); ++i) {
      const std::string field = "start[" + std::to_string(i) + "]";
      if (!a->get(i)->is_table()) Fail(a->get(i), field, "expected a [[start]] table");
      StartSpec s = ReadStartTable(*a->get(i)->as_table(), field);
      if (i == 0) spec_.setup.start = std::move(s);
      else spec_.setup.more_starts.push_back(std::move(s));
    }
    return;
  }
  const toml::table& t = RequiredTable(root_, "start", "");
  if (const toml::node* w = t.get("word")) {
    Fail(w, "start.word", "a start in another word is a [[start]] table beside the file word's start");
  }
  spec_.setup.start = ReadStartTable(t, "start");
}

// An automaton's [[start]]: one start per word (`word`, the file's word where absent); a model without first
// integral may also give several starts of one word. The file's word needs one.
void Reader::ReadWordStarts(const toml::array& a) {
  if (a.empty()) Fail(&a, "start", "at least one start");
  bool own = false;
  std::vector<std::vector<int>> words;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const std::string field = "start[" + std::to_string(i) + "]";
    if (!a.get(i)->is_table()) Fail(a.get(i), field, "expected a [[start]] table");
    const toml::table& t = *a.get(i)->as_table();
    std::vector<int> word = automaton_.word;
    if (const toml::node* w = t.get("word")) {
      if (!conservative_) {
        Fail(w, field + ".word", "starts in other words are for conservative models (a run along a parameter "
                                 "follows the start's word only)");
      }
      if (const toml::node* c = t.get("conditions")) {
        Fail(c, field + ".conditions", "a start in another word is a regular orbit: it has no start conditions");
      }
      try {
        word = HybridAutomaton::Graph(spec_.name, automaton_.modes, automaton_.transitions, automaton_.anchor_mode)
                   ->WordOf(StringArray(*w, field + ".word"));
      } catch (const std::invalid_argument& e) {
        const std::string what = e.what();
        Fail(w, field + ".word", what.substr(what.find(": ") + 2));
      }
    }
    if (conservative_ && std::find(words.begin(), words.end(), word) != words.end()) {
      Fail(a.get(i), field + ".word", "a second start of this word: a conservative model's exploration branches from "
                                      "one start per word");
    }
    words.push_back(word);
    StartSpec s = ReadStartTable(t, field, word == automaton_.word ? std::vector<int>{} : word);
    if (s.word.empty() && !own) {
      spec_.setup.start = std::move(s);
      own = true;
    } else if (s.word.empty()) {
      spec_.setup.more_starts.push_back(std::move(s));
    } else {
      spec_.setup.word_starts.push_back(std::move(s));
    }
  }
  if (!own) Fail(&a, "start", "no start of the file's word (top-level `word`): give one without `word`");
}

StartSpec Reader::ReadStartTable(const toml::table& st, const std::string& field, const std::vector<int>& word) {
  const toml::table* t = &st;
  StartSpec start;
  start.word = word;
  start.where = At(t, field);
  if (!transition_tables_.empty()) CheckKeys(*t, field, {"kind", "values", "conditions", "cycles", "word"});
  else CheckKeys(*t, field, {"kind", "values", "conditions", "cycles"});
  const std::string kind = OptionalString(*t, "kind", field, "singular");
  if (!word.empty() && kind != "guess") {
    Fail(t->get("kind") ? t->get("kind") : t, field + ".kind",
         "a start in another word is an approximate orbit (kind = \"guess\"), which Newton corrects at its level H");
  }
  if (kind == "singular") start.kind = StartSpec::Kind::kSingular;
  else if (kind == "guess") start.kind = StartSpec::Kind::kGuess;
  else if (kind == "simulation") start.kind = StartSpec::Kind::kSimulation;
  else Fail(t->get("kind"), field + ".kind", "'" + kind + "': expected 'singular', 'guess' or 'simulation'");
  start.cycles = OptionalInteger(*t, "cycles", field, 0, 0, 1000000);
  if (start.cycles > 0 && start.kind != StartSpec::Kind::kSimulation) {
    Fail(t->get("cycles"), field + ".cycles", "only a simulation start has cycles");
  }
  if (const toml::table* values = OptionalTable(*t, "values", field)) {
    for (auto&& [key, node] : *values) {
      const std::string name(key.str());
      if (word.empty()) CheckUnknown(&node, field + ".values." + name, name, false);
      else CheckWordUnknown(&node, field + ".values." + name, name, word);
      SetupValue v = AsSetupValue(node, field + ".values." + name);
      CheckSetupValue(v, {});
      start.values.push_back({name, v});
    }
  }
  if (const toml::node* c = t->get("conditions")) {
    const toml::array& a = AsArray(*c, field + ".conditions");
    for (std::size_t i = 0; i < a.size(); ++i) {
      const std::string cf = field + ".conditions[" + std::to_string(i) + "]";
      if (!a.get(i)->is_table()) Fail(a.get(i), cf, "expected a table { terms = {...}, description = \"...\" }");
      const toml::table& ct = *a.get(i)->as_table();
      CheckKeys(ct, cf, {"terms", "description"});
      StartSpec::Condition cond;
      const toml::table& terms = RequiredTable(ct, "terms", cf);
      for (auto&& [key, node] : terms) {
        const std::string name(key.str());
        if (word.empty()) CheckUnknown(&node, cf + ".terms." + name, name, false);
        else CheckWordUnknown(&node, cf + ".terms." + name, name, word);
        cond.terms.push_back({name, AsNumber(node, cf + ".terms." + name)});
      }
      if (cond.terms.empty()) Fail(&terms, cf + ".terms", "a condition needs at least one term");
      cond.description = OptionalString(ct, "description", cf, "");
      start.conditions.push_back(cond);
    }
  }
  return start;
}

void Reader::ReadRun() {
  RunSpec& run = spec_.setup.run;
  // Without a [run] table: |xi| <= 1 and the defaults of RunSpec; a model file should bound H.
  if (conservative_) run.bounds.push_back({"xi", "-1", "1"});
  const toml::table* t = OptionalTable(root_, "run", "");
  if (t == nullptr && !conservative_) {
    Fail(&root_, "run.parameter", "a model with conservative = false needs [run] parameter = \"NAME\" (the model "
                                  "parameter its families are continued in)");
  }
  if (t == nullptr) return;
  CheckKeys(*t, "run", {"bounds", "scales", "max_branches", "max_depth", "max_points", "initial_step", "max_step",
                        "keyframes", "parameter"});
  if (const toml::node* p = t->get("parameter")) {
    run.parameter = AsString(*p, "run.parameter");
    if (conservative_) {
      Fail(p, "run.parameter", "a conservative model is continued in H (run.parameter is for conservative = false; "
                               "continue in a parameter with --free NAME --fix H=VALUE)");
    }
    if (!parameter_index_.count(run.parameter)) {
      Fail(p, "run.parameter", "'" + run.parameter + "' is not a parameter of the model");
    }
  } else if (!conservative_) {
    Fail(t, "run.parameter", "a model with conservative = false needs parameter = \"NAME\" (the model parameter its "
                             "families are continued in)");
  }
  if (!conservative_) run.keyframe_component = run.parameter;
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
  run.max_points = OptionalInteger(*t, "max_points", "run", run.max_points, 2, 100000);
  run.initial_step = OptionalNumber(*t, "initial_step", "run", run.initial_step);
  run.max_step = OptionalNumber(*t, "max_step", "run", run.max_step);
  if (!(run.initial_step > 0)) Fail(t->get("initial_step"), "run.initial_step", "must be positive");
  if (!(run.max_step >= run.initial_step)) Fail(t->get("max_step"), "run.max_step", "must be at least initial_step");
  if (const toml::table* k = OptionalTable(*t, "keyframes", "run")) {
    CheckKeys(*k, "run.keyframes", {"component", "value", "orbits"});
    run.keyframe_component = OptionalString(*k, "component", "run.keyframes", run.keyframe_component);
    const std::string level = conservative_ ? "H" : run.parameter;
    if (run.keyframe_component != level && run.keyframe_component != "T") {
      Fail(k->get("component"), "run.keyframes.component", "expected \"" + level + "\" or \"T\"");
    }
    if (const toml::node* v = k->get("value")) run.keyframe_value = AsSetupValue(*v, "run.keyframes.value");
    CheckSetupValue(run.keyframe_value, {});
    run.keyframe_orbits = OptionalInteger(*k, "orbits", "run.keyframes", run.keyframe_orbits, 0, 100);
  }
}

void Reader::ReadFamilies() {
  const toml::node* n = root_.get("families");
  if (n == nullptr) return;
  const toml::array& a = AsArray(*n, "families");
  for (std::size_t i = 0; i < a.size(); ++i) {
    const std::string field = "families[" + std::to_string(i) + "]";
    if (!a.get(i)->is_table()) Fail(a.get(i), field, "expected a [[families]] table");
    const toml::table& t = *a.get(i)->as_table();
    CheckKeys(t, field, {"name", "when", "word"});
    FamilyRule rule;
    rule.name = RequiredString(t, "name", field);
    if (const toml::node* w = t.get("word")) {
      if (transition_tables_.empty()) {
        Fail(w, field + ".word", "'word' names a word of an automaton ([[modes]] and [[transitions]])");
      }
      try {
        rule.word = HybridAutomaton::Graph(spec_.name, automaton_.modes, automaton_.transitions, automaton_.anchor_mode)
                        ->WordOf(StringArray(*w, field + ".word"));
      } catch (const std::invalid_argument& e) {
        const std::string what = e.what();
        Fail(w, field + ".word", what.substr(what.find(": ") + 2));
      }
      if (rule.word == automaton_.word) rule.word.clear();
    }
    CheckText(t.get("name"), field + ".name", rule.name);
    const toml::node* when = t.get("when");
    rule.when = when ? AsSetupValue(*when, field + ".when") : SetupValue("1", At(&t, field));
    spec_.setup.families.push_back(rule);
  }
}

void Reader::ReadQuantities() {
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

}  // namespace hybridcont::internal
