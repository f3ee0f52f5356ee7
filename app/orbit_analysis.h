// The analysis of one accepted point of a run, in the time-based layout: its classification (physical or
// why not), and for a physical orbit the event-driven replay and the Floquet multipliers with their test
// functions, written into the point's extra CSV columns.
//   PointRecord record;  record.u = u;  ...
//   AnalyzePoint(model, integrator, &floquet_map, replay_options, &record);
#ifndef HYBRIDCONT_APP_ORBIT_ANALYSIS_H_
#define HYBRIDCONT_APP_ORBIT_ANALYSIS_H_

#include "hybridcont/replay.h"
#include "hybridcont/timebased_shooting.h"
#include "results_writer.h"

namespace hybridcont::app {

// Extra CSV columns (order fixed: every row of a branch has the same header): replay_error, stable,
// normal, num_unit, max_multiplier, bp_test, pd_test, then mu<j>_re, mu<j>_im per nontrivial multiplier.
constexpr int kBpColumn = 5;
constexpr int kPdColumn = 6;

// Replay tolerances equal to the integrator's.
ReplayOptions ReplayOptionsFor(const IntegratorOptions& integrator);

// With free parameters in floquet_map's layout, record->u ends with their values: the orbit is the head of
// u in the model's own layout, classified and replayed on `model`, which must carry those values
// (SetFreeParameters); without, `model` is the map's model.
// Classifies record->u (by its unknowns, or else along its trace), fills the extra columns
// (AnalyzePhysicalOrbit) and the residual of floquet_map at u (NaN where it cannot be evaluated).
void AnalyzePoint(const HybridModel& model, const IntegratorOptions& integrator, TimeBasedShooting& floquet_map,
                  const ReplayOptions& replay_options, PointRecord* record);

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

// Floquet multipliers, stability and the event-driven replay of a physical orbit. A physical point whose
// replay does not return is reclassified "replay-failed". Columns of non-physical points stay empty
// (NaN): their monodromy has no meaning for the mechanical system.
void AnalyzePhysicalOrbit(const HybridModel& model, TimeBasedShooting& floquet_map, const ReplayOptions& replay_options,
                          const Vector& u, PointRecord* record);

}  // namespace hybridcont::app

#endif  // HYBRIDCONT_APP_ORBIT_ANALYSIS_H_
