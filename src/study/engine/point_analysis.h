// The analysis of one accepted point of a run (the library's AnalyzeOrbit, orbit_analysis.h) as the
// results files write it: the point's record with its extra CSV columns.
//   PointRecord record;  record.u = u;  ...
//   AnalyzePoint(model, integrator, &floquet_map, replay_options, &record);
#ifndef HYBRIDCONT_STUDY_POINT_ANALYSIS_H_
#define HYBRIDCONT_STUDY_POINT_ANALYSIS_H_

#include "hybridcont/orbit_analysis.h"
#include "hybridcont/replay.h"
#include "hybridcont/timebased_shooting.h"
#include "study/io/results_writer.h"

namespace hybridcont::study {

// Extra CSV columns (order fixed: every row of a branch has the same header): replay_error, stable,
// normal, num_unit, max_multiplier, bp_test, pd_test, then mu<j>_re, mu<j>_im per nontrivial multiplier.
constexpr int kBpColumn = 5;
constexpr int kPdColumn = 6;

// Replay tolerances equal to the integrator's.
ReplayOptions ReplayOptionsFor(const IntegratorOptions& integrator);

// With free parameters in floquet_map's layout, record->u ends with their values: the orbit is the head of
// u in the model's own layout, classified and replayed on `model`, which must carry those values
// (SetFreeParameters); without, `model` is the map's model.
// AnalyzeOrbit at record->u (with record->at_branch_point), into the record: classification, stability,
// residual, observables and the extra columns.
// `known`: what the exploration's Floquet test functions learnt of the point (ModelExploration::
// KnownBranchPointAnalysis), used instead of integrating it again; null for none.
void AnalyzePoint(const HybridModel& model, const IntegratorOptions& integrator, TimeBasedShooting& floquet_map,
                  const ReplayOptions& replay_options, PointRecord* record,
                  const FloquetTestFunctions::BranchPointAnalysis* known = nullptr);

// Whether the time-based point u (the model's own layout) is a physical orbit of the model (classified by
// its unknowns, or else along its trace).
bool IsPhysical(const HybridModel& model, const Vector& u, const IntegratorOptions& integrator);
// Its classification.
Classification ClassifyPoint(const HybridModel& model, const Vector& u, const IntegratorOptions& integrator);

// Sets the free parameters of `layout` on *model to their values in u.
void SetFreeParameters(const ShootingLayout& layout, const Vector& u, HybridModel* model);
// The orbit of a point u of `layout`: u without its free parameters (the model's own layout).
inline Vector OrbitPart(const ShootingLayout& layout, const Vector& u) {
  return u.head(layout.num_orbit_unknowns());
}

// The extra CSV columns of an analysis (the order above; NaN where undefined).
std::vector<std::pair<std::string, double>> ExtraColumns(const HybridModel& model, const OrbitAnalysis& a);

}  // namespace hybridcont::study

#endif  // HYBRIDCONT_STUDY_POINT_ANALYSIS_H_
