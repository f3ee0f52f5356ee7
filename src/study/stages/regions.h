// The regions of a parameter plane (a study with curves: options.curves = p): where each family is physical
// and where it is stable, as polygons in (p, a), a the coordinate the families are continued in (H̄ or a free
// parameter). A family's range in a at the run's p0 ends at a special point or at a bound; where the range's
// ends are both edges known over p — the curve of its special point (or a curve through the end at p0), or
// the bound a branch reached — the region between those edges over the p both cover is one polygon. A range
// with an end of neither kind (a singular start, an end that is not located) has no region: its edge over p
// is not known.
//
//   std::vector<StudyRegion> regions = ParameterRegions(result.branches, result.curves, result.curve_parameter, p0);
//
// Derived data, like the families (families.h): written to summary.json ("regions"), recomputed by LoadStudy.
#ifndef HYBRIDCONT_STUDY_STAGES_REGIONS_H_
#define HYBRIDCONT_STUDY_STAGES_REGIONS_H_

#include <string>
#include <vector>

#include "hybridcont/study.h"

namespace hybridcont::study {

// The families' coordinate a the curves are drawn in besides their parameter: every curve's first column
// (parameter_curves.h); "H" without columns.
std::string CurvesCoordinate(const std::vector<StudyCurve>& curves);

// The regions of the families of `branches` (their ranges, continued coordinate and origin are read) between
// `curves` in (parameter, a), `value` the run's parameter value; empty without curves.
std::vector<StudyRegion> ParameterRegions(const std::vector<StudyBranch>& branches,
                                          const std::vector<StudyCurve>& curves, const std::string& parameter,
                                          double value);

}  // namespace hybridcont::study

#endif  // HYBRIDCONT_STUDY_STAGES_REGIONS_H_
