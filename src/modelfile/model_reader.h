// The model-file reader (private to src/modelfile): walks the parsed TOML tree of a model file, checks every
// field against the format and builds the ExpressionModelSpec; a violation throws ModelInputError with the
// file, line and field. Its methods are defined by section:
//   model_reader.cc        Read (the order of the tables), messages, typed access, symbols
//   read_setup.cc          version, parameters, definitions, start, run, families, quantities
//   read_phases.cc         phases (headers, then the functions of each) and symmetries
//   read_observables.cc    observables and constraints
//   read_presentation.cc   figures and drawing
//   ExpressionModelSpec spec = Reader(root, "slip.toml").Read();
#ifndef HYBRIDCONT_SRC_MODELFILE_MODEL_READER_H_
#define HYBRIDCONT_SRC_MODELFILE_MODEL_READER_H_

#include <toml++/toml.h>

#include <initializer_list>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "hybridcont/model_file.h"
#include "hybridcont/shooting_layout.h"
#include "model_compiler.h"

namespace hybridcont {
struct MechanicalSystem;  // mechanics.h
}  // namespace hybridcont

namespace hybridcont::internal {

class Reader {
 public:
  Reader(const toml::table& root, std::string file) : root_(root), file_(std::move(file)) {}

  ExpressionModelSpec Read();

 private:
  // ---- messages
  SourceLocation At(const toml::node* node, const std::string& field) const;
  [[noreturn]] void Fail(const toml::node* node, const std::string& field, const std::string& what) const;
  static std::string Join(const std::string& prefix, const std::string& key);
  static std::string TypeName(const toml::node& n);

  // Every key of `table` must be one of `known`.
  void CheckKeys(const toml::table& table, const std::string& prefix, std::initializer_list<const char*> known) const;

  // ---- typed access
  const toml::table& RequiredTable(const toml::table& t, const std::string& key, const std::string& prefix) const;
  const toml::table* OptionalTable(const toml::table& t, const std::string& key, const std::string& prefix) const;
  std::string RequiredString(const toml::table& t, const std::string& key, const std::string& prefix) const;
  std::string OptionalString(const toml::table& t, const std::string& key, const std::string& prefix,
                             const std::string& fallback) const;
  std::string AsString(const toml::node& n, const std::string& field) const;
  double AsNumber(const toml::node& n, const std::string& field) const;
  double OptionalNumber(const toml::table& t, const std::string& key, const std::string& prefix, double fallback) const;
  int OptionalInteger(const toml::table& t, const std::string& key, const std::string& prefix, int fallback, int lo,
                      int hi) const;
  bool OptionalBool(const toml::table& t, const std::string& key, const std::string& prefix, bool fallback) const;
  const toml::array& AsArray(const toml::node& n, const std::string& field) const;
  std::vector<std::string> StringArray(const toml::node& n, const std::string& field) const;
  // A set-up value: a number or an expression string (checked later against its symbols).
  SetupValue AsSetupValue(const toml::node& n, const std::string& field) const;
  // An expression string (numbers are accepted and written as constants).
  std::string ExpressionText(const toml::node& n, const std::string& field) const;

  // ---- symbols
  // Parameters and [definitions] (definitions are expressions over parameters and other definitions).
  ExprPtr GlobalSymbol(const std::string& name);
  ExprPtr Definition(const std::string& name);
  // A phase's states, its `let` quantities, then the global symbols.
  ExprPtr PhaseSymbol(int phase, const std::string& name);
  // A definition or let quantity `name` (at node n, field) begins to be resolved: refused, naming the chain, when
  // the definitions and quantities being resolved already use one another kMaxSymbolNesting deep.
  void BeginResolving(const toml::node* n, const std::string& field, const std::string& name);
  ExprPtr ParsePhaseExpression(int phase, const toml::node& n, const std::string& field);
  // Checks a set-up value against its symbols now, so that a typo is reported before anything runs.
  void CheckSetupValue(const SetupValue& v, const std::vector<std::string>& extra_symbols);
  // Names of the time-based layout's unknowns: t1..t<m+1>, x<i>_<state>, xi (xi1.. for k > 1), H.
  std::vector<std::string> UnknownNames() const;
  // The same for a word of the file's automaton (catalogue phases).
  std::vector<std::string> UnknownNames(const std::vector<int>& word) const;

