#include "hybridcont/study_report.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <memory>
#include <stdexcept>
#include <utility>
#include <vector>

#include <unistd.h>

#include <nlohmann/json.hpp>

#include "hybridcont/classification.h"
#include "hybridcont/orbit_trace.h"
#include "hybridcont/setup_evaluation.h"
#include "hybridcont/study_answer.h"
#include "study/io/summary_json.h"
#include "study/stages/regions.h"

namespace hybridcont {

namespace {

using nlohmann::json;

// A number as JSON: NaN and infinities (undefined values) as null.
json Number(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }

// Each end said as the answer says it (RangeEndText: "PD4", not the engine's "PD #4, located to ...", whose
// precision is the arclength's, not the table's).
json RangesJson(const std::vector<Range>& ranges, const std::vector<StudySpecialPoint>& special_points) {
  json out = json::array();
  for (const Range& r : ranges) {
    out.push_back({{"from", Number(r.from.value)}, {"to", Number(r.to.value)},
                   {"how_from", RangeEndText(r.from, special_points)}, {"how_to", RangeEndText(r.to, special_points)},
                   {"first_point", r.first_point}, {"last_point", r.last_point}});
  }
  return out;
}

// Each point's orbit drawn at kAnimationFrames instants (null where not physical or not drawable): one flat
// row [x0, y0, x1, y1, ...] over the presentation's points per instant. A family continued in a parameter
// (its last unknown) is drawn on the model at each point's value of it.
json AnimationJson(const StudyBranch& b, const HybridModel& model, const OrbitPresentation& presentation) {
  // One copy of the model for the branch, its parameter set at each point.
  const std::unique_ptr<HybridModel> copy = b.continued != "H" ? std::make_unique<HybridModel>(model.Clone()) : nullptr;
  json frames = json::array();
  for (const StudyPoint& p : b.points) {
    if (!p.analysis.classification.physical) {
      frames.push_back(nullptr);
      continue;
    }
    const HybridModel* at_point = nullptr;
    Vector state = p.u;
    if (copy) {
      try {
        copy->SetParameter(b.continued, p.u(p.u.size() - 1));
        at_point = copy.get();
      } catch (const std::invalid_argument&) {  // a value outside the parameter's range: not drawn
        frames.push_back(nullptr);
        continue;
      }
      state = p.u.head(p.u.size() - 1);
    }
    const OrbitTrace trace(at_point ? *at_point : model, state, IntegratorOptions{});
    if (!trace.ok()) {
      frames.push_back(nullptr);
      continue;
    }
    const std::vector<OrbitSample> samples = trace.Sample(kAnimationFrames);
    const std::vector<Matrix> drawn = presentation.DrawOrbit(samples);
    json orbit = json::array();
    for (const Matrix& points : drawn) {
      json row = json::array();
      for (Eigen::Index k = 0; k < points.cols(); ++k) row.push_back(Number(points(0, k))), row.push_back(Number(points(1, k)));
      orbit.push_back(std::move(row));
    }
    frames.push_back(std::move(orbit));
  }
  return frames;
}

json BranchJson(const StudyBranch& b, const std::vector<StudySpecialPoint>& special_points) {
  json columns = json::object();
  for (std::size_t k = 0; k < b.unknown_names.size(); ++k) {
    json values = json::array();
    for (const StudyPoint& p : b.points) values.push_back(Number(static_cast<Eigen::Index>(k) < p.u.size() ? p.u(k) : NAN));
    columns[b.unknown_names[k]] = std::move(values);
  }
  json period = json::array(), physical = json::array(), stable = json::array(), classification = json::array(),
       stability = json::array(), multipliers = json::array();
  std::vector<std::string> observables;
  for (const StudyPoint& p : b.points) {
    for (const auto& [name, value] : p.analysis.observables) {
      if (std::find(observables.begin(), observables.end(), name) == observables.end()) observables.push_back(name);
    }
  }
  for (const std::string& name : observables) columns[name] = json::array();
  for (const StudyPoint& p : b.points) {
    const OrbitAnalysis& a = p.analysis;
    period.push_back(Number(p.T));
    physical.push_back(a.classification.physical);
    stable.push_back(a.classification.physical && a.floquet && a.stable);
    classification.push_back(a.classification.physical ? std::string("physical") : ToString(a.classification.reason));
    stability.push_back(a.floquet ? a.stability : std::string());
    if (a.floquet) {
      json mu = json::array();
      for (const std::complex<double>& m : a.multipliers) mu.push_back({Number(m.real()), Number(m.imag())});
      multipliers.push_back(std::move(mu));
    } else {
      multipliers.push_back(nullptr);
    }
    for (const std::string& name : observables) {
      const auto it = std::find_if(a.observables.begin(), a.observables.end(),
                                   [&](const auto& o) { return o.first == name; });
      columns[name].push_back(it == a.observables.end() ? json(nullptr) : Number(it->second));
    }
  }
  columns["T"] = std::move(period);
  return {{"id", b.id},
          {"family", b.family},
          {"word", b.word},
          {"origin", b.origin},
          {"image_of", b.image_of},
          {"symmetry", b.symmetry},
          {"continued", b.continued},
          {"termination", b.termination},
          {"columns", std::move(columns)},
          {"physical", std::move(physical)},
          {"stable", std::move(stable)},
          {"classification", std::move(classification)},
          {"stability", std::move(stability)},
          {"multipliers", std::move(multipliers)},
          {"ranges", {{"physical", RangesJson(b.ranges.physical, special_points)},
                      {"stable", RangesJson(b.ranges.stable, special_points)}}}};
}

json SpecialPointJson(const StudySpecialPoint& sp, const StudyResult& study) {
  json columns = json::object();
  double coordinate = NAN;
  if (sp.branch >= 0 && sp.branch < static_cast<int>(study.branches.size())) {
    const StudyBranch& b = study.branches[sp.branch];
    for (std::size_t k = 0; k < b.unknown_names.size() && static_cast<Eigen::Index>(k) < sp.u.size(); ++k) {
      columns[b.unknown_names[k]] = Number(sp.u(k));
      if (b.unknown_names[k] == b.continued) coordinate = sp.u(k);
    }
  }
  columns["T"] = Number(sp.T);
  return {{"label", sp.Label()}, {"code", sp.code},           {"branch", sp.branch},
          {"index", sp.index},   {"coordinate", Number(coordinate)}, {"H", Number(sp.H)},
          {"T", Number(sp.T)},   {"precision", Number(sp.precision)}, {"status", sp.status},
          {"message", sp.message}, {"columns", std::move(columns)}};
}

// The (p, a) plane of a study with curves (options.curves = p; a the coordinate its families are continued
// in, H̄ or a free parameter): each curve as (p, a) pairs, and the regions where a family is physical and
// where stable (StudyResult::regions, regions.h).
json PlaneJson(const StudyResult& study) {
  if (study.curves.empty() || study.curve_parameter.empty()) return nullptr;
  const double p0 = study::ParameterValue(study, study.curve_parameter);
  const std::string a = study::CurvesCoordinate(study.curves);
  json curves = json::array();
  for (const StudyCurve& c : study.curves) {
    const auto h = std::find(c.columns.begin(), c.columns.end(), a) - c.columns.begin();
    const auto q = std::find(c.columns.begin(), c.columns.end(), study.curve_parameter) - c.columns.begin();
    json points = json::array();
    if (h < static_cast<long>(c.columns.size()) && q < static_cast<long>(c.columns.size())) {
      for (const Vector& u : c.points) points.push_back({Number(u(q)), Number(u(h))});
    }
    std::string label = c.name;
    std::string family;
    if (c.special_point >= 0 && c.special_point < static_cast<int>(study.special_points.size())) {
      const StudySpecialPoint& sp = study.special_points[c.special_point];
      label = sp.Label();
      if (sp.branch >= 0 && sp.branch < static_cast<int>(study.branches.size())) family = study.branches[sp.branch].family;
    }
    curves.push_back({{"id", c.id}, {"type", c.type}, {"label", label}, {"family", family}, {"points", std::move(points)}});
  }
  json regions = json::array();
  for (const StudyRegion& r : study.regions) {
    json polygon = json::array();
    for (const auto& [p, level] : r.polygon) polygon.push_back({Number(p), Number(level)});
    regions.push_back({{"family", r.family}, {"kind", r.kind}, {"branch", r.branch}, {"polygon", std::move(polygon)}});
  }
  return {{"parameter", study.curve_parameter}, {"coordinate", a}, {"value", Number(p0)}, {"curves", std::move(curves)},
          {"regions", std::move(regions)}};
}

std::string Read(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("report: cannot read " + path.string());
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// The template with each marker replaced by its text. Every marker is found in the template itself (once; it
// must be there) before anything is inserted, so that inserted text holding a marker (a family's name in the
// data) is never taken for one.
std::string FillTemplate(const std::string& page, std::vector<std::pair<std::string, std::string>> parts) {
  std::vector<std::pair<std::size_t, std::size_t>> at;  // (position in page, part)
  for (std::size_t i = 0; i < parts.size(); ++i) {
    const std::size_t where = page.find(parts[i].first);
    if (where == std::string::npos) throw std::runtime_error("report: the template lacks " + parts[i].first);
    at.push_back({where, i});
  }
  std::sort(at.begin(), at.end());
  std::string out;
  std::size_t done = 0;
  for (const auto& [where, i] : at) {
    if (where < done) throw std::runtime_error("report: the template's markers overlap");
    out += page.substr(done, where - done) + parts[i].second;
    done = where + parts[i].first.size();
  }
  return out + page.substr(done);
}

}  // namespace

std::string ReportAssets::Missing() const {
  std::string missing;
  for (const std::filesystem::path& p : {template_html, viewer_js, viewer_css, plotly_js}) {
    std::error_code ec;
    if (p.empty() || !std::filesystem::is_regular_file(p, ec)) missing += (missing.empty() ? "" : ", ") + p.string();
  }
  return missing;
}

std::string StudyReportData(const StudyResult& study, const HybridModel* model) {
  json branches = json::array(), special = json::array(), parameters = json::array();
  std::unique_ptr<OrbitPresentation> presentation;
  json drawing = nullptr;
  if (model != nullptr) {
    presentation = std::make_unique<OrbitPresentation>(*model);
    if (!presentation->has_drawing()) presentation.reset();
    const json summary = json::parse(study.summary_json, nullptr, false);
    if (presentation && summary.is_object() && summary.contains("presentation") &&
        summary["presentation"].contains("drawing")) {
      drawing = summary["presentation"]["drawing"];
      drawing["points"] = presentation->point_names();
    }
  }
  for (const StudyBranch& b : study.branches) {
    json branch = BranchJson(b, study.special_points);
    // The study's own model, its families in H̄ (the orbit's unknowns alone) or in a parameter (its last
    // unknown): a period-doubled family or another word runs on another model.
    const bool continued_last = !b.unknown_names.empty() && b.unknown_names.back() == b.continued;
    if (presentation && !drawing.is_null() && b.origin.empty() && b.model == study.model &&
        (b.continued == "H" || continued_last)) {
      branch["animation"] = AnimationJson(b, *model, *presentation);
    }
    branches.push_back(std::move(branch));
  }
  for (const StudySpecialPoint& sp : study.special_points) {
    if (sp.duplicate_of < 0) special.push_back(SpecialPointJson(sp, study));
  }
  for (const NamedValue& p : study.parameters) parameters.push_back({{"name", p.name}, {"value", Number(p.value)}});
  const json data = {{"model", study.model},         {"version", study.version},
                     {"description", ""},            {"parameters", std::move(parameters)},
                     {"drawing", std::move(drawing)},
                     {"status", ToString(study.status)}, {"branches", std::move(branches)},
                     {"special_points", std::move(special)},
                     {"plane", PlaneJson(study)}};
  return data.dump(-1, ' ', false, json::error_handler_t::replace);
}

std::string StudyReportHtml(const StudyResult& study, const ReportAssets& assets, const HybridModel* model) {
  std::string page = Read(assets.template_html);
  // Inside <script> only "</script" (any case) ends the element early: "<\/script" means the same to
  // JavaScript (in a string, a regular expression or a comment, the only places it can stand) and to JSON.
  const auto inert = [](std::string text) {
    for (std::size_t at = 0; (at = text.find("</", at)) != std::string::npos; at += 2) {
      std::string next = text.substr(at + 2, 6);
      std::transform(next.begin(), next.end(), next.begin(), [](unsigned char c) { return std::tolower(c); });
      if (next == "script") text.replace(at, 2, "<\\/"), ++at;
    }
    return text;
  };
  // The data is JSON: every "<" (only ever inside its strings) written as \u003c, so that no text of the study
  // ("<!--<script>" in a family's name) changes how the page's script element is parsed.
  std::string data = StudyReportData(study, model), escaped;
  for (const char c : data) escaped += c == '<' ? std::string("\\u003c") : std::string(1, c);
  page = FillTemplate(page, {{"/*HYBRIDCONT_STYLE*/", Read(assets.viewer_css)},
                             {"/*HYBRIDCONT_PLOTLY*/", inert(Read(assets.plotly_js))},
                             {"/*HYBRIDCONT_DATA*/", escaped},
                             {"/*HYBRIDCONT_VIEWER*/", inert(Read(assets.viewer_js))}});
  return page;
}

namespace {

// The process's umask, read without changing it (umask(2) would, for every thread): Linux's /proc/self/status;
// 022 where it cannot be read.
unsigned ProcessUmask() {
  std::ifstream status("/proc/self/status");
  for (std::string line; std::getline(status, line);) {
    if (line.rfind("Umask:", 0) == 0) return static_cast<unsigned>(std::strtoul(line.c_str() + 6, nullptr, 8)) & 0777u;
  }
  return 022;
}

}  // namespace

std::string SaveStudyReport(const StudyResult& study, const std::filesystem::path& dir, const ReportAssets& assets,
                            const HybridModel* model) {
  if (const std::string missing = assets.Missing(); !missing.empty()) return "the report's files are missing: " + missing;
  const std::filesystem::path target = dir / "report.html";
  std::filesystem::path temporary;
  try {
    const std::string html = StudyReportHtml(study, assets, model);
    std::string name = (dir / ".report.html.XXXXXX").string();
    const int fd = mkstemp(name.data());
    if (fd < 0) return "cannot write " + (dir / ".report.html.*").string() + " (" + std::strerror(errno) + ")";
    close(fd);
    temporary = name;
    {
      std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
      out << html;
      if (!out.flush()) throw std::runtime_error("cannot write " + temporary.string());
    }
    // mkstemp made it private (0600): the report gets the mode any new file of the user gets (0666 less the umask).
    std::filesystem::permissions(temporary, static_cast<std::filesystem::perms>(0666 & ~ProcessUmask()));
    std::filesystem::rename(temporary, target);
  } catch (const std::exception& e) {
    std::error_code ec;
    if (!temporary.empty()) std::filesystem::remove(temporary, ec);
    return e.what();
  }
  return "";
}

}  // namespace hybridcont
