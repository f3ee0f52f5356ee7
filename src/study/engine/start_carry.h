// A start carried to the parameters a user set. A model file's start (a guess Newton corrects, or a simulated
// cycle) is written for the file's own parameter values; at other values — a stiffer leg, another touch-down
// angle, a steeper slope — Newton from the same guess often fails. The start is then carried, as AUTO and
// BifurcationKit start at new parameters: the corrected start orbit at the model's own values is continued in
// one changed parameter after another, at the start's level H̄ fixed (the time-based map with that parameter
// free, FreeParameters{{p}, {{"H", level}}}), from its own value to the value set, by pseudo-arclength
// continuation with the set value as a target.
//
//   CarriedStart c = CarryStart(model_at_set_values, own_values, start_at_own_values, integrator);
//   if (c.ok) exploration.SetStart(c.u, c.report);   // "start carried from k = 20 to 30 at H = 1.04 (12 steps)"
//
// The orbit followed is the start's family in the parameter at fixed H̄; where it turns back (a fold in the
// parameter) before the set value, no orbit of it exists there on that side: the carry stops and says where
// (the parameter's farthest value and the turning point located there), the work kept in the message.
#ifndef HYBRIDCONT_STUDY_ENGINE_START_CARRY_H_
#define HYBRIDCONT_STUDY_ENGINE_START_CARRY_H_

#include <string>
#include <vector>

#include "hybridcont/flow.h"
#include "hybridcont/model.h"
#include "hybridcont/study_options.h"

namespace hybridcont::study {

struct CarriedStart {
  bool ok = false;
  Vector u;            // the start orbit at the set values (time-based layout of the model, model units)
  std::string report;  // what was done, one line
  std::string why;     // where and why it stopped (not ok)
  int steps = 0;       // accepted continuation points over every parameter
};

// `model` at the values the user set; `own` the model's own values of the parameters the user changed (in the
// order they are carried); `start` the start orbit corrected at `own` (time-based layout). Every other
// parameter is at its set value throughout.
CarriedStart CarryStart(const HybridModel& model, const std::vector<NamedValue>& own, const Vector& start,
                        const IntegratorOptions& integrator);

// A start given as a guess (StartPoint: a word's declared start) corrected by Newton at its level H with the
// model at its `own` values, then carried as CarryStart does. Not ok where the guess does not converge even
// there, or where the orbit it converges to is not physical there (nothing to carry).
CarriedStart CarryGuess(const HybridModel& model, const std::vector<NamedValue>& own, const Vector& guess,
                        const IntegratorOptions& integrator);

}  // namespace hybridcont::study

#endif  // HYBRIDCONT_STUDY_ENGINE_START_CARRY_H_
