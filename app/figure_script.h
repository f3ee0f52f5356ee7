// The figure script (hybridcont_plot, found by install_paths.h) run on a results folder as a child
// process, without a shell:
//   if (DrawFigures(dir, err, false) == 0) out << "figures written\n";
#ifndef HYBRIDCONT_APP_FIGURE_SCRIPT_H_
#define HYBRIDCONT_APP_FIGURE_SCRIPT_H_

#include <filesystem>
#include <ostream>
#include <string>

namespace hybridcont::app {

// What `hybridcont plot` asks of the figure script (its command-line options, python/hybridcont_plot.py).
struct FigureOptions {
  bool svg = false;  // every figure also as SVG (text kept as text)
  bool pdf = false;  // every figure also as PDF (fonts embedded)
  bool all = false;  // every branch's special points labelled, the view not narrowed to the physical families
  std::string x, y;  // both set: only the diagram of column y over column x, <y>_<x>.png
};

// Runs the figure script on dir and returns its exit code (2: the script found the results malformed;
// 127: python could not be started; 128 + n: killed by signal n). Its output goes to dir/plot.log (when
// the folder is writable); its error lines — and with `all_messages` its warnings too — are repeated on err.
int DrawFigures(const std::filesystem::path& dir, std::ostream& err, bool all_messages,
                const FigureOptions& options = {});

}  // namespace hybridcont::app

#endif  // HYBRIDCONT_APP_FIGURE_SCRIPT_H_
