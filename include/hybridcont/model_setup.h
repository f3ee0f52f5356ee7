// What a model declares beyond its equations: its default run and how its results are presented.
//
// Everything the tool knows of a model lives with the model (one home per model): the start point, the
// bounds and scales of the continuation, where key frames are taken, how families are named, which
// per-point quantities and figures its results have, and how to draw the mechanism. A built-in model fills
// this struct in its own source file; a model file (model_file.h) fills it from its [start], [run],
// [[family]], [quantities], [[figure]] and [drawing] tables. The command line, the results writer and the
// figure script read it from here; no model name appears anywhere else.
//
// Values are expressions (expression.h) so that they follow the parameters: the rocking block's energy
// bound is "m*g*l0*(1 - cos(beta))", the SLIP's start "pi*sqrt(m/k)". They are evaluated when a run is set
// up (setup_evaluation.h), after `--set` has changed the parameters. Symbols:
//   set-up values (start, bounds, scales, key frames)   the model's parameters and `definitions`
//   family rules and quantities                          also the unknowns of the time-based layout
//                                                        (t1.., x<i>_<state>, xi / xi<j>, H) and T (period)
//   drawing                                              also the phase's states and X (see DrawingSpec)
#ifndef HYBRIDCONT_MODEL_SETUP_H_
#define HYBRIDCONT_MODEL_SETUP_H_

#include <limits>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "hybridcont/expression.h"

