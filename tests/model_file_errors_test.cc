// Bad model files: each row breaks one thing of a good model file and states the line and the message the
// reader must give. A model file is untrusted input: every problem is a ModelInputError naming the file,
// the line and the field (docs/model-files.md lists these rows with their messages), and through the
// command line an exit code of 2, the message on stderr and nothing written.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "hybridcont/model_file.h"

namespace hybridcont {
namespace {

namespace fs = std::filesystem;

// models/slip.toml as this table was written against: a copy, so that edits of the shipped model do not
// move the lines below (ShippedModelsParse reads the shipped files).
constexpr const char* kSlip = R"toml(# The spring-loaded inverted pendulum hopper with a swing leg (Raff & Remy 2025, eq. HDSslip, §4.4),
# written as a model file. Units: m = l0 = g = 1.
hybridcont = 1
name = "slip"
title = "SLIP hopper"
description = "spring-loaded inverted pendulum hopper with swing leg (paper §4.4), as a model file"

[parameters]
m  = { value = 1.0,  range = "(0, inf)", description = "point mass" }
l0 = { value = 1.0,  range = "(0, inf)", description = "natural leg length" }
g  = { value = 1.0,  range = "(0, inf)", description = "gravity" }
k  = { value = 40.0, range = "(0, inf)", description = "leg stiffness" }
w2 = { value = 5.0,  range = "(0, inf)", description = "squared swing frequency omega^2 of the leg in flight" }

# Stance: the foot is on the ground; leg angle alpha from the vertical and leg length l.
[[phases]]
name = "stance"
states = ["alpha", "l", "dalpha", "dl"]
typical = [0.1, 0.9, 0.3, -0.4]
ode.alpha = "dalpha"
ode.l = "dl"
ode.dalpha = "-2*dalpha*dl/l + g/l*sin(alpha)"
ode.dl = "l*dalpha^2 - g*cos(alpha) - k/m*(l - l0)"
energy = "0.5*m*(dalpha^2*l^2 + dl^2) + m*g*cos(alpha)*l + 0.5*k*(l - l0)^2"
event = "l0 - l"                      # lift-off at natural length
anchor = "-dl"                        # Poincaré section at the nadir
reset.y = "l*cos(alpha)"
reset.alpha = "alpha"
reset.dx = "-dl*sin(alpha) - dalpha*l*cos(alpha)"
reset.dy = "dl*cos(alpha) - dalpha*l*sin(alpha)"
reset.dalpha = "dalpha"

# Flight: the body flies ballistically, the massless leg swings as a harmonic oscillator.
[[phases]]
name = "flight"
states = ["y", "alpha", "dx", "dy", "dalpha"]
typical = [0.95, 0.1, 0.3, 0.5, -0.2]
ode = { y = "dy", alpha = "dalpha", dx = "0", dy = "-g", dalpha = "-alpha*w2" }
energy = "0.5*m*(dx^2 + dy^2) + m*g*y"
event = "y - l0*cos(alpha)"           # touch-down
let.s = "sin(alpha)"
let.c = "cos(alpha)"
reset.alpha = "alpha"
reset.l = "l0"
reset.dalpha = "-(c*dx + s*dy)/l0"
reset.dl = "c*dy - s*dx"

[[symmetries]]
name = "mirror"                       # x -> -x: forward and backward hopping
flip = { stance = ["alpha", "dalpha"], flight = ["alpha", "dx", "dalpha"] }

[[symmetries]]
name = "time-reversal"                # velocities flip
reverses_time = true
flip = { stance = ["dalpha", "dl"], flight = ["dx", "dy", "dalpha"] }

# The vertical harmonic oscillation with zero flight time at H = m g l0 (the paper's start).
[start]
kind = "singular"
values = { t1 = "pi*sqrt(m/k)", t2 = 0, t3 = "pi*sqrt(m/k)", x1_l = "l0 - 2*m*g/k", x2_y = "l0", x3_l = "l0", H = "m*g*l0" }

[run]
bounds = { xi = [-1, 1], H = [0, 2], period = [-20, 20] }
keyframes = { component = "H", value = 1.8, orbits = 4 }

[[families]]
name = "hopping in place"
when = "abs(x2_dx) < 1e-6"

[[families]]
name = "forward hopping"
when = "x2_dx > 0"

[[families]]
name = "backward hopping"

[[figures]]
file = "slip_durations.png"
title = "stance and flight durations"
x = "t2"
y = ["t1", "t3"]

[[figures]]
file = "slip_speed.png"
title = "forward speed in flight"
x = "H"
y = "x2_dx"

# The body at (X, height); X advances with the body's horizontal speed.
[drawing.stance]
x_velocity = "-dl*sin(alpha) - l*cos(alpha)*dalpha"
points = { body = ["X", "l*cos(alpha)"], foot = ["X + l*sin(alpha)", "0"] }
lines = [["foot", "body"]]
masses = ["body"]

[drawing.flight]
x_velocity = "dx"
points = { body = ["X", "y"], foot = ["X + l0*sin(alpha)", "y - l0*cos(alpha)"] }
lines = [["foot", "body"]]
masses = ["body"]
)toml";

std::string Repeat(const std::string& s, int n) {
  std::string out;
  for (int i = 0; i < n; ++i) out += s;
  return out;
}

// A model given by its mechanics, for the rows of bad mechanics.
constexpr const char* kPendulum = R"toml(# The pendulum on a bouncing slider (models/bouncing-pendulum.toml), trimmed: the base of the bad-mechanics rows.
hybridcont = 1
name = "bouncing-pendulum"

[parameters]
m1 = { value = 1.0, range = "(0, inf)" }
m2 = { value = 1.0, range = "(0, inf)" }
l  = { value = 1.0, range = "(0, inf)" }
g  = { value = 1.0, range = "(0, inf)" }

[[phases]]
name = "flight"
coordinates = ["y", "theta"]
typical = [0.3, 0.4, -0.2, 0.5]
kinetic = "0.5*m1*dy^2 + 0.5*m2*((l*cos(theta)*dtheta)^2 + (dy + l*sin(theta)*dtheta)^2)"
potential = "(m1 + m2)*g*y + m2*g*l*(1 - cos(theta))"
impact = { constraint = "y", restitution = 1 }
anchor = "dy"

[start]
kind = "singular"
values = { t1 = "sqrt(0.5)", t2 = "sqrt(0.5)", x1_y = "0.25", x2_dy = "sqrt(0.5)", H = "0.5" }

[run]
bounds = { xi = [-1, 1], H = [0.05, 3], period = [-20, 20] }
)toml";


