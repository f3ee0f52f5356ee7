// Reading [[phases]] (names, states, typical states, then each phase's functions) and [[symmetries]].
#include "model_reader.h"

#include <algorithm>
#include <set>

#include "hybridcont/expression_function.h"

namespace hybridcont::internal {

ExpressionPhaseSpec Reader::ReadPhaseHeader(const toml::table& t, const std::string& field, std::set<std::string>* names,
                                            bool mode) {
  if (mode) {
    CheckKeys(t, field, {"name", "states", "typical", "let", "ode", "energy", "integrals", "anchor", "coordinates",
                         "velocities", "ignorable", "pinned", "kinetic", "potential", "mass_matrix", "forces"});
  } else {
    CheckKeys(t, field, {"name", "states", "typical", "let", "ode", "energy", "integrals", "event", "reset", "anchor",
                         "coordinates", "velocities", "ignorable", "pinned", "kinetic", "potential", "mass_matrix",
                         "forces", "impact"});
  }
  ExpressionPhaseSpec p;
  p.name = RequiredString(t, "name", field);
  CheckLabel(t.get("name"), field + ".name", p.name);
  if (p.name.empty() || !names->insert(p.name).second) {
    Fail(t.get("name"), field + ".name", std::string(mode ? "mode" : "phase") + " name '" + p.name +
                                             "' is empty or used twice");
  }
  const std::string pf = (mode ? "modes." : "phases.") + p.name;
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
  return p;
}

void Reader::ReadPhaseHeaders() {
  if (root_.get("modes") || root_.get("transitions")) {
    ReadAutomatonHeaders();
    return;
  }
  const toml::node* n = root_.get("phases");
  if (n == nullptr) {
    Fail(&root_, "phases", "missing field 'phases' (at least one [[phases]] table, or [[modes]] and [[transitions]])");
  }
  const toml::array& a = AsArray(*n, "phases");
  if (a.empty()) Fail(n, "phases", "a model needs at least one phase");
  if (a.size() > kMaxPhases) {
    Fail(n, "phases", std::to_string(a.size()) + " phases; a model has at most " + std::to_string(kMaxPhases));
  }
  std::set<std::string> names;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const std::string field = "phases[" + std::to_string(i) + "]";
    if (!a.get(i)->is_table()) Fail(a.get(i), field, "expected a [[phases]] table, got " + TypeName(*a.get(i)));
    const toml::table& t = *a.get(i)->as_table();
    ExpressionPhaseSpec p = ReadPhaseHeader(t, field, &names, false);
    const std::string pf = "phases." + p.name;
    if (i > 0 && t.get("anchor")) Fail(t.get("anchor"), pf + ".anchor", "only the first phase carries the anchor");
    spec_.phases.push_back(std::move(p));
    phase_tables_.push_back(&t);
    phase_lets_.push_back(OptionalTable(t, "let", pf));
  }
}

