// A model's set-up (model_setup.h) evaluated at the model's current parameters: values, the start point,
// and the presentation of orbits (quantities, family names, the drawing of key frames). No I/O.
//
//   HybridModel slip = MakeSlip();
//   slip.SetParameter("k", 20.0);
//   Vector u0 = StartPoint(slip);                         // t1 = t3 = pi*sqrt(m/k), ..., H = m g l0
//   double T_max = EvaluateSetupValue(slip, slip.setup().run.bounds[2].upper);   // 20
//   OrbitPresentation presentation(slip);                 // parses every expression once (throws)
//   presentation.Family(u);                               // "forward hopping" where x2_dx > 0
//   presentation.Quantities(u);                           // one value per setup().quantities
//
// Symbols (as in model_setup.h): set-up values see the parameters and setup().definitions; quantities
// see the unknowns of the time-based layout (shooting_layout.h: t1.., x<i>_<state>, xi / xi<j>, H),
// T = the period, the parameters and definitions; family rules see these and the quantities' names; a
// drawing sees the phase's states, X, the parameters and definitions. A name is looked up in that order,
// so a state shadows a parameter of the same name.
//
// Drawing a sampled orbit (DrawOrbit): X starts at 0 at t = 0 and integrates the x_velocity of each
// sample's phase drawing by the trapezoidal rule between consecutive samples; the two samples of a reset
// share their time, so X is continuous across resets (a body keeps its horizontal position when the
// contact changes). The trapezoidal rule is exact where x_velocity is linear in time (the SLIP's flight)
// and second-order accurate elsewhere: the figure needs positions to a fraction of a line width, not more.
#ifndef HYBRIDCONT_SETUP_EVALUATION_H_
#define HYBRIDCONT_SETUP_EVALUATION_H_

#include <string>
#include <vector>

#include "hybridcont/expression.h"
#include "hybridcont/model.h"
#include "hybridcont/orbit_trace.h"
#include "hybridcont/shooting_layout.h"

namespace hybridcont {

// The value of v over the model's parameters at their current values (and the set-up's definitions).
// Throws ModelInputError naming v.where (and the text) for an expression that does not parse (unknown
// symbol, a definition in terms of itself, ...) or whose value is not finite. field names the value in that message when v has no location of its own (a built-in
// model's values, written in code): "run.bounds.H[1]".
double EvaluateSetupValue(const HybridModel& model, const SetupValue& v, const std::string& field = "");

// The start of the exploration in the time-based layout: setup().start.values evaluated, every other
// unknown 0. Throws ModelInputError for a name that is not an unknown or a bad value.
Vector StartPoint(const HybridModel& model);
// The same for one of the model's starts (ModelSetup::start or an entry of more_starts).
Vector StartPoint(const HybridModel& model, const StartSpec& start);

// The name of an orbit that no family rule names.
inline constexpr const char* kUnnamedFamily = "periodic orbit";

// How the orbits of one model are presented: per-point quantities, family names and the key-frame
// drawing, every expression parsed once at construction. Keeps a reference to the model (which must
// outlive it).
//
// A point u is given in the time-based layout with the free parameters `free` (shooting_layout.h): its
// orbit unknowns, then the free parameters and observables. Quantities and family rules see the orbit
// unknowns, T = the sum of the durations, and the parameters at the point: a free parameter (a non-
// conservative model's family parameter, `--free k`) at its value in u, every other parameter at the
// model's current value. A u of only the orbit unknowns is read at the model's current parameters.
class OrbitPresentation {
 public:
  // Throws ModelInputError naming the field (e.g. "families[1].when") for an expression that does not
  // parse, and for a drawing of a phase the model lacks, a line or mass naming no point of its drawing, or
  // two drawings of one phase (for different segments) with different points, lines or masses; throws
  // std::invalid_argument for free parameters the model does not have (ShootingLayout).
  explicit OrbitPresentation(const HybridModel& model, const FreeParameters& free = {});

  const std::vector<std::string>& quantity_names() const { return quantity_names_; }
  std::vector<std::string> family_names() const;

  // The declared quantities at u, in the order of setup().quantities.
  std::vector<double> Quantities(const Vector& u) const;
  // The name of the first family rule whose condition is nonzero at u; kUnnamedFamily if none is.
  std::string Family(const Vector& u) const;

  // ---- drawing
  bool has_drawing() const { return !drawings_.empty(); }
  // Every point name of every phase drawing, in the order of first declaration (a name used by several
  // phases, e.g. the SLIP's "body", appears once).
  const std::vector<std::string>& point_names() const { return point_names_; }
  // The drawing of shooting segment `segment` (0-based; its phase is segment mod m) for the phase state
  // x: X's velocity (0 without a drawing) and the coordinates of every point of point_names() as the
  // columns of a 2 x P matrix, NaN for the points this drawing does not place.
  double XVelocity(int segment, const Vector& x) const;
  Matrix DrawingPoints(int segment, const Vector& x, double X) const;
  // DrawingPoints of every sample, with X integrated along the samples (see the header comment).
  std::vector<Matrix> DrawOrbit(const std::vector<OrbitSample>& samples) const;

 private:
  struct CompiledDrawing {
    int phase = 0;
    std::vector<int> segments;   // 0-based; empty: every segment of the phase
    ExpressionProgram program;   // outputs: x_velocity, then x and y of each point; inputs: states, X
    std::vector<int> columns;    // point i of this drawing -> column in point_names()
  };
  std::vector<double> ParameterValues() const;
  // The orbit program's inputs at u (orbit unknowns, then T) and the parameters at u.
  void OrbitInputs(const Vector& u, std::vector<double>* x, std::vector<double>* p) const;
  const CompiledDrawing* DrawingOf(int segment) const;

  const HybridModel* model_;
  ShootingLayout layout_;        // the orbit unknowns alone: the orbit program's inputs
  ShootingLayout point_layout_;  // with the free parameters: the layout of the points given
  std::vector<std::string> quantity_names_;
  // Inputs: u, then T. Quantities first, then one output per family rule.
  ExpressionProgram orbit_program_;
  std::vector<std::string> family_names_;
  std::vector<CompiledDrawing> drawings_;
  std::vector<std::string> point_names_;
};

}  // namespace hybridcont

#endif  // HYBRIDCONT_SETUP_EVALUATION_H_