// A hybrid automaton (docs/model-files.md, "Automata"): one mode, two transitions.
const char* const kBall = R"toml(hybridcont = 1
name = "ball"
word = ["floor"]

[parameters]
g = { value = 1.0, range = "(0, inf)" }
h = { value = 1.0, range = "(0, inf)" }

[[modes]]
name = "fly"
states = ["y", "v"]
ode = { y = "v", v = "-g" }
energy = "0.5*v^2 + g*y"
anchor = "y - 0.25"

[[transitions]]
name = "floor"
from = "fly"
to = "fly"
event = "y"
reset.v = "-v"

[[transitions]]
name = "ceiling"
from = "fly"
to = "fly"
event = "h - y"
reset.v = "-v"
)toml";

struct BadFile {
  std::string name;     // the test's name
  std::string find;     // text of `model` to replace (it occurs exactly once); empty: append `replace`
  std::string replace;
  int line;             // the line the error must name (where().line)
  std::string message;  // a substring of the message: the field and the problem
  const char* model = kSlip;
};

// Every row breaks one thing; the line is the line of the broken value (or of the table that lacks it).
const BadFile kBadFiles[] = {
    // ---- TOML and the file's header
    {"TomlUnterminatedString", "title = \"SLIP hopper\"", "title = \"SLIP hopper", 5, "TOML syntax"},
    {"TomlDuplicateKey", "ode.l = \"dl\"\n", "ode.l = \"dl\"\node.l = \"l\"\n", 22, "TOML syntax"},
    {"TomlMissingValue", "event = \"l0 - l\"", "event =", 25, "TOML syntax"},
    {"TomlDuplicateTable", "[drawing.flight]", "[drawing.stance]", 96, "TOML syntax"},
    {"MissingVersion", "hybridcont = 1\n", "", 1, "missing field 'hybridcont'"},
    {"Version2", "hybridcont = 1", "hybridcont = 2", 3, "hybridcont: format version 2 is not supported"},
    {"VersionNotAnInteger", "hybridcont = 1", "hybridcont = \"1\"", 3,
     "hybridcont: expected the format version as an integer"},
    {"MissingName", "name = \"slip\"\n", "", 1, "name: missing field 'name'"},
    {"NameWithSpace", "name = \"slip\"", "name = \"my slip\"", 4,
     "name: 'my slip' is not a label (1 to 64 letters, digits, '_' or '-', not starting with '-'): it names files"},
    {"NameDots", "name = \"slip\"", "name = \"..\"", 4, "name: '..' is not a label"},
    {"NameNewline", "name = \"slip\"", "name = \"a\\nb\"", 4, "name: 'a\\x0ab' is not a label"},
    {"PhaseNameComma", "name = \"stance\"", "name = \"st,ance\"", 17, "phases[0].name: 'st,ance' is not a label"},
    {"TitleNewline", "title = \"SLIP hopper\"", "title = \"SLIP\\nhopper\"", 5, "title: 'SLIP\\x0ahopper' holds a control character"},
    {"UnknownTopLevelField", "title = \"SLIP hopper\"\n", "title = \"SLIP hopper\"\nauthor = \"me\"\n", 6,
     "author: unknown field 'author'"},
    {"StringExpectedGotInteger", "title = \"SLIP hopper\"", "title = 3", 5, "title: expected a string, got an integer"},
    {"TableExpectedGotInteger", "keyframes = { component = \"H\", value = 1.8, orbits = 4 }", "keyframes = 4", 64,
     "run.keyframes: expected a table, got an integer"},
    // ---- parameters and definitions
    {"ParameterOutsideRange", "value = 40.0", "value = -40.0", 12,
     "parameters.k.value: value -40 is outside the range (0, inf)"},
    {"ParameterNotFinite", "value = 1.0,  range = \"(0, inf)\", description = \"gravity\"",
     "value = nan,  range = \"(0, inf)\", description = \"gravity\"", 11, "parameters.g.value: expected a finite number"},
    {"RangeMalformed", "m  = { value = 1.0,  range = \"(0, inf)\"", "m  = { value = 1.0,  range = \"0, inf\"", 9,
     "parameters.m.range: range '0, inf': expected '(' or '[' first"},
    {"RangeLowerAboveUpper", "g  = { value = 1.0,  range = \"(0, inf)\"", "g  = { value = 1.0,  range = \"(2, 1)\"", 11,
     "parameters.g.range: range '(2, 1)': the lower end must be below the upper end"},
    {"ParameterMissingValue", "k  = { value = 40.0, range", "k  = { range", 12,
     "parameters.k.value: missing field 'value'"},
    {"ParameterShadowsFunction", "w2 = {", "sin = {", 13, "parameters.sin: 'sin' is reserved"},
    {"DefinitionCycle", "\n# Stance:", "\n[definitions]\na = \"2*b\"\nb = \"a + 1\"\n\n# Stance:", 16,
     "definitions.a: 'a' is defined in terms of itself"},
    {"DefinitionUsesAState", "\n# Stance:", "\n[definitions]\nmgl = \"m*g*l\"\n\n# Stance:", 16,
     "definitions.mgl: in expression 'm*g*l' at column 5: unknown symbol 'l'"},
    // ---- phases
    {"UnknownPhaseField", "typical = [0.1, 0.9, 0.3, -0.4]\n", "typical = [0.1, 0.9, 0.3, -0.4]\nmass = 1\n", 20,
     "phases[0].mass: unknown field 'mass'"},
    {"DuplicatePhaseName", "name = \"flight\"", "name = \"stance\"", 35,
     "phases[1].name: phase name 'stance' is empty or used twice"},
    {"StateListedTwice", "states = [\"alpha\", \"l\", \"dalpha\", \"dl\"]", "states = [\"alpha\", \"l\", \"dalpha\", \"l\"]", 18,
     "phases.stance.states: state 'l' listed twice"},
    {"NoStates", "states = [\"alpha\", \"l\", \"dalpha\", \"dl\"]", "states = []", 18,
     "phases.stance.states: 0 states, expected at least 1"},
    {"TypicalWrongDimension", "typical = [0.1, 0.9, 0.3, -0.4]", "typical = [0.1, 0.9, 0.3]", 19,
     "phases.stance.typical: 3 values for 4 states"},
    {"MissingOdeEntry", "ode.l = \"dl\"\n", "", 20, "phases.stance.ode: missing the rate of state 'l'"},
    {"OdeForUnknownState", "ode.l = \"dl\"", "ode.q = \"dl\"", 21,
     "phases.stance.ode.q: 'q' is not a state of phase 'stance'"},
    {"UnknownSymbol", "+ g/l*sin(alpha)", "+ gg/l*sin(alpha)", 22,
     "phases.stance.ode.dalpha: in expression '-2*dalpha*dl/l + gg/l*sin(alpha)' at column 18: unknown symbol 'gg'"},
    {"UnknownFunction", "+ g/l*sin(alpha)", "+ g/l*sine(alpha)", 22,
     "phases.stance.ode.dalpha: in expression '-2*dalpha*dl/l + g/l*sine(alpha)' at column 22: unknown function 'sine'"},
    {"WrongArity", "event = \"y - l0*cos(alpha)\"", "event = \"y - l0*cos(alpha, y)\"", 40,
     "phases.flight.event: in expression 'y - l0*cos(alpha, y)' at column 8: cos takes 1 argument(s), got 2"},
    {"MalformedNumber", "energy = \"0.5*m*(dx^2", "energy = \"0.5.1*m*(dx^2", 39,
     "phases.flight.energy: in expression '0.5.1*m*(dx^2 + dy^2) + m*g*y' at column 1: malformed number '0.5.1'"},
    {"NumberOutOfRange", "energy = \"0.5*m*(dalpha^2", "energy = \"1e999*m*(dalpha^2", 24,
     "phases.stance.energy: in expression '1e999*m*(dalpha^2*l^2 + dl^2) + m*g*cos(alpha)*l + 0.5*k*(l - l0)^2' at column 1: number '1e999' is out of range"},
    {"UnbalancedParenthesis", "k/m*(l - l0)\"", "k/m*(l - l0\"", 23,
     "phases.stance.ode.dl: in expression 'l*dalpha^2 - g*cos(alpha) - k/m*(l - l0' at column 40: expected ')'"},
    {"TrailingOperator", "event = \"l0 - l\"", "event = \"l0 - l -\"", 25,
     "phases.stance.event: in expression 'l0 - l -' at column 9: expression ends where an operand is expected"},
    {"TrailingText", "event = \"l0 - l\"", "event = \"l0 - l)\"", 25,
     "phases.stance.event: in expression 'l0 - l)' at column 7: unexpected ')'"},
    {"EmptyExpression", "anchor = \"-dl\"", "anchor = \"\"", 26,
     "phases.stance.anchor: in expression '' at column 1: empty expression"},
    {"ComparisonInOde", "ode.l = \"dl\"", "ode.l = \"dl*(l > 0)\"", 21,
     "phases.stance.ode.l: comparisons, logic, min and max are not differentiable"},
    {"MinInReset", "reset.dl = \"c*dy - s*dx\"", "reset.dl = \"min(c*dy, s*dx)\"", 46,
     "phases.flight.reset.dl: comparisons, logic, min and max are not differentiable"},
    {"NestedTooDeep", "ode.l = \"dl\"", "ode.l = \"" + Repeat("(", 250) + "dl" + Repeat(")", 250) + "\"", 21,
     "phases.stance.ode.l: in expression '" + Repeat("(", 77) + "...' at column 101: nested more than 200 levels deep"},
    {"SumTooLong", "ode.l = \"dl\"", "ode.l = \"dl" + Repeat("+dl", 10000) + "\"", 21,
     "phases.stance.ode.l: in expression 'dl+dl+dl+dl+dl+dl+dl+dl+dl+dl+dl+dl+dl+dl+dl+dl+dl+dl+dl+dl+dl+dl+dl+dl+dl+dl...' at column 12006: "
     "more than 4000 operations in one expression (split it into `let` quantities or definitions)"},
    {"LetCycle", "let.s = \"sin(alpha)\"\nlet.c = \"cos(alpha)\"", "let.s = \"c\"\nlet.c = \"s\"", 42,
     "phases.flight.let.c: 'c' is defined in terms of itself"},
    {"LetShadowsState", "let.s = \"sin(alpha)\"", "let.y = \"sin(alpha)\"", 41,
     "phases.flight.let.y: 'y' is also a state or a parameter"},
    {"EnergyAndIntegrals", "energy = \"0.5*m*(dx^2 + dy^2) + m*g*y\"\n",
     "energy = \"0.5*m*(dx^2 + dy^2) + m*g*y\"\nintegrals = [\"0.5*m*(dx^2 + dy^2) + m*g*y\"]\n", 40,
     "phases.flight.energy: give exactly one of 'energy' (the first integral) or 'integrals'"},
    {"IntegralsDifferAcrossPhases", "energy = \"0.5*m*(dx^2 + dy^2) + m*g*y\"",
     "integrals = [\"0.5*m*(dx^2 + dy^2) + m*g*y\", \"dx\"]", 39,
     "phases.flight: phase 'flight' has 2 first integrals, the first phase 1"},
    {"MissingEvent", "event = \"l0 - l\"                      # lift-off at natural length\n", "", 16,
     "phases.stance.event: missing field 'event'"},
    {"ResetMissingNextPhaseState", "reset.dy = \"dl*cos(alpha) - dalpha*l*sin(alpha)\"\n", "", 27,
     "phases.stance.reset: missing the value of state 'dy' of the next phase 'flight'"},
    {"ResetNamesStateNotInNextPhase", "reset.dalpha = \"dalpha\"", "reset.dl = \"dalpha\"", 31,
     "phases.stance.reset.dl: 'dl' is not a state of the next phase 'flight'"},
    {"AnchorInSecondPhase", "event = \"y - l0*cos(alpha)\"", "anchor = \"dy\"\nevent = \"y - l0*cos(alpha)\"", 40,
     "phases.flight.anchor: only the first phase carries the anchor"},
    {"MissingAnchor", "anchor = \"-dl\"                        # Poincaré section at the nadir\n", "", 16,
     "phases.stance.anchor: missing field 'anchor' in the first phase"},
    // ---- symmetries
    {"SymmetryFlipsUnknownState", "flip = { stance = [\"alpha\", \"dalpha\"]", "flip = { stance = [\"alpha\", \"dbeta\"]", 50,
     "symmetries[0].flip.stance: 'dbeta' is not a state of phase 'stance'"},
    {"OdeMissingARate", "ode.l = \"dl\"\n", "", 20, "phases.stance.ode: missing the rate of state 'l'"},
    {"SymmetryFlipsAStateTwice", "flip = { stance = [\"alpha\", \"dalpha\"]", "flip = { stance = [\"alpha\", \"dalpha\", \"alpha\"]", 50,
     "symmetries[0].flip.stance: 'alpha' is flipped twice (once flips its sign)"},
    {"SymmetryFlipsUnknownPhase", "flight = [\"dx\", \"dy\", \"dalpha\"] }", "hover = [\"dx\", \"dy\", \"dalpha\"] }", 55,
     "symmetries[1].flip.hover: 'hover' is not a phase"},
    {"SymmetryDeclaredTwice", "name = \"time-reversal\"", "name = \"mirror\"", 53,
     "symmetries[1].name: symmetry 'mirror' declared twice"},
    {"SymmetryWithoutName", "name = \"mirror\"", "name = \"\"", 49, "symmetries[0].name: '' is not a label"},
    {"SymmetryIsTheIdentity", "flip = { stance = [\"alpha\", \"dalpha\"], flight = [\"alpha\", \"dx\", \"dalpha\"] }",
     "flip = {}", 50, "symmetries[0].flip: symmetry 'mirror' flips no state and does not reverse time"},
    // ---- start and run
    {"StartValueForUnknownUnknown", "x2_y = \"l0\"", "x2_q = \"l0\"", 60,
     "start.values.x2_q: 'x2_q' is not an unknown of the model"},
    {"StartKindWrong", "kind = \"singular\"", "kind = \"exact\"", 59,
     "start.kind: 'exact': expected 'singular', 'guess' or 'simulation'"},
    {"StartValueUnknownSymbol", "H = \"m*g*l0\"", "H = \"m*g*L0\"", 60,
     "start.values.H: in expression 'm*g*L0' at column 5: unknown symbol 'L0'"},
    {"BoundWithOneElement", "H = [0, 2]", "H = [0]", 63, "run.bounds.H: expected [lower, upper]"},
    {"BoundForUnknownUnknown", "H = [0, 2]", "E = [0, 2]", 63, "run.bounds.E: 'E' is not an unknown of the model"},
    {"KeyframesComponentQ", "component = \"H\"", "component = \"Q\"", 64,
     "run.keyframes.component: expected \"H\" or \"T\""},
    {"KeyframesOrbitsOutOfRange", "orbits = 4", "orbits = 101", 64, "run.keyframes.orbits: 101 is outside [0, 100]"},
    // ---- families, quantities, figures, drawing
    {"FamilyRuleUnknownSymbol", "when = \"x2_dx > 0\"", "when = \"x2_dz > 0\"", 72,
     "families[1].when: in expression 'x2_dz > 0' at column 1: unknown symbol 'x2_dz'"},
    {"QuantityUnknownSymbol", "", "\n[quantities]\nspeed = \"abs(x2_dxx)\"\n", 103,
     "quantities.speed: in expression 'abs(x2_dxx)' at column 5: unknown symbol 'x2_dxx'"},
    {"ObservableWithTwoKinds", "", "\n[observables]\nspeed = { mean = { flight = \"dx\" }, maximum = { flight = \"y\" } }\n", 103,
     "observables.speed: give exactly one of value, integral, mean, minimum, maximum, final (got 2)"},
    {"ObservableOverAnUnknownPhase", "", "\n[observables]\nspeed = { mean = { swing = \"dx\" } }\n", 103,
     "observables.speed.mean.swing: 'swing' is not a phase (phases: stance, flight)"},
    {"ObservableNamedLikeAnUnknown", "", "\n[observables]\nH = { value = \"t2\" }\n", 103,
     "observables.H: 'H' is also an unknown, T or a parameter"},
    {"ConstraintNotDifferentiable", "", "\n[constraints]\nclearance = { flight = \"min(y, 1)\" }\n", 103,
     "constraints.clearance.flight: comparisons, logic, min and max have no derivative and cannot be used here"},
    // ---- automata
    {"WordOfAmbiguousModes", "word = [\"floor\"]", "word = [\"fly\"]", 3,
     "word: modes 'fly' and 'fly' are joined by several transitions (floor, ceiling)", kBall},
    {"WordOfUnknownMode", "word = [\"floor\"]", "word = [\"swim\"]", 3, "word: 'swim' is neither a mode nor a transition",
     kBall},
    {"TransitionIntoUnknownMode", "to = \"fly\"\nevent = \"y\"", "to = \"air\"\nevent = \"y\"", 19,
     "transitions.floor.to: 'air' is not a mode (modes: fly)", kBall},
    {"NoModeCarriesTheAnchor", "anchor = \"y - 0.25\"\n", "", 9, "modes: no mode carries the anchor", kBall},
    {"TransitionResetOfUnknownState", "reset.v = \"-v\"\n\n", "reset.w = \"-v\"\n\n", 21,
     "transitions.floor.reset.w: 'w' is not a state of the next mode 'fly'", kBall},
    {"TransitionWithoutGuard", "event = \"h - y\"\n", "", 23, "transitions.ceiling.event: missing field 'event'", kBall},
    {"StartInAnotherWordNotAGuess", "",
     "\n[[start]]\nkind = \"guess\"\nvalues = { H = 0.5 }\n\n[[start]]\nword = [\"ceiling\"]\nvalues = { H = 2 }\n", 34,
     "start[1].kind: a start in another word is an approximate orbit (kind = \"guess\")", kBall},
    {"TwoStartsOfOneWord", "",
     "\n[[start]]\nkind = \"guess\"\nvalues = { H = 0.5 }\n\n[[start]]\nkind = \"guess\"\nvalues = { H = 0.6 }\n", 34,
     "start[1].word: a second start of this word", kBall},
    {"StartWordInASingleStart", "", "\n[start]\nword = [\"ceiling\"]\n", 31,
     "start.word: a start in another word is a [[start]] table beside the file word's start", kBall},
    {"StartValueNotOfItsWord", "",
     "\n[[start]]\nkind = \"guess\"\nvalues = { H = 0.5 }\n\n[[start]]\nword = [\"ceiling\"]\nkind = \"guess\"\nvalues = { x3_y = 2 }\n", 37,
     "start[1].values.x3_y: 'x3_y' is not an unknown of the start's word", kBall},
    {"StartInAnotherWordWithConditions", "",
     "\n[[start]]\nkind = \"guess\"\nvalues = { H = 0.5 }\n\n[[start]]\nword = [\"ceiling\"]\nkind = \"guess\"\nconditions = [{ terms = { H = 1 } }]\n", 37,
     "start[1].conditions: a start in another word is a regular orbit: it has no start conditions", kBall},
    {"FigureFileWithSlash", "file = \"slip_speed.png\"", "file = \"plots/slip_speed.png\"", 84,
     "figures[1].file: 'plots/slip_speed.png': a plain file name ending in .png"},
    {"FigureColumnUnknown", "x = \"t2\"", "x = \"t9\"", 80, "figures[0].x: 't9' is not a column"},
    {"DrawingLineNamesUnknownPoint", "lines = [[\"foot\", \"body\"]]\nmasses = [\"body\"]\n\n[drawing.flight]",
     "lines = [[\"foot\", \"head\"]]\nmasses = [\"body\"]\n\n[drawing.flight]", 93,
     "drawing.stance.lines[0]: 'head' is not a point of drawing.stance"},
    {"DrawingOfUnknownPhase", "[drawing.flight]", "[drawing.hover]", 96, "drawing.hover: 'hover' is neither a phase"},
    {"DrawingUsesALetQuantity", "foot = [\"X + l0*sin(alpha)\"", "foot = [\"X + l0*s\"", 98,
     "drawing.flight.points.foot[0]: in expression 'X + l0*s' at column 8: unknown symbol 's'"},
    {"DrawingUnknownSymbol", "x_velocity = \"dx\"", "x_velocity = \"dz\"", 97,
     "drawing.flight.x_velocity: in expression 'dz' at column 1: unknown symbol 'dz'"},
    // ---- bad mechanics (a phase given by its mechanics, mechanics.h)
    {"KineticNotQuadratic", "kinetic = \"0.5*m1*dy^2", "kinetic = \"0.1*dy^4 + 0.5*m1*dy^2", 15,
     "phases.flight.kinetic: the kinetic energy is not quadratic in the velocities", kPendulum},
    {"KineticWithLinearTerm", "kinetic = \"0.5*m1*dy^2", "kinetic = \"m1*g*dy + 0.5*m1*dy^2", 15,
     "phases.flight.kinetic: the kinetic energy is not a quadratic form in the velocities: T = ", kPendulum},
    {"PotentialOfAVelocity", "potential = \"(m1 + m2)*g*y", "potential = \"(m1 + m2)*g*y + dtheta", 16,
     "phases.flight.potential: the potential energy V(q) depends on a velocity", kPendulum},
    {"MassMatrixNotSymmetric", "kinetic = \"0.5*m1*dy^2 + 0.5*m2*((l*cos(theta)*dtheta)^2 + (dy + l*sin(theta)*dtheta)^2)\"", "mass_matrix = [[\"m1 + m2\", \"m2*l*sin(theta)\"], [\"0\", \"m2*l^2\"]]", 15,
     "phases.flight.mass_matrix: the mass matrix is not symmetric: entry (2, 1) = 0 but (1, 2) = ", kPendulum},
    {"MassMatrixWrongSize", "kinetic = \"0.5*m1*dy^2 + 0.5*m2*((l*cos(theta)*dtheta)^2 + (dy + l*sin(theta)*dtheta)^2)\"", "mass_matrix = [[\"m1 + m2\"]]", 15,
     "phases.flight.mass_matrix: 1 rows for 2 coordinates (M is n × n)", kPendulum},
    {"MassMatrixOfAVelocity", "kinetic = \"0.5*m1*dy^2 + 0.5*m2*((l*cos(theta)*dtheta)^2 + (dy + l*sin(theta)*dtheta)^2)\"", "mass_matrix = [[\"m1 + m2\", \"0\"], [\"0\", \"m2*l^2*dy\"]]", 15,
     "phases.flight.mass_matrix: mass-matrix entry (2, 2) depends on a velocity", kPendulum},
    {"KineticAndMassMatrix", "potential = \"", "mass_matrix = [[\"1\", \"0\"], [\"0\", \"1\"]]\npotential = \"", 16,
     "phases.flight.mass_matrix: give 'kinetic' (T, M derived from it) or 'mass_matrix', not both", kPendulum},
    {"NeitherKineticNorMassMatrix", "kinetic = \"0.5*m1*dy^2 + 0.5*m2*((l*cos(theta)*dtheta)^2 + (dy + l*sin(theta)*dtheta)^2)\"\n", "", 11,
     "phases.flight.kinetic: a phase with coordinates needs 'kinetic' (T, a Lagrangian) or 'mass_matrix' (M)", kPendulum},
    {"ConstraintWithoutCoordinates", "constraint = \"y\"", "constraint = \"l - 1\"", 17,
     "phases.flight.impact.constraint: the contact constraint g(q) does not depend on the coordinates", kPendulum},
    {"ConstraintOfAVelocity", "constraint = \"y\"", "constraint = \"y + dy\"", 17,
     "phases.flight.impact.constraint: the contact constraint g(q) depends on a velocity", kPendulum},
    {"ImpactWithoutConstraint", "constraint = \"y\", ", "", 17,
     "phases.flight.impact.constraint: missing field 'constraint'", kPendulum},
    {"RestitutionBelowOne", "restitution = 1", "restitution = 0.8", 17,
     "phases.flight.impact.restitution: restitution 0.8: only the elastic law (1)", kPendulum},
    {"UndeclaredCoordinateUsed", "dy^2 + 0.5*m2", "dy^2 + 0.5*dphi^2 + 0.5*m2", 15,
     "unknown symbol 'dphi'", kPendulum},
    {"ForceOnUndeclaredCoordinate", "anchor = \"dy\"", "anchor = \"dy\"\nforces = { phi = \"0\" }", 19,
     "phases.flight.forces.phi: 'phi' is not a coordinate of phase 'flight' (forces are keyed by coordinate: y, theta)", kPendulum},
    {"OdeForACoordinate", "anchor = \"dy\"", "anchor = \"dy\"\node = { theta = \"dtheta\" }", 19,
     "phases.flight.ode.theta: 'theta' is a coordinate or velocity: its rate comes from the mechanics", kPendulum},
    {"VelocitiesCountWrong", "coordinates = [\"y\", \"theta\"]", "coordinates = [\"y\", \"theta\"]\nvelocities = [\"dy\"]", 14,
     "phases.flight.velocities: 1 velocities for 2 coordinates", kPendulum},
    {"IgnorableNotACoordinate", "coordinates = [\"y\", \"theta\"]", "coordinates = [\"y\", \"theta\"]\nignorable = [\"x\"]", 14,
     "phases.flight.ignorable: 'x' is not a coordinate", kPendulum},
    {"MechanicsWithoutCoordinates", "coordinates = [\"y\", \"theta\"]\n", "states = [\"y\", \"theta\", \"dy\", \"dtheta\"]\n", 15,
     "phases.flight.kinetic: 'kinetic' needs 'coordinates'", kPendulum},
    // (the pinned coordinate with a mass in the kinetic energy, so that the impact can be derived)
    {"PinnedCoordinateInTheAnchor", "0.5*m1*dy^2 + 0.5*m2*((l*cos(theta)*dtheta)^2 + (dy + l*sin(theta)*dtheta)^2)\"\n"
     "potential = \"(m1 + m2)*g*y + m2*g*l*(1 - cos(theta))\"\nimpact = { constraint = \"y\", restitution = 1 }\n"
     "anchor = \"dy\"",
     "0.5*m1*(dy^2 + dxp^2) + 0.5*m2*((l*cos(theta)*dtheta)^2 + (dy + l*sin(theta)*dtheta)^2)\"\n"
     "potential = \"(m1 + m2)*g*y + m2*g*l*(1 - cos(theta))\"\nimpact = { constraint = \"y\", restitution = 1 }\n"
     "anchor = \"dy + dxp\"\npinned = [\"xp\"]", 18,
     "phases.flight.anchor: in expression 'dy + dxp' at column 6: unknown symbol 'dxp'", kPendulum},
    {"RelabelNotACoordinate", "restitution = 1 }", "restitution = 1, relabel = { phi = \"theta\" } }", 17,
     "phases.flight.impact.relabel.phi: 'phi' is not a coordinate of phase 'flight' that is a state", kPendulum},
    {"RelabelOfAVelocity", "restitution = 1 }", "restitution = 1, relabel = { theta = \"dy - theta\" } }", 17,
     "phases.flight.impact.relabel: the relabelling depends on a velocity", kPendulum},
    {"ConstraintRowWithoutCoordinates", "constraint = \"y\"", "constraint = [\"y\", \"l\"]", 17,
     "phases.flight.impact.constraint: the contact constraint g(q) (row 2) does not depend on the coordinates", kPendulum},
    {"PinnedCoordinateWithoutMass", "coordinates = [\"y\", \"theta\"]", "coordinates = [\"y\", \"theta\"]\npinned = [\"xp\"]", 18,
     "phases.flight.impact: the impact cannot be derived: the mass matrix is not positive definite at (y = 0.3, "
     "theta = 0.4, xp = 0): pivot 3 of its Cholesky factorization is 0", kPendulum},
    {"StatesWithoutAVelocity", "coordinates = [\"y\", \"theta\"]", "coordinates = [\"y\", \"theta\"]\nstates = [\"y\", \"theta\", \"dy\"]", 14,
     "phases.flight.states: 'dtheta' is a coordinate or velocity but not a state", kPendulum},
};

