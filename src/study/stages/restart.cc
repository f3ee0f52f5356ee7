#include "study/stages/restart.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <regex>

#include "hybridcont/shooting_layout.h"

namespace hybridcont::study {

namespace {

[[noreturn]] void Refuse(const RestartSpec& spec, const std::string& why) {
  throw StudyOptionError("restart", -1, "'" + spec.Source() + "' '" + spec.label + "': " + why);
}

std::shared_ptr<const StudyResult> Saved(const RestartSpec& spec) {
  if (spec.study) return spec.study;
  try {
    return std::make_shared<const StudyResult>(LoadStudy(spec.from));
  } catch (const std::invalid_argument& e) {
    Refuse(spec, std::string("not a saved study: ") + e.what());
  }
}

// "B5" or "B5:12": the branch and point (-1: its last point); false for another label.
bool BranchLabel(const std::string& label, int* branch, int* point) {
  static const std::regex kBranch(R"(B(\d{1,6})(?::(\d{1,7}))?)");
  std::smatch m;
  if (!std::regex_match(label, m, kBranch)) return false;
  *branch = std::stoi(m[1].str());
  *point = m[2].matched ? std::stoi(m[2].str()) : -1;
  return true;
}

}  // namespace

double RestartLevel(const RestartSpec& spec) {
  const std::shared_ptr<const StudyResult> held = Saved(spec);
  const StudyResult& saved = *held;
  const auto H = std::find(saved.unknown_names.begin(), saved.unknown_names.end(), "H");
  if (H == saved.unknown_names.end()) return std::nan("");
  const Eigen::Index h = H - saved.unknown_names.begin();
  int branch = -1, point = -1;
  if (BranchLabel(spec.label, &branch, &point)) {
    if (branch >= static_cast<int>(saved.branches.size()) || saved.branches[branch].points.empty()) return std::nan("");
    const auto& points = saved.branches[branch].points;
    const StudyPoint& p = point < 0 || point >= static_cast<int>(points.size()) ? points.back() : points[point];
    return p.u.size() > h ? p.u(h) : std::nan("");
  }
  const StudySpecialPoint* sp = saved.FindSpecialPoint(spec.label);
  return sp != nullptr && sp->u.size() > h ? sp->u(h) : std::nan("");
}

namespace {

using Kind = RestartSpec::Kind;

// The saved study must be of this model at these parameter values, in the model's own layout.
void CheckSameModel(const RestartSpec& spec, const StudyResult& saved, const HybridModel& model,
                    const ShootingLayout& layout) {
  if (saved.model != model.name()) {
    Refuse(spec, "the saved study is of model '" + saved.model + "', not '" + model.name() + "'");
  }
  for (const NamedValue& p : saved.parameters) {
    if (model.FindParameter(p.name) < 0) Refuse(spec, "the saved study's parameter '" + p.name + "' is not the model's");
    const double here = model.parameter(p.name);
    if (!(std::abs(here - p.value) <= 1e-12 * std::max(1.0, std::abs(p.value)))) {
      Refuse(spec, fmt::format("the saved study has {} = {:g}, this study {:g}: its points are orbits at its own values "
                               "(set them with parameters)", p.name, p.value, here));
    }
  }
  if (saved.unknown_names != layout.unknown_names()) {
    Refuse(spec, "the saved study's unknowns are not the model's own layout (a study with a free parameter or "
                 "observables among the unknowns cannot be restarted from)");
  }
}

// "B5" / "B5:12": the branch's point (its last one), continued along the branch (or the start of a family in a
// free parameter).
void PlanAtBranchPoint(const RestartSpec& spec, const StudyOptions& options, const HybridModel& model,
                       const ShootingLayout& layout, const StudyResult& saved, int branch, int index, RestartPlan* plan) {
  if (branch >= static_cast<int>(saved.branches.size())) {
    Refuse(spec, fmt::format("the saved study has branches 0 to {}", static_cast<int>(saved.branches.size()) - 1));
  }
  const StudyBranch& b = saved.branches[branch];
  if (b.unknown_names != layout.unknown_names() || (!b.word.empty() && b.word != model.WordModeNames())) {
    Refuse(spec, "branch " + std::to_string(branch) + " is a family of another layout (" +
                     (b.origin.empty() ? b.model : b.origin) + "): restart from the model's own families");
  }
  if (b.points.size() < 2) Refuse(spec, "branch " + std::to_string(branch) + " has fewer than two points");
  const int n = static_cast<int>(b.points.size());
  if (index >= n) Refuse(spec, fmt::format("branch {} has points 0 to {}", branch, n - 1));
  const int at = index < 0 ? n - 1 : index;
  plan->kind = spec.kind == Kind::kAuto ? (options.free.empty() ? Kind::kContinue : Kind::kFree) : spec.kind;
  if (plan->kind != Kind::kContinue && plan->kind != Kind::kFree) {
    Refuse(spec, "a branch point restarts as 'continue' or 'free', not '" + ToString(plan->kind) + "'");
  }
  plan->u = b.points[at].u;
  // The branch's direction at the point: towards its later points (from its last point: beyond its end).
  plan->tangent = at + 1 < n ? Vector(b.points[at + 1].u - plan->u) : Vector(plan->u - b.points[at - 1].u);
  if (!(plan->tangent.norm() > 0)) Refuse(spec, "the branch does not move at that point");
  plan->where["branch"] = branch;
  plan->where["point"] = at;
  plan->description = fmt::format("point {} of branch {} of {}", at, branch, spec.Source());
}

// What a special point restarts as, unless the spec says: PD its period-doubled family, SB/BP every branch
// through it (or, with curves, its curve), TP its branch continued (or its curve), others their branch.
Kind DefaultKind(const StudySpecialPoint& sp, const StudyOptions& options) {
  switch (sp.type) {
    case SpecialPointType::kPeriodDoubling: return Kind::kPeriodDoubled;
    case SpecialPointType::kSimpleBifurcation:
    case SpecialPointType::kFloquetBranchPoint:
    case SpecialPointType::kSingularStart: return options.curves.empty() ? Kind::kSwitch : Kind::kCurve;
    case SpecialPointType::kTurningPoint: return options.curves.empty() ? Kind::kContinue : Kind::kCurve;
    default: return options.free.empty() ? Kind::kContinue : Kind::kFree;
  }
}

// "PD4": the special point, as the kind it restarts as needs it.
void PlanAtSpecialPoint(const RestartSpec& spec, const StudyOptions& options, const HybridModel& model,
                        const ShootingLayout& layout, const StudyResult& saved, RestartPlan* plan) {
  const StudySpecialPoint* sp = saved.FindSpecialPoint(spec.label);
  if (sp == nullptr) {
    std::string labels;
    for (const StudySpecialPoint& p : saved.special_points) {
      if (labels.size() < 200) labels += (labels.empty() ? "" : ", ") + p.Label();
    }
    Refuse(spec, "no such label in the saved study (branches B0 ..., points B<branch>:<point>, special points: " +
                     (labels.empty() ? std::string("none") : labels) + ")");
  }
  if (sp->u.size() != layout.num_unknowns() || !sp->u.allFinite() ||
      (!sp->word.empty() && sp->word != model.WordModeNames())) {
    Refuse(spec, "the special point is not a point of the model's own layout (a family of another layout's?)");
  }
  plan->kind = spec.kind == Kind::kAuto ? DefaultKind(*sp, options) : spec.kind;
  if (plan->kind == Kind::kPeriodDoubled && sp->type != SpecialPointType::kPeriodDoubling) {
    Refuse(spec, "a period-doubled family starts at a PD point, not at a " + sp->code + " point");
  }
  if (plan->kind == Kind::kCurve && options.curves.empty()) {
    Refuse(spec, "a curve of the point needs its second parameter (curves)");
  }
  // A saved point is in the model's own layout; a run with free parameters or observables among its unknowns
  // continues its curves in another one (its --free parameter at a fixed value, its observables joined).
  if (plan->kind == Kind::kCurve && (!options.free.empty() || !options.extrema.empty() || !options.monitors.empty())) {
    Refuse(spec, "a saved point's curve is continued in (H, " + options.curves + ") only: not with " +
                     MentionOption("free") + ", " + MentionOption("monitors") + " or " + MentionOption("extrema") +
                     " (run those studies whole: their curves come with them)");
  }
  if (plan->kind == Kind::kCurve && sp->type != SpecialPointType::kTurningPoint &&
      sp->type != SpecialPointType::kSimpleBifurcation) {
    Refuse(spec, "curves continue turning points and SB points, not " + sp->code + " points");
  }
  if (plan->kind == Kind::kContinue) {
    // Along its branch's direction at the point.
    if (sp->branch < 0 || sp->branch >= static_cast<int>(saved.branches.size())) {
      Refuse(spec, "the special point lies on no branch of the saved study");
    }
    const StudyBranch& b = saved.branches[sp->branch];
    if (b.points.size() < 2 || b.points.front().u.size() != sp->u.size()) {
      Refuse(spec, "its branch has fewer than two points of the model's own layout");
    }
    const int i = std::clamp(sp->index, 0, static_cast<int>(b.points.size()) - 2);
    plan->tangent = b.points[i + 1].u - b.points[i].u;
  }
  plan->u = sp->u;
  plan->point.id = sp->id;
  plan->point.type = sp->type;
  plan->point.status = sp->status == "located" ? LocationStatus::kLocated : LocationStatus::kBracketed;
  plan->point.branch_id = -1;
  plan->point.index = sp->index;
  plan->point.component = sp->component;
  plan->point.u = sp->u;
  plan->where["special_point"] = sp->id;
  plan->description = fmt::format("{} of {}", sp->Label(), spec.Source());
}

}  // namespace

RestartPlan PlanRestart(const RestartSpec& spec, const StudyOptions& options, const HybridModel& model) {
  if (options.formulation != Formulation::kTimeBased) Refuse(spec, "a restart needs the time-based formulation");
  const std::shared_ptr<const StudyResult> held = Saved(spec);
  const StudyResult& saved = *held;
  const ShootingLayout layout(model);
  CheckSameModel(spec, saved, model, layout);
  RestartPlan plan;
  plan.where = {{"folder", spec.Source()}, {"label", spec.label}};
  int branch = -1, index = -1;
  if (BranchLabel(spec.label, &branch, &index)) {
    PlanAtBranchPoint(spec, options, model, layout, saved, branch, index, &plan);
  } else {
    PlanAtSpecialPoint(spec, options, model, layout, saved, &plan);
  }
  plan.where["kind"] = ToString(plan.kind);
  const auto H = std::find(saved.unknown_names.begin(), saved.unknown_names.end(), "H");
  if (H != saved.unknown_names.end()) {
    const double level = plan.u(H - saved.unknown_names.begin());
    plan.where["H"] = level;
    plan.description += fmt::format(" (H = {:.12g})", level);
  }
  return plan;
}

}  // namespace hybridcont::study
