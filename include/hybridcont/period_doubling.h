// Period-doubled families: the orbits born where a family's Floquet multiplier passes through −1.
//
// The k-fold repeated model traverses the phase sequence k times. It cuts each cycle at the Poincaré
// section, so that a cycle is the parent's shooting segments again: with m phases,
//
//   phases    1, 2, …, m, 1→a,  1, 2, …, m, 1→a,  …,  1, 2, …, m          (k·m + k − 1 phases)
//   segments  k·(m+1), the parent's m+1 segments k times (the last is phase 1 up to the anchor, as always)
//
// where 1→a is phase 1 ended at the section: its event is the anchor a, its reset the identity (so its
// saltation matrix is the identity). A parent orbit u = [c | ξ | H̄] (c: the segment blocks t_i, x̄_i)
// is the k-fold orbit
//
//   u_k = [c | c | … | c | ξ | H̄]                      (RepeatedOrbit; H̄ and ξ unchanged)
//
// with period k·T, monodromy Φ_T^k and multipliers μ^k. Unknown names follow the k-fold layout
// (t1 … t<k(m+1)>): the parent's t_i is t_i, t_{i+m+1}, … in the copies.
//
// At a period-doubling (PD) point of the parent (a multiplier μ = −1) the doubled map has μ² = +1 a
// further time: u_2 is a simple bifurcation point of r_2 whose kernel is spanned by the repeated
// tangent [τ_c | τ_c | τ_ξ | τ_H] of the parent family and by the antiperiodic direction [δ | −δ | 0 | 0]
// of the −1 eigenvector. The period-doubled family leaves along the second (a pitchfork: its two
// half-branches are the same orbits shifted by one parent period); the parent family traversed twice
// is the first, and is not a new family. ExplorePeriodDoubled therefore starts the exploration of r_2
// at u_2 as a singular start (branch_switching.h) restricted by the linear condition τ_H = 0, which
// the antiperiodic direction satisfies and the parent's does not (generic: the PD point is no turning
// point in H̄), and declares every repeated ray (a k-fold point left along a k-fold direction) known
// (ExplorationOptions::known_ray): at the family's other meetings with the parent family, switching
// does not trace the parent again.
//
// The repeated model is a view: its phases and anchor forward to the parent's objects (the parent must
// outlive it); its parameters are the parent's, read through (SetParameter on it throws: set them on
// the parent). Symmetries carry over (1→a takes phase 1's signs), and so does the set-up, with bounds
// and scales on an unknown applied to each of its copies and a bound on the period scaled by k.
//
//   HybridModel slip = MakeSlip();
//   HybridModel doubled = RepeatedModel(slip, 2);
//   TimeBasedShooting parent_map(slip, {}), doubled_map(doubled, {});
//   BifurcationDiagram d = ExplorePeriodDoubled(&doubled_map, parent_map.layout(), u_pd, options);
//   // d.branches: the period-doubled family from H̄ = 1.2828 (the PD point of hopping in place)
#ifndef HYBRIDCONT_PERIOD_DOUBLING_H_
#define HYBRIDCONT_PERIOD_DOUBLING_H_

#include <string>
#include <vector>

#include "hybridcont/exploration.h"
#include "hybridcont/model.h"
#include "hybridcont/shooting_layout.h"
#include "hybridcont/zero_problem.h"

namespace hybridcont {

// The k-fold repeated model (k >= 1), named "<name>-x<k>". Throws std::invalid_argument for k < 1.
HybridModel RepeatedModel(const HybridModel& model, int k);

// u_k from a parent point u of `layout` (the parent's). Throws std::invalid_argument for a wrong size or
// k < 1.
Vector RepeatedOrbit(const ShootingLayout& layout, const Vector& u, int k);

// The names of the k copies of the parent unknown `name` of `layout` in the k-fold layout ("t2" -> "t2",
// "t5" for m = 2, k = 2); ξ, H̄ and names that are no unknown of `layout` map to themselves alone.
std::vector<std::string> RepeatedNames(const ShootingLayout& layout, const std::string& name, int k);

// Whether u_k (of the k-fold layout of `layout`) repeats its first cycle: every cycle within
// tolerance · (1 + ||u_k||∞) of the first, componentwise.
bool IsRepeatedOrbit(const ShootingLayout& layout, const Vector& u_k, int k, double tolerance);

// Explores the period-doubled family born at the PD point u_pd of the parent (in the parent layout's
// unknowns; `doubled` is a map of RepeatedModel(parent, 2) in the same units, e.g. a ScaledProblem whose
// scales are the parent's repeated). `options` are used as given, except start_conditions (replaced by
// τ_H = 0) and known_ray (set as above). The diagram's status is kStartFailed, with the reason, when u_2 is
// not a singular point of the doubled map with one direction transverse to the parent family (an
// imprecise PD point, or a PD point at a turning point in H̄).
BifurcationDiagram ExplorePeriodDoubled(ZeroProblem* doubled, const ShootingLayout& layout, const Vector& u_pd,
                                        ExplorationOptions options);

}  // namespace hybridcont

#endif  // HYBRIDCONT_PERIOD_DOUBLING_H_