void Reader::ReadAutomatonHeaders() {
  if (const toml::node* phases = root_.get("phases")) {
    Fail(phases, "phases", "a model gives either [[phases]] (one cycle) or [[modes]] and [[transitions]] (an automaton), "
                           "not both");
  }
  const toml::node* mn = root_.get("modes");
  if (mn == nullptr) Fail(&root_, "modes", "missing field 'modes' (an automaton's [[modes]] tables)");
  const toml::array& ma = AsArray(*mn, "modes");
  if (ma.size() > kMaxPhases) {
    Fail(mn, "modes", std::to_string(ma.size()) + " modes; an automaton has at most " + std::to_string(kMaxPhases));
  }
  if (ma.empty()) Fail(mn, "modes", "an automaton needs at least one mode");
  std::set<std::string> names;
  std::vector<ExpressionPhaseSpec> modes;
  std::vector<const toml::table*> mode_tables;
  std::vector<MechanicalNames> mode_mechanics;
  int anchor_mode = -1;
  for (std::size_t i = 0; i < ma.size(); ++i) {
    const std::string field = "modes[" + std::to_string(i) + "]";
    if (!ma.get(i)->is_table()) Fail(ma.get(i), field, "expected a [[modes]] table, got " + TypeName(*ma.get(i)));
    const toml::table& t = *ma.get(i)->as_table();
    modes.push_back(ReadPhaseHeader(t, field, &names, true));
    mode_mechanics.push_back(std::move(mechanical_names_.back()));
    mechanical_names_.pop_back();
    mode_tables.push_back(&t);
    if (t.get("anchor")) {
      if (anchor_mode >= 0) {
        Fail(t.get("anchor"), "modes." + modes.back().name + ".anchor",
             "only one mode carries the anchor (mode '" + modes[anchor_mode].name + "' does)");
      }
      anchor_mode = static_cast<int>(i);
    }
  }
  if (anchor_mode < 0) Fail(mn, "modes", "no mode carries the anchor (the Poincaré section: its downward zero crossing)");
  const toml::node* tn = root_.get("transitions");
  if (tn == nullptr) Fail(&root_, "transitions", "missing field 'transitions' (an automaton's [[transitions]] tables)");
  const toml::array& ta = AsArray(*tn, "transitions");
  if (ta.size() > kMaxPhases) {
    Fail(tn, "transitions", std::to_string(ta.size()) + " transitions; an automaton has at most " + std::to_string(kMaxPhases));
  }
  struct Header {
    AutomatonTransition transition;
    const toml::table* table;
  };
  std::vector<Header> headers;
  std::set<std::string> transition_names;
  const auto mode_index = [&](const toml::table& t, const std::string& key, const std::string& field) {
    const std::string name = RequiredString(t, key, field);
    for (std::size_t m = 0; m < modes.size(); ++m) {
      if (modes[m].name == name) return static_cast<int>(m);
    }
    std::vector<std::string> known;
    for (const ExpressionPhaseSpec& m : modes) known.push_back(m.name);
    Fail(t.get(key), field + "." + key, "'" + name + "' is not a mode (modes: " + JoinNames(known) + ")");
  };
  for (std::size_t i = 0; i < ta.size(); ++i) {
    const std::string field = "transitions[" + std::to_string(i) + "]";
    if (!ta.get(i)->is_table()) Fail(ta.get(i), field, "expected a [[transitions]] table, got " + TypeName(*ta.get(i)));
    const toml::table& t = *ta.get(i)->as_table();
    CheckKeys(t, field, {"name", "from", "to", "event", "reset", "let"});
    Header h{{}, &t};
    h.transition.name = RequiredString(t, "name", field);
    CheckName(t.get("name"), field + ".name", h.transition.name);
    if (IsLayoutName(HybridAutomaton::GuardConstraintName(h.transition))) {
      Fail(t.get("name"), field + ".name",
           "transition name '" + h.transition.name + "': its guard constraint '" +
               HybridAutomaton::GuardConstraintName(h.transition) +
               "' would be named like an unknown of the orbit (t<i>, x<i>_<state>, xi, H, T)");
    }
    if (!transition_names.insert(h.transition.name).second) {
      Fail(t.get("name"), field + ".name", "transition name '" + h.transition.name + "' is used twice");
    }
    const std::string tf = "transitions." + h.transition.name;
    h.transition.from = mode_index(t, "from", tf);
    h.transition.to = mode_index(t, "to", tf);
    if (!t.get("event")) Fail(&t, tf + ".event", "missing field 'event' (the guard: the transition at its downward zero crossing)");
    h.transition.cut = h.transition.from == h.transition.to && !t.get("reset");
    headers.push_back(std::move(h));
  }
  for (std::size_t m = 0; m < modes.size(); ++m) {
    if (std::none_of(headers.begin(), headers.end(), [&](const Header& h) { return h.transition.from == static_cast<int>(m); })) {
      Fail(mode_tables[m], "modes." + modes[m].name, "mode '" + modes[m].name + "' has no transition out of it");
    }
  }
  // The catalogue: one phase per transition, those out of the anchor mode first (the anchor is read with
  // catalogue phase 0, and compiled over its states).
  std::stable_partition(headers.begin(), headers.end(),
                        [&](const Header& h) { return h.transition.from == anchor_mode; });
  for (const Header& h : headers) {
    const int from = h.transition.from;
    spec_.phases.push_back(modes[from]);
    phase_tables_.push_back(mode_tables[from]);
    phase_lets_.push_back(OptionalTable(*mode_tables[from], "let", "modes." + modes[from].name));
    mechanical_names_.push_back(mode_mechanics[from]);
    transition_tables_.push_back(h.table);
    transition_lets_.push_back(OptionalTable(*h.table, "let", "transitions." + h.transition.name));
    automaton_.transitions.push_back(h.transition);
  }
  for (const Header& h : headers) {
    int next = 0;
    while (automaton_.transitions[next].from != h.transition.to) ++next;
    next_phase_.push_back(next);
  }
  for (const ExpressionPhaseSpec& m : modes) automaton_.modes.push_back({m.name, m.state_names});
  automaton_.anchor_mode = anchor_mode;
  ReadWord();
}

