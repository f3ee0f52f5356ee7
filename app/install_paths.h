// Where the hybridcont tool finds its data: the figure script and the folder of model files.
//
//   const std::filesystem::path script = PlotScriptPath();  // e.g. /opt/hc/share/hybridcont/hybridcont_plot.py
//   if (script.empty()) { /* no figures; the results are still written */ }
//
// One rule, decided by where the running executable is (/proc/self/exe), never by which files exist:
//  - the executable in the build tree (in the directory the build writes `hybridcont` to) reads the source
//    tree, python/hybridcont_plot.py and models/: the build tree holds no copies, and an edited script
//    takes effect without installing;
//  - every other executable reads the installation it belongs to, <exe dir>/<bin-to-data>/hybridcont_plot.py
//    and <exe dir>/<bin-to-data>/models, where bin-to-data is the path from ${CMAKE_INSTALL_BINDIR} to
//    ${CMAKE_INSTALL_DATADIR}/hybridcont fixed at configure time (usually ../share/hybridcont). Relative, so
//    it holds for a prefix chosen at install time (`cmake --install build --prefix P`) and for an
//    installation moved as a whole.
//  - the executable of a Python package (a wheel's hybridcont/data/bin/hybridcont, run by the package's
//    `hybridcont` command) reads the package's data: hybridcont/data/{hybridcont_plot.py, models, report}, and
//    the package itself from the folder holding hybridcont/ (model files compile against
//    hybridcont/data/include, model_compiler.cc: <exe dir>/../include).
// So an installed executable never reads the source tree it was built from, even while that still exists.
// `hybridcont --paths` prints both paths.
#ifndef HYBRIDCONT_APP_INSTALL_PATHS_H_
#define HYBRIDCONT_APP_INSTALL_PATHS_H_

#include <filesystem>

#include "hybridcont/study_report.h"

namespace hybridcont::app {

// The figure script (python/hybridcont_plot.py) the rule above selects; empty if that file does not exist
// or the executable's own path cannot be read.
std::filesystem::path PlotScriptPath();

// The folder holding the Python package (hybridcont/) by the same rule: in the build tree <build>/python,
// installed where `cmake --install` put it (Python's dist-packages under the prefix); empty where there is none.
std::filesystem::path PythonPackageDirectory();

// The folder of model files (models/) the rule above selects; empty if it does not exist or the
// executable's own path cannot be read.
std::filesystem::path ModelsDirectory();

// The files report.html is assembled from (study_report.h), by the same rule: in the build tree the viewer
// of the source tree (report/) and the plotting library the build installed from npm (<build>/report/);
// installed, <exe dir>/<bin-to-data>/report/. ReportAssets::Missing() says what is not there.
ReportAssets ReportAssetsOfTool();

}  // namespace hybridcont::app

#endif  // HYBRIDCONT_APP_INSTALL_PATHS_H_
