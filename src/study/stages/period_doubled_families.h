// `hybridcont run --period-doubling`: the period-doubled family of every located PD point of a run,
// explored with the doubled model RepeatedModel(model, 2) (period_doubling.h) like the run's own families:
// each accepted point classified, replayed and its Floquet multipliers written (orbit_analysis.h), its
// turning, SB, BP and PD points from the continuation (BP and PD as test functions,
// floquet_test_functions.h). Branch and special point ids continue the run's; each branch's summary entry says
// "period_doubled_from" (the PD point's id), "model" (the doubled model's name), "unknowns" (its
// layout's names, the columns of its CSV) and "stability_changes" (where the linear stability flips).
//   std::string report = ExplorePeriodDoubledFamilies(model, doubled, setup, diagram, &special_points, writer);
#ifndef HYBRIDCONT_STUDY_PERIOD_DOUBLED_FAMILIES_H_
#define HYBRIDCONT_STUDY_PERIOD_DOUBLED_FAMILIES_H_

#include <nlohmann/json.hpp>
#include <ostream>
#include <string>

#include "hybridcont/exploration.h"
#include "hybridcont/model.h"
#include "study/io/results_writer.h"
#include "study/engine/run_setup.h"

namespace hybridcont::study {

// `doubled` is RepeatedModel(model, 2); `diagram` and `special_points` are the run's (time-based layout);
// a family starts at each located PD point among the diagram's special points (duplicates skipped). Appends the families' special points to
// special_points, writes their branches through `writer` (its hooks see their points); returns the
// report section.
std::string ExplorePeriodDoubledFamilies(const HybridModel& model, const HybridModel& doubled, const RunSetup& setup,
                                         const BifurcationDiagram& diagram, std::vector<StudySpecialPoint>* special_points,
                                         ResultsWriter& writer);

}  // namespace hybridcont::study

#endif  // HYBRIDCONT_STUDY_PERIOD_DOUBLED_FAMILIES_H_