  // Checks shared by several sections.
  // A symbol name must be an identifier that is not a function or a reserved name.
  void CheckName(const toml::node* n, const std::string& field, const std::string& name) const;
  // A label names files, folders and CSV columns (the model, its phases or modes, its symmetries): 1 to
  // kMaxLabelLength of letters, digits, '_' and '-', not starting with '-'. One rule, so that no output path
  // leaves the results folder ("..") and no CSV cell needs quoting.
  void CheckLabel(const toml::node* n, const std::string& field, const std::string& label) const;
  // Free text shown to a person (a title, a description, a family's name): no control characters (a
  // newline would break a message or a report line).
  void CheckText(const toml::node* n, const std::string& field, const std::string& text) const;
  static constexpr std::size_t kMaxLabelLength = 64;
  // Bounds on a file's size in names and phases: work that grows with them (deriving the equations of a
  // phase from its mechanics is cubic in its coordinates and pinned ones; each phase is compiled) stays
  // bounded for a small file. Far above the largest legitimate models (a 40-state walker, 10 phases).
  static constexpr std::size_t kMaxListLength = 256;  // entries of a list of names (states, lines, ...)
  static constexpr std::size_t kMaxPinned = 16;       // pinned coordinates of a mechanical phase
  static constexpr std::size_t kMaxPhases = 100;      // phases, or modes and transitions of an automaton
  // `name` must be an unknown of the time-based layout (or, with allow_period, "period").
  void CheckUnknown(const toml::node* n, const std::string& field, const std::string& name, bool allow_period) const;
  // `name` must be an unknown of `word`'s time-based layout.
  void CheckWordUnknown(const toml::node* n, const std::string& field, const std::string& name,
                        const std::vector<int>& word) const;
  static std::string JoinNames(const std::vector<std::string>& names);
  // The symbols of an orbit's columns: the unknowns, T and the quantities.
  std::vector<std::string> OrbitSymbols() const;

  // ---- sections (read_setup.cc)
  void ReadVersion();
  // A parameter range written as an interval: "(0, inf)", "[0, 1]".
  ParameterRange ParseRange(const toml::node& n, const std::string& field) const;
  void ReadParameters();
  void ReadDefinitions();
  void ReadStart();
  void ReadWordStarts(const toml::array& a);
  // One start table ([start] or an element of [[start]]); its values name `word`'s unknowns (empty: the
  // file's word).
  StartSpec ReadStartTable(const toml::table& t, const std::string& field, const std::vector<int>& word = {});
  void ReadRun();
  void ReadFamilies();
  void ReadQuantities();

  // ---- sections (read_phases.cc)
  void ReadPhaseHeaders();
  // One [[phases]] or [[modes]] table's name, states and typical state (mode: the keys of a mode).
  ExpressionPhaseSpec ReadPhaseHeader(const toml::table& t, const std::string& field, std::set<std::string>* names,
                                      bool mode);
  // [[modes]] and [[transitions]]: the catalogue of phases, one per transition (hybrid_automaton.h), and `word`.
  void ReadAutomatonHeaders();
  void ReadWord();
  // The phases of the file's word: catalogue indices (an automaton) or 0..m-1.
  const std::vector<int>& WordPhases() const;
  // The phase that phase i resets into.
  int NextPhase(int i) const;
  // The table holding phase i's event and reset: its transition's for an automaton.
  const toml::table& EventTable(int i) const { return transition_tables_.empty() ? *phase_tables_[i] : *transition_tables_[i]; }
  // "phases.<name>" or "transitions.<name>": the field of phase i's event and reset.
  std::string TransitionField(int i) const;
  // The functions of phase i: its let quantities, ode, first integrals, event, reset and (first phase) anchor.
  void ReadPhaseFunctions(int i);
  // The let quantities of phase i, each parsed now: errors in unused quantities are errors too.
  void ReadLets(int i);
  // ode: one expression per state, keyed by the state's name; `derived` (non-empty for a phase given by its
  // mechanics) holds the rates of its coordinates and velocities, and ode gives the others.
  void ReadVectorField(int i, const std::vector<ExprPtr>& derived);
  // First integrals: `energy` (one) or `integrals` (several), as many in every phase as in the first; a
  // phase given by its mechanics may leave both out (derived_energy, H = T + V).
  void ReadIntegrals(int i, const ExprPtr& derived_energy);
  // reset: the next phase's states by name (the next phase may have another dimension); `defaults` (after
  // an impact: the post-impact state, non-empty) fills the states the reset table does not give.
  void ReadReset(int i, const std::vector<ExprPtr>& defaults);

