// BP (a further multiplier crosses +1) and PD (one crosses -1) points of a run: sign changes of the
// Floquet test functions between consecutive physical points of a branch, located on the branch
// (test_function_root.h), and pairs of crossings inside one step (FindHiddenRootPair: the SLIP's two −1
// crossings of hopping in place are found with steps far wider than their distance).
//   std::string report = LocateFloquetPoints(diagram, bp_tests, pd_tests, floquet_map, layout, &points);
#ifndef HYBRIDCONT_APP_FLOQUET_POINTS_H_
#define HYBRIDCONT_APP_FLOQUET_POINTS_H_

#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "hybridcont/exploration.h"
#include "hybridcont/shooting_layout.h"
#include "hybridcont/timebased_shooting.h"

namespace hybridcont::app {

// bp and pd hold, per branch id, the test function at each accepted point (NaN where undefined, e.g. on
// non-physical points); the diagram's points are in the time-based layout of `map`. Returns the report
// lines; appends the points to special_points (summary_json.h: FloquetPointJson), numbered on from its size.
std::string LocateFloquetPoints(const BifurcationDiagram& diagram, const std::map<int, std::vector<double>>& bp,
                                const std::map<int, std::vector<double>>& pd, TimeBasedShooting& map,
                                const ShootingLayout& layout, nlohmann::json* special_points);

}  // namespace hybridcont::app

#endif  // HYBRIDCONT_APP_FLOQUET_POINTS_H_
