// LoadStudy (study.h): a results folder read back into the typed study. The folder is untrusted input: its
// summary.json and every branch file are checked, and an error names the file, the line and the field.
//
// Precision: u is written with 17 significant digits and the analysis columns (multipliers, replay errors, test
// functions, residual, step, the period's slope) in their shortest exact form, so a loaded study equals the
// computed one to the bit (folders written before 0.9.0: the analysis to 10 digits, docs/results-format.md). Key-frame orbits are read with their samples
// (orbit-<k>.csv: time and states at 17 digits, exactly; older folders' 12).
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "hybridcont/study.h"
#include "study/io/results_writer.h"
#include "study/io/json_fields.h"
#include "study/io/study_document.h"
#include "study/io/summary_json.h"
#include "study/stages/regions.h"

namespace hybridcont {

namespace {

namespace fs = std::filesystem;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::vector<std::string> SplitRow(const std::string& line) {
  std::vector<std::string> fields;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = line.find(',', start);
    fields.push_back(line.substr(start, comma == std::string::npos ? std::string::npos : comma - start));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return fields;
}

// A number of a CSV field: empty is NaN (undefined for this point), "nan" too.
double Field(const std::string& text, const std::string& where) {
  if (text.empty() || text == "nan" || text == "-nan") return kNaN;
  // strtod, not stod: a subnormal number (an angle of 1e-311 the integrator left) is a number; stod calls its
  // underflow out of range. Overflow (beyond the largest double) is refused.
  char* end = nullptr;
  errno = 0;
  const double value = std::strtod(text.c_str(), &end);
  const bool overflow = errno == ERANGE && std::isinf(value);
  if (end != text.c_str() + text.size() || text.empty() || std::isspace(static_cast<unsigned char>(text[0])) || overflow) {
    throw std::invalid_argument(where + ": '" + text + "' is not a number");
  }
  return value;
}

// A file of the folder opened for reading: a name that is there but no regular file (a FIFO, a device, a
// folder) is refused before it is opened, since opening a FIFO blocks until someone writes it. A file that is
// not there gives a stream that cannot be read.
std::ifstream OpenRegular(const fs::path& file) {
  std::error_code ec;
  const fs::file_status status = fs::status(file, ec);
  if (fs::exists(status) && !fs::is_regular_file(status)) {
    throw std::invalid_argument(file.string() + ": not a regular file (a results folder's files are regular files)");
  }
  return std::ifstream(file);
}

// The analysed points of one branch file: its unknowns, analysis, observables and quantities (by name), and the
// period's slope dT_d<continued>.
std::vector<StudyPoint> ReadBranchFile(const fs::path& file, const std::vector<std::string>& unknowns,
                                       const std::vector<std::string>& observables,
                                       const std::vector<std::string>& quantities, const std::string& continued) {
  std::ifstream f = OpenRegular(file);
  if (!f) throw std::invalid_argument(file.string() + ": cannot be read");
  std::string line;
  if (!std::getline(f, line)) throw std::invalid_argument(file.string() + ": empty (no header)");
  const std::vector<std::string> header = SplitRow(line);
  std::map<std::string, std::size_t> first, last;
  for (std::size_t i = 0; i < header.size(); ++i) first.emplace(header[i], i), last[header[i]] = i;
  const auto column = [&](const std::string& name) {
    const auto it = first.find(name);
    if (it == first.end()) throw std::invalid_argument(file.string() + ": line 1: no column '" + name + "'");
    return it->second;
  };
  std::vector<std::size_t> u_columns;
  for (const std::string& name : unknowns) u_columns.push_back(column(name));
  const std::size_t index = column("index"), T = column("T"), physical = column("physical"),
                    reason = column("classification"), stability = column("stability"), residual = column("residual"),
                    newton = column("newton_iterations"), step = column("step");
  const auto optional_column = [&](const std::string& name) -> long {
    const auto it = first.find(name);
    return it == first.end() ? -1 : static_cast<long>(it->second);
  };
  std::vector<StudyPoint> points;
  for (int row = 2; std::getline(f, line); ++row) {
    const std::vector<std::string> fields = SplitRow(line);
    const std::string where = file.string() + ": line " + std::to_string(row);
    if (fields.size() != header.size()) {
      throw std::invalid_argument(where + ": " + std::to_string(fields.size()) + " fields, the header has " +
                                  std::to_string(header.size()));
    }
    const auto number = [&](std::size_t c) { return Field(fields[c], where + ", column '" + header[c] + "'"); };
    const auto optional = [&](const std::string& name) {
      const long c = optional_column(name);
      return c < 0 ? kNaN : number(static_cast<std::size_t>(c));
    };
    StudyPoint p;
    const double i = number(index);
    if (!(i >= 0 && i == std::floor(i) && i < 1e9)) throw std::invalid_argument(where + ": index '" + fields[index] + "'");
    p.index = static_cast<int>(i);
    p.u.resize(static_cast<Eigen::Index>(unknowns.size()));
    for (std::size_t k = 0; k < u_columns.size(); ++k) p.u(static_cast<Eigen::Index>(k)) = number(u_columns[k]);
    p.T = number(T);
    OrbitAnalysis& a = p.analysis;
    a.classification.physical = fields[physical] == "1";
    if (!FromString(fields[reason], &a.classification.reason)) {
      throw std::invalid_argument(where + ": classification '" + fields[reason] + "' is no orbit class");
    }
    a.stability = fields[stability];
    a.residual = number(residual);
    const double iterations = number(newton);
    if (!(iterations >= 0 && iterations < 1e9 && iterations == std::floor(iterations))) {
      throw std::invalid_argument(where + ": newton_iterations '" + fields[newton] + "'");
    }
    p.newton_iterations = static_cast<int>(iterations);
    p.step = number(step);
    a.replay_error = optional("replay_error");
    a.automaton_replay_error = optional("automaton_replay_error");
    const double stable = optional("stable");
    a.floquet = std::isfinite(stable);
    a.stable = stable == 1;
    a.normal = optional("normal") == 1;
    const double unit = optional("num_unit");
    a.num_unit = std::isfinite(unit) && unit >= 0 && unit < 1e6 ? static_cast<int>(unit) : 0;
    a.max_multiplier = optional("max_multiplier");
    a.multiplier_error = optional("multiplier_error");  // since 0.11.0
    a.stability_undetermined = a.stability.rfind("undetermined", 0) == 0;
    a.bp_test = optional("bp_test");
    a.pd_test = optional("pd_test");
    for (int j = 1; optional_column("mu" + std::to_string(j) + "_re") >= 0; ++j) {
      const double re = optional("mu" + std::to_string(j) + "_re"), im = optional("mu" + std::to_string(j) + "_im");
      if (std::isfinite(re)) a.multipliers.emplace_back(re, im);
    }
    for (const std::string& name : observables) {
      const auto it = last.find(name);
      if (it != last.end()) a.observables.emplace_back(name, number(it->second));
    }
    for (const std::string& name : quantities) {  // before the observables: the first column of the name
      const auto it = first.find(name);
      if (it != first.end()) p.quantities.push_back({name, number(it->second)});
    }
    p.period_slope = optional("dT_d" + continued);
    points.push_back(std::move(p));
  }
  return points;
}

// The two-parameter curves summary.json lists ("curves", with options.curves.parameter), each read from its
// file (docs/results-format.md). A listed file that is missing is skipped (an interrupted study).
void ReadCurves(const nlohmann::json& summary, const fs::path& dir, StudyResult* r) {
  const auto* options = summary.contains("options") ? &summary["options"] : nullptr;
  if (options && options->is_object() && options->contains("curves") && (*options)["curves"].is_object()) {
    const nlohmann::json& c = (*options)["curves"];
    if (c.contains("parameter") && c["parameter"].is_string()) r->curve_parameter = c["parameter"];
  }
  if (!summary.contains("curves")) return;
  if (!summary["curves"].is_array()) throw std::invalid_argument("curves: expected a list");
  for (std::size_t i = 0; i < summary["curves"].size(); ++i) {
    const nlohmann::json& e = summary["curves"][i];
    const std::string at = "curves[" + std::to_string(i) + "]";
    if (!e.is_object() || !e.contains("file") || !e["file"].is_string()) {
      throw std::invalid_argument(at + ": expected an object with a file name");
    }
    const std::string file = e["file"];
    if (fs::path(file).filename().string() != file) throw std::invalid_argument(at + ".file: '" + file + "' is not a file name");
    std::error_code ec;
    if (!fs::exists(dir / file, ec)) continue;
    StudyCurve curve;
    curve.id = static_cast<int>(r->curves.size());
    curve.type = e.value("type", std::string());
    curve.name = e.contains("name") && e["name"].is_string() ? e["name"].get<std::string>() : std::string();
    curve.special_point = e.contains("special_point") && e["special_point"].is_number_integer() ? e["special_point"].get<int>() : -1;
    curve.status = e.value("status", std::string());
    curve.message = e.contains("message") && e["message"].is_string() ? e["message"].get<std::string>() : std::string();
    using study::JsonNumber, study::JsonText, study::JsonTexts;
    if (e.contains("termination")) curve.termination = JsonTexts(e, "termination", at);
    // The families' coordinate the curve's points are in besides p (before it was written: H).
    const std::string coordinate = e.contains("coordinate") ? JsonText(e, "coordinate", at) : std::string("H");
    if (e.contains("codim_two")) {
      if (!e["codim_two"].is_array()) throw std::invalid_argument(at + ".codim_two: expected a list");
      for (std::size_t k = 0; k < e["codim_two"].size(); ++k) {
        const nlohmann::json& q = e["codim_two"][k];
        const std::string where = at + ".codim_two[" + std::to_string(k) + "]";
        curve.codim_two.push_back({JsonText(q, "type", where), JsonText(q, "name", where, ""), JsonText(q, "status", where),
                                   JsonNumber(q, coordinate, where), JsonNumber(q, r->curve_parameter, where)});
      }
    }
    std::ifstream f = OpenRegular(dir / file);
    std::string line;
    if (!std::getline(f, line)) throw std::invalid_argument((dir / file).string() + ": empty (no header)");
    curve.columns = SplitRow(line);
    for (int row = 2; std::getline(f, line); ++row) {
      const std::vector<std::string> fields = SplitRow(line);
      const std::string where = (dir / file).string() + ":" + std::to_string(row);
      if (fields.size() != curve.columns.size()) {
        throw std::invalid_argument(where + ": " + std::to_string(fields.size()) + " fields, the header has " +
                                    std::to_string(curve.columns.size()));
      }
      Vector v(static_cast<Eigen::Index>(fields.size()));
      for (std::size_t j = 0; j < fields.size(); ++j) {
        v(static_cast<Eigen::Index>(j)) = Field(fields[j], where + ", column '" + curve.columns[j] + "'");
      }
      curve.points.push_back(std::move(v));
    }
    r->curves.push_back(std::move(curve));
  }
}

// The samples of the key-frame orbits r lists (summary.json's "orbits", in order): orbit-<k>.csv's time,
// segment and the state of the sample's phase (its columns "<phase>.<state>", the phases in the order of
// summary.json's "phases"; the sample's phase is its segment modulo their number).
void ReadOrbitSamples(const nlohmann::json& summary, const fs::path& dir, StudyResult* r) {
  if (!summary.contains("orbits") || !summary["orbits"].is_array()) return;
  std::vector<std::size_t> offset, dim;  // of each phase's columns after t, segment, phase
  std::size_t columns = 0;
  if (summary.contains("phases") && summary["phases"].is_array()) {
    for (const nlohmann::json& phase : summary["phases"]) {
      const std::size_t n = phase.is_object() && phase.contains("states") && phase["states"].is_array() ? phase["states"].size() : 0;
      offset.push_back(3 + columns);
      dim.push_back(n);
      columns += n;
    }
  }
  if (offset.empty()) return;
  const nlohmann::json& list = summary["orbits"];
  for (std::size_t i = 0; i < list.size() && i < r->orbits.size(); ++i) {
    if (!list[i].is_object() || !list[i].contains("file") || !list[i]["file"].is_string()) continue;
    const std::string file = list[i]["file"];
    if (fs::path(file).filename().string() != file) {
      throw std::invalid_argument("orbits[" + std::to_string(i) + "].file: '" + file + "' is not a file name");
    }
    std::ifstream f = OpenRegular(dir / file);
    std::string line;
    if (!f || !std::getline(f, line)) continue;  // an orbit file that was not written (a full disk)
    StudyOrbit& orbit = r->orbits[i];
    for (int row = 2; std::getline(f, line); ++row) {
      const std::vector<std::string> fields = SplitRow(line);
      const std::string where = (dir / file).string() + ":" + std::to_string(row);
      if (fields.size() < 3 + columns) throw std::invalid_argument(where + ": " + std::to_string(fields.size()) + " fields, too few");
      const double segment = Field(fields[1], where + ", column 'segment'");
      if (!(segment >= 1 && segment <= 1e6 && segment == std::floor(segment))) {
        throw std::invalid_argument(where + ", column 'segment': '" + fields[1] + "' is not a segment number");
      }
      const std::size_t phase = static_cast<std::size_t>(segment - 1) % offset.size();
      Vector x(static_cast<Eigen::Index>(dim[phase]));
      for (std::size_t c = 0; c < dim[phase]; ++c) {
        x(static_cast<Eigen::Index>(c)) = Field(fields[offset[phase] + c], where + ", state " + std::to_string(c + 1));
      }
      orbit.t.push_back(Field(fields[0], where + ", column 't'"));
      orbit.segment.push_back(static_cast<int>(segment) - 1);
      orbit.x.push_back(std::move(x));
    }
  }
}

}  // namespace

StudyResult LoadStudy(const std::string& dir_text) {
  const fs::path dir = dir_text;
  const fs::path summary_file = dir / "summary.json";
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) throw std::invalid_argument("'" + dir_text + "': not a folder");
  std::ifstream f = OpenRegular(summary_file);
  if (!f) throw std::invalid_argument(summary_file.string() + ": cannot be read (not a results folder?)");
  nlohmann::json summary;
  try {
    summary = nlohmann::json::parse(f);
  } catch (const nlohmann::json::exception& e) {  // not JSON, or a number out of range
    throw std::invalid_argument(summary_file.string() + ": not JSON (" + e.what() + ")");
  }
  if (summary.is_object() && summary.contains("format")) {
    const nlohmann::json& format = summary["format"];
    if (!format.is_number_integer() || format.get<long long>() < 1) {
      throw std::invalid_argument(summary_file.string() + ": format: expected a positive integer, found " + format.dump());
    }
    if (format.get<long long>() > study::kResultsFormat) {
      throw std::invalid_argument(summary_file.string() + ": format " + format.dump() + " is newer than this hybridcont's (" +
                                  std::to_string(study::kResultsFormat) + "): read it with hybridcont " +
                                  (summary.contains("version") ? summary["version"].dump() : std::string("of that version")));
    }
  }
  try {
    std::vector<std::string> observables, quantities;
    if (summary.contains("presentation") && summary["presentation"].is_object()) {
      const nlohmann::json& presentation = summary["presentation"];
      if (presentation.contains("observables") && presentation["observables"].is_array()) {
        for (const nlohmann::json& o : presentation["observables"]) {
          if (o.is_object() && o.contains("name") && o["name"].is_string()) observables.push_back(o["name"]);
        }
      }
      if (presentation.contains("quantities")) quantities = study::JsonTexts(presentation, "quantities", "presentation");
    }
    // The typed branches first (their layouts), then their files.
    StudyResult shape = study::ResultFromSummary(summary, {});
    std::map<int, std::vector<StudyPoint>> points;
    std::map<int, const nlohmann::json*> entries;  // by id (ResultFromSummary has checked them)
    for (const nlohmann::json& entry : summary["branches"]) entries[entry["id"].get<int>()] = &entry;
    for (const StudyBranch& b : shape.branches) {
      const auto listed = entries.find(b.id);
      if (listed == entries.end()) continue;  // not listed by an interrupted study
      const nlohmann::json& entry = *listed->second;
      const std::string file = entry.contains("file") && entry["file"].is_string() ? entry["file"].get<std::string>()
                                                                                      : BranchFileName(b.id);
      if (fs::path(file).filename().string() != file) {
        throw std::invalid_argument("branches[" + std::to_string(b.id) + "].file: '" + file + "' is not a file name");
      }
      if (!fs::exists(dir / file, ec)) continue;  // listed before its first point was written
      // A branch of another model names its own quantities and observables (summary_json.h, BranchJson).
      const std::string at = "branches[" + std::to_string(b.id) + "]";
      const std::vector<std::string> own_quantities =
          entry.contains("quantities") ? study::JsonTexts(entry, "quantities", at) : quantities;
      const std::vector<std::string> own_observables =
          entry.contains("observables") ? study::JsonTexts(entry, "observables", at) : observables;
      points[b.id] = ReadBranchFile(dir / file, b.unknown_names, own_observables, own_quantities, b.continued);
    }
    StudyResult r = study::ResultFromSummary(summary, std::move(points));
    ReadCurves(summary, dir, &r);
    r.regions = study::ParameterRegions(r.branches, r.curves, r.curve_parameter,
                                        study::ParameterValue(r, r.curve_parameter));
    ReadOrbitSamples(summary, dir, &r);
    return r;
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    if (what.rfind(dir.string(), 0) == 0) throw;
    throw std::invalid_argument(summary_file.string() + ": " + what);
  }
}

}  // namespace hybridcont
