// A study guided by the families of a saved study of the same model at nearby parameter values
// (StudyOptions::families_of): the exploration traces only the half-branches whose counterpart in the saved
// study led to a family — a branch named by the model's family rules, or one from which such a branch was
// reached by switching, period doubling or a change of word. The others, which found no physical orbit there,
// are pruned. This is what lets a sweep continue its neighbouring grid point's families instead of repeating
// the whole exploration: the SLIP's 23 half-branches become the 5 of its three families.
//
//   FamilyGuide guide = FamilyGuide::Load("results/sweep/points/3_4", model, layout);
//   exploration.set_ray_filter([&](const Vector& u, const Vector& v) { return guide.Prune(u, v, scales); });
//
// Counterparts. A half-branch leaves a switch point (the singular start, or an SB/BP point) u along a direction
// v. Its counterpart in the saved study leaves the saved switch point nearest u (in scaled unknowns, relative to
// 1 + |u|) along the direction nearest v. A ray is pruned only when the match is clear:
//   - the nearest saved switch point is closer than kMaxPointDistance, and every other saved switch point is at
//     least twice as far (points that are one point located twice, SB and BP, count as one);
//   - some saved half-branch from it has cos(v, v_saved) ≥ kSameDirectionCosine, and every saved half-branch
//     from it with cos ≥ kCloseDirectionCosine led to no family.
// Anything else is traced: a new switch point, an ambiguous one, a direction the saved study did not take.
// The saved study's own pruned rays (a guided study guiding the next one) are saved half-branches that led to
// no family (to none of its `families`, if it continued only those: then they guide only a study continuing
// some of them). The saved study must be complete (a study stopped at max_branches never followed some of its
// branches) and have this study's bounds, targets (until) and max_depth: a branch it ended sooner may lead to
// a family beyond.
//
// What this cannot see: a family born on a branch that had no physical orbit in the saved study and has some
// here. A sweep explores a grid point whole where a family of its neighbour is not found (sweeps.py), and
// `strategy="explore"` everywhere.
#ifndef HYBRIDCONT_STUDY_FAMILY_GUIDE_H_
#define HYBRIDCONT_STUDY_FAMILY_GUIDE_H_

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "hybridcont/model.h"
#include "hybridcont/shooting_layout.h"
#include "hybridcont/types.h"

namespace hybridcont::study {

class FamilyGuide {
 public:
  static constexpr double kMaxPointDistance = 0.25;
  static constexpr double kSameDirectionCosine = 0.9;
  static constexpr double kCloseDirectionCosine = 0.7;

  // The saved study in `dir`: it must be of `model` (any parameter values) with the model's own unknowns
  // (`layout`). Throws StudyOptionError("families_of", ...) otherwise, naming the folder. `families`: the
  // families to continue (names; empty: all), each the model's or the saved study's (StudyOptionError
  // "families[i]" otherwise); a half-branch that led only to others is pruned like one that led to none.
  // `options`: this study's effective options (summary.json's "options"); the guide's bounds, targets and
  // max_depth must be these.
  static FamilyGuide Load(const std::string& dir, const HybridModel& model, const ShootingLayout& layout,
                          const std::vector<std::string>& families = {},
                          const nlohmann::json& options = nlohmann::json::object());

  // True if the half-branch from u along v (model units, the time-based layout, observables among the unknowns
  // included) is to be pruned; `scales` are the exploration's unknown scales. Records the pruned ray (Json).
  // Called on the exploring thread.
  bool Prune(const Vector& u, const Vector& v, const Vector& scales);

  const std::string& dir() const { return dir_; }
  int num_rays() const { return static_cast<int>(rays_.size()); }
  int num_fruitful() const;
  // summary.json's "guided": the folder, the families continued (empty: all), the counts, and every ray pruned
  // at one of `switch_points` (the study's special points, model units) as {u, v}, so that this study can guide
  // the next one. Independent of the order and number of Prune calls (a threaded exploration's speculation).
  nlohmann::json Json(const std::vector<Vector>& switch_points) const;

 private:
  struct Ray {
    Vector u, v;        // the switch point and the direction (model units)
    bool fruitful = false;
  };
  std::string dir_;
  std::vector<Ray> rays_;
  std::vector<Ray> pruned_;
  std::vector<std::string> families_;
};

}  // namespace hybridcont::study

#endif  // HYBRIDCONT_STUDY_FAMILY_GUIDE_H_
