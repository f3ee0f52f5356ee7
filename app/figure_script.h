// The figure script (hybridcont_plot, found by install_paths.h) run on a results folder as a child
// process, without a shell:
//   if (DrawFigures(dir, err, false) == 0) out << "figures written\n";
#ifndef HYBRIDCONT_APP_FIGURE_SCRIPT_H_
#define HYBRIDCONT_APP_FIGURE_SCRIPT_H_

#include <filesystem>
#include <ostream>

namespace hybridcont::app {

// Runs the figure script on dir and returns its exit code (2: the script found the results malformed;
// 127: python could not be started; 128 + n: killed by signal n). Its output goes to dir/plot.log (when
// the folder is writable); its error lines — and with `all_messages` its warnings too — are repeated on err.
int DrawFigures(const std::filesystem::path& dir, std::ostream& err, bool all_messages);

}  // namespace hybridcont::app

#endif  // HYBRIDCONT_APP_FIGURE_SCRIPT_H_
