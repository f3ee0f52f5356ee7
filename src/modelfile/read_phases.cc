// Reading [[phases]] (names, states, typical states, then each phase's functions) and [[symmetries]].
#include "model_reader.h"

#include <algorithm>

namespace hybridcont::internal {

void Reader::ReadPhaseHeaders() {
  const toml::node* n = root_.get("phases");
  if (n == nullptr) Fail(&root_, "phases", "missing field 'phases' (at least one [[phases]] table)");
  const toml::array& a = AsArray(*n, "phases");
  if (a.empty()) Fail(n, "phases", "a model needs at least one phase");
  std::set<std::string> names;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const std::string field = "phases[" + std::to_string(i) + "]";
    if (!a.get(i)->is_table()) Fail(a.get(i), field, "expected a [[phases]] table, got " + TypeName(*a.get(i)));
    const toml::table& t = *a.get(i)->as_table();
    CheckKeys(t, field, {"name", "states", "typical", "let", "ode", "energy", "integrals", "event", "reset", "anchor",
                         "coordinates", "velocities", "ignorable", "pinned", "kinetic", "potential", "mass_matrix", "forces",
                         "impact"});
    ExpressionPhaseSpec p;
    p.name = RequiredString(t, "name", field);
    if (p.name.empty() || !names.insert(p.name).second) {
      Fail(t.get("name"), field + ".name", "phase name '" + p.name + "' is empty or used twice");
    }
    const std::string pf = "phases." + p.name;
    const toml::node* states = t.get("states");
    MechanicalNames mech = ReadMechanicalNames(t, pf);
    if (states == nullptr && mech.coordinates.empty()) {
      Fail(&t, pf + ".states", "missing field 'states' (or 'coordinates', for a phase given by its mechanics)");
    }
    if (states) {
      p.state_names = StringArray(*states, pf + ".states");
    } else {
      states = t.get("coordinates");
      for (const std::string& q : mech.coordinates) {
        if (!mech.ignorable.count(q)) p.state_names.push_back(q);
      }
      p.state_names.insert(p.state_names.end(), mech.velocities.begin(), mech.velocities.end());
    }
    for (const std::vector<std::string>* names : {&mech.coordinates, &mech.velocities}) {
      for (const std::string& s : *names) {
        const bool is_state = std::find(p.state_names.begin(), p.state_names.end(), s) != p.state_names.end();
        if (mech.ignorable.count(s)) {
          if (is_state) Fail(states, pf + ".states", "'" + s + "' is ignorable: it is not a state");
        } else if (!is_state) {
          Fail(states, pf + ".states", "'" + s + "' is a coordinate or velocity but not a state (the state holds " +
                                           "every coordinate and its velocity)");
        }
      }
    }
    // Phases given by `ode` have any number of states (above kMaxPhaseDim they take the dynamic-size path,
    // large_expression_phase.h); a mechanical phase's mass matrix is fixed-capacity storage.
    const bool mechanical = !mech.coordinates.empty();
    mechanical_names_.push_back(std::move(mech));
    if (p.state_names.empty()) Fail(states, pf + ".states", "0 states, expected at least 1");
    if (mechanical && static_cast<int>(p.state_names.size()) > kMaxPhaseDim) {
      Fail(states, pf + ".states", std::to_string(p.state_names.size()) + " states: a phase given by its mechanics has "
                                   "at most " + std::to_string(kMaxPhaseDim) + " (write a larger one with `ode`)");
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

void Reader::ReadPhaseFunctions(int i) {
  ReadLets(i);
  const Mechanics mechanics = ReadMechanics(i);
  ReadVectorField(i, mechanics.vector_field);
  ReadIntegrals(i, mechanics.energy);
  const toml::table& t = *phase_tables_[i];
  ExpressionPhaseSpec& p = spec_.phases[i];
  const std::string pf = "phases." + p.name;
  const int dim = static_cast<int>(p.state_names.size());
  const toml::node* event = t.get("event");
  if (event != nullptr) {
    p.event = ExpressionProgram({ParsePhaseExpression(i, *event, pf + ".event")}, dim, true, {At(event, pf + ".event")});
  } else if (mechanics.constraint) {  // the phase ends at its contact
    p.event = ExpressionProgram({mechanics.constraint}, dim, true, {mechanics.constraint_where});
  } else {
    Fail(&t, pf + ".event", "missing field 'event' (the phase ends at its downward zero crossing)");
  }
  ReadReset(i, mechanics.reset);
  if (i == 0) {
    const toml::node* anchor = t.get("anchor");
    if (anchor == nullptr) {
      Fail(&t, pf + ".anchor", "missing field 'anchor' in the first phase (the Poincaré section: its downward zero crossing)");
    }
    spec_.anchor = ExpressionProgram({ParsePhaseExpression(0, *anchor, pf + ".anchor")}, dim, true,
                                     {At(anchor, pf + ".anchor")});
  }
}

void Reader::ReadLets(int i) {
  const ExpressionPhaseSpec& p = spec_.phases[i];
  const std::string pf = "phases." + p.name;
  if (const toml::table* let = phase_lets_[i]) {
    for (auto&& [key, node] : *let) {
      const std::string name(key.str());
      CheckName(&node, pf + ".let." + name, name);
      if (std::find(p.state_names.begin(), p.state_names.end(), name) != p.state_names.end() ||
          parameter_index_.count(name)) {
        Fail(&node, pf + ".let." + name, "'" + name + "' is also a state or a parameter");
      }
      // Checked where the pinned coordinates are known (a quantity of the energies may use them); a use
      // elsewhere is checked where it is made.
      if (!mechanical_names_[i].pinned.empty()) pinned_symbols_phase_ = i;
      PhaseSymbol(i, name);
      pinned_symbols_phase_ = -1;
    }
  }
}

void Reader::ReadVectorField(int i, const std::vector<ExprPtr>& derived) {
  const toml::table& t = *phase_tables_[i];
  ExpressionPhaseSpec& p = spec_.phases[i];
  const std::string pf = "phases." + p.name;
  const int dim = static_cast<int>(p.state_names.size());
  const bool mechanical = !derived.empty();
  static const toml::table kNoEquations;
  const toml::table& ode = mechanical && !t.get("ode") ? kNoEquations : RequiredTable(t, "ode", pf);
  std::vector<ExprPtr> f = mechanical ? derived : std::vector<ExprPtr>(dim);
  std::vector<SourceLocation> f_where(dim, At(t.get("kinetic") ? t.get("kinetic") : t.get("mass_matrix"), pf));
  for (auto&& [key, node] : ode) {
    const std::string name(key.str());
    const auto it = std::find(p.state_names.begin(), p.state_names.end(), name);
    if (it == p.state_names.end()) {
      Fail(&node, pf + ".ode." + name, "'" + name + "' is not a state of phase '" + p.name + "'");
    }
    const int k = static_cast<int>(it - p.state_names.begin());
    if (f[k]) {
      Fail(&node, pf + ".ode." + name, "'" + name + "' is a coordinate or velocity: its rate comes from the " +
                                           "mechanics (give 'ode' for the other states only)");
    }
    f[k] = ParsePhaseExpression(i, node, pf + ".ode." + name);
    f_where[k] = At(&node, pf + ".ode." + name);
  }
  for (int k = 0; k < dim; ++k) {
    if (!f[k]) Fail(&ode, pf + ".ode", "missing the rate of state '" + p.state_names[k] + "'");
  }
  p.vector_field = ExpressionProgram(f, dim, true, f_where);
}

void Reader::ReadIntegrals(int i, const ExprPtr& derived_energy) {
  const toml::table& t = *phase_tables_[i];
  ExpressionPhaseSpec& p = spec_.phases[i];
  const std::string pf = "phases." + p.name;
  const toml::node* energy = t.get("energy");
  const toml::node* integrals = t.get("integrals");
  if (!conservative_) {
    if (energy || integrals) {
      Fail(energy ? energy : integrals, pf + (energy ? ".energy" : ".integrals"),
           "a model with conservative = false has no first integral (write what you measure as a [quantities] "
           "entry)");
    }
    p.integrals = ExpressionProgram({}, static_cast<int>(p.state_names.size()), true, {});
    return;
  }
  if (energy && integrals) {
    Fail(integrals, pf + ".energy", "give exactly one of 'energy' (the first integral) or 'integrals' (several)");
  }
  if (!energy && !integrals && !derived_energy) {
    Fail(&t, pf + ".energy", "give exactly one of 'energy' (the first integral) or 'integrals' (several)");
  }
  std::vector<ExprPtr> h;
  std::vector<SourceLocation> h_where;
  if (!energy && !integrals) {  // H = T + V of a phase given by its mechanics
    h.push_back(derived_energy);
    h_where.push_back(At(t.get("kinetic") ? t.get("kinetic") : t.get("mass_matrix"), pf + ".energy"));
    energy = t.get("kinetic") ? t.get("kinetic") : t.get("mass_matrix");
  } else if (energy) {
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
  p.integrals = ExpressionProgram(h, static_cast<int>(p.state_names.size()), true, h_where);
}

void Reader::ReadReset(int i, const std::vector<ExprPtr>& defaults) {
  const toml::table& t = *phase_tables_[i];
  ExpressionPhaseSpec& p = spec_.phases[i];
  const std::string pf = "phases." + p.name;
  const int m = static_cast<int>(spec_.phases.size());
  const ExpressionPhaseSpec& next = spec_.phases[(i + 1) % m];
  static const toml::table kNoReset;
  const toml::table& reset = !defaults.empty() && !t.get("reset") ? kNoReset : RequiredTable(t, "reset", pf);
  std::vector<ExprPtr> r(next.state_names.size());
  std::vector<SourceLocation> r_where(next.state_names.size(), At(t.get("impact"), pf + ".impact"));
  if (!defaults.empty()) r = defaults;
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
      Fail(t.get("reset") ? static_cast<const toml::node*>(&reset) : &t, pf + ".reset", "missing the value of state '" + next.state_names[k] + "' of the next phase '" +
                                      next.name + "' (the reset gives all " + std::to_string(r.size()) + " of them)");
    }
  }
  p.reset = ExpressionProgram(r, static_cast<int>(p.state_names.size()), true, r_where);
}

void Reader::ReadSymmetries() {
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

}  // namespace hybridcont::internal