void Reader::ReadWord() {
  const toml::node* n = root_.get("word");
  if (n == nullptr) {
    Fail(&root_, "word", "missing field 'word' (the modes of the cycle the run starts on, e.g. [\"stance\", \"flight\"])");
  }
  const std::vector<std::string> names = StringArray(*n, "word");
  try {  // the guards are read later: the automaton's names and connections resolve the word
    automaton_.word =
        HybridAutomaton::Graph(spec_.name, automaton_.modes, automaton_.transitions, automaton_.anchor_mode)->WordOf(names);
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    Fail(n, "word", what.substr(what.find(": ") + 2));
  }
}

const std::vector<int>& Reader::WordPhases() const {
  static const std::vector<int> kNone;
  if (transition_tables_.empty()) {
    if (cycle_.size() != spec_.phases.size()) {
      cycle_.clear();
      for (std::size_t i = 0; i < spec_.phases.size(); ++i) cycle_.push_back(static_cast<int>(i));
    }
    return cycle_;
  }
  return automaton_.word;
}

int Reader::NextPhase(int i) const {
  if (transition_tables_.empty()) return (i + 1) % static_cast<int>(spec_.phases.size());
  return next_phase_[i];
}

std::string Reader::TransitionField(int i) const {
  if (transition_tables_.empty()) return "phases." + spec_.phases[i].name;
  return "transitions." + automaton_.transitions[i].name;
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
  const std::string ef = TransitionField(i);
  const toml::node* event = EventTable(i).get("event");
  if (event != nullptr) {
    const ExprPtr e = ParsePhaseExpression(i, *event, ef + ".event");
    p.event = ExpressionProgram({e}, dim, true, {At(event, ef + ".event")});
    if (!transition_tables_.empty()) {
      automaton_.transitions[i].guard = std::make_shared<ExpressionFunction>(
          e, dim, static_cast<int>(spec_.parameters.size()), At(event, ef + ".event"));
    }
  } else if (mechanics.constraint) {  // the phase ends at its contact
    p.event = ExpressionProgram({mechanics.constraint}, dim, true, {mechanics.constraint_where});
  } else {
    Fail(&t, pf + ".event", "missing field 'event' (the phase ends at its downward zero crossing)");
  }
  ReadReset(i, mechanics.reset);
  if (i == 0) {  // for an automaton, catalogue phase 0 leaves the anchor mode
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
  const toml::table* transition_let = transition_lets_.empty() ? nullptr : transition_lets_[i];
  for (const toml::table* let : {phase_lets_[i], transition_let}) {
    if (let == nullptr) continue;
    const std::string pf = let == transition_let ? TransitionField(i) : "phases." + p.name;
    for (auto&& [key, node] : *let) {
      const std::string name(key.str());
      CheckName(&node, pf + ".let." + name, name);
      if (std::find(p.state_names.begin(), p.state_names.end(), name) != p.state_names.end() ||
          parameter_index_.count(name)) {
        Fail(&node, pf + ".let." + name, "'" + name + "' is also a state or a parameter");
      }
      if (definitions_.count(name)) {  // the let would hide the definition inside this phase only
        Fail(&node, pf + ".let." + name, "'" + name + "' is also a definition ([definitions]); name it otherwise");
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
    if (f[k]) continue;
    // Dotted keys (ode.l = "dl") make a table without a place of its own: its first entry's line, else the
    // phase's.
    const toml::node* at = &ode;
    if (ode.source().begin.line == 0) at = ode.empty() ? static_cast<const toml::node*>(&t) : &ode.cbegin()->second;
    Fail(at, pf + ".ode", "missing the rate of state '" + p.state_names[k] + "'");
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
  const toml::table& t = EventTable(i);
  ExpressionPhaseSpec& p = spec_.phases[i];
  const std::string pf = TransitionField(i);
  const bool transition = !transition_tables_.empty();
  const ExpressionPhaseSpec& next = spec_.phases[NextPhase(i)];
  static const toml::table kNoReset;
  const toml::table& reset =
      (!defaults.empty() || transition) && !t.get("reset") ? kNoReset : RequiredTable(t, "reset", pf);
  std::vector<ExprPtr> r(next.state_names.size());
  std::vector<SourceLocation> r_where(next.state_names.size(), At(t.get("impact"), pf + ".impact"));
  if (!defaults.empty()) r = defaults;
  if (transition) {  // a transition carries the states of the same name over
    for (std::size_t k = 0; k < r.size(); ++k) {
      const auto it = std::find(p.state_names.begin(), p.state_names.end(), next.state_names[k]);
      if (it != p.state_names.end()) r[k] = MakeInput(static_cast<int>(it - p.state_names.begin())), r_where[k] = At(&t, pf);
    }
  }
  for (auto&& [key, node] : reset) {
    const std::string name(key.str());
    const auto it = std::find(next.state_names.begin(), next.state_names.end(), name);
    if (it == next.state_names.end()) {
      Fail(&node, pf + ".reset." + name, "'" + name + "' is not a state of the next " +
                                             (transition ? "mode" : "phase") + " '" + next.name +
                                             "' (its states: " + JoinNames(next.state_names) + ")");
    }
    const int k = static_cast<int>(it - next.state_names.begin());
    r[k] = ParsePhaseExpression(i, node, pf + ".reset." + name);
    r_where[k] = At(&node, pf + ".reset." + name);
  }
  for (std::size_t k = 0; k < r.size(); ++k) {
    if (!r[k]) {
      Fail(t.get("reset") ? static_cast<const toml::node*>(&reset) : &t, pf + ".reset",
           "missing the value of state '" + next.state_names[k] + "' of the next " +
               (transition ? "mode" : "phase") + " '" + next.name + "' (" +
               (transition ? "a transition gives those its mode does not have by name)"
                           : "the reset gives all " + std::to_string(r.size()) + " of them)"));
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
    CheckLabel(t.get("name"), field + ".name", s.name);
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
        std::set<std::string> flipped;
        for (const std::string& state : StringArray(node, ff)) {
          const auto st = std::find(it->state_names.begin(), it->state_names.end(), state);
          if (st == it->state_names.end()) Fail(&node, ff, "'" + state + "' is not a state of phase '" + phase + "'");
          if (!flipped.insert(state).second) Fail(&node, ff, "'" + state + "' is flipped twice (once flips its sign)");
          for (std::size_t k = 0; k < spec_.phases.size(); ++k) {  // every phase of the mode, in an automaton
            if (spec_.phases[k].name == phase) s.state_signs[k](st - it->state_names.begin()) = -1.0;
          }
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
