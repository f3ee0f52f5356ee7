#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <set>

#include "hybridcont/setup_evaluation.h"

namespace hybridcont {

namespace {

// A copy of v whose location names `field` when v carries none (a built-in model's values are written in
// code, without a file and line): messages then say which value is bad.
SetupValue Located(const SetupValue& v, const std::string& field) {
  SetupValue located = v;
  if (located.where.file.empty() && located.where.line == 0 && located.where.field.empty()) located.where.field = field;
  return located;
}

// Symbols of set-up values: the model's parameters (index into model.parameters()), then the set-up's
// definitions, each parsed once on first use.
class GlobalSymbols {
 public:
  explicit GlobalSymbols(const HybridModel& model) : model_(model) {}

  ExprPtr operator()(const std::string& name) {
    const std::vector<ParameterInfo>& infos = model_.parameters();
    for (std::size_t i = 0; i < infos.size(); ++i) {
      if (infos[i].name == name) return MakeParameter(static_cast<int>(i));
    }
    if (const auto it = parsed_.find(name); it != parsed_.end()) return it->second;
    const auto& definitions = model_.setup().definitions;
    const auto definition = std::find_if(definitions.begin(), definitions.end(),
                                         [&](const auto& d) { return d.first == name; });
    if (definition == definitions.end()) return nullptr;
    const SetupValue v = Located(definition->second, "definitions." + name);
    if (!resolving_.insert(name).second) throw ModelInputError(v.where, "'" + name + "' is defined in terms of itself");
    const ExprPtr e = ParseExpression(v.expression, [this](const std::string& s) { return (*this)(s); }, v.where);
    resolving_.erase(name);
    parsed_[name] = e;
    return e;
  }

 private:
  const HybridModel& model_;
  std::map<std::string, ExprPtr> parsed_;
  std::set<std::string> resolving_;
};

std::vector<double> ParameterValuesOf(const HybridModel& model) {
  std::vector<double> p;
  for (const ParameterInfo& info : model.parameters()) p.push_back(model.parameter(info.name));
  return p;
}

double Finite(double value, const SetupValue& v) {
  if (!std::isfinite(value)) {
    throw ModelInputError(v.where, "'" + v.expression + "' evaluates to " + std::to_string(value) +
                                       " at the current parameters");
  }
  return value;
}

// Symbols of an orbit's expressions (quantities and family rules): the unknowns of the time-based layout
// (inputs 0..n-1), the period T (input n), the quantities declared so far when `with_quantities`, then
// the global symbols.
class OrbitSymbols {
 public:
  OrbitSymbols(const ShootingLayout& layout, GlobalSymbols& global)
      : unknowns_(layout.unknown_names()), num_unknowns_(layout.num_unknowns()), global_(global) {}

  ExprPtr operator()(const std::string& s, bool with_quantities) {
    if (const auto it = std::find(unknowns_.begin(), unknowns_.end(), s); it != unknowns_.end()) {
      return MakeInput(static_cast<int>(it - unknowns_.begin()));
    }
    if (s == "T") return MakeInput(num_unknowns_);
    if (with_quantities) {
      if (const auto it = quantities_.find(s); it != quantities_.end()) return it->second;
    }
    return global_(s);
  }
  void AddQuantity(const std::string& name, const ExprPtr& e) { quantities_[name] = e; }

