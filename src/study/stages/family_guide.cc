#include "study/stages/family_guide.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <utility>
#include <limits>

#include "hybridcont/setup_evaluation.h"
#include "study/io/json_fields.h"
#include "hybridcont/study.h"

namespace hybridcont::study {

namespace {

[[noreturn]] void Refuse(const std::string& dir, const std::string& why) {
  throw StudyOptionError("families_of", -1, "'" + dir + "': " + why);
}

// The saved study, checked: of the model, complete (a branch whose switch points were never followed would look
// like one that led to no family), with the exploration's limits of this study, in the model's own layout.
StudyResult CheckedGuide(const std::string& dir, const HybridModel& model, const ShootingLayout& layout,
                         const nlohmann::json& options, nlohmann::json* summary) {
  StudyResult saved;
  try {
    saved = LoadStudy(dir);
  } catch (const std::invalid_argument& e) {
    Refuse(dir, std::string("not a saved study: ") + e.what());
  }
  if (saved.model != model.name()) {
    Refuse(dir, "the saved study is of model '" + saved.model + "', not '" + model.name() + "'");
  }
  *summary = nlohmann::json::parse(saved.summary_json, nullptr, false);
  const nlohmann::json& j = *summary;
  const std::string folder_status =
      j.is_object() && j.contains("status") && j["status"].is_string() ? j["status"].get<std::string>() : "";
  if (folder_status != "complete" || saved.status != ExplorationStatus::kCompleted) {
    // A branch whose switch points were never followed (the study stopped at max_branches, was cancelled, or
    // failed) would look like one that led to no family.
    Refuse(dir, "the saved study did not complete (" +
                    (folder_status != "complete" ? "its folder is " + (folder_status.empty() ? std::string("not marked") : folder_status)
                                                 : "its exploration: " + ToString(saved.status)) +
                    "): the branches it did not follow cannot guide");
  }
  // What limits the branches the exploration follows must be the same: a branch the guide ended at a nearer
  // bound or target (until), or a switch it did not make (max_depth), may lead to a family beyond.
  if (j.is_object() && j.contains("options") && j["options"].is_object()) {
    for (const char* key : {"bounds", "targets", "max_depth"}) {
      const nlohmann::json& theirs = j["options"].contains(key) ? j["options"][key] : nlohmann::json();
      if (options.contains(key) && theirs != options[key]) {
        Refuse(dir, std::string("the saved study was run with other ") +
                        (std::string(key) == "targets" ? "targets (until)" : key) + " (" + theirs.dump() + ", this study " +
                        options[key].dump() + "): a branch it ended sooner may lead to a family beyond");
      }
    }
  }
  if (saved.unknown_names != layout.unknown_names()) {
    Refuse(dir, "the saved study's unknowns are not the model's own layout (a study in a free parameter, or "
                "with other observables among its unknowns)");
  }
  return saved;
}

// The families asked for must be names the model's rules give, or names the saved study's branches have (an
// automaton's families of other words are named by their words).
void CheckFamilyNames(const std::string& dir, const HybridModel& model, const StudyResult& saved,
                      const std::vector<std::string>& families) {
  std::vector<std::string> known = OrbitPresentation(model).family_names();
  for (const StudyBranch& b : saved.branches) {
    if (!b.family.empty() && std::find(known.begin(), known.end(), b.family) == known.end()) known.push_back(b.family);
  }
  for (std::size_t i = 0; i < families.size(); ++i) {
    if (std::find(known.begin(), known.end(), families[i]) == known.end()) {
      std::string names;
      for (const std::string& k : known) names += (names.empty() ? "'" : ", '") + k + "'";
      throw StudyOptionError("families", static_cast<int>(i), "'" + families[i] + "': not a family of model '" +
                             model.name() + "' nor of '" + dir + "' (families: " + names + ")");
    }
  }
}

// Per branch of the saved study: whether it led to a wanted family. A branch leads to the branches switched to
// at its special points, the period-doubled families born at its PD points, the families of other words its
// orbits were handed over to; a branch and its image under a symmetry lead to the images of each other's
// families. A fixed point of these relations.
std::vector<bool> LedToFamilies(const StudyResult& saved, const std::function<bool(const std::string&)>& wanted) {
  const int n = static_cast<int>(saved.branches.size());
  std::vector<bool> fruitful(n, false);
  for (const StudyBranch& b : saved.branches) fruitful[b.id] = wanted(b.family);
  std::vector<std::vector<int>> children(n);
  const auto on_branch = [&](int special_point) {
    return special_point >= 0 && special_point < static_cast<int>(saved.special_points.size())
               ? saved.special_points[special_point].branch
               : -1;
  };
  for (const StudyBranch& b : saved.branches) {
    for (const int parent : {on_branch(b.parent_special_point), on_branch(b.period_doubled_from), b.image_of}) {
      if (parent >= 0 && parent < n && parent != b.id) children[parent].push_back(b.id);
    }
    if (b.image_of >= 0 && b.image_of < n) children[b.id].push_back(b.image_of);
  }
  for (const StudyWordChange& change : saved.word_changes) {
    if (change.from_branch < 0 || change.from_branch >= n) continue;
    for (const int to : change.to_branches) {
      if (to >= 0 && to < n) children[change.from_branch].push_back(to);
    }
  }
  for (bool changed = true; changed;) {
    changed = false;
    for (int b = 0; b < n; ++b) {
      if (fruitful[b]) continue;
      if (std::any_of(children[b].begin(), children[b].end(), [&](int c) { return fruitful[c]; })) {
        fruitful[b] = changed = true;
      }
    }
  }
  return fruitful;
}

// The rays the saved study pruned itself (it was guided too), as {u, v} of `layout`'s length: they led to
// none of the families it continued (all, or those it names), so to none of ours if ours are among them; none
// where they may have led to a family we continue.
std::vector<std::pair<Vector, Vector>> PrunedBefore(const std::string& dir, const nlohmann::json& summary,
                                                    const std::vector<std::string>& families,
                                                    const ShootingLayout& layout) {
  const nlohmann::json* guided = summary.is_object() && summary.contains("guided") && summary["guided"].is_object() &&
                                         summary["guided"].contains("pruned") && summary["guided"]["pruned"].is_array()
                                     ? &summary["guided"]
                                     : nullptr;
  if (guided == nullptr) return {};
  std::vector<std::string> theirs;
  try {
    theirs = JsonTexts(*guided, "families", "summary.json: guided");
  } catch (const std::invalid_argument& e) {
    Refuse(dir, e.what());
  }
  if (!theirs.empty()) {
    const bool covered = !families.empty() && std::all_of(families.begin(), families.end(), [&](const std::string& f) {
      return std::find(theirs.begin(), theirs.end(), f) != theirs.end();
    });
    if (!covered) return {};  // its pruned rays may have led to families we continue
  }
  std::vector<std::pair<Vector, Vector>> rays;
  for (std::size_t i = 0; i < (*guided)["pruned"].size(); ++i) {
    const nlohmann::json& p = (*guided)["pruned"][i];
    const std::string where = "summary.json: guided.pruned[" + std::to_string(i) + "]";
    Vector u, v;
    try {
      u = VectorFrom(JsonField(p, "u", where), where + ".u");
      v = VectorFrom(JsonField(p, "v", where), where + ".v");
    } catch (const std::invalid_argument& e) {
      Refuse(dir, e.what());
    }
    if (u.size() != static_cast<Eigen::Index>(layout.num_unknowns()) || v.size() != u.size() || !u.allFinite() ||
        !v.allFinite()) {
      Refuse(dir, "summary.json: guided.pruned: a ray of another length or not finite");
    }
    rays.emplace_back(std::move(u), std::move(v));
  }
  return rays;
}

}  // namespace

FamilyGuide FamilyGuide::Load(const std::string& dir, const HybridModel& model, const ShootingLayout& layout,
                              const std::vector<std::string>& families, const nlohmann::json& options) {
  nlohmann::json summary;
  const StudyResult saved = CheckedGuide(dir, model, layout, options, &summary);
  CheckFamilyNames(dir, model, saved, families);
  const auto wanted = [&](const std::string& family) {
    return !family.empty() && (families.empty() || std::find(families.begin(), families.end(), family) != families.end());
  };
  const std::vector<bool> fruitful = LedToFamilies(saved, wanted);
  FamilyGuide guide;
  guide.dir_ = dir;
  guide.families_ = families;
  // Each half-branch of the model's own families that leaves a switch point, and whether it led to a family.
  for (const StudyBranch& b : saved.branches) {
    if (!b.origin.empty() || b.unknown_names != saved.unknown_names || b.points.size() < 2) continue;
    if (b.parent_special_point < 0 || b.parent_special_point >= static_cast<int>(saved.special_points.size())) continue;
    const StudySpecialPoint& from = saved.special_points[b.parent_special_point];
    Ray ray;
    ray.u = from.u.size() == b.points[0].u.size() ? from.u : b.points[0].u;
    ray.v = b.points[1].u - b.points[0].u;
    if (!ray.u.allFinite() || !ray.v.allFinite() || !(ray.v.norm() > 0)) continue;
    ray.fruitful = fruitful[b.id];
    guide.rays_.push_back(std::move(ray));
  }
  for (auto& [u, v] : PrunedBefore(dir, summary, families, layout)) guide.rays_.push_back({std::move(u), std::move(v), false});
  return guide;
}

bool FamilyGuide::Prune(const Vector& u, const Vector& v, const Vector& scales) {
  // Every unknown is compared (Load checked that the saved study has this layout); in scaled units.
  Eigen::Index m = std::min(u.size(), std::min(v.size(), scales.size()));
  for (const Ray& r : rays_) m = std::min(m, r.u.size());
  if (m == 0 || rays_.empty()) return false;
  const auto scaled = [&](const Vector& w) -> Vector { return w.head(m).cwiseQuotient(scales.head(m)); };
  const Vector us = scaled(u);
  std::vector<Vector> points(rays_.size());
  std::vector<double> d(rays_.size());
  std::size_t nearest = 0;
  for (std::size_t i = 0; i < rays_.size(); ++i) {
    points[i] = scaled(rays_[i].u);
    d[i] = (us - points[i]).lpNorm<Eigen::Infinity>() / (1 + us.lpNorm<Eigen::Infinity>());
    if (d[i] < d[nearest]) nearest = i;
  }
  if (!(d[nearest] <= kMaxPointDistance)) return false;
  // The nearest saved switch point (with the rays of points located there twice), clearly nearer than any other.
  const Vector& at_scaled = points[nearest];
  const double same = 1e-6 * (1 + at_scaled.lpNorm<Eigen::Infinity>());
  std::vector<std::size_t> here;
  for (std::size_t i = 0; i < rays_.size(); ++i) {
    const double apart = (points[i] - at_scaled).lpNorm<Eigen::Infinity>();
    if (apart <= same) {
      here.push_back(i);
    } else if (d[i] < 2 * d[nearest]) {
      return false;  // two saved switch points about as near: no clear counterpart
    }
  }
  const Vector vs = scaled(v).normalized();
  double best = -1;
  for (const std::size_t i : here) {
    const double c = vs.dot(scaled(rays_[i].v).normalized());
    if (c >= kCloseDirectionCosine && rays_[i].fruitful) return false;
    best = std::max(best, c);
  }
  if (!(best >= kSameDirectionCosine)) return false;
  // Recorded once (a speculative switch of a threaded exploration may ask again for the same ray).
  const bool known = std::any_of(pruned_.begin(), pruned_.end(), [&](const Ray& r) {
    return r.u.size() == u.size() && (r.u - u).lpNorm<Eigen::Infinity>() <= 1e-12 * (1 + u.lpNorm<Eigen::Infinity>()) &&
           (r.v.normalized() - v.normalized()).lpNorm<Eigen::Infinity>() <= 1e-9;
  });
  if (!known) pruned_.push_back({u, v, false});
  return true;
}

int FamilyGuide::num_fruitful() const {
  return static_cast<int>(std::count_if(rays_.begin(), rays_.end(), [](const Ray& r) { return r.fruitful; }));
}

nlohmann::json FamilyGuide::Json(const std::vector<Vector>& switch_points) const {
  nlohmann::json pruned = nlohmann::json::array();
  for (const Ray& r : pruned_) {
    // Only rays at the study's own switch points: a threaded exploration also asks at points it later finds
    // to be duplicates, whose groups it drops.
    const bool switched = std::any_of(switch_points.begin(), switch_points.end(), [&](const Vector& p) {
      return p.size() == r.u.size() && (p - r.u).lpNorm<Eigen::Infinity>() <= 1e-9 * (1 + r.u.lpNorm<Eigen::Infinity>());
    });
    if (switched) pruned.push_back({{"u", VectorJson(r.u)}, {"v", VectorJson(r.v)}});
  }
  nlohmann::json families = nlohmann::json::array();
  for (const std::string& f : families_) families.push_back(f);
  return {{"from", dir_},
          {"families", families},
          {"rays", rays_.size()},
          {"rays_to_families", num_fruitful()},
          {"pruned_half_branches", pruned.size()},
          {"pruned", pruned}};
}

}  // namespace hybridcont::study