  // ---- phases given by their mechanics (read_mechanics.cc)
  struct MechanicalNames {
    std::vector<std::string> coordinates, velocities;  // empty: the phase is given by its ode
    std::set<std::string> ignorable;                   // coordinates that are not states (cyclic)
    // Pinned coordinates (at rest in the phase, free in its impact) and their velocities ("d" + name):
    // symbols of kinetic, potential, forces and the impact's constraint only.
    std::vector<std::string> pinned, pinned_velocities;
  };
  // coordinates and velocities (default: "d" + coordinate), checked as names.
  MechanicalNames ReadMechanicalNames(const toml::table& t, const std::string& pf) const;
  struct Mechanics {
    std::vector<ExprPtr> vector_field;  // empty for an ode phase; else the rates of q and q̇, null elsewhere
    ExprPtr energy;                     // H derived from the mechanics
    ExprPtr constraint;                 // the impact's contact constraint g(q), if any
    SourceLocation constraint_where;
    std::vector<ExprPtr> reset;         // after an impact: the next phase's states (null where not known)
  };
  // kinetic/potential or mass_matrix/forces/potential, and impact: derives the equations of motion
  // (mechanics.h), checks them and stores M for explanations.
  Mechanics ReadMechanics(int i);
  void CheckImpactMassMatrix(const std::vector<std::vector<ExprPtr>>& mass, const std::vector<Vector>& states,
                             const std::vector<double>& values, const toml::table& impact, const std::string& field,
                             int i) const;
  // Phase i's (table t, field pf) kinetic and potential (T, V), or mass_matrix (M, n × n rows of expressions),
  // and forces (Q, keyed by coordinate; null where not given), with where each came from, into *system.
  void ReadEnergiesAndForces(int i, const toml::table& t, const std::string& pf, MechanicalSystem* system);
  // The contact of phase i's impact (at field, its keys checked): its constraints g(q), several for a contact
  // that neither slips nor rebounds; sets out->constraint_where, and out->constraint for a single one.
  std::vector<ExprPtr> ReadContactConstraints(int i, const toml::table& impact, const std::string& field,
                                              Mechanics* out);
  // The impact's (at field) restitution e: a number in [0, 1] or an expression of the parameters (a parameter
  // to continue in), 1 if not given; only the elastic law (1) in a conservative model.
  ExprPtr ReadRestitution(const toml::table& impact, const std::string& field);
  // The relabelling q' = S(q) after phase i's impact (rl, the table `relabel` of the impact at field): keyed
  // by coordinate, an expression of the coordinates; per coordinate, null where not given.
  std::vector<ExprPtr> ReadRelabelling(int i, const toml::table& rl, const std::string& field);
  void ReadSymmetries();

  // ---- sections (read_observables.cc)
  void ReadObservables();
  void ReadConstraints();
  // The names of the time-based layout's unknowns in its order (t_{m+1}, x̄_{m+1}, ..., ξ, H̄).
  std::vector<std::string> LayoutNames() const;
  // A table of expressions by phase name (the key `skip` left out), one ExpressionFunction per named phase
  // (null elsewhere).
  std::vector<std::shared_ptr<const SmoothFunction>> ReadPhaseFunctions(const toml::node& node, const std::string& field,
                                                                        const std::string& skip = "");
  // An observable's or constraint's name: an identifier that no unknown, parameter, quantity or other
  // observable has.
  // A `final` table names exactly one phase.
  void CheckOnePhase(const toml::node& node, const std::string& field) const;
  void CheckObservableName(const toml::node& node, const std::string& field, const std::string& name) const;

  // ---- sections (read_presentation.cc)
  void ReadFigures();
  void ReadDrawing();
  // The drawing of one phase: [drawing.<phase>] with x_velocity, points, lines and masses.
  DrawingSpec::PhaseDrawing ReadPhaseDrawing(const toml::node& node, const std::string& k, int phase);
  // A drawing value, checked against the symbols OrbitPresentation gives a drawing: the phase's states, X,
  // parameters, definitions (not the phase's let quantities, which the run would refuse after compiling the
  // model).
  SetupValue DrawingValue(const toml::node& n, const std::string& f, int phase);
  // A drawing's lines (two or more points each) and masses, each naming a point of the drawing.
  void ReadLinesAndMasses(const toml::table& pt, const std::string& field, const std::set<std::string>& point_names,
                          DrawingSpec::PhaseDrawing* pd) const;

  const toml::table& root_;
  std::string file_;
  ExpressionModelSpec spec_;
  std::map<std::string, int> parameter_index_;
  std::map<std::string, const toml::node*> definition_sources_;
  std::map<std::string, ExprPtr> definitions_;
  std::map<std::string, ExprPtr> lets_;
  std::set<std::string> resolving_;
  // The definitions and let quantities being resolved, each using the next (resolving recurses through them).
  std::vector<std::string> resolving_chain_;
  // The longest such chain: each level is a nested parse on the stack, and this bound keeps the deepest chain
  // far from the stack's end (bench/README.md, "Requests that ran away, refused").
  static constexpr std::size_t kMaxSymbolNesting = 1000;
  std::vector<const toml::table*> phase_tables_;
  std::vector<const toml::table*> phase_lets_;
  // An automaton: per catalogue phase its transition's table and let, the phase it resets into.
  std::vector<const toml::table*> transition_tables_;
  std::vector<const toml::table*> transition_lets_;
  std::vector<int> next_phase_;
  ExpressionAutomatonSpec automaton_;
  mutable std::vector<int> cycle_;
  int num_integrals_ = 1;
  std::vector<MechanicalNames> mechanical_names_;
  // The phase whose pinned coordinates are symbols (while its energies and contact are read), or -1.
  int pinned_symbols_phase_ = -1;
  // `conservative = false`: no phase has a first integral; families are continued in run.parameter.
  bool conservative_ = true;
};

}  // namespace hybridcont::internal

#endif  // HYBRIDCONT_SRC_MODELFILE_MODEL_READER_H_
