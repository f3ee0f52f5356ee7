#include "study/io/results_writer.h"

#include <fmt/format.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <set>
#include <sstream>
#include <stdexcept>

#include "hybridcont/version.h"
#include "study/io/study_document.h"

namespace hybridcont::study {

namespace fs = std::filesystem;

void ResultsWriter::PrepareDirectory(const fs::path& dir, const std::string& model, bool overwrite) {
  const std::string where = "--out '" + dir.string() + "': ";
  std::error_code ec;
  if (fs::exists(dir, ec) && !fs::is_directory(dir, ec)) {
    throw std::invalid_argument(where + "exists and is not a folder");
  }
  // Results of another run: the same model's are replaced; another model's (or a summary.json that is not
  // ours) only with --overwrite, so that a mistyped --out does not wipe a finished diagram.
  const fs::path summary = dir / "summary.json";
  if (!model.empty() && !overwrite && fs::exists(summary, ec)) {
    // Opened only where it is a regular file: a FIFO named summary.json would block the open.
    nlohmann::json old;
    if (fs::is_regular_file(summary, ec)) {
      std::ifstream f(summary);
      old = nlohmann::json::parse(f, nullptr, false);
    }
    const bool readable = old.is_object() && old.contains("model") && old["model"].is_string();
    if (!readable) {
      throw std::invalid_argument(where + "holds a summary.json that is not the results of a hybridcont run (or is "
                                  "damaged); choose another folder or pass --overwrite to replace it");
    }
    if (old["model"].get<std::string>() != model) {
      throw std::invalid_argument(where + "holds the results of model '" + old["model"].get<std::string>() +
                                  "', not '" + model + "'; choose another folder or pass --overwrite to replace them");
    }
  }
  fs::create_directories(dir, ec);
  if (ec) throw std::invalid_argument(where + "cannot create the folder (" + ec.message() + ")");
  if (!fs::is_directory(dir)) throw std::invalid_argument(where + "not a folder");
  const fs::path probe = dir / ".hybridcont-write-test";
  {
    std::ofstream f(probe);
    if (!f || !(f << "x") || !f.flush()) {
      f.close();
      fs::remove(probe, ec);
      throw std::invalid_argument(where + "folder is not writable");
    }
  }
  fs::remove(probe, ec);
}

namespace {

// What the figure script needs to know of the model's presentation (model_setup.h).
// The model's observables and constraints: name, kind, whether a constraint (>= 0), description.
nlohmann::json ObservablesJson(const HybridModel& model) {
  nlohmann::json list = nlohmann::json::array();
  for (const Observable& o : model.observables()) {
    list.push_back({{"name", o.name}, {"kind", ToString(o.kind)}, {"constraint", o.constraint},
                    {"description", o.description}});
  }
  return list;
}

nlohmann::json PresentationJson(const HybridModel& model, const OrbitPresentation& presentation,
                                const FreeParameters& free) {
  const ModelSetup& setup = model.setup();
  nlohmann::json figures = nlohmann::json::array();
  for (const FigureSpec& f : setup.figures) {
    // At a fixed H the families vary in the free parameter: it takes H's place on the horizontal axis.
    const std::string x = f.x == "H" && !free.parameters.empty() ? free.parameters.front() : f.x;
    figures.push_back({{"file", f.file}, {"title", f.title}, {"x", x}, {"y", f.y}, {"zoom", f.zoom_special_points}});
  }
  nlohmann::json phases = nlohmann::json::object();
  for (const DrawingSpec::PhaseDrawing& d : setup.drawing.phases) {
    if (phases.contains(d.phase)) continue;  // drawings of one phase for other segments look alike
    phases[d.phase] = {{"lines", d.lines}, {"masses", d.masses}};
  }
  return {{"title", setup.title.empty() ? model.name() : setup.title},
          {"quantities", presentation.quantity_names()},
          {"observables", ObservablesJson(model)},
          {"families", presentation.family_names()},
          {"figures", figures},
          {"drawing",
           {{"ground", setup.drawing.ground}, {"mass_radius", setup.drawing.mass_radius}, {"phases", phases}}}};
}

}  // namespace

ResultsWriter::ResultsWriter(fs::path dir, const HybridModel& model, nlohmann::json options,
                             const FreeParameters& free, const StudyHooks* hooks)
    : dir_(std::move(dir)), model_(model), free_(free), layout_(model, free), presentation_(model, free),
      hooks_(hooks) {
  summary_["model"] = model.name();
  summary_["version"] = HYBRIDCONT_VERSION;
  summary_["format"] = kResultsFormat;  // docs/results-format.md
  summary_["description"] = model.description();
  nlohmann::json params = nlohmann::json::object();
  for (const auto& info : model.parameters()) params[info.name] = model.parameter(info.name);
  summary_["parameters"] = params;
  nlohmann::json phases = nlohmann::json::array();
  for (int i = 0; i < model.num_phases(); ++i) {
    phases.push_back({{"name", model.phase(i).name()}, {"states", model.phase(i).state_names()}});
  }
  summary_["phases"] = phases;
  summary_["unknowns"] = layout_.unknown_names();
  // The special-point codes and what they mean, from their one definition (special_point.h).
  nlohmann::json codes = nlohmann::json::object();
  for (int t = 0; t <= static_cast<int>(SpecialPointType::kKreinCollision); ++t) {
    std::string meaning = ToString(static_cast<SpecialPointType>(t));
    std::replace(meaning.begin(), meaning.end(), '-', ' ');
    codes[Code(static_cast<SpecialPointType>(t))] = meaning;
  }
  summary_["special_point_codes"] = codes;
  summary_["presentation"] = PresentationJson(model, presentation_, free);
  summary_["options"] = std::move(options);
  summary_["branches"] = nlohmann::json::array();
  summary_["special_points"] = nlohmann::json::array();
  summary_["orbits"] = nlohmann::json::array();
  summary_["status"] = "running";
  // Remove the results of an earlier run in the same folder so that the folder describes this run only:
  // summary.json first (while the rest is removed the folder claims nothing), then the CSV files, the
  // figures (the generic ones, those the old summary declared and every one figures.txt lists), the report and
  // the figure script's log.
  if (!writes_files()) return;
  std::set<std::string> figures = {"H_T", "H_T_xi", "keyframes", "curves", "words"};
  // Every figure drawn into the folder, as the figure script lists them (figures.txt: one plain file name a line).
  std::set<std::string> drawn;
  {
    std::ifstream f(dir_ / "figures.txt");
    for (std::string line; std::getline(f, line);) {
      const fs::path file = line;
      const std::string ext = file.extension().string();
      if (!line.empty() && line[0] != '.' && file == file.filename() && (ext == ".png" || ext == ".svg" || ext == ".pdf")) {
        drawn.insert(line);
      }
    }
  }
  std::error_code ec;
  {
    std::ifstream f(dir_ / "summary.json");
    const nlohmann::json old = f ? nlohmann::json::parse(f, nullptr, false) : nlohmann::json(nullptr);
    if (old.is_object() && old.contains("presentation") && old["presentation"].is_object() &&
        old["presentation"].contains("figures") && old["presentation"]["figures"].is_array()) {
      for (const nlohmann::json& figure : old["presentation"]["figures"]) {
        if (!figure.is_object() || !figure.contains("file") || !figure["file"].is_string()) continue;
        const fs::path file = figure["file"].get<std::string>();
        if (file.has_filename() && file == file.filename()) figures.insert(file.stem().string());
      }
    }
  }
  fs::remove(dir_ / "summary.json", ec);
  for (const auto& entry : fs::directory_iterator(dir_, ec)) {
    const std::string name = entry.path().filename().string();
    const std::string ext = entry.path().extension().string();
    const bool ours = ((name.rfind("branch-", 0) == 0 || name.rfind("orbit-", 0) == 0 || name.rfind("curve_", 0) == 0) &&
                       ext == ".csv") ||
                      ((ext == ".png" || ext == ".svg") && figures.count(entry.path().stem().string())) ||
                      drawn.count(name) || name == "figures.txt" || name == "report.html" || name == "plot.log" ||
                      name == "summary.json.tmp" || name.rfind(".report.html.", 0) == 0;  // a report write cut short
    if (ours && entry.is_regular_file(ec)) fs::remove(entry.path(), ec);
  }
  WriteSummary();
}

bool ResultsWriter::WriteFailed(const fs::path& file) {
  if (write_error_.empty()) {
    write_error_ = "writing " + file.string() + " failed (" + (errno ? std::strerror(errno) : "I/O error") + ")";
  }
  failed_ = true;
  return false;
}

void ResultsWriter::SetBranchModel(int branch_id, const HybridModel& model, const std::string& origin) {
  // The run's free parameters are the other model's too (a doubled model's columns: its unknowns and p).
  branch_models_.insert_or_assign(branch_id, BranchModel{ShootingLayout(model, free_), OrbitPresentation(model, free_),
                                                         model.WordModeNames(), model.name(), origin});
}

int ResultsWriter::next_branch_id() const {
  int next = 0;
  for (const nlohmann::json& b : summary_["branches"]) next = std::max(next, b["id"].get<int>() + 1);
  return next;
}

void ResultsWriter::SetBranchFamily(int branch_id, const BranchFamily& family) {
  families_[branch_id] = family;
  const auto json_of = [](const std::vector<Range>& list) {
    nlohmann::json a = nlohmann::json::array();
    for (const Range& r : list) {
      a.push_back({{"from", r.from.value}, {"to", r.to.value}, {"from_how", r.from.how}, {"to_how", r.to.how},
                   {"from_special_point", r.from.special_point}, {"to_special_point", r.to.special_point},
                   {"first_point", r.first_point}, {"last_point", r.last_point}, {"family", r.family}});
    }
    return a;
  };
  AnnotateBranch(branch_id, {{"family", family.family},
                             {"physical_ranges", json_of(family.ranges.physical)},
                             {"stable_ranges", json_of(family.ranges.stable)}});
}

void ResultsWriter::AnnotateBranch(int branch_id, const nlohmann::json& fields) {
  for (nlohmann::json& b : summary_["branches"]) {
    if (b["id"] == branch_id) b.update(fields);
  }
  WriteSummary();
}

void ResultsWriter::AddPoint(int branch_id, const PointRecord& p) {
  const auto other = branch_models_.find(branch_id);
  const ShootingLayout& layout = other == branch_models_.end() ? layout_ : other->second.layout;
  std::vector<StudyPoint>& points = points_[branch_id];
  points.push_back({p.index, p.u, layout.Period(p.u), p.analysis, p.newton_iterations, p.step, p.at_branch_point});
  if (points.size() == 1 && !writes_files()) StartBranchEntry(branch_id);
  WritePoint(branch_id, p, layout, other == branch_models_.end() ? presentation_ : other->second.presentation);
  if (hooks_ && hooks_->on_point) {
    auto live = live_.find(branch_id);
    if (live == live_.end()) live = live_.emplace(branch_id, BranchOf(branch_id, /*with_points=*/false)).first;
    hooks_->on_point(points.back(), live->second);
  }
}

void ResultsWriter::WritePoint(int branch_id, const PointRecord& p, const ShootingLayout& layout,
                               const OrbitPresentation& presentation) {
  if (!writes_files() || !write_error_.empty()) return;  // a full disk: keep what is there, write nothing more
  // The row (and, first, the header) is made in memory and written at once; a write that fails leaves the
  // file cut back to its last whole row (a full disk tears no row).
  std::ostringstream f;
  auto it = branch_files_.find(branch_id);
  if (it == branch_files_.end()) {
    it = branch_files_.emplace(branch_id, std::ofstream(dir_ / BranchFileName(branch_id))).first;
    branch_bytes_[branch_id] = 0;
    StartBranchEntry(branch_id);  // listed from its first point on: an interrupted run shows what it traced
    f << "index,H,T";
    const auto& names = layout.unknown_names();
    for (int j = 0; j < layout.num_free_parameters(); ++j) f << "," << names[layout.parameter_index(j)];
    for (int j = 0; j < layout.num_first_integrals(); ++j) f << "," << names[layout.xi_index(j)];
    for (int i = 0; i < layout.num_segments(); ++i) f << ",t" << i + 1;
    for (int i = 0; i < layout.num_segments(); ++i) {
      for (int c = 0; c < layout.dim(i); ++c) f << "," << names[layout.state_offset(i) + c];
    }
    f << ",physical,classification,stability,residual,newton_iterations,step";
    f << ",dT_d" << layout.continued_name();
    for (const auto& [name, value] : p.extra) f << "," << name;
    for (const std::string& name : presentation.quantity_names()) f << "," << name;
    for (const auto& [name, value] : p.observables) f << "," << name;
    f << "\n";
  }
  const Vector& u = p.u;
  // A model without first integral has no H̄: the column stays (every branch file has it) and holds nan.
  f << fmt::format("{},{:.17g},{:.17g}", p.index, layout.has_level() ? u(layout.H_index()) : std::nan(""),
                   layout.Period(u));
  for (int j = 0; j < layout.num_free_parameters(); ++j) f << fmt::format(",{:.17g}", u(layout.parameter_index(j)));
  for (int j = 0; j < layout.num_first_integrals(); ++j) f << fmt::format(",{:.17g}", u(layout.xi_index(j)));
  for (int i = 0; i < layout.num_segments(); ++i) f << fmt::format(",{:.17g}", u(layout.time_index(i)));
  for (int i = 0; i < layout.num_segments(); ++i) {
    for (int c = 0; c < layout.dim(i); ++c) f << fmt::format(",{:.17g}", u(layout.state_offset(i) + c));
  }
  f << fmt::format(",{},{},{},{:.3e},{},{:.6g}", p.classification.physical ? 1 : 0, ToString(p.classification.reason),
                   p.stability, p.residual, p.newton_iterations, p.step);
  if (std::isfinite(p.period_slope)) f << fmt::format(",{:.10g}", p.period_slope);
  else f << ",";
  for (const auto& [name, value] : p.extra) {
    if (std::isfinite(value)) f << fmt::format(",{:.10g}", value);
    else f << ",";  // not defined for this point (e.g. Floquet data of a non-physical orbit)
  }
  for (const double value : presentation.Quantities(u)) {
    if (std::isfinite(value)) f << fmt::format(",{:.17g}", value);
    else f << ",";
  }
  for (const auto& [name, value] : p.observables) {
    if (std::isfinite(value)) f << fmt::format(",{:.17g}", value);
    else f << ",";
  }
  f << "\n";
  const std::string row = f.str();
  std::ofstream& file = it->second;
  errno = 0;
  if (!file.write(row.data(), static_cast<std::streamsize>(row.size())) || !file.flush()) {
    WriteFailed(dir_ / BranchFileName(branch_id));
    file.close();
    std::error_code ec;
    fs::resize_file(dir_ / BranchFileName(branch_id), branch_bytes_[branch_id], ec);
    return;
  }
  branch_bytes_[branch_id] += row.size();
  ++points_per_branch_[branch_id];
}

void ResultsWriter::EndBranch(const Branch& b) {
  auto file = branch_files_.find(b.id);
  if (file != branch_files_.end()) file->second.close();
  if (!writes_files()) {
    const auto listed = points_.find(b.id);
    points_per_branch_[b.id] = listed == points_.end() ? 0 : static_cast<int>(listed->second.size());
  }
  nlohmann::json entry = {{"id", b.id},
                          {"file", BranchFileName(b.id)},
                          {"parent", b.parent_special_point},
                          {"direction", b.direction},
                          {"depth", b.depth},
                          {"points", points_per_branch_[b.id]},
                          {"termination", ToString(b.termination)},
                          {"message", b.message},
                          {"newton_iterations", b.newton_iterations},
                          {"rejected_steps", b.rejected_steps}};
  // Its phase sequence: the modes of its word (a cyclic model's phases).
  const auto other = branch_models_.find(b.id);
  entry["word"] = other == branch_models_.end() ? model_.WordModeNames() : other->second.word;
  // A branch of another layout (another word's, a period-doubled family's) names its unknowns, the order of u.
  if (other != branch_models_.end()) entry["unknowns"] = other->second.layout.unknown_names();
  if (b.image_of >= 0) {  // mapped, not traced (exploration.h, "Symmetries")
    entry["image_of"] = b.image_of;
    entry["symmetry"] = b.symmetry;
  }
  if (b.reflected_from >= 0) {  // a loop traced to its midpoint and completed by reflection
    entry["reflected_from"] = b.reflected_from;
    entry["symmetry"] = b.symmetry;
  }
  // The entry listed at the branch's first point (StartBranchEntry) is replaced in place.
  nlohmann::json& branches = summary_["branches"];
  const auto listed = std::find_if(branches.begin(), branches.end(), [&](const nlohmann::json& e) { return e["id"] == b.id; });
  if (listed != branches.end()) {
    *listed = std::move(entry);
  } else {  // a branch without points: listed in the order of the ids
    const auto later = std::find_if(branches.begin(), branches.end(),
                                    [&](const nlohmann::json& e) { return e["id"].get<int>() > b.id; });
    branches.insert(later, std::move(entry));
  }
  WriteSummary();
  live_.erase(b.id);
  if (hooks_ && hooks_->on_branch) hooks_->on_branch(BranchOf(b.id, /*with_points=*/true));
}

StudyBranch ResultsWriter::BranchOf(int branch_id, bool with_points) const {
  const nlohmann::json& branches = summary_["branches"];
  const auto entry = std::find_if(branches.begin(), branches.end(),
                                  [&](const nlohmann::json& e) { return e["id"] == branch_id; });
  const auto other = branch_models_.find(branch_id);
  const ShootingLayout& layout = other == branch_models_.end() ? layout_ : other->second.layout;
  const auto points = points_.find(branch_id);
  StudyBranch b = entry == branches.end() ? StudyBranch{} : BranchFromSummary(*entry, layout.unknown_names());
  b.id = branch_id;
  b.continued = layout.continued_name();
  if (other != branch_models_.end()) b.model = other->second.model_name, b.origin = other->second.origin;
  else b.model = model_.name();
  if (with_points && points != points_.end()) b.points = points->second;
  if (const auto f = families_.find(branch_id); f != families_.end()) {
    b.family = f->second.family;
    b.ranges = f->second.ranges;
    b.ranges.branch = branch_id;
  }
  return b;
}

void ResultsWriter::StartBranchEntry(int branch_id) {
  const auto other = branch_models_.find(branch_id);
  summary_["branches"].push_back({{"id", branch_id},
                                  {"file", BranchFileName(branch_id)},
                                  {"points", 0},
                                  {"termination", "running"},
                                  {"word", other == branch_models_.end() ? model_.WordModeNames() : other->second.word}});
  WriteSummary();
}

void ResultsWriter::Annotate(const std::string& key, nlohmann::json value) {
  summary_[key] = std::move(value);
  WriteSummary();
}

void ResultsWriter::SetSpecialPoints(nlohmann::json special_points) {
  summary_["special_points"] = std::move(special_points);
}

std::string ResultsWriter::AddOrbit(const OrbitTrace& trace, int branch_id, int index, double H, double T,
                                    const std::string& label, const Matrix& monodromy) {
  const std::string name = "orbit-" + std::to_string(summary_["orbits"].size()) + ".csv";
  const std::vector<OrbitSample> samples = trace.Sample(400);
  StudyOrbit orbit{branch_id, index, label, H, T, {}, {}, {}, monodromy};
  nlohmann::json entry = {{"file", name}, {"branch", branch_id}, {"index", index}, {"H", H}, {"T", T}, {"label", label}};
  if (monodromy.size() > 0) {
    nlohmann::json rows = nlohmann::json::array();
    for (Eigen::Index i = 0; i < monodromy.rows(); ++i) {
      nlohmann::json row = nlohmann::json::array();
      for (Eigen::Index j = 0; j < monodromy.cols(); ++j) row.push_back(monodromy(i, j));
      rows.push_back(std::move(row));
    }
    entry["monodromy"] = std::move(rows);
  }
  for (const OrbitSample& s : samples) orbit.t.push_back(s.t), orbit.segment.push_back(s.segment), orbit.x.push_back(s.x);
  orbits_.push_back(std::move(orbit));
  if (!writes_files()) {
    summary_["orbits"].push_back(std::move(entry));
    return name;
  }
  if (!write_error_.empty()) return name;
  errno = 0;
  std::ofstream f(dir_ / name);
  f << "t,segment,phase";
  for (int p = 0; p < model_.num_phases(); ++p) {
    for (const auto& s : model_.phase(p).state_names()) f << "," << model_.phase(p).name() << "." << s;
  }
  for (const std::string& point : presentation_.point_names()) f << ",draw." << point << ".x,draw." << point << ".y";
  f << "\n";
  const std::vector<Matrix> drawn = presentation_.DrawOrbit(samples);
  for (std::size_t k = 0; k < samples.size(); ++k) {
    const OrbitSample& s = samples[k];
    const int phase = s.segment % model_.num_phases();
    // Time and states at full precision (read back exactly by LoadStudy); the drawing's points at 12 digits.
    f << fmt::format("{:.17g},{},{}", s.t, s.segment + 1, model_.phase(phase).name());
    for (int p = 0; p < model_.num_phases(); ++p) {
      for (int c = 0; c < model_.phase(p).dim(); ++c) {
        if (p == phase) f << fmt::format(",{:.17g}", s.x(c));
        else f << ",";
      }
    }
    for (Eigen::Index point = 0; point < drawn[k].cols(); ++point) {
      for (int c = 0; c < 2; ++c) {
        const double value = drawn[k](c, point);
        if (std::isfinite(value)) f << fmt::format(",{:.12g}", value);
        else f << ",";  // a point that the drawing of this sample's phase does not place
      }
    }
    f << "\n";
  }
  if (!f.flush()) {
    WriteFailed(dir_ / name);
    f.close();
    std::error_code ec;
    fs::remove(dir_ / name, ec);  // no torn orbit: it is listed nowhere
    return name;
  }
  summary_["orbits"].push_back(std::move(entry));
  return name;
}

void ResultsWriter::SetReport(const std::string& report) { summary_["report"] = report; }

bool ResultsWriter::WriteSummary() {
  if (!writes_files()) return true;
  if (!write_error_.empty()) return false;
  const fs::path tmp = dir_ / "summary.json.tmp";
  errno = 0;
  bool ok = false;
  {
    std::ofstream f(tmp);
    f << summary_.dump(1) << "\n";
    f.close();
    ok = !f.fail();
  }
  std::error_code ec;
  if (ok) fs::rename(tmp, dir_ / "summary.json", ec);
  if (!ok || ec) {
    if (ec) errno = ec.value();
    WriteFailed(dir_ / "summary.json");
    fs::remove(tmp, ec);  // never rename a partial summary over the last good one
    return false;
  }
  return true;
}

bool ResultsWriter::Finish(bool cancelled) {
  summary_["status"] = cancelled ? "cancelled" : "complete";
  return WriteSummary();
}

void ResultsWriter::Fail(const std::string& message) {
  summary_["status"] = "failed";
  summary_["status_message"] = message;
  if (write_error_.empty()) WriteSummary();
}

}  // namespace hybridcont::study
