// `hybridcont run MODEL --curves p`: the located turning points (in H̄) and SB points of the physical
// families, each continued in (H̄, p) as a two-parameter curve (special_point_curve.h), written as
// curve_<n>.csv and listed in summary.json under "curves".
//
//   std::vector<StudyCurve> curves = TraceParameterCurves(model, setup, diagram, writer.dir(), &report);
//
// Base map of every curve: the time-based map with p free and held at its value by a fixing row
// (FreeParameters{{p}, {{p, p0}}}): the family in H̄ at fixed p, whose turning points are folds and whose
// SB points are branch points; dropping the fixing row lets (H̄, p) move along the curve. Each point of the
// run's diagram becomes a point of that map by appending p0. PD curves need a PD test function of the
// library and are not traced.
//
// Boundaries of the physical families are traced too: where a physical family's phase duration t_i passes 0
// (between two branch points) and where it crosses a constraint's boundary (a located CB point), the map
// with p free and that quantity held at 0 (a constraint joins the unknowns: shooting_layout.h) is a curve
// in (H̄, p) — the boundary of the region where the family exists and is physical. One curve per boundary
// quantity and place (a start on a traced curve of the same quantity is skipped).
//
// summary.json (summary_json.h, CurvesJson): "curves": [{"id", "type" ("fold" | "branch-point" | "boundary"), "file", "special_point"
// (null for a boundary), "name" (a boundary's "t2 = 0", "clearance = 0"), "status", "points", "termination":
// [backward, forward], "codim_two": [{"type", "name", "status", "H", p}]}].
// curve_<n>.csv: H, p, then the other curve unknowns (those of the map, and beta for branch points).
#ifndef HYBRIDCONT_STUDY_PARAMETER_CURVES_H_
#define HYBRIDCONT_STUDY_PARAMETER_CURVES_H_

#include <filesystem>
#include <stdexcept>
#include <string>

#include "hybridcont/exploration.h"
#include "hybridcont/study.h"
#include "study/engine/run_setup.h"

namespace hybridcont::study {

// A curve's file could not be written (a full disk): the study records it as its write error and stops writing.
class CurveFileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Traces the curves of diagram's special points (model units, the model's layout) in
// setup.curve_parameter within setup.curve_bound and the scenario's H bound, writes their files into
// dir (when not empty) and returns them, id == index; report gets one line per curve. A file that cannot be
// written throws CurveFileError.
std::vector<StudyCurve> TraceParameterCurves(const HybridModel& model, const RunSetup& setup,
                                             const BifurcationDiagram& diagram, const std::filesystem::path& dir,
                                             std::string* report);

}  // namespace hybridcont::study

#endif  // HYBRIDCONT_STUDY_PARAMETER_CURVES_H_
