// `hybridcont run MODEL --curves p`: the located turning points (in H̄) and SB points of the physical
// families, each continued in (H̄, p) as a two-parameter curve (special_point_curve.h), written as
// curve_<n>.csv and listed in summary.json under "curves".
//
//   nlohmann::json curves = TraceParameterCurves(model, setup, diagram, writer.dir(), &report);
//
// Base map of every curve: the time-based map with p free and held at its value by a fixing row
// (FreeParameters{{p}, {{p, p0}}}): the family in H̄ at fixed p, whose turning points are folds and whose
// SB points are branch points; dropping the fixing row lets (H̄, p) move along the curve. Each point of the
// run's diagram becomes a point of that map by appending p0. PD curves need a PD test function of the
// library and are not traced.
//
// summary.json: "curves": [{"id", "type" ("fold" | "branch-point"), "file", "special_point", "status",
// "points", "termination": [backward, forward], "codim_two": [{"type", "name", "status", "H", p}]}].
// curve_<n>.csv: H, p, then the other curve unknowns (those of the map, and beta for branch points).
#ifndef HYBRIDCONT_APP_PARAMETER_CURVES_H_
#define HYBRIDCONT_APP_PARAMETER_CURVES_H_

#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "hybridcont/exploration.h"
#include "run_setup.h"

namespace hybridcont::app {

// Traces the curves of diagram's special points (model units, the model's layout) in
// setup.curve_parameter within setup.curve_bound and the scenario's H bound, writes their files into
// dir and returns the "curves" list; report gets one line per curve.
nlohmann::json TraceParameterCurves(const HybridModel& model, const RunSetup& setup, const BifurcationDiagram& diagram,
                                    const std::filesystem::path& dir, std::string* report);

}  // namespace hybridcont::app

#endif  // HYBRIDCONT_APP_PARAMETER_CURVES_H_
