// Reading a phase given by its mechanics: coordinates and velocities, a Lagrangian (kinetic, potential,
// forces) or a mass-matrix form (mass_matrix, forces, potential), and an impact law at a contact.
#include <algorithm>
#include <sstream>

#include "hybridcont/expression_derivative.h"
#include "hybridcont/mechanics.h"
#include "model_reader.h"

namespace hybridcont::internal {

Reader::MechanicalNames Reader::ReadMechanicalNames(const toml::table& t, const std::string& pf) const {
  MechanicalNames names;
  const toml::node* coordinates = t.get("coordinates");
  if (coordinates == nullptr) {
    for (const char* key : {"velocities", "ignorable", "pinned", "kinetic", "potential", "mass_matrix", "forces", "impact"}) {
      if (const toml::node* n = t.get(key)) {
        Fail(n, pf + "." + key, std::string("'") + key + "' needs 'coordinates' (a phase given by its mechanics)");
      }
    }
    return names;
  }
  names.coordinates = StringArray(*coordinates, pf + ".coordinates");
  if (names.coordinates.empty()) Fail(coordinates, pf + ".coordinates", "at least one coordinate");
  if (const toml::node* v = t.get("velocities")) {
    names.velocities = StringArray(*v, pf + ".velocities");
    if (names.velocities.size() != names.coordinates.size()) {
      Fail(v, pf + ".velocities", std::to_string(names.velocities.size()) + " velocities for " +
                                      std::to_string(names.coordinates.size()) + " coordinates");
    }
  } else {
    for (const std::string& q : names.coordinates) names.velocities.push_back("d" + q);
  }
  if (const toml::node* ig = t.get("ignorable")) {
    for (const std::string& q : StringArray(*ig, pf + ".ignorable")) {
      if (std::find(names.coordinates.begin(), names.coordinates.end(), q) == names.coordinates.end()) {
        Fail(ig, pf + ".ignorable", "'" + q + "' is not a coordinate (ignorable coordinates are coordinates that " +
                                        "T, V and the forces do not depend on, left out of the state)");
      }
      names.ignorable.insert(q);
    }
  }
  if (const toml::node* pinned = t.get("pinned")) {
    names.pinned = StringArray(*pinned, pf + ".pinned");
    if (names.pinned.size() > kMaxPinned) {
      Fail(pinned, pf + ".pinned", std::to_string(names.pinned.size()) + " pinned coordinates; a phase has at most " +
                                       std::to_string(kMaxPinned));
    }
    if (!t.get("kinetic")) {
      Fail(pinned, pf + ".pinned", "pinned coordinates need 'kinetic' (the impact's mass matrix in the extended "
                                   "coordinates is derived from T)");
    }
    for (const std::string& q : names.pinned) names.pinned_velocities.push_back("d" + q);
  }
  if (!t.get("kinetic") && !t.get("mass_matrix")) {
    Fail(&t, pf + ".kinetic", "a phase with coordinates needs 'kinetic' (T, a Lagrangian) or 'mass_matrix' (M)");
  }
  if (t.get("kinetic") && t.get("mass_matrix")) {
    Fail(t.get("mass_matrix"), pf + ".mass_matrix", "give 'kinetic' (T, M derived from it) or 'mass_matrix', not both");
  }
  std::set<std::string> seen;
  for (const std::vector<std::string>* list :
       {&names.coordinates, &names.velocities, &names.pinned, &names.pinned_velocities}) {
    for (const std::string& s : *list) {
      const bool pinned = list == &names.pinned || list == &names.pinned_velocities;
      const std::string field = pf + (pinned                          ? ".pinned"
                                      : list == &names.coordinates ? ".coordinates"
                                                                   : ".velocities");
      const toml::node* at = pinned ? t.get("pinned")
                             : list == &names.coordinates || !t.get("velocities") ? coordinates
                                                                                  : t.get("velocities");
      CheckName(at, field, s);
      if (!seen.insert(s).second) {
        Fail(at, field, "'" + s + "' is listed twice (as a coordinate, velocity or pinned coordinate or its velocity)");
      }
    }
  }
  return names;
}

namespace {
std::string FormatNumber(double v) {
  std::ostringstream os;
  os << v;
  return os.str();
}

// The state (of a phase with states state_names) holding a coordinate's or velocity's name s; -1 for an
// ignorable coordinate (derivatives in it vanish: no input is -1), state_names.size() for a name that is no state.
int StateIndex(const std::set<std::string>& ignorable, const std::vector<std::string>& state_names,
               const std::string& s) {
  if (ignorable.count(s)) return -1;
  return static_cast<int>(std::find(state_names.begin(), state_names.end(), s) - state_names.begin());
}

// The states at which a phase's mechanics is checked in values: its typical state and two others around it
// (dim states each; the velocities, at the indices given, reversed and scaled in the third).
std::vector<Vector> MechanicsCheckStates(const Vector& typical_state, int dim, const std::vector<int>& velocities) {
  std::vector<Vector> states;
  for (int k = 0; k < 3; ++k) {
    Vector x = typical_state;
    for (int j = 0; j < dim; ++j) x(j) += k == 0 ? 0.0 : 0.1 * (k == 1 ? 1.0 + 0.3 * j : -1.0 + 0.2 * j);
    for (int v : velocities) x(v) *= k == 2 ? -1.7 : 1.0;
    states.push_back(x);
  }
  return states;
}
}  // namespace

void Reader::ReadEnergiesAndForces(int i, const toml::table& t, const std::string& pf, MechanicalSystem* system) {
  const MechanicalNames& names = mechanical_names_[i];
  const ExpressionPhaseSpec& p = spec_.phases[i];
  const int n = static_cast<int>(names.coordinates.size());
  if (const toml::node* kinetic = t.get("kinetic")) {
    system->kinetic = ParsePhaseExpression(i, *kinetic, pf + ".kinetic");
    system->kinetic_where = At(kinetic, pf + ".kinetic");
  }
  if (const toml::node* potential = t.get("potential")) {
    system->potential = ParsePhaseExpression(i, *potential, pf + ".potential");
    system->potential_where = At(potential, pf + ".potential");
  }
  if (const toml::node* mass = t.get("mass_matrix")) {
    const std::string field = pf + ".mass_matrix";
    system->mass_matrix_where = At(mass, field);
    const toml::array& rows = AsArray(*mass, field);
    if (static_cast<int>(rows.size()) != n) {
      Fail(mass, field, std::to_string(rows.size()) + " rows for " + std::to_string(n) + " coordinates (M is n × n)");
    }
    for (int r = 0; r < n; ++r) {
      const std::string rf = field + "[" + std::to_string(r) + "]";
      const toml::array& row = AsArray(*rows.get(r), rf);
      if (static_cast<int>(row.size()) != n) {
        Fail(rows.get(r), rf, std::to_string(row.size()) + " entries for " + std::to_string(n) + " coordinates");
      }
      system->mass_matrix.emplace_back();
      for (int c = 0; c < n; ++c) {
        system->mass_matrix.back().push_back(
            ParsePhaseExpression(i, *row.get(c), rf + "[" + std::to_string(c) + "]"));
      }
    }
  }
  system->forces.assign(n, nullptr);
  if (const toml::table* forces = OptionalTable(t, "forces", pf)) {
    system->forces_where = At(forces, pf + ".forces");
    for (auto&& [key, node] : *forces) {
      const std::string name(key.str());
      const auto it = std::find(names.coordinates.begin(), names.coordinates.end(), name);
      if (it == names.coordinates.end()) {
        Fail(&node, pf + ".forces." + name, "'" + name + "' is not a coordinate of phase '" + p.name +
                                                "' (forces are keyed by coordinate: " + JoinNames(names.coordinates) +
                                                ")");
      }
      system->forces[it - names.coordinates.begin()] = ParsePhaseExpression(i, node, pf + ".forces." + name);
    }
  }
}

std::vector<ExprPtr> Reader::ReadContactConstraints(int i, const toml::table& impact, const std::string& field,
                                                    Mechanics* out) {
  std::vector<ExprPtr> constraints;
  CheckKeys(impact, field, {"constraint", "restitution", "relabel"});
  const toml::node* g = impact.get("constraint");
  if (g == nullptr) {
    Fail(&impact, field + ".constraint", "missing field 'constraint' (the contact's g(q); impact at g = 0)");
  }
  out->constraint_where = At(g, field + ".constraint");
  if (g->is_array()) {  // a contact of several constraints: a point that neither slips nor rebounds
    const toml::array& rows = *g->as_array();
    if (rows.empty()) Fail(g, field + ".constraint", "an empty list of constraints");
    for (std::size_t r = 0; r < rows.size(); ++r) {
      constraints.push_back(
          ParsePhaseExpression(i, *rows.get(r), field + ".constraint[" + std::to_string(r) + "]"));
    }
  } else {
    constraints.push_back(ParsePhaseExpression(i, *g, field + ".constraint"));
    out->constraint = constraints[0];
  }
  return constraints;
}

ExprPtr Reader::ReadRestitution(const toml::table& impact, const std::string& field) {
  ExprPtr e = MakeConstant(1.0);
  if (const toml::node* r = impact.get("restitution")) {
    const std::string rf = field + ".restitution";
    e = ParseExpression(ExpressionText(*r, rf), [this](const std::string& name) { return GlobalSymbol(name); },
                        At(r, rf));
    if (e->op == ExprOp::kConstant && !(e->value >= 0.0 && e->value <= 1.0)) {
      Fail(r, rf, "restitution " + FormatNumber(e->value) + " is outside [0, 1]");
    }
    if (conservative_ && !IsConstant(e, 1.0)) {
      const std::string shown = e->op == ExprOp::kConstant ? FormatNumber(e->value) : ExpressionText(*r, rf);
      Fail(r, rf, "restitution " + shown + ": only the elastic law (1), which conserves the "
                  "energy, is possible in a conservative model (declare conservative = false for a dissipative one)");
    }
  }
  return e;
}

std::vector<ExprPtr> Reader::ReadRelabelling(int i, const toml::table& rl, const std::string& field) {
  const MechanicalNames& names = mechanical_names_[i];
  const ExpressionPhaseSpec& p = spec_.phases[i];
  std::vector<ExprPtr> relabel(names.coordinates.size());
  for (auto&& [key, node] : rl) {
    const std::string name(key.str());
    const std::string rf = field + ".relabel." + name;
    const auto it = std::find(names.coordinates.begin(), names.coordinates.end(), name);
    if (it == names.coordinates.end() || names.ignorable.count(name)) {
      Fail(&node, rf, "'" + name + "' is not a coordinate of phase '" + p.name + "' that is a state (the " +
                          "relabelling gives coordinates after the impact: " + JoinNames(names.coordinates) + ")");
    }
    relabel[it - names.coordinates.begin()] = ParsePhaseExpression(i, node, rf);
  }
  return relabel;
}

// The impact's mass matrix (coordinates, then pinned coordinates) positive definite at the check states: a
// pinned coordinate whose velocity the kinetic energy does not contain has no mass, and no impulse can be
// derived (the impact would divide by zero).
void Reader::CheckImpactMassMatrix(const std::vector<std::vector<ExprPtr>>& mass, const std::vector<Vector>& states,
                                   const std::vector<double>& values, const toml::table& impact,
                                   const std::string& field, int i) const {
  const MechanicalNames& names = mechanical_names_[i];
  if (names.pinned.empty()) return;  // the phase's own mass matrix, checked where the motion is integrated
  const ExpressionPhaseSpec& p = spec_.phases[i];
  const int ne = static_cast<int>(mass.size());
  std::vector<ExprPtr> entries;
  for (const auto& row : mass) entries.insert(entries.end(), row.begin(), row.end());
  const ExpressionProgram program(entries, static_cast<int>(p.state_names.size()), false, {});
  std::vector<std::string> coordinate_names = names.coordinates;
  coordinate_names.insert(coordinate_names.end(), names.pinned.begin(), names.pinned.end());
  for (const Vector& x : states) {
    std::vector<double> m(ne * ne);
    for (int k = 0; k < ne * ne; ++k) m[k] = program.EvaluateScalar(x.data(), values.data(), k);
    std::vector<double> q(ne, 0.0);  // the coordinates' values, for the message (pinned ones at rest: 0)
    for (int k = 0; k < static_cast<int>(names.coordinates.size()); ++k) {
      const int s = StateIndex(names.ignorable, p.state_names, names.coordinates[k]);
      if (s >= 0 && s < x.size()) q[k] = x(s);
    }
    const std::string why = ExplainMassMatrix(m, coordinate_names, q);
    if (!why.empty()) {
      Fail(&impact, field, "the impact cannot be derived: " + why + " (the coordinates, then the pinned ones " +
                               JoinNames(names.pinned) + "); every pinned coordinate's velocity must enter 'kinetic' " +
                               "with the mass it moves, or the impulse that stops the new contact is undefined");
    }
  }
}

Reader::Mechanics Reader::ReadMechanics(int i) {
  Mechanics out;
  const MechanicalNames& names = mechanical_names_[i];
  if (names.coordinates.empty()) return out;
  const toml::table& t = *phase_tables_[i];
  ExpressionPhaseSpec& p = spec_.phases[i];
  const std::string pf = "phases." + p.name;
  const int dim = static_cast<int>(p.state_names.size());
  const int n = static_cast<int>(names.coordinates.size());
  const auto index = [&](const std::string& s) { return StateIndex(names.ignorable, p.state_names, s); };
  MechanicalSystem system;
  for (int k = 0; k < n; ++k) {
    system.coordinates.push_back(index(names.coordinates[k]));
    system.velocities.push_back(index(names.velocities[k]));
  }
  // The pinned coordinates and their velocities are inputs after the states (PhaseSymbol), known to the
  // energies, forces and contact only.
  const int np = static_cast<int>(names.pinned.size());
  for (int k = 0; k < np; ++k) {
    system.pinned_coordinates.push_back(dim + k);
    system.pinned_velocities.push_back(dim + np + k);
  }
  if (np > 0) pinned_symbols_phase_ = i;  // until the contact is read (a failure ends the reading)
  ReadEnergiesAndForces(i, t, pf, &system);
  const toml::table* impact = OptionalTable(t, "impact", pf);
  const std::string field = pf + ".impact";
  std::vector<ExprPtr> constraints;
  if (impact) constraints = ReadContactConstraints(i, *impact, field, &out);
  pinned_symbols_phase_ = -1;
  const EquationsOfMotion eq = DeriveEquationsOfMotion(system);

  // Values only: T quadratic in q̇, M symmetric; at the typical state and two others around it.
  std::vector<double> values;
  for (const ParameterInfo& info : spec_.parameters) values.push_back(info.default_value);
  const std::vector<Vector> states = MechanicsCheckStates(p.typical_state, dim, system.velocities);
  CheckMechanics(PinnedAtRest(system), eq, dim, states, values, p.state_names);

  out.vector_field.assign(dim, nullptr);
  for (int k = 0; k < n; ++k) {
    if (system.coordinates[k] >= 0) out.vector_field[system.coordinates[k]] = MakeInput(system.velocities[k]);
    out.vector_field[system.velocities[k]] = eq.accelerations[k];
  }
  if (conservative_) out.energy = eq.energy;
  std::vector<ExprPtr> entries;
  for (int r = 0; r < n; ++r) {
    for (int c = 0; c < n; ++c) entries.push_back(eq.mass_matrix[r][c]);
  }
  p.mass_matrix = ExpressionProgram(entries, dim, false, {});
  p.coordinates = system.coordinates;

  if (impact) {
    const ExprPtr e = ReadRestitution(*impact, field);
    std::vector<std::vector<ExprPtr>> impact_mass;
    std::vector<ExprPtr> after = ImpactVelocities(system, eq, constraints, e, out.constraint_where, &impact_mass);
    CheckImpactMassMatrix(impact_mass, states, values, *impact, field, i);
    std::vector<ExprPtr> relabel(n);
    if (const toml::table* rl = OptionalTable(*impact, "relabel", field)) {
      relabel = ReadRelabelling(i, *rl, field);
      after = RelabelVelocities(system, relabel, after, At(rl, field + ".relabel"));
    }
    // Into the next phase: a state named like one of this phase's takes its value after the impact.
    const ExpressionPhaseSpec& next = spec_.phases[NextPhase(i)];
    for (const std::string& s : next.state_names) {
      const auto v = std::find(names.velocities.begin(), names.velocities.end(), s);
      const auto q = std::find(names.coordinates.begin(), names.coordinates.end(), s);
      if (v != names.velocities.end()) {
        out.reset.push_back(after[v - names.velocities.begin()]);
      } else if (q != names.coordinates.end() && relabel[q - names.coordinates.begin()]) {
        out.reset.push_back(relabel[q - names.coordinates.begin()]);
      } else if (index(s) >= 0 && index(s) < dim) {
        out.reset.push_back(MakeInput(index(s)));
      } else {
        out.reset.push_back(nullptr);
      }
    }
  }
  return out;
}

}  // namespace hybridcont::internal