void PrintTo(const BadFile& row, std::ostream* os) { *os << row.name; }

std::string Mutate(const BadFile& row) {
  std::string text = row.model;
  if (row.find.empty()) return text + row.replace;
  const std::size_t at = text.find(row.find);
  if (at == std::string::npos || text.find(row.find, at + 1) != std::string::npos) {
    ADD_FAILURE() << row.name << ": '" << row.find << "' must occur exactly once in the model";
    return text;
  }
  return text.replace(at, row.find.size(), row.replace);
}

TEST(ModelFileErrors, TheUnbrokenModelParses) {
  const ExpressionModelSpec spec = ParseModelText(kSlip, "slip.toml");
  EXPECT_EQ(spec.phases.size(), 2u);
  EXPECT_EQ(ParseModelText(kPendulum, "pendulum.toml").phases.size(), 1u);
  EXPECT_GE(std::size(kBadFiles), 40u);
}

TEST(ModelFileErrors, ShippedModelsParse) {
  for (const auto& entry : fs::directory_iterator(fs::path(HYBRIDCONT_SOURCE_DIR) / "models")) {
    if (entry.path().extension() != ".toml") continue;
    EXPECT_NO_THROW(ReadModelFile(entry.path())) << entry.path();
  }
}

class ModelFileErrorTable : public ::testing::TestWithParam<BadFile> {};