namespace hybridcont {

// A value given as an expression, with where it was written (for messages).
struct SetupValue {
  std::string expression;
  SourceLocation where;
  SetupValue() = default;
  SetupValue(const char* text) : expression(text) {}  // NOLINT(google-explicit-constructor)
  SetupValue(std::string text, SourceLocation at = {}) : expression(std::move(text)), where(std::move(at)) {}  // NOLINT
};

// The start of the exploration.
struct StartSpec {
  // kSingular: an exact point of the family where r = 0 holds by construction (an equilibrium with zero
  // durations, a zero-flight-time oscillation; the paper's starts); the exploration analyses its kernel.
  // kGuess: an approximate orbit; Newton corrects it at fixed H before the exploration starts from it.
  // kSimulation: the state x1 given (values x1_<state>) starts an event-driven simulation of the phase cycle
  // that runs until it converges to an attracting orbit (models without first integral), which Newton then
  // refines at fixed parameters.
  enum class Kind { kSingular, kGuess, kSimulation };
  Kind kind = Kind::kSingular;
  // kSimulation: cycles simulated; 0 runs until the cycle settles (an attracting orbit), n > 0 exactly n
  // cycles whose last is Newton's guess (an unstable orbit the simulation passes close to).
  int cycles = 0;
  // Unknowns of the time-based layout by name (t1.., x<i>_<state>, xi, H); unlisted unknowns are 0.
  std::vector<std::pair<std::string, SetupValue>> values;
  // Linear conditions sum coefficient * direction[component] = 0 that select the start direction when the
  // start's kernel has dimension > 2 (the rod's symmetric branch: t2 - t1 - t3 = 0).
  struct Condition {
    std::vector<std::pair<std::string, double>> terms;
    std::string description;
  };
  std::vector<Condition> conditions;
  // A hybrid automaton's start in another word than the model's (hybrid_automaton.h: transition indices);
  // its values name that word's unknowns. Empty: the model's own word.
  std::vector<int> word;
  // Where the start was declared (a model file's [start] table), for messages about it.
  SourceLocation where;
};

struct BoundSpec {
  std::string component;  // an unknown's name, or "period" for the sum of all durations
  SetupValue lower, upper;
};

// The default run: everything `hybridcont run` needs that is not a tolerance. Defaults fit the paper's
// models; a model overrides what it needs.
struct RunSpec {
  std::vector<BoundSpec> bounds;
  // Typical magnitudes of unknowns far from 1; the continuation works in u ./ scale (scaled_problem.h).
  std::vector<std::pair<std::string, SetupValue>> scales;
  // Enough for every built-in diagram (the SLIP has 23 half-branches to H = 2).
  int max_branches = 64;
  int max_depth = 3;
  int max_points = 600;
  double initial_step = 0.02;
  double max_step = 0.1;
  // Key frames: on each physical branch, the point closest to `value` of `component` ("H" or "T"; the
  // continuation parameter for a model without first integral).
  std::string keyframe_component = "H";
  // A model without first integral: the model parameter its families are continued in (e.g. "gamma").
  std::string parameter;
  SetupValue keyframe_value = "0.5";
  int keyframe_orbits = 4;
};

// A family's name for physical orbits where `when` is true (first matching rule wins).
struct FamilyRule {
  std::string name;
  SetupValue when;
  // A hybrid automaton's word whose orbits the rule names (transition indices, as StartSpec::word; `when`
  // names that word's unknowns). Empty: the model's own word.
  std::vector<int> word;
};

// A named per-point quantity, written as a column of every branch file (e.g. the rod's asymmetry).
struct QuantitySpec {
  std::string name;
  SetupValue expression;
  std::string description;
};

// A figure drawn from the branch files: y columns over an x column, physical parts solid.
struct FigureSpec {
  std::string file;               // e.g. "slip_durations.png"
  std::string title;
  std::string x;                  // a column: H, T, xi, t<i>, x<i>_<state>, a quantity
  std::vector<std::string> y;
  bool zoom_special_points = false;  // limits around the special points instead of the whole diagram
};

// The mechanism drawn in key frames. Points are expressions of the phase's states, the parameters and X,
// the integral over the orbit of the phase's x_velocity (0 at the start of the orbit, continuous across
// resets): a point mass moving forward is drawn at ("X", "y"), the SLIP's foot in stance at
// ("X + l*sin(alpha)", "0") with x_velocity = the body's horizontal speed. Points named in `masses` are
// drawn as filled discs, `lines` are polylines through named points.
struct DrawingSpec {
  struct Point {
    std::string name;
    SetupValue x, y;
  };
  struct PhaseDrawing {
    std::string phase;
    SetupValue x_velocity = "0";
    std::vector<Point> points;
    std::vector<std::vector<std::string>> lines;
    std::vector<std::string> masses;
    // The shooting segments (1..m+1) this drawing applies to; empty: every segment of the phase. Drawings
    // of one phase for different segments have the same points, lines and masses, placed differently: a
    // model that folds a mirror-image motion onto one phase draws it mirrored where the fold happened (the
    // rocking block rocks on its right corner in segment 2, after the impact, but its state is written
    // about the left corner).
    std::vector<int> segments;
  };
  std::vector<PhaseDrawing> phases;  // empty: no key-frame drawing
  bool ground = true;                // the line y = 0
  double mass_radius = 0.05;
};

struct ModelSetup {
  StartSpec start;
  // Further starts ([[start]] in a model file), each traced as a family of its own: for models without
  // first integral, whose families need not meet (the walker's long- and short-period gaits).
  std::vector<StartSpec> more_starts;
  // A hybrid automaton's starts in other words ([[start]] with `word`): gaits that no change of the phase
  // sequence need connect (walking and running), each explored after the model's own word.
  std::vector<StartSpec> word_starts;
  RunSpec run;
  std::vector<FamilyRule> families;
  std::vector<QuantitySpec> quantities;
  std::vector<FigureSpec> figures;
  DrawingSpec drawing;
  std::string title;  // for figures ("SLIP hopper"); the model's name if empty
  // Named values over the parameters and other definitions (a model file's [definitions]) that every
  // expression above may use, e.g. ("H_max", "m*g*l0*(1 - cos(beta))") for "0.5*H_max". A name is looked
  // up after the unknowns, states and parameters, so a definition cannot redefine those.
  std::vector<std::pair<std::string, SetupValue>> definitions;
};

}  // namespace hybridcont

#endif  // HYBRIDCONT_MODEL_SETUP_H_
