// Reading [[figures]] and [drawing].
#include "model_reader.h"

#include <algorithm>
#include <cctype>

namespace hybridcont::internal {

void Reader::ReadFigures() {
  const toml::node* n = root_.get("figures");
  if (n == nullptr) return;
  const toml::array& a = AsArray(*n, "figures");
  std::vector<std::string> columns = OrbitSymbols();
  for (std::size_t i = 0; i < a.size(); ++i) {
    const std::string field = "figures[" + std::to_string(i) + "]";
    if (!a.get(i)->is_table()) Fail(a.get(i), field, "expected a [[figures]] table");
    const toml::table& t = *a.get(i)->as_table();
    CheckKeys(t, field, {"file", "title", "x", "y", "zoom"});
    FigureSpec f;
    f.file = RequiredString(t, "file", field);
    const bool safe = f.file.size() > 4 && f.file.substr(f.file.size() - 4) == ".png" &&
                      std::all_of(f.file.begin(), f.file.end(), [](char c) {
                        return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.';
                      });
    if (!safe) Fail(t.get("file"), field + ".file", "'" + f.file + "': a plain file name ending in .png");
    f.title = OptionalString(t, "title", field, "");
    f.x = RequiredString(t, "x", field);
    const toml::node* y = t.get("y");
    if (y == nullptr) Fail(&t, field + ".y", "missing field 'y'");
    f.y = y->is_string() ? std::vector<std::string>{AsString(*y, field + ".y")} : StringArray(*y, field + ".y");
    for (const std::string& c : f.y) {
      if (std::find(columns.begin(), columns.end(), c) == columns.end()) {
        Fail(y, field + ".y", "'" + c + "' is not a column (an unknown, T, or a quantity)");
      }
    }
    if (std::find(columns.begin(), columns.end(), f.x) == columns.end()) {
      Fail(t.get("x"), field + ".x", "'" + f.x + "' is not a column (an unknown, T, or a quantity)");
    }
    f.zoom_special_points = OptionalBool(t, "zoom", field, false);
    spec_.setup.figures.push_back(f);
  }
}

void Reader::ReadDrawing() {
  const toml::table* t = OptionalTable(root_, "drawing", "");
  if (t == nullptr) return;
  DrawingSpec& d = spec_.setup.drawing;
  for (auto&& [key, node] : *t) {
    const std::string k(key.str());
    if (k == "ground") {
      d.ground = OptionalBool(*t, "ground", "drawing", true);
      continue;
    }
    if (k == "mass_radius") {
      d.mass_radius = OptionalNumber(*t, "mass_radius", "drawing", d.mass_radius);
      if (!(d.mass_radius > 0)) Fail(&node, "drawing.mass_radius", "must be positive");
      continue;
    }
    const auto it = std::find_if(spec_.phases.begin(), spec_.phases.end(),
                                 [&](const ExpressionPhaseSpec& p) { return p.name == k; });
    if (it == spec_.phases.end()) {
      Fail(&node, "drawing." + k, "'" + k + "' is neither a phase nor one of: ground, mass_radius");
    }
    d.phases.push_back(ReadPhaseDrawing(node, k, static_cast<int>(it - spec_.phases.begin())));
  }
}

DrawingSpec::PhaseDrawing Reader::ReadPhaseDrawing(const toml::node& node, const std::string& k, int phase) {
  const std::string field = "drawing." + k;
  if (!node.is_table()) Fail(&node, field, "expected a table");
  const toml::table& pt = *node.as_table();
  CheckKeys(pt, field, {"x_velocity", "points", "lines", "masses"});
  DrawingSpec::PhaseDrawing pd;
  pd.phase = k;
  if (const toml::node* v = pt.get("x_velocity")) pd.x_velocity = DrawingValue(*v, field + ".x_velocity", phase);
  std::set<std::string> point_names;
  if (const toml::table* pts = OptionalTable(pt, "points", field)) {
    for (auto&& [pk, pn] : *pts) {
      const std::string name(pk.str());
      const std::string pf = field + ".points." + name;
      CheckLabel(&pn, pf, name);  // a CSV column of the key-frame orbits (draw.<point>.x)
      const toml::array& xy = AsArray(pn, pf);
      if (xy.size() != 2) Fail(&pn, pf, "expected [x, y]");
      pd.points.push_back({name, DrawingValue(*xy.get(0), pf + "[0]", phase), DrawingValue(*xy.get(1), pf + "[1]", phase)});
      point_names.insert(name);
    }
  }
  ReadLinesAndMasses(pt, field, point_names, &pd);
  return pd;
}

SetupValue Reader::DrawingValue(const toml::node& n, const std::string& f, int phase) {
  SetupValue v = AsSetupValue(n, f);
  const std::vector<std::string>& states = spec_.phases[phase].state_names;
  ParseExpression(v.expression,
                  [&](const std::string& s) -> ExprPtr {
                    if (s == "X" || std::find(states.begin(), states.end(), s) != states.end()) return MakeInput(0);
                    return GlobalSymbol(s);
                  },
                  v.where);
  return v;
}

void Reader::ReadLinesAndMasses(const toml::table& pt, const std::string& field, const std::set<std::string>& point_names,
                        DrawingSpec::PhaseDrawing* pd) const {
  const auto check_point = [&](const toml::node* n, const std::string& f, const std::string& name) {
    if (!point_names.count(name)) Fail(n, f, "'" + name + "' is not a point of " + field);
  };
  if (const toml::node* lines = pt.get("lines")) {
    const toml::array& a = AsArray(*lines, field + ".lines");
    for (std::size_t i = 0; i < a.size(); ++i) {
      const std::string lf = field + ".lines[" + std::to_string(i) + "]";
      std::vector<std::string> line = StringArray(*a.get(i), lf);
      if (line.size() < 2) Fail(a.get(i), lf, "a line needs at least two points");
      for (const std::string& p : line) check_point(a.get(i), lf, p);
      pd->lines.push_back(line);
    }
  }
  if (const toml::node* masses = pt.get("masses")) {
    for (const std::string& p : StringArray(*masses, field + ".masses")) check_point(masses, field + ".masses", p);
    pd->masses = StringArray(*masses, field + ".masses");
  }
}

}  // namespace hybridcont::internal
