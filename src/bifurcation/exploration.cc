// Automatic exploration (exploration.h).
#include "hybridcont/exploration.h"

#include "continuation/branch_geometry.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <deque>
#include <functional>
#include <sstream>
#include <stdexcept>

namespace hybridcont {
namespace {

class Explorer {
 public:
  Explorer(ZeroProblem* problem, const ExplorationOptions& options) : problem_(problem), options_(options) {
    if (problem_ == nullptr) throw std::invalid_argument("Explore: problem is null");
    if (const std::string error = options_.Validate(); !error.empty()) throw std::invalid_argument(error);
    diagram_.unknown_names = problem_->unknown_names();
    if (const std::string error = options_.continuation.ValidateFor(diagram_.unknown_names); !error.empty()) {
      throw std::invalid_argument("ExplorationOptions::continuation: " + error);
    }
  }

  BifurcationDiagram Run(const Vector& u0, const Vector* tangent) {
    if (tangent != nullptr) {
      TraceRegularStart(u0, tangent);
    } else {
      StartOptions start;
      start.switching = options_.switching;
      start.conditions = options_.start_conditions;
      diagram_.start = AnalyzeSingularPoint(problem_, u0, start);
      if (diagram_.start.status == BranchSwitchStatus::kRegular) {
        TraceRegularStart(u0, nullptr);
      } else if (!diagram_.start.directions.empty()) {
        TraceSingularStart(u0);
      } else {
        diagram_.status = ExplorationStatus::kStartFailed;
        diagram_.message = "singular start point without branch directions: " + diagram_.start.BriefReport();
        return std::move(diagram_);
      }
    }
    ProcessQueue();
    if (diagram_.status == ExplorationStatus::kCompleted && !diagram_.branches.empty() &&
        std::all_of(diagram_.branches.begin(), diagram_.branches.end(),
                    [](const Branch& b) { return b.termination == TerminationReason::kStartFailed; })) {
      diagram_.status = ExplorationStatus::kStartFailed;
      diagram_.message = diagram_.branches.front().message;
    }
    return std::move(diagram_);
  }

 private:
  // A traced direction leaving a special point.
  struct Ray {
    int point;
    Vector direction;
  };

  void TraceRegularStart(const Vector& u0, const Vector* tangent) {
    for (const int d : {+1, -1}) {
      if (!diagram_.branches.empty() &&
          (diagram_.branches.back().termination == TerminationReason::kClosedLoop ||
           diagram_.branches.back().termination == TerminationReason::kStartFailed)) {
        break;
      }
      ContinuationOptions options = options_.continuation;
      options.direction = d;
      Trace(options, -1, 0, d, [&](ContinuationStepper* stepper) {
        return tangent != nullptr ? stepper->Start(u0, d * *tangent) : stepper->Start(u0);
      });
    }
  }

  void TraceSingularStart(const Vector& u0) {
    SpecialPoint start;
    start.type = SpecialPointType::kSingularStart;
    start.status = LocationStatus::kLocated;
    start.u = u0;
    start.message = diagram_.start.BriefReport();
    const int id = AddUnique(std::move(start), 0);
    NoteLines(id, diagram_.start.directions);
    for (const Vector& line : diagram_.start.directions) {
      for (const int d : {+1, -1}) TraceFromPoint(id, d * line, d, 1);
    }
  }

  // Traces a half-branch leaving special point `id` along `direction`, unless that ray is known.
  bool TraceFromPoint(int id, const Vector& direction, int d, int depth) {
    if (RayKnown(id, direction)) return false;
    rays_.push_back({id, direction.normalized()});
    const Vector u = diagram_.special_points[id].u;
    Trace(options_.continuation, id, depth, d,
          [&](ContinuationStepper* stepper) { return stepper->StartAtSingularPoint(u, direction); });
    return true;
  }

  void Trace(const ContinuationOptions& options, int parent, int depth, int d,
             const std::function<StepStatus(ContinuationStepper*)>& start) {
    if (static_cast<int>(diagram_.branches.size()) >= options_.max_branches) {
      diagram_.status = ExplorationStatus::kMaxBranches;
      diagram_.message = "max_branches = " + std::to_string(options_.max_branches) + " reached";
      return;
    }
    const int id = static_cast<int>(diagram_.branches.size());
    ContinuationStepper stepper(problem_, options, id);
    StepStatus status = start(&stepper);
    while (status == StepStatus::kContinuing) {
      status = stepper.Step();
      const auto& points = stepper.branch().points;
      const int index = static_cast<int>(points.size()) - 1;
      if (index >= 1 && index <= options_.known_branch_check_points && status == StepStatus::kContinuing) {
        if (const int other = OnTracedBranch(points.back()); other >= 0) {
          stepper.Terminate(TerminationReason::kKnownBranch,
                            "runs along branch " + std::to_string(other) + " (already traced)");
          status = StepStatus::kFinished;
        }
      }
    }
    Branch branch = stepper.TakeBranch();
    branch.parent_special_point = parent;
    branch.depth = depth;
    branch.direction = d;
    for (SpecialPoint& point : branch.special_points) Register(&point, depth);
    if (branch.termination == TerminationReason::kClosedLoop && parent >= 0) {
      rays_.push_back({parent, -branch.points.back().tangent});  // it returns to the point from this side
    }
    diagram_.branches.push_back(std::move(branch));
  }

