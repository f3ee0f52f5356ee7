#include "install_paths.h"

#include <system_error>

// Set by CMakeLists.txt for this file alone:
//   HYBRIDCONT_BIN_TO_DATA   path from the install bin dir to the install data dir of hybridcont
//   HYBRIDCONT_BUILD_BIN_DIR the directory the build writes the `hybridcont` executable to
//   HYBRIDCONT_SOURCE_TREE   the source tree (python/, models/)
#if !defined(HYBRIDCONT_BIN_TO_DATA) || !defined(HYBRIDCONT_BUILD_BIN_DIR) || !defined(HYBRIDCONT_SOURCE_TREE)
#error "install_paths.cc needs HYBRIDCONT_BIN_TO_DATA, HYBRIDCONT_BUILD_BIN_DIR and HYBRIDCONT_SOURCE_TREE"
#endif
//   HYBRIDCONT_BIN_TO_PYTHON path from the install bin dir to the folder the Python package is installed in
//                            (empty: the build has no Python package)
#ifndef HYBRIDCONT_BIN_TO_PYTHON
#define HYBRIDCONT_BIN_TO_PYTHON ""
#endif

namespace hybridcont::app {

namespace fs = std::filesystem;

namespace {

struct DataLocation {
  fs::path plot_script;
  fs::path models;
  ReportAssets report;
  fs::path python;  // the folder holding the package hybridcont/
};

// The rule of install_paths.h; empty paths if the executable's path cannot be read.
DataLocation Locate() {
  std::error_code ec;
  const fs::path executable = fs::read_symlink("/proc/self/exe", ec);  // symlinks already resolved
  if (ec || executable.empty()) return {};
  const fs::path exe_dir = executable.parent_path();
  // The executable a Python package carries (a wheel: hybridcont/data/bin/hybridcont) reads the package's data.
  if (exe_dir.filename() == "bin" && exe_dir.parent_path().filename() == "data" &&
      exe_dir.parent_path().parent_path().filename() == "hybridcont") {
    const fs::path data = exe_dir.parent_path();
    const fs::path report = data / "report";
    return {data / "hybridcont_plot.py", data / "models",
            {report / "template.html", report / "viewer.js", report / "viewer.css", report / "plotly-basic.min.js"},
            data.parent_path().parent_path()};
  }
  // equivalent() is false (with ec set) once the build directory is gone: the executable is then not in it.
  if (fs::equivalent(exe_dir, fs::path(HYBRIDCONT_BUILD_BIN_DIR), ec)) {
    const fs::path source = HYBRIDCONT_SOURCE_TREE;
    const fs::path viewer = source / "report";
    return {source / "python" / "hybridcont_plot.py", source / "models",
            {viewer / "template.html", viewer / "viewer.js", viewer / "viewer.css",
             exe_dir / "report" / "plotly-basic.min.js"},
            exe_dir / "python"};
  }
  const fs::path data = (exe_dir / HYBRIDCONT_BIN_TO_DATA).lexically_normal();
  const fs::path report = data / "report";
  const std::string to_python = HYBRIDCONT_BIN_TO_PYTHON;
  return {data / "hybridcont_plot.py", data / "models",
          {report / "template.html", report / "viewer.js", report / "viewer.css", report / "plotly-basic.min.js"},
          to_python.empty() ? fs::path() : (exe_dir / to_python).lexically_normal()};
}

fs::path IfExists(const fs::path& path) {
  std::error_code ec;
  return !path.empty() && fs::exists(path, ec) ? path : fs::path();
}

}  // namespace

fs::path PlotScriptPath() { return IfExists(Locate().plot_script); }

fs::path PythonPackageDirectory() {
  const fs::path folder = Locate().python;
  return IfExists(folder / "hybridcont" / "__init__.py").empty() ? fs::path() : folder;
}

ReportAssets ReportAssetsOfTool() { return Locate().report; }

fs::path ModelsDirectory() {
  const fs::path models = IfExists(Locate().models);
  std::error_code ec;
  return !models.empty() && fs::is_directory(models, ec) ? models : fs::path();
}

}  // namespace hybridcont::app
