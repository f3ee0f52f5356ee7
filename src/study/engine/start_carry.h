// A start carried to the parameters a user set. A model file's start (a guess Newton corrects, a simulated
// cycle, a declared orbit) is written for the file's own parameter values; at other values — a stiffer leg,
// another touch-down angle, a steeper slope — Newton from the same guess often fails, or converges to another
// orbit (a long-step walker's guess falls onto the short-step gait). The start is therefore carried, as AUTO
// and BifurcationKit start at new parameters: the start orbit corrected at the model's own values is
// continued in one changed parameter after another, from its own value to the value set, by pseudo-arclength
// continuation with the set value as a target, holding the coordinate its family is followed in:
//   - families in H̄ (a first integral): H̄ fixed, FreeParameters{{p}, {{"H", level}}};
//   - families in a parameter q (no first integral, or --free q --fix ...): q fixed, p joining the free
//     parameters; where p is q itself the carry is the family's own continuation to the set value.
//
//   CarriedStart c = CarryStart(model_at_set_values, own_values, start_at_own_values, integrator, route);
//   if (c.ok) exploration.SetStart(c.u, c.report);   // "start carried from k = 25.5 to 30 at H = 1.04 (22 steps)"
//
// Along the family. Where the carry at a fixed level turns back (a fold: at that level the family has no
// orbit beyond it), the orbits of other levels are tried: the family at the farthest value reached is traced
// in its coordinate within the study's bound (route.level_bound), and the carry is resumed from a few of its
// orbits spread over it, each at its own level; the first that arrives is the start, at the level where it
// arrived. A running gait whose family at H̄ = 2 folds at k = 27.7 reaches k = 30 at a higher energy. Where
// no level gets through, the carry stops and says where (the farthest value and the fold located there).
#ifndef HYBRIDCONT_STUDY_ENGINE_START_CARRY_H_
#define HYBRIDCONT_STUDY_ENGINE_START_CARRY_H_

#include <string>
#include <vector>

#include "hybridcont/continuation.h"
#include "hybridcont/flow.h"
#include "hybridcont/model.h"
#include "hybridcont/shooting_layout.h"
#include "hybridcont/study_options.h"

namespace hybridcont::study {

// The study's layout of the start and the bound of its family's coordinate (the along-family route stays
// inside it; an empty component: no bound).
struct CarryRoute {
  FreeParameters free;  // the study's free parameters, fixed unknowns and observables (empty: families in H̄)
  ComponentBound level_bound;
};

struct CarriedStart {
  bool ok = false;
  Vector u;            // the start orbit at the set values (the layout of `route.free`, model units)
  std::string report;  // what was done, one line
  std::string why;     // where and why it stopped (not ok)
  int steps = 0;       // accepted continuation points over every parameter and level tried
};

// `model` at the values the user set; `own` the model's own values of the parameters the user changed (in the
// order they are carried); `start` the start orbit at `own` (ShootingLayout(model, route.free)). Every other
// parameter is at its set value throughout.
CarriedStart CarryStart(const HybridModel& model, const std::vector<NamedValue>& own, const Vector& start,
                        const IntegratorOptions& integrator, const CarryRoute& route = {});

// A start given as a guess of an orbit of a conservative model (StartPoint: a word's declared start, time-based
// layout without free parameters) corrected by Newton at its level H̄ with the model at its `own` values, then
// carried as CarryStart does. Not ok where the guess does not converge even there, or where the orbit it
// converges to is not physical there (nothing to carry).
CarriedStart CarryGuess(const HybridModel& model, const std::vector<NamedValue>& own, const Vector& guess,
                        const IntegratorOptions& integrator, const CarryRoute& route = {});

}  // namespace hybridcont::study

#endif  // HYBRIDCONT_STUDY_ENGINE_START_CARRY_H_
