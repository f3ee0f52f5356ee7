// [observables] and [constraints]: named quantities of an orbit and admissibility constraints
// (observable.h), each compiled into ExpressionFunctions with exact gradients.
//
//   [observables]
//   speed = { mean = { stance = "-dl*sin(alpha) - l*cos(alpha)*dalpha", flight = "dx" } }
//   flight_speed = { value = "x2_dx" }          # the orbit's unknowns, T, parameters, definitions
//   apex = { maximum = { flight = "y" }, description = "highest point of the body" }
//   touchdown_rate = { final = { flight = "dy + l0*sin(alpha)*dalpha" } }   # at the end of the phase
//   [constraints]
//   clearance = { flight = "y - l0*cos(alpha)", description = "the swing foot stays above the ground" }
//   touchdown = { final = { flight = "-(dy + l0*sin(alpha)*dalpha)" } }      # >= 0 at the end of flight
#include <memory>

#include "hybridcont/expression_derivative.h"
#include "hybridcont/expression_function.h"
#include "model_reader.h"

namespace hybridcont::internal {

std::vector<std::string> Reader::LayoutNames() const {
  // The time-based layout's order (shooting_layout.h): segments m+1 down to 1, then ξ and H̄.
  std::vector<std::string> names;
  const std::vector<int>& word = WordPhases();
  const int m = static_cast<int>(word.size());
  for (int i = m; i >= 0; --i) {
    names.push_back(std::string("t").append(std::to_string(i + 1)));
    for (const std::string& s : spec_.phases[word[i % m]].state_names) names.push_back(std::string("x").append(std::to_string(i + 1)).append("_").append(s));
  }
  for (int j = 0; j < num_integrals_; ++j) names.push_back(num_integrals_ == 1 ? "xi" : "xi" + std::to_string(j + 1));
  if (num_integrals_ > 0) names.push_back("H");
  return names;
}

std::vector<std::shared_ptr<const SmoothFunction>> Reader::ReadPhaseFunctions(const toml::node& node,
                                                                              const std::string& field,
                                                                              const std::string& skip) {
  const int m = static_cast<int>(spec_.phases.size());
  const int num_parameters = static_cast<int>(spec_.parameters.size());
  if (!node.is_table() || node.as_table()->empty()) {
    Fail(&node, field, "expected a table of expressions by phase name (e.g. { flight = \"dx\" }), got " + TypeName(node));
  }
  std::vector<std::shared_ptr<const SmoothFunction>> functions(m);
  for (auto&& [key, value] : *node.as_table()) {
    const std::string phase(key.str());
    if (phase == skip) continue;
    const std::string f = field + "." + phase;
    int i = 0;
    while (i < m && spec_.phases[i].name != phase) ++i;
    if (i == m) {
      std::string known;
      for (const ExpressionPhaseSpec& p : spec_.phases) known += (known.empty() ? "" : ", ") + p.name;
      Fail(&value, f, "'" + phase + "' is not a phase (phases: " + known + ")");
    }
    // Every phase of that name: an automaton's mode is a phase per transition out of it.
    for (; i < m; ++i) {
      if (spec_.phases[i].name != phase) continue;
      const ExprPtr e = ParsePhaseExpression(i, value, f);
      functions[i] = std::make_shared<ExpressionFunction>(e, static_cast<int>(spec_.phases[i].state_names.size()),
                                                          num_parameters, At(&value, f));
    }
  }
  return functions;
}

void Reader::CheckObservableName(const toml::node& node, const std::string& field, const std::string& name) const {
  CheckName(&node, field, name);
  const std::vector<std::string> layout = LayoutNames();
  if (std::find(layout.begin(), layout.end(), name) != layout.end() || name == "T" || parameter_index_.count(name)) {
    Fail(&node, field, "'" + name + "' is also an unknown, T or a parameter");
  }
  for (const Observable& o : spec_.observables) {
    if (o.name == name) Fail(&node, field, "'" + name + "' is declared twice (observables and constraints share names)");
  }
  for (const QuantitySpec& q : spec_.setup.quantities) {
    if (q.name == name) Fail(&node, field, "'" + name + "' is also a quantity");
  }
}

void Reader::CheckOnePhase(const toml::node& node, const std::string& field) const {
  if (node.as_table()->size() != 1) Fail(&node, field, "a final value names exactly one phase");
}

void Reader::ReadObservables() {
  const toml::table* t = OptionalTable(root_, "observables", "");
  if (t == nullptr) return;
  const std::vector<std::string> layout = LayoutNames();
  const int num_parameters = static_cast<int>(spec_.parameters.size());
  for (auto&& [key, node] : *t) {
    const std::string name(key.str());
    const std::string field = "observables." + name;
    CheckObservableName(node, field, name);
    if (!node.is_table()) {
      Fail(&node, field, "expected a table with one of value, integral, mean, minimum, maximum, got " + TypeName(node));
    }
    const toml::table& ot = *node.as_table();
    CheckKeys(ot, field, {"value", "integral", "mean", "minimum", "maximum", "final", "description"});
    Observable o;
    o.name = name;
    o.description = OptionalString(ot, "description", field, "");
    int kinds = 0;
    const std::pair<const char*, ObservableKind> kinds_by_key[] = {
        {"value", ObservableKind::kValue},     {"integral", ObservableKind::kIntegral},
        {"mean", ObservableKind::kMean},       {"minimum", ObservableKind::kMinimum},
        {"maximum", ObservableKind::kMaximum}, {"final", ObservableKind::kFinal}};
    for (const auto& [k, kind] : kinds_by_key) {
      const toml::node* v = ot.get(k);
      if (v == nullptr) continue;
      ++kinds;
      o.kind = kind;
      const std::string f = field + "." + k;
      if (kind != ObservableKind::kValue) {
        o.phases = ReadPhaseFunctions(*v, f);
        if (kind == ObservableKind::kFinal) CheckOnePhase(*v, f);
        continue;
      }
      // The orbit's unknowns by their layout index, T their durations' sum, then parameters and definitions.
      const ExprPtr e = ParseExpression(
          ExpressionText(*v, f),
          [&](const std::string& s) -> ExprPtr {
            const auto it = std::find(layout.begin(), layout.end(), s);
            if (it != layout.end()) return MakeInput(static_cast<int>(it - layout.begin()));
            if (s == "T") {
              ExprPtr sum = MakeConstant(0.0);
              for (int i = 0; i < static_cast<int>(layout.size()); ++i) {
                if (layout[i][0] == 't') sum = Add(sum, MakeInput(i));
              }
              return sum;
            }
            return GlobalSymbol(s);
          },
          At(v, f));
      o.value = std::make_shared<ExpressionFunction>(e, static_cast<int>(layout.size()), num_parameters, At(v, f));
    }
    if (kinds != 1) {
      Fail(&node, field,
           "give exactly one of value, integral, mean, minimum, maximum, final (got " + std::to_string(kinds) + ")");
    }
    spec_.observables.push_back(std::move(o));
  }
}

void Reader::ReadConstraints() {
  const toml::table* t = OptionalTable(root_, "constraints", "");
  if (t == nullptr) return;
  for (auto&& [key, node] : *t) {
    const std::string name(key.str());
    const std::string field = "constraints." + name;
    CheckObservableName(node, field, name);
    if (!node.is_table()) {
      Fail(&node, field, "expected a table of expressions by phase name that must stay >= 0, got " + TypeName(node));
    }
    Observable o;
    o.name = name;
    o.constraint = true;
    const toml::table& phases = *node.as_table();
    if (const toml::node* d = phases.get("description")) o.description = AsString(*d, field + ".description");
    if (const toml::node* final_value = phases.get("final")) {
      // { final = { phase = "..." } }: the value at the end of that phase, >= 0.
      CheckKeys(phases, field, {"final", "description"});
      o.kind = ObservableKind::kFinal;
      o.phases = ReadPhaseFunctions(*final_value, field + ".final");
      CheckOnePhase(*final_value, field + ".final");
    } else {
      if (phases.size() == (phases.get("description") ? 1u : 0u)) {
        Fail(&node, field, "names no phase (e.g. { flight = \"y - l0*cos(alpha)\" })");
      }
      o.kind = ObservableKind::kMinimum;
      o.phases = ReadPhaseFunctions(node, field, "description");
    }
    spec_.observables.push_back(std::move(o));
  }
}

}  // namespace hybridcont::internal
