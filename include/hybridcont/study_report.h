// The interactive report of a study (report.html): one self-contained HTML file that opens offline, from its
// folder or as an attachment. It holds the study's data (a JSON block: every branch's columns, class,
// stability and multipliers per point, its ranges; every special point) and the code to draw it: the viewer
// (report/viewer.js, viewer.css, template.html of the source tree) and the plotting library Plotly.js
// (plotly.js-basic-dist-min, MIT), installed from npm when the tool is built and inlined here, never fetched
// when a report is viewed.
//
//   const ReportAssets assets = ...;  // the tool's: app/install_paths.h
//   std::ofstream("results/slip/report.html") << StudyReportHtml(RunStudy(options), assets);
#ifndef HYBRIDCONT_STUDY_REPORT_H_
#define HYBRIDCONT_STUDY_REPORT_H_

#include <filesystem>
#include <string>

#include "hybridcont/study.h"

namespace hybridcont {

// The files a report is assembled from.
struct ReportAssets {
  std::filesystem::path template_html;  // report/template.html: the page, with a placeholder for each part
  std::filesystem::path viewer_js;      // report/viewer.js
  std::filesystem::path viewer_css;     // report/viewer.css
  std::filesystem::path plotly_js;      // plotly-basic.min.js from the npm package
  // Empty when every file exists and is readable; otherwise what is missing (for the tool's note).
  std::string Missing() const;
};

// The study's data as the viewer reads it (JSON text). With the study's model (MakeStudyModel), every physical
// point of the families continued in H̄ carries its orbit drawn as the model draws it (its presentation's
// points at kAnimationFrames instants of one period: the viewer animates it), and the presentation's lines,
// masses and ground; without, no animations.
std::string StudyReportData(const StudyResult& study, const HybridModel* model = nullptr);
inline constexpr int kAnimationFrames = 40;

// report.html of the study. Throws std::runtime_error naming the asset that cannot be read.
std::string StudyReportHtml(const StudyResult& study, const ReportAssets& assets, const HybridModel* model = nullptr);

// Writes StudyReportHtml into dir/report.html whole: a temporary file of its own (unique to the call, so that
// two writers of one folder never share one) renamed over it, removed when anything fails. Returns the reason
// it was not written, empty when it was.
std::string SaveStudyReport(const StudyResult& study, const std::filesystem::path& dir, const ReportAssets& assets,
                            const HybridModel* model = nullptr);

}  // namespace hybridcont

#endif  // HYBRIDCONT_STUDY_REPORT_H_
