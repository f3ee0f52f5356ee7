// `hybridcont run MODEL --curves p`: the located turning points, SB, PD, NS and grazing points of the physical
// families, each continued in (a, p) as a two-parameter curve (special_point_curve.h), a the coordinate the
// run's families are continued in: H̄, or with --free the free parameter at the fixed unknown (`--free k --fix
// H=1.5 --curves w2`: curves in (k, w2) at H̄ = 1.5), or for a model without first integral its run parameter.
// Each written as curve_<n>.csv and listed in summary.json under "curves".
//
//   std::vector<StudyCurve> curves = TraceParameterCurves(model, setup, diagram, writer.dir(), &report);
//
// Base map of every curve: the time-based map of the run (its free parameters, fixed unknowns and joined
// observables) with p free as well and held at its value by one more fixing row: the run's family at fixed p,
// whose turning points in a are folds and whose SB points are branch points; dropping that row lets (a, p)
// move along the curve. Each point of the run's diagram becomes a point of that map with p0 inserted (by the
// unknowns' names). PD and NS points are continued as zeros of their Floquet test functions, grazing points
// (a phase's event crossed tangentially) as zeros of the event's crossing speed. A special point on a traced
// curve of its type (a mirror image's, the other end of one grazing curve) is not traced again.
//
// Boundaries of the physical families are traced too: where a physical family's phase duration t_i passes 0
// (between two branch points) and where it crosses a constraint's boundary (a located CB point), the map
// with p free and that quantity held at 0 (a constraint joins the unknowns: shooting_layout.h) is a curve
// in (a, p) — the boundary of the region where the family exists and is physical. One curve per boundary
// quantity and place (a start on a traced curve of the same quantity is skipped).
//
// summary.json (summary_json.h, CurvesJson): "curves": [{"id", "type" ("fold" | "branch-point" |
// "period-doubling" | "neimark-sacker" | "grazing" | "boundary"), "file", "special_point" (null for a
// boundary), "name" (a boundary's "t2 = 0", "clearance = 0"), "status", "points", "coordinate" (a),
// "termination": [backward, forward], "codim_two": [{"type", "name", "status", a, p}]}].
// curve_<n>.csv: a, p, then the other curve unknowns (those of the map, and beta for branch points).
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
