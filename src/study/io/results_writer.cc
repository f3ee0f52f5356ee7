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
#include "hybridcont/invariant.h"
#include "study/io/study_document.h"
#include "study/io/summary_json.h"
#include "study/stages/regions.h"

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
                             const StudyModelSource& source, const FreeParameters& free, const StudyHooks* hooks)
    : dir_(std::move(dir)), model_(model), free_(free), layout_(model, free), presentation_(model, free),
      hooks_(hooks) {
  record_.version = HYBRIDCONT_VERSION;
  record_.model = model.name();
  record_.model_source = source;
  for (const auto& info : model.parameters()) record_.parameters.push_back({info.name, model.parameter(info.name)});
  record_.unknown_names = layout_.unknown_names();
  document_["format"] = kResultsFormat;  // docs/results-format.md
  document_["description"] = model.description();
  nlohmann::json phases = nlohmann::json::array();
  for (int i = 0; i < model.num_phases(); ++i) {
    phases.push_back({{"name", model.phase(i).name()}, {"states", model.phase(i).state_names()}});
  }
  document_["phases"] = phases;
  // The special-point codes and what they mean, from their one definition (special_point.h).
  nlohmann::json codes = nlohmann::json::object();
  for (int t = 0; t <= static_cast<int>(kLastSpecialPointType); ++t) {
    std::string meaning = ToString(static_cast<SpecialPointType>(t));
    std::replace(meaning.begin(), meaning.end(), '-', ' ');
    codes[Code(static_cast<SpecialPointType>(t))] = meaning;
  }
  document_["special_point_codes"] = codes;
  document_["presentation"] = PresentationJson(model, presentation_, free);
  document_["options"] = std::move(options);
  document_["status"] = "running";
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

int ResultsWriter::next_branch_id() const { return branches_.empty() ? 0 : branches_.rbegin()->first + 1; }

int ResultsWriter::num_points() const {
  int n = 0;
  for (const auto& [id, b] : branches_) n += static_cast<int>(b.points.size());
  return n;
}

const std::vector<StudyPoint>* ResultsWriter::PointsOf(int branch_id) const {
  const auto b = branches_.find(branch_id);
  return b == branches_.end() || b->second.points.empty() ? nullptr : &b->second.points;
}

StudyBranch& ResultsWriter::Listed(int branch_id) {
  const auto found = branches_.find(branch_id);
  if (found != branches_.end()) return found->second;
  StudyBranch& b = branches_[branch_id];
  b.id = branch_id;
  b.termination = "running";
  const auto other = branch_models_.find(branch_id);
  const ShootingLayout& layout = other == branch_models_.end() ? layout_ : other->second.layout;
  b.unknown_names = layout.unknown_names();
  b.continued = layout.continued_name();
  b.ranges.branch = branch_id;
  if (other != branch_models_.end()) {
    b.model = other->second.model_name;
    b.origin = other->second.origin;
    b.word = other->second.word;
  } else {
    b.model = model_.name();
    b.word = model_.WordModeNames();
  }
  return b;
}

StudyBranch& ResultsWriter::Ended(int branch_id) {
  const auto found = branches_.find(branch_id);
  HYBRIDCONT_DEMAND(found != branches_.end());  // a later stage annotates a branch after its end
  return found->second;
}

StudyBranch ResultsWriter::Unpointed(int branch_id) const {
  StudyBranch b = branches_.at(branch_id);  // asked at the branch's first point: one point copied
  b.points.clear();
  return b;
}

void ResultsWriter::SetBranchFamily(int branch_id, const BranchFamily& family) {
  StudyBranch& b = Ended(branch_id);
  b.family = family.family;
  b.ranges = family.ranges;
  b.ranges.branch = branch_id;
  WriteSummary();
}

void ResultsWriter::SetPeriodDoubledFrom(int branch_id, int special_point) {
  StudyBranch& b = Ended(branch_id);
  b.period_doubled_from = special_point;
  if (b.origin.empty()) b.origin = "period-doubled";
  WriteSummary();
}

void ResultsWriter::SetStartedInWord(int branch_id) {
  Ended(branch_id).started_in_word = true;
  WriteSummary();
}

void ResultsWriter::SetHandedOverFrom(int branch_id, int word_change) {
  Ended(branch_id).handed_over_from = word_change;
  WriteSummary();
}

void ResultsWriter::AddPoint(int branch_id, const PointRecord& p) {
  const auto other = branch_models_.find(branch_id);
  const ShootingLayout& layout = other == branch_models_.end() ? layout_ : other->second.layout;
  const bool first = branches_.find(branch_id) == branches_.end();
  StudyBranch& b = Listed(branch_id);
  const OrbitPresentation& presentation = other == branch_models_.end() ? presentation_ : other->second.presentation;
  StudyPoint point{p.index, p.u, layout.Period(p.u), p.analysis, p.newton_iterations, p.step, p.at_branch_point,
                   p.period_slope, {}};
  const std::vector<double> quantities = presentation.Quantities(p.u);
  for (std::size_t q = 0; q < quantities.size(); ++q) point.quantities.push_back({presentation.quantity_names()[q], quantities[q]});
  b.points.push_back(std::move(point));
  WritePoint(branch_id, p, b.points.back(), layout);
  if (first) WriteSummary();  // listed from its first point on: an interrupted run shows what it traced
  if (hooks_ && hooks_->on_point) {
    auto live = live_.find(branch_id);
    if (live == live_.end()) live = live_.emplace(branch_id, Unpointed(branch_id)).first;
    hooks_->on_point(b.points.back(), live->second);
  }
}
void ResultsWriter::WritePoint(int branch_id, const PointRecord& p, const StudyPoint& point,
                               const ShootingLayout& layout) {
  if (!writes_files() || !write_error_.empty()) return;  // a full disk: keep what is there, write nothing more
  // The row (and, first, the header) is made in memory and written at once; a write that fails leaves the
  // file cut back to its last whole row (a full disk tears no row).
  std::ostringstream f;
  auto it = branch_files_.find(branch_id);
  if (it == branch_files_.end()) {
    it = branch_files_.emplace(branch_id, std::ofstream(dir_ / BranchFileName(branch_id))).first;
    branch_bytes_[branch_id] = 0;
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
    for (const NamedValue& q : point.quantities) f << "," << q.name;
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
  // Every number below in its shortest form that reads back exactly ("{}"): a study read back is the study.
  f << fmt::format(",{},{},{},{},{},{}", p.classification.physical ? 1 : 0, ToString(p.classification.reason),
                   p.stability, p.residual, p.newton_iterations, p.step);
  if (!std::isnan(p.period_slope)) f << fmt::format(",{}", p.period_slope);  // inf at a turning point
  else f << ",";
  for (const auto& [name, value] : p.extra) {
    if (std::isfinite(value)) f << fmt::format(",{}", value);
    else f << ",";  // not defined for this point (e.g. Floquet data of a non-physical orbit)
  }
  for (const NamedValue& q : point.quantities) {
    if (std::isfinite(q.value)) f << fmt::format(",{:.17g}", q.value);
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
  ++rows_[branch_id];
}

void ResultsWriter::EndBranch(const Branch& b) {
  auto file = branch_files_.find(b.id);
  if (file != branch_files_.end()) file->second.close();
  StudyBranch& record = Listed(b.id);
  record.parent_special_point = b.parent_special_point;
  record.direction = b.direction;
  record.depth = b.depth;
  record.termination = ToString(b.termination);
  record.message = b.message;
  record.newton_iterations = b.newton_iterations;
  record.rejected_steps = b.rejected_steps;
  record.image_of = b.image_of;  // mapped, not traced (exploration.h, "Symmetries")
  record.reflected_from = b.reflected_from;  // a loop traced to its midpoint and completed by reflection
  record.symmetry = b.image_of >= 0 || b.reflected_from >= 0 ? b.symmetry : "";
  WriteSummary();
  live_.erase(b.id);
  if (hooks_ && hooks_->on_branch) hooks_->on_branch(record);
}

void ResultsWriter::Annotate(const std::string& key, nlohmann::json value) {
  document_[key] = std::move(value);
  WriteSummary();
}

void ResultsWriter::SetExplorationStatus(ExplorationStatus status, const std::string& message) {
  record_.status = status;
  record_.message = message;
  Annotate("exploration", {{"status", ToString(status)}, {"message", message}});
}

void ResultsWriter::SetParameterStarts(const StudyParameterStarts& starts) {
  record_.parameter_starts = starts;
  WriteSummary();
}

void ResultsWriter::SetWords(const std::vector<StudyWord>& words, const std::vector<StudyWordChange>& changes) {
  record_.words = words;
  record_.word_changes = changes;
  WriteSummary();
}

void ResultsWriter::SetCurves(const std::string& parameter, const std::vector<StudyCurve>& curves) {
  record_.curve_parameter = parameter;
  record_.curves = curves;
  WriteSummary();
}

void ResultsWriter::SetSpecialPoints(std::vector<StudySpecialPoint> special_points) {
  record_.special_points = std::move(special_points);
}

std::string ResultsWriter::AddOrbit(const OrbitTrace& trace, int branch_id, int index, double H, double T,
                                    const std::string& label, const Matrix& monodromy) {
  const std::string name = OrbitFileName(listed_orbits_);
  const std::vector<OrbitSample> samples = trace.Sample(400);
  StudyOrbit orbit{branch_id, index, label, H, T, {}, {}, {}, monodromy};
  for (const OrbitSample& s : samples) orbit.t.push_back(s.t), orbit.segment.push_back(s.segment), orbit.x.push_back(s.x);
  record_.orbits.push_back(std::move(orbit));
  if (!writes_files()) {
    ++listed_orbits_;
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
  ++listed_orbits_;
  return name;
}

void ResultsWriter::SetReport(const std::string& report) { record_.report = report; }

StudyResult ResultsWriter::Record() const {
  StudyResult r = record_;
  // id == index: an id not listed (a branch without points that never ended: an interrupted study) is there,
  // "unlisted", as LoadStudy gives it.
  for (const auto& [id, b] : branches_) {
    while (static_cast<int>(r.branches.size()) < id) {
      r.branches.push_back(UnlistedBranch(static_cast<int>(r.branches.size()), r, layout_.continued_name()));
    }
    r.branches.push_back(b);
  }
  r.families = FoldFamilies(r.branches, r.special_points);
  r.regions = ParameterRegions(r.branches, r.curves, r.curve_parameter, ParameterValue(r, r.curve_parameter));
  r.summary_json = Document().dump(1);
  return r;
}

nlohmann::json ResultsWriter::Document() const {
  std::map<int, int> listed_rows = rows_;
  if (!writes_files()) {
    for (const auto& [id, b] : branches_) listed_rows[id] = static_cast<int>(b.points.size());
  }
  return SummaryJson(record_, branches_, listed_rows, listed_orbits_, document_);
}

bool ResultsWriter::WriteSummary() {
  if (!writes_files()) return true;
  if (!write_error_.empty()) return false;
  const fs::path tmp = dir_ / "summary.json.tmp";
  errno = 0;
  bool ok = false;
  {
    std::ofstream f(tmp);
    f << Document().dump(1) << "\n";
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
  document_["status"] = cancelled ? "cancelled" : "complete";
  return WriteSummary();
}

void ResultsWriter::Fail(const std::string& message) {
  document_["status"] = "failed";
  document_["status_message"] = message;
  if (write_error_.empty()) WriteSummary();
}

}  // namespace hybridcont::study
