// Where a restarted study begins (StudyOptions::restart, study.h): a labelled point of a saved study, checked
// against the model of the new study, as the engine needs it.
//
//   label   "PD4", "SB36", "TP22", "BP3"   a special point: its code and id in the saved study
//           "B5"                           branch 5's last point, continued beyond it
//           "B5:12"                        point 12 of branch 5 (continued in the branch's direction, or the
//                                          start of a family in a free parameter)
// The saved study must be of the same model with the same parameter values (the point is an orbit of that
// model only); its point must lie in the model's own layout (not a period-doubled family's or another word's).
#ifndef HYBRIDCONT_STUDY_RESTART_H_
#define HYBRIDCONT_STUDY_RESTART_H_

#include <string>

#include <nlohmann/json.hpp>

#include "hybridcont/model.h"
#include "hybridcont/special_point.h"
#include "hybridcont/study.h"

namespace hybridcont::study {

struct RestartPlan {
  RestartSpec::Kind kind = RestartSpec::Kind::kAuto;  // resolved: never kAuto
  Vector u;              // the point, in the saved study's (time-based, the model's own) layout
  Vector tangent;        // kContinue: the direction to continue in
  SpecialPoint point;    // kPeriodDoubled, kSwitch, kCurve: the special point as the engine types it
  nlohmann::json where;  // summary.json's "restarted_from": folder, label, kind, branch, point, H
  std::string description;  // "PD4 of results/slip (H = 1.246740110061)"
};

// Reads the saved study and resolves spec (kAuto as study.h says). Throws StudyOptionError("restart", ...) for
// a label the saved study lacks, a kind the label cannot give, or a saved study of another model or of other
// parameter values.
RestartPlan PlanRestart(const RestartSpec& spec, const StudyOptions& options, const HybridModel& model);

// The saved study's point H of a label (to fix H at in a restart with a free parameter); NaN if it has none.
double RestartLevel(const RestartSpec& spec);

}  // namespace hybridcont::study

#endif  // HYBRIDCONT_STUDY_RESTART_H_
