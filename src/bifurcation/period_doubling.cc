// The exploration of a period-doubled family from its PD point (period_doubling.h).
#include "hybridcont/period_doubling.h"

#include <stdexcept>

#include "hybridcont/branch_switching.h"

namespace hybridcont {
namespace {

// A direction whose cycles differ by less than this fraction of its norm repeats its first cycle: the
// parent's tangent repeated has none of it, the antiperiodic direction [δ | −δ] all of it, so any
// threshold far from both (0 and 1) separates them.
constexpr double kRepeatedDirection = 1e-2;

}  // namespace

BifurcationDiagram ExplorePeriodDoubled(ZeroProblem* doubled, const ShootingLayout& layout, const Vector& u_pd,
                                        ExplorationOptions options) {
  if (doubled == nullptr) throw std::invalid_argument("ExplorePeriodDoubled: problem is null");
  const Vector u2 = RepeatedOrbit(layout, u_pd, 2);
  if (doubled->num_unknowns() != u2.size()) {
    throw std::invalid_argument("ExplorePeriodDoubled: the problem has " + std::to_string(doubled->num_unknowns()) +
                                " unknowns, the doubled layout " + std::to_string(u2.size()));
  }
  // The antiperiodic direction keeps the level (H̄, or the parameter of a model without first integral).
  options.start_conditions = {LinearCondition{{{layout.level_name(), 1.0}}}};
  const double point_tolerance = options.same_point_tolerance;
  options.known_ray = [&layout, point_tolerance](const Vector& u, const Vector& v) {
    return IsRepeatedOrbit(layout, u, 2, point_tolerance) &&
           IsRepeatedOrbit(layout, v / v.lpNorm<Eigen::Infinity>(), 2, kRepeatedDirection);
  };
  // The doubled map must be singular at u_2 with the one transverse direction: otherwise the singular
  // start would take u_2 for a regular point and trace the parent family twice over.
  StartOptions start;
  start.switching = options.switching;
  start.conditions = options.start_conditions;
  const BranchDirections directions = AnalyzeSingularPoint(doubled, u2, start);
  if (directions.status != BranchSwitchStatus::kOk || directions.directions.size() != 1) {
    BifurcationDiagram failed;
    failed.unknown_names = doubled->unknown_names();
    failed.start = directions;
    failed.status = ExplorationStatus::kStartFailed;
    failed.message = "the PD point is not a simple bifurcation point of the doubled map with a direction transverse "
                     "to the parent family: " + directions.BriefReport();
    return failed;
  }
  return Explore(doubled, u2, options);
}

}  // namespace hybridcont