 private:
  const std::vector<std::string>& unknowns_;
  const int num_unknowns_;
  GlobalSymbols& global_;
  std::map<std::string, ExprPtr> quantities_;
};

// The orbit program: one output per quantity (which may not name other quantities), then one per family
// rule (which may); inputs u, then T. Fills the quantities' and the families' names in the same order.
ExpressionProgram CompileOrbitProgram(const ModelSetup& setup, const ShootingLayout& layout, GlobalSymbols& global,
                                      std::vector<std::string>* quantity_names,
                                      std::vector<std::string>* family_names) {
  OrbitSymbols symbols(layout, global);
  std::vector<ExprPtr> outputs;
  std::vector<SourceLocation> where;
  for (const QuantitySpec& q : setup.quantities) {
    const SetupValue v = Located(q.expression, "quantities." + q.name);
    const ExprPtr e = ParseExpression(v.expression, [&](const std::string& s) { return symbols(s, false); }, v.where);
    symbols.AddQuantity(q.name, e);
    quantity_names->push_back(q.name);
    outputs.push_back(e);
    where.push_back(v.where);
  }
  for (std::size_t i = 0; i < setup.families.size(); ++i) {
    const SetupValue v = Located(setup.families[i].when, "families[" + std::to_string(i) + "].when");
    outputs.push_back(ParseExpression(v.expression, [&](const std::string& s) { return symbols(s, true); }, v.where));
    where.push_back(v.where);
    family_names->push_back(setup.families[i].name);
  }
  return ExpressionProgram(outputs, layout.num_unknowns() + 1, false, where);
}

// A compiled phase drawing, field by field as OrbitPresentation::CompiledDrawing holds it.
struct DrawingParts {
  int phase = -1;
  std::vector<int> segments;
  ExpressionProgram program;
  std::vector<int> columns;
};

// The index of the phase a drawing names; throws naming `field` when the model has no such phase.
int DrawnPhase(const HybridModel& model, const DrawingSpec::PhaseDrawing& pd, const std::string& field) {
  int phase = -1;
  for (int i = 0; i < model.num_phases(); ++i) {
    if (model.phase(i).name() == pd.phase) phase = i;
  }
  if (phase < 0) throw ModelInputError(SourceLocation{"", 0, field}, "'" + pd.phase + "' is not a phase of the model");
  return phase;
}

// The drawing's segments, 1-based in the file and 0-based here; each must be a segment of a phase of the
// drawing's name (a repeated model, period_doubling.h, has several copies of a phase under one name: the same
// states, drawn alike).
std::vector<int> DrawnSegments(const HybridModel& model, const DrawingSpec::PhaseDrawing& pd, const std::string& field) {
  const int m = model.num_phases();
  std::vector<int> segments;
  for (int s : pd.segments) {
    if (s < 1 || s > m + 1 || model.phase((s - 1) % m).name() != pd.phase) {
      throw ModelInputError(SourceLocation{"", 0, field + ".segments"},
                            "segment " + std::to_string(s) + " is not a segment of phase '" + pd.phase + "'");
    }
    segments.push_back(s - 1);
  }
  return segments;
}

// The drawing's outputs (x_velocity, then x and y of each point) over its phase's states (inputs
// 0..dim-1) and X (input dim). Adds new point names to `point_names` and the column of each point to
// `columns`; returns the drawing's own point names, in order (a name declared twice throws).
std::vector<std::string> ParseDrawingOutputs(const HybridModel& model, const DrawingSpec::PhaseDrawing& pd, int phase,
                                             const std::string& field, GlobalSymbols& global,
                                             std::vector<ExprPtr>* outputs, std::vector<SourceLocation>* where,
                                             std::vector<int>* columns, std::vector<std::string>* point_names) {
  const std::vector<std::string>& states = model.phase(phase).state_names();
  const int dim = static_cast<int>(states.size());
  const auto symbol = [&](const std::string& s) -> ExprPtr {
    if (const auto it = std::find(states.begin(), states.end(), s); it != states.end()) {
      return MakeInput(static_cast<int>(it - states.begin()));
    }
    if (s == "X") return MakeInput(dim);
    return global(s);
  };
  const auto parse = [&](const SetupValue& value, const std::string& f) {
    const SetupValue v = Located(value, f);
    where->push_back(v.where);
    return ParseExpression(v.expression, symbol, v.where);
  };
  outputs->push_back(parse(pd.x_velocity, field + ".x_velocity"));
  std::vector<std::string> names;
  for (const DrawingSpec::Point& point : pd.points) {
    const std::string pf = field + ".points." + point.name;
    if (std::find(names.begin(), names.end(), point.name) != names.end()) {
      throw ModelInputError(SourceLocation{"", 0, pf}, "point '" + point.name + "' is declared twice");
    }
    names.push_back(point.name);
    outputs->push_back(parse(point.x, pf + "[0]"));
    outputs->push_back(parse(point.y, pf + "[1]"));
    const auto it = std::find(point_names->begin(), point_names->end(), point.name);
    columns->push_back(static_cast<int>(it - point_names->begin()));
    if (it == point_names->end()) point_names->push_back(point.name);
  }
  return names;
}

// Every line and mass of the drawing names one of its points.
void CheckLinesAndMasses(const DrawingSpec::PhaseDrawing& pd, const std::vector<std::string>& names,
                         const std::string& field) {
  const auto check_point = [&](const std::string& name, const std::string& f) {
    if (std::find(names.begin(), names.end(), name) == names.end()) {
      throw ModelInputError(SourceLocation{"", 0, f}, "'" + name + "' is not a point of " + field);
    }
  };
  for (std::size_t i = 0; i < pd.lines.size(); ++i) {
    for (const std::string& name : pd.lines[i]) check_point(name, field + ".lines[" + std::to_string(i) + "]");
  }
  for (const std::string& name : pd.masses) check_point(name, field + ".masses");
}

// Drawings of one phase for different segments must look alike: the results name lines and masses per
// phase. Compares pd with the drawings declared before it.
void CheckAlikeDrawings(const DrawingSpec& drawing, const DrawingSpec::PhaseDrawing& pd,
                        const std::vector<std::string>& names, const std::string& field) {
  for (const DrawingSpec::PhaseDrawing& other : drawing.phases) {
    if (&other == &pd) break;
    if (other.phase != pd.phase) continue;
    std::vector<std::string> other_names;
    for (const DrawingSpec::Point& point : other.points) other_names.push_back(point.name);
    if (other_names != names || other.lines != pd.lines || other.masses != pd.masses) {
      throw ModelInputError(SourceLocation{"", 0, field},
                            "two drawings of phase '" + pd.phase + "' with different points, lines or masses");
    }
  }
}

// One phase drawing of the model's set-up, checked and compiled; `point_names` gains its new points.
DrawingParts CompileDrawing(const HybridModel& model, const DrawingSpec::PhaseDrawing& pd, GlobalSymbols& global,
                            std::vector<std::string>* point_names) {
  const std::string field = "drawing." + pd.phase;
  DrawingParts d;
  d.phase = DrawnPhase(model, pd, field);
  d.segments = DrawnSegments(model, pd, field);
  std::vector<ExprPtr> outputs;
  std::vector<SourceLocation> where;
  const std::vector<std::string> names =
      ParseDrawingOutputs(model, pd, d.phase, field, global, &outputs, &where, &d.columns, point_names);
  CheckLinesAndMasses(pd, names, field);
  CheckAlikeDrawings(model.setup().drawing, pd, names, field);
  const int dim = static_cast<int>(model.phase(d.phase).state_names().size());
  d.program = ExpressionProgram(outputs, dim + 1, false, where);
  return d;
}

}  // namespace

double EvaluateSetupValue(const HybridModel& model, const SetupValue& value, const std::string& field) {
  const SetupValue v = Located(value, field);
  GlobalSymbols global(model);
  const ExprPtr e = ParseExpression(v.expression, [&](const std::string& s) { return global(s); }, v.where);
  const ExpressionProgram program({e}, 0, false, {v.where});
  const std::vector<double> p = ParameterValuesOf(model);
  return Finite(program.EvaluateScalar(nullptr, p.data()), v);
}

Vector StartPoint(const HybridModel& model) { return StartPoint(model, model.setup().start); }

Vector StartPoint(const HybridModel& model, const StartSpec& start) {
  const ShootingLayout layout(model);
  const std::vector<std::string>& names = layout.unknown_names();
  Vector u = Vector::Zero(layout.num_unknowns());
  for (const auto& [name, value] : start.values) {
    const SetupValue v = Located(value, "start.values." + name);
    const auto it = std::find(names.begin(), names.end(), name);
    if (it == names.end()) throw ModelInputError(v.where, "'" + name + "' is not an unknown of the time-based layout");
    u(it - names.begin()) = EvaluateSetupValue(model, v);
  }
  return u;
}

OrbitPresentation::OrbitPresentation(const HybridModel& model, const FreeParameters& free)
    : model_(&model), layout_(model), point_layout_(model, free) {
  GlobalSymbols global(model);
  orbit_program_ = CompileOrbitProgram(model.setup(), layout_, global, &quantity_names_, &family_names_);
  for (const DrawingSpec::PhaseDrawing& pd : model.setup().drawing.phases) {
    DrawingParts d = CompileDrawing(model, pd, global, &point_names_);
    drawings_.push_back({d.phase, std::move(d.segments), std::move(d.program), std::move(d.columns)});
  }
}

std::vector<std::string> OrbitPresentation::family_names() const { return family_names_; }

std::vector<double> OrbitPresentation::ParameterValues() const { return ParameterValuesOf(*model_); }

void OrbitPresentation::OrbitInputs(const Vector& u, std::vector<double>* x, std::vector<double>* p) const {
  const int n = layout_.num_unknowns();
  HYBRIDCONT_DEMAND(u.size() == n || u.size() == point_layout_.num_unknowns());
  x->assign(u.data(), u.data() + n);
  x->push_back(layout_.Period(u.head(n)));
  *p = ParameterValues();
  if (u.size() == n) return;
  for (int j = 0; j < point_layout_.num_free_parameters(); ++j) {
    (*p)[point_layout_.parameter_model_index(j)] = u(point_layout_.parameter_index(j));
  }
}

std::vector<double> OrbitPresentation::Quantities(const Vector& u) const {
  std::vector<double> x, p;
  OrbitInputs(u, &x, &p);
  std::vector<double> values;
  for (std::size_t i = 0; i < quantity_names_.size(); ++i) {
    values.push_back(orbit_program_.EvaluateScalar(x.data(), p.data(), static_cast<int>(i)));
  }
  return values;
}

std::string OrbitPresentation::Family(const Vector& u) const {
  std::vector<double> x, p;
  OrbitInputs(u, &x, &p);
  const int first = static_cast<int>(quantity_names_.size());
  for (std::size_t i = 0; i < family_names_.size(); ++i) {
    const double when = orbit_program_.EvaluateScalar(x.data(), p.data(), first + static_cast<int>(i));
    if (when != 0.0 && !std::isnan(when)) return family_names_[i];
  }
  return kUnnamedFamily;
}

const OrbitPresentation::CompiledDrawing* OrbitPresentation::DrawingOf(int segment) const {
  const int phase = segment % model_->num_phases();
  for (const CompiledDrawing& d : drawings_) {
    if (d.phase != phase) continue;
    if (d.segments.empty() || std::find(d.segments.begin(), d.segments.end(), segment) != d.segments.end()) return &d;
  }
  return nullptr;
}

double OrbitPresentation::XVelocity(int segment, const Vector& x) const {
  const CompiledDrawing* d = DrawingOf(segment);
  if (d == nullptr) return 0.0;
  std::vector<double> in(x.data(), x.data() + x.size());
  in.push_back(0.0);
  const std::vector<double> p = ParameterValues();
  return d->program.EvaluateScalar(in.data(), p.data(), 0);
}

Matrix OrbitPresentation::DrawingPoints(int segment, const Vector& x, double X) const {
  Matrix points = Matrix::Constant(2, static_cast<Eigen::Index>(point_names_.size()),
                                   std::numeric_limits<double>::quiet_NaN());
  const CompiledDrawing* d = DrawingOf(segment);
  if (d == nullptr) return points;
  std::vector<double> in(x.data(), x.data() + x.size());
  in.push_back(X);
  const std::vector<double> p = ParameterValues();
  for (std::size_t i = 0; i < d->columns.size(); ++i) {
    for (int c = 0; c < 2; ++c) {
      points(c, d->columns[i]) = d->program.EvaluateScalar(in.data(), p.data(), 1 + 2 * static_cast<int>(i) + c);
    }
  }
  return points;
}

std::vector<Matrix> OrbitPresentation::DrawOrbit(const std::vector<OrbitSample>& samples) const {
  std::vector<Matrix> drawn;
  double X = 0.0, t_previous = 0.0, v_previous = 0.0;
  for (std::size_t k = 0; k < samples.size(); ++k) {
    const OrbitSample& s = samples[k];
    double v = XVelocity(s.segment, s.x);
    if (!std::isfinite(v)) v = 0.0;  // keep X finite: one bad sample must not blank the rest of the orbit
    if (k > 0) X += 0.5 * (v_previous + v) * (s.t - t_previous);
    drawn.push_back(DrawingPoints(s.segment, s.x, X));
    t_previous = s.t;
    v_previous = v;
  }
  return drawn;
}

}  // namespace hybridcont
