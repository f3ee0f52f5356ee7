// What a run knows about one point of a family, typed: its classification (physical, or why not), the
// residual of the time-based map there, and for a physical orbit the event-driven replay (and, for a word of
// an automaton, the automaton's own simulation), the Floquet multipliers with their stability class and
// test functions, and the model's observables. A non-physical orbit has no replay, no multipliers and no
// observables (their values would mean nothing for the mechanical system): NaN and empty there.
//
//   TimeBasedShooting floquet_map(model, integrator);
//   const OrbitAnalysis a = AnalyzeOrbit(model, floquet_map, u, OrbitAnalysisOptions::For(integrator));
//   if (a.classification.physical && a.floquet) ... a.stability, a.multipliers
#ifndef HYBRIDCONT_ORBIT_ANALYSIS_H_
#define HYBRIDCONT_ORBIT_ANALYSIS_H_

#include <complex>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "hybridcont/classification.h"
#include "hybridcont/floquet_test_functions.h"
#include "hybridcont/replay.h"
#include "hybridcont/timebased_shooting.h"

namespace hybridcont {

struct OrbitAnalysisOptions {
  IntegratorOptions integrator;  // of the classification's trace and the observables
  ReplayOptions replay;          // of the event-driven replay
  // The point is a located branch point or a branch's start at one: its multipliers near 1 are classified
  // as at a branch point (FloquetOptions::at_branch_point).
  bool at_branch_point = false;
  // What the Floquet test functions learnt of this point at the same integrator tolerances (its class, replay,
  // multipliers and residual; floquet_test_functions.h): taken instead of integrating the orbit again. Null:
  // everything is computed here. Its multipliers are used only where at_branch_point is false (they were
  // classified without that option).
  const FloquetTestFunctions::BranchPointAnalysis* known = nullptr;
  // Replay tolerances equal to the integrator's.
  static OrbitAnalysisOptions For(const IntegratorOptions& integrator);
};

struct OrbitAnalysis {
  static constexpr double kUndefined = std::numeric_limits<double>::quiet_NaN();
  // Physical, or the first reason it is not; a physical orbit whose replay does not return is
  // "replay-failed".
  Classification classification;
  double residual = kUndefined;  // |r(u)| of the map (NaN where it cannot be evaluated)
  // Physical orbits:
  double replay_error = kUndefined;            // distance at which the event-driven replay returns
  double automaton_replay_error = kUndefined;  // a word of an automaton: the automaton's simulation's
  bool floquet = false;                        // the multipliers below were computed
  std::string stability;                       // StabilityClass::ToString ("asymptotically stable", ...)
  bool stable = false;                         // asymptotically or neutrally stable
  // The multipliers cannot tell stable from unstable (StabilityClass::undetermined): stable is false then,
  // and not a verdict.
  bool stability_undetermined = false;
  double multiplier_error = kUndefined;        // FloquetResult::multiplier_error
  // Whether the integration resolves the orbit (floquet.h, kUnresolvedMultiplierError). Where a family's
  // orbits pass ever nearer an equilibrium (its period grows without bound) its ranges end at the last
  // resolved orbit (family_ranges.h).
  bool resolved() const { return !(floquet && multiplier_error > kUnresolvedMultiplierError); }
  bool normal = false;                         // FloquetResult::normal
  int num_unit = 0;                            // multipliers on the unit circle
  double max_multiplier = kUndefined;          // largest modulus of the nontrivial multipliers
  double bp_test = kUndefined, pd_test = kUndefined;
  std::vector<std::complex<double>> multipliers;  // the nontrivial ones (floquet.h)
  // The model's observables at the point, by name (observable.h): an observable that is an unknown of the
  // layout is read from u, the others evaluated at a physical orbit (NaN elsewhere or where it fails).
  std::vector<std::pair<std::string, double>> observables;
};

// u is a point of floquet_map's layout (free parameters included; `model` carries their values, as the
// map's model does); the orbit is its head in the model's own layout. Evaluates floquet_map (its cache is
// left at u).
OrbitAnalysis AnalyzeOrbit(const HybridModel& model, TimeBasedShooting& floquet_map, const Vector& u,
                           const OrbitAnalysisOptions& options);

}  // namespace hybridcont

#endif  // HYBRIDCONT_ORBIT_ANALYSIS_H_