  // Gives a special point found on a branch its diagram id (a known point: duplicate_of) and records the
  // rays of the branch through it.
  void Register(SpecialPoint* point, int depth) {
    for (const SpecialPoint& known : diagram_.special_points) {
      const bool comparable = point->type == known.type ||
                              (point->type == SpecialPointType::kSimpleBifurcation &&
                               known.type == SpecialPointType::kSingularStart);
      if (comparable && point->component == known.component &&
          (point->u - known.u).lpNorm<Eigen::Infinity>() <= options_.same_point_tolerance * (1 + known.u.norm())) {
        point->duplicate_of = known.id;
        point->id = known.id;
        AddPassingRays(known.id, *point);
        return;
      }
    }
    const int id = AddUnique(*point, depth);
    point->id = id;
    AddPassingRays(id, *point);
    if (point->type == SpecialPointType::kSimpleBifurcation) queue_.push_back(id);
  }

  int AddUnique(SpecialPoint point, int depth) {
    point.id = static_cast<int>(diagram_.special_points.size());
    point.duplicate_of = -1;
    diagram_.special_points.push_back(std::move(point));
    depth_.push_back(depth);
    line_angle_.push_back(std::numbers::pi / 2);
    return diagram_.special_points.back().id;
  }

  void AddPassingRays(int id, const SpecialPoint& point) {
    if (point.type == SpecialPointType::kTurningPoint) return;
    rays_.push_back({id, point.tangent});
    rays_.push_back({id, -point.tangent});
  }

  // A ray matches a known one within same_direction_cosine, or within half the smallest angle between
  // the branch lines through the point when that is smaller (branches crossing at a small angle).
  bool RayKnown(int id, const Vector& direction) const {
    const Vector unit = direction.normalized();
    const double cosine = std::max(options_.same_direction_cosine, std::cos(0.5 * line_angle_[id]));
    return std::any_of(rays_.begin(), rays_.end(), [&](const Ray& ray) {
      return ray.point == id && ray.direction.dot(unit) >= cosine;
    });
  }

  // Records the smallest angle between branch lines through special point `id`.
  void NoteLines(int id, const std::vector<Vector>& lines) {
    for (size_t i = 0; i < lines.size(); ++i) {
      for (size_t j = i + 1; j < lines.size(); ++j) {
        const double c = std::abs(lines[i].normalized().dot(lines[j].normalized()));
        line_angle_[id] = std::min(line_angle_[id], std::acos(std::min(1.0, c)));
      }
    }
  }

  // Id of a traced branch that p lies on (within the chord sag of one of its chords, parallel tangent), or −1.
  int OnTracedBranch(const ContinuationPoint& p) const {
    for (const Branch& branch : diagram_.branches) {
      for (size_t i = 0; i + 1 < branch.points.size(); ++i) {
        const ContinuationPoint& a = branch.points[i];
        const ContinuationPoint& b = branch.points[i + 1];
        const Vector chord = b.u - a.u;
        const double length = chord.norm();
        if (!(length > 0)) continue;
        const double t = chord.dot(p.u - a.u) / (length * length);
        if (t < 0 || t > 1) continue;
        const double distance = (a.u + t * chord - p.u).norm();
        const double allowed = options_.known_branch_tolerance * (1 + p.u.norm()) +
                               length * (internal::AngleBetween(a.tangent, b.tangent) / 4 + 1e-3);
        // Parallel tangent: p's tangent against the known branch's tangent at the projection (the two end
        // tangents interpolated, exact to far less than a quarter of their angle). A branch crossing the
        // known one at a small angle θ stays within the chord sag near the crossing, but its tangent is θ
        // off everywhere.
        const Vector known_tangent = ((1 - t) * a.tangent + t * b.tangent).normalized();
        const double angle = std::acos(std::min(1.0, std::abs(p.tangent.dot(known_tangent))));
        const double allowed_angle = internal::AngleBetween(a.tangent, b.tangent) / 4 + options_.known_branch_angle;
        if (distance <= allowed && angle <= allowed_angle) return branch.id;
      }
    }
    return -1;
  }

