// The special points of an exploration as the study records them (StudySpecialPoint, study.h): in the
// time-based layout of their branch, with H̄ and T, how precisely each was located (in u, along the branch, in
// H̄), the free parameters and observables among the unknowns by name, and the model's observables and
// constraints evaluated at each (the analysis the serializer never does).
//
//   std::vector<StudySpecialPoint> points = RecordSpecialPoints(diagram, layout, &model, integrator);
#ifndef HYBRIDCONT_STUDY_STAGES_SPECIAL_POINTS_H_
#define HYBRIDCONT_STUDY_STAGES_SPECIAL_POINTS_H_

#include <string>
#include <vector>

#include "hybridcont/continuation.h"
#include "hybridcont/exploration.h"
#include "hybridcont/model.h"
#include "hybridcont/shooting_layout.h"
#include "hybridcont/study.h"

namespace hybridcont::study {

// Marks the turning points of d whose component is one of `extrema` (observables among the unknowns) as EX points
// (SpecialPointType::kExtremum), in d's list and in its branches', with a message saying whether the observable
// is largest or smallest there along the family (ExtremumSign).
void MarkExtrema(const std::vector<std::string>& extrema, BifurcationDiagram* d);

// +1 where an EX point's component rises before it and falls after it along its branch (a maximum along the
// family: the sign of the tangent's component at the branch points on either side), -1 for a minimum, 0 where
// the tangents do not tell (not an EX point, or no tangents).
int ExtremumSign(const SpecialPoint& sp);

// d's special points (u in `layout`, ids as in d). With a model that has observables, each point's are
// evaluated at its parameter values (NaN where one is undefined or a parameter leaves its range).
std::vector<StudySpecialPoint> RecordSpecialPoints(const BifurcationDiagram& d, const ShootingLayout& layout,
                                                   const HybridModel* model = nullptr,
                                                   const IntegratorOptions& integrator = {});

}  // namespace hybridcont::study

#endif  // HYBRIDCONT_STUDY_STAGES_SPECIAL_POINTS_H_
