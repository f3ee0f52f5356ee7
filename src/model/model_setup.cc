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

}  // namespace

double EvaluateSetupValue(const HybridModel& model, const SetupValue& value, const std::string& field) {
  const SetupValue v = Located(value, field);
  GlobalSymbols global(model);
  const ExprPtr e = ParseExpression(v.expression, [&](const std::string& s) { return global(s); }, v.where);
  const ExpressionProgram program({e}, 0, false, {v.where});
  const std::vector<double> p = ParameterValuesOf(model);
  return Finite(program.EvaluateScalar(nullptr, p.data()), v);
}

Vector StartPoint(const HybridModel& model) {
  const ShootingLayout layout(model);
  const std::vector<std::string>& names = layout.unknown_names();
  Vector u = Vector::Zero(layout.num_unknowns());
  for (const auto& [name, value] : model.setup().start.values) {
    const SetupValue v = Located(value, "start.values." + name);
    const auto it = std::find(names.begin(), names.end(), name);
    if (it == names.end()) throw ModelInputError(v.where, "'" + name + "' is not an unknown of the time-based layout");
    u(it - names.begin()) = EvaluateSetupValue(model, v);
  }
  return u;
}

OrbitPresentation::OrbitPresentation(const HybridModel& model) : model_(&model), layout_(model) {
  const ModelSetup& setup = model.setup();
  const std::vector<std::string>& unknowns = layout_.unknown_names();
  const int num_unknowns = layout_.num_unknowns();
  std::map<std::string, ExprPtr> quantities;
  GlobalSymbols global(model);
  // Unknowns, T, (quantities,) parameters and definitions.
  const auto orbit_symbol = [&](const std::string& s, bool with_quantities) -> ExprPtr {
    if (const auto it = std::find(unknowns.begin(), unknowns.end(), s); it != unknowns.end()) {
      return MakeInput(static_cast<int>(it - unknowns.begin()));
    }
    if (s == "T") return MakeInput(num_unknowns);
    if (with_quantities) {
      if (const auto it = quantities.find(s); it != quantities.end()) return it->second;
    }
    return global(s);
  };
  std::vector<ExprPtr> outputs;
  std::vector<SourceLocation> where;
  for (const QuantitySpec& q : setup.quantities) {
    const SetupValue v = Located(q.expression, "quantities." + q.name);
    const ExprPtr e =
        ParseExpression(v.expression, [&](const std::string& s) { return orbit_symbol(s, false); }, v.where);
    quantities[q.name] = e;
    quantity_names_.push_back(q.name);
    outputs.push_back(e);
    where.push_back(v.where);
  }
  for (std::size_t i = 0; i < setup.families.size(); ++i) {
    const SetupValue v = Located(setup.families[i].when, "families[" + std::to_string(i) + "].when");
    outputs.push_back(
        ParseExpression(v.expression, [&](const std::string& s) { return orbit_symbol(s, true); }, v.where));
    where.push_back(v.where);
    family_names_.push_back(setup.families[i].name);
  }
  orbit_program_ = ExpressionProgram(outputs, num_unknowns + 1, false, where);

  const int m = model.num_phases();
  for (const DrawingSpec::PhaseDrawing& pd : setup.drawing.phases) {
    const std::string field = "drawing." + pd.phase;
    CompiledDrawing d;
    d.phase = -1;
    for (int i = 0; i < m; ++i) {
      if (model.phase(i).name() == pd.phase) d.phase = i;
    }
    if (d.phase < 0) {
      throw ModelInputError(SourceLocation{"", 0, field}, "'" + pd.phase + "' is not a phase of the model");
    }
    for (int s : pd.segments) {
      if (s < 1 || s > m + 1 || (s - 1) % m != d.phase) {
        throw ModelInputError(SourceLocation{"", 0, field + ".segments"},
                              "segment " + std::to_string(s) + " is not a segment of phase '" + pd.phase + "'");
      }
      d.segments.push_back(s - 1);
    }
    const std::vector<std::string>& states = model.phase(d.phase).state_names();
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
      where.push_back(v.where);
      return ParseExpression(v.expression, symbol, v.where);
    };
    outputs.clear();
    where.clear();
    outputs.push_back(parse(pd.x_velocity, field + ".x_velocity"));
    std::vector<std::string> names;
    for (const DrawingSpec::Point& point : pd.points) {
      const std::string pf = field + ".points." + point.name;
      if (std::find(names.begin(), names.end(), point.name) != names.end()) {
        throw ModelInputError(SourceLocation{"", 0, pf}, "point '" + point.name + "' is declared twice");
      }
      names.push_back(point.name);
      outputs.push_back(parse(point.x, pf + "[0]"));
      outputs.push_back(parse(point.y, pf + "[1]"));
      const auto it = std::find(point_names_.begin(), point_names_.end(), point.name);
      d.columns.push_back(static_cast<int>(it - point_names_.begin()));
      if (it == point_names_.end()) point_names_.push_back(point.name);
    }
    const auto check_point = [&](const std::string& name, const std::string& f) {
      if (std::find(names.begin(), names.end(), name) == names.end()) {
        throw ModelInputError(SourceLocation{"", 0, f}, "'" + name + "' is not a point of " + field);
      }
    };
    for (std::size_t i = 0; i < pd.lines.size(); ++i) {
      for (const std::string& name : pd.lines[i]) check_point(name, field + ".lines[" + std::to_string(i) + "]");
    }
    for (const std::string& name : pd.masses) check_point(name, field + ".masses");
    // Drawings of one phase for different segments must look alike: the results name lines and masses
    // per phase.
    for (const DrawingSpec::PhaseDrawing& other : setup.drawing.phases) {
      if (&other == &pd) break;
      if (other.phase != pd.phase) continue;
      std::vector<std::string> other_names;
      for (const DrawingSpec::Point& point : other.points) other_names.push_back(point.name);
      if (other_names != names || other.lines != pd.lines || other.masses != pd.masses) {
        throw ModelInputError(SourceLocation{"", 0, field},
                              "two drawings of phase '" + pd.phase + "' with different points, lines or masses");
      }
    }
    d.program = ExpressionProgram(outputs, dim + 1, false, where);
    drawings_.push_back(std::move(d));
  }
}

std::vector<std::string> OrbitPresentation::family_names() const { return family_names_; }

std::vector<double> OrbitPresentation::ParameterValues() const { return ParameterValuesOf(*model_); }

std::vector<double> OrbitPresentation::Quantities(const Vector& u) const {
  std::vector<double> x(u.data(), u.data() + u.size());
  x.push_back(layout_.Period(u));
  const std::vector<double> p = ParameterValues();
  std::vector<double> values;
  for (std::size_t i = 0; i < quantity_names_.size(); ++i) {
    values.push_back(orbit_program_.EvaluateScalar(x.data(), p.data(), static_cast<int>(i)));
  }
  return values;
}

std::string OrbitPresentation::Family(const Vector& u) const {
  std::vector<double> x(u.data(), u.data() + u.size());
  x.push_back(layout_.Period(u));
  const std::vector<double> p = ParameterValues();
  const int first = static_cast<int>(quantity_names_.size());
  for (std::size_t i = 0; i < family_names_.size(); ++i) {
    const double when = orbit_program_.EvaluateScalar(x.data(), p.data(), first + static_cast<int>(i));
    if (when != 0.0 && !std::isnan(when)) return family_names_[i];
  }
  return "periodic orbit";
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