  void ProcessQueue() {
    while (!queue_.empty() && diagram_.status == ExplorationStatus::kCompleted) {
      const int id = queue_.front();
      queue_.pop_front();
      if (depth_[id] >= options_.max_depth) continue;
      SwitchRecord record;
      record.special_point = id;
      record.result = SwitchDirectionAt(problem_, diagram_.special_points[id], options_.switching);
      if (record.result.status == BranchSwitchStatus::kOk || record.result.status == BranchSwitchStatus::kFallback) {
        NoteLines(id, {record.result.direction, record.result.incoming_direction});
        for (const int d : {+1, -1}) {
          if (diagram_.status != ExplorationStatus::kCompleted) break;
          if (TraceFromPoint(id, d * record.result.direction, d, depth_[id] + 1)) {
            ++record.traced;
          } else {
            ++record.skipped;
          }
        }
      }
      diagram_.switches.push_back(std::move(record));
    }
  }

  ZeroProblem* problem_;
  ExplorationOptions options_;
  BifurcationDiagram diagram_;
  std::vector<int> depth_;  // per unique special point: depth of the branch it was found on
  std::vector<double> line_angle_;  // per unique special point: smallest angle between its branch lines
  std::vector<Ray> rays_;
  std::deque<int> queue_;
};

}  // namespace

std::string ToString(ExplorationStatus status) {
  switch (status) {
    case ExplorationStatus::kCompleted: return "completed";
    case ExplorationStatus::kMaxBranches: return "max-branches";
    case ExplorationStatus::kStartFailed: return "start-failed";
  }
  return "unknown";
}

std::string ExplorationOptions::Validate() const {
  std::ostringstream out;
  if (const std::string error = continuation.Validate(); !error.empty()) {
    out << "ExplorationOptions::continuation: " << error;
  } else if (const std::string switch_error = switching.Validate(); !switch_error.empty()) {
    out << "ExplorationOptions::switching: " << switch_error;
  } else if (max_depth < 0) {
    out << "ExplorationOptions::max_depth = " << max_depth << " must be >= 0";
  } else if (max_branches < 1) {
    out << "ExplorationOptions::max_branches = " << max_branches << " must be >= 1";
  } else if (!(same_point_tolerance > 0)) {
    out << "ExplorationOptions::same_point_tolerance = " << same_point_tolerance << " must be > 0";
  } else if (!(same_direction_cosine > 0 && same_direction_cosine < 1)) {
    out << "ExplorationOptions::same_direction_cosine = " << same_direction_cosine << " must lie in (0, 1)";
  } else if (known_branch_check_points < 0) {
    out << "ExplorationOptions::known_branch_check_points = " << known_branch_check_points << " must be >= 0";
  } else if (!(known_branch_tolerance >= 0)) {
    out << "ExplorationOptions::known_branch_tolerance = " << known_branch_tolerance << " must be >= 0";
  } else if (!(known_branch_angle >= 0 && known_branch_angle < 1)) {
    out << "ExplorationOptions::known_branch_angle = " << known_branch_angle << " must lie in [0, 1)";
  }
  return out.str();
}

std::string BifurcationDiagram::BriefReport() const {
  int sb = 0, located = 0, turning = 0;
  for (const SpecialPoint& point : special_points) {
    if (point.type == SpecialPointType::kSimpleBifurcation) {
      ++sb;
      if (point.status == LocationStatus::kLocated) ++located;
    } else if (point.type == SpecialPointType::kTurningPoint) {
      ++turning;
    }
  }
  std::ostringstream out;
  out << "Exploration " << ToString(status) << ": " << branches.size() << " branches, " << sb << " SB points ("
      << located << " located), " << turning << " turning points";
  return out.str();
}

std::string BifurcationDiagram::FullReport() const {
  std::ostringstream out;
  out << BriefReport() << "\n";
  if (!message.empty()) out << "  " << message << "\n";
  if (start.kernel_dimension > 1) out << "Start: " << start.BriefReport() << "\n";
  out << "Branches:\n";
  for (const Branch& branch : branches) out << "  " << branch.FullReport(unknown_names);
  out << "Special points:\n";
  for (const SpecialPoint& point : special_points) out << "  " << point.BriefReport(unknown_names) << "\n";
  out << "Branch switches:\n";
  for (const SwitchRecord& record : switches) {
    out << "  at #" << record.special_point << ": " << record.result.BriefReport() << ", traced " << record.traced
        << ", already known " << record.skipped << "\n";
  }
  return out.str();
}

BifurcationDiagram Explore(ZeroProblem* problem, const Vector& u0, const ExplorationOptions& options) {
  return Explorer(problem, options).Run(u0, nullptr);
}

BifurcationDiagram Explore(ZeroProblem* problem, const Vector& u0, const Vector& tangent,
                           const ExplorationOptions& options) {
  return Explorer(problem, options).Run(u0, &tangent);
}

}  // namespace hybridcont