TEST_P(ModelFileErrorTable, RefusedWithFileLineFieldAndProblem) {
  const BadFile& row = GetParam();
  try {
    ParseModelText(Mutate(row), "bad.toml");
    FAIL() << "accepted";
  } catch (const ModelInputError& e) {
    const std::string what = e.what();
    EXPECT_EQ(e.where().file, "bad.toml");
    EXPECT_EQ(e.where().line, row.line) << what;
    EXPECT_EQ(what.rfind("bad.toml:" + std::to_string(row.line) + ": ", 0), 0u) << what;
    EXPECT_NE(what.find(row.message), std::string::npos) << "expected '" << row.message << "' in:\n" << what;
    // HYBRIDCONT_PRINT_ERROR_TABLE=1 prints the rows as docs/model-files.md shows them.
    if (const char* p = std::getenv("HYBRIDCONT_PRINT_ERROR_TABLE"); p != nullptr && std::string(p) == "1") {
      std::cout << "ROW | " << row.name << " | " << what << "\n";
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Slip, ModelFileErrorTable, ::testing::ValuesIn(kBadFiles),
                         [](const ::testing::TestParamInfo<BadFile>& info) { return info.param.name; });

// ---- the same through the command-line tool: exit code 2, file:line on stderr, no results folder.

struct ToolResult {
  int code = -1;
  std::string err;
};

ToolResult RunTool(const std::string& args, const fs::path& dir) {
  const fs::path err = dir / "stderr.txt";
  const std::string command = std::string("'") + HYBRIDCONT_CLI_PATH + "' " + args + " >'" +
                              (dir / "stdout.txt").string() + "' 2>'" + err.string() + "'";
  const int status = std::system(command.c_str());
  ToolResult r;
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  std::ifstream in(err);
  std::ostringstream text;
  text << in.rdbuf();
  r.err = text.str();
  return r;
}

TEST(ModelFileErrorsCli, ExitCode2MessageNamesFileAndLineNothingWritten) {
  const fs::path dir = fs::temp_directory_path() / ("hybridcont_model_file_errors_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::vector<std::string> rows = {"Version2",          "TomlDuplicateKey",      "UnknownSymbol",
                                         "ResetMissingNextPhaseState", "ComparisonInOde", "ParameterOutsideRange",
                                         "FigureFileWithSlash", "KineticWithLinearTerm", "MassMatrixNotSymmetric",
                                         "ConstraintWithoutCoordinates"};
  for (const std::string& name : rows) {
    const auto row = std::find_if(std::begin(kBadFiles), std::end(kBadFiles),
                                  [&](const BadFile& b) { return name == b.name; });
    ASSERT_NE(row, std::end(kBadFiles)) << name;
    const fs::path model = dir / (name + ".toml");
    std::ofstream(model) << Mutate(*row);
    const std::string where = "error: " + model.string() + ":" + std::to_string(row->line) + ": ";
    for (const std::string& command : {std::string("run"), std::string("check")}) {
      const fs::path out = dir / ("out-" + name);
      const std::string args = command + " '" + model.string() + "'" +
                               (command == "run" ? " --quiet --no-plots --out '" + out.string() + "'" : std::string());
      const ToolResult r = RunTool(args, dir);
      EXPECT_EQ(r.code, 2) << command << " " << name << ": " << r.err;
      EXPECT_EQ(r.err.rfind(where, 0), 0u) << command << " " << name << ": expected '" << where << "' first in: "
                                           << r.err;
      EXPECT_NE(r.err.find(row->message), std::string::npos) << command << " " << name << ": " << r.err;
      EXPECT_FALSE(fs::exists(out)) << command << " " << name << ": " << out << " was created";
    }
  }
  fs::remove_all(dir);
}

// A model that parses but does not conserve its energy (a damping torque on the pendulum): `run` refuses it
// before anything runs (exit code 2, the phase named, nothing written), `check` says so (exit code 1).
TEST(ModelFileErrorsCli, EnergyNotConservedIsRefused) {
  const fs::path dir = fs::temp_directory_path() / ("hybridcont_energy_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::string text = kPendulum;
  const std::string anchor = "anchor = \"dy\"";
  text.replace(text.find(anchor), anchor.size(), anchor + "\nforces = { theta = \"-0.1*dtheta\" }");
  const fs::path model = dir / "damped.toml";
  std::ofstream(model) << text;
  const fs::path out = dir / "out";
  const ToolResult run = RunTool("run '" + model.string() + "' --quiet --no-plots --out '" + out.string() + "'", dir);
  EXPECT_EQ(run.code, 2) << run.err;
  EXPECT_NE(run.err.find("model 'bouncing-pendulum' does not conserve its energy: phase 'flight': H kept by the flow"),
            std::string::npos)
      << run.err;
  EXPECT_FALSE(fs::exists(out));
  const ToolResult check = RunTool("check '" + model.string() + "'", dir);
  EXPECT_EQ(check.code, 1) << check.err;
  std::ifstream in(dir / "stdout.txt");
  std::ostringstream table;
  table << in.rdbuf();
  EXPECT_NE(table.str().find("THE ENERGY IS NOT CONSERVED"), std::string::npos) << table.str();
  EXPECT_NE(table.str().find("phase 'flight': H kept by the flow"), std::string::npos) << table.str();
  fs::remove_all(dir);
}

}  // namespace
}  // namespace hybridcont
