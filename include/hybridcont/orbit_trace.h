// One periodic orbit of the time-based formulation, integrated once and kept as dense output.
//
// Given a point u of a time-based branch, OrbitTrace integrates each segment 1..m+1 with xi from u and
// records every accepted step (t, x, f~). Between two steps the trajectory is the cubic Hermite
// interpolant of the step's end values and derivatives (4th-order local error, the same order as the
// integrator's own interpolants), so events can be searched on the whole trajectory, not on a few samples.
//
//   OrbitTrace trace(model, u, IntegratorOptions{});
//   if (trace.ok()) for (const auto& s : trace.Sample(200)) { s.t, s.segment, s.x ... }
#ifndef HYBRIDCONT_ORBIT_TRACE_H_
#define HYBRIDCONT_ORBIT_TRACE_H_

#include <string>
#include <vector>

#include "hybridcont/flow.h"
#include "hybridcont/shooting_layout.h"

namespace hybridcont {

struct TraceNode {
  double t;  // local time within the segment (from 0 to t_i, or to a negative t_i)
  Vector x;
  Vector f;  // f~(x, xi)
};

struct OrbitSample {
  double t;     // global time from the start of segment 1
  int segment;  // 0-based segment (m is the return to phase 1)
  Vector x;
};

class OrbitTrace {
 public:
  OrbitTrace(const HybridModel& model, const Vector& u, const IntegratorOptions& options);

  bool ok() const { return message_.empty(); }
  const std::string& message() const { return message_; }
  int num_segments() const { return static_cast<int>(segments_.size()); }
  const std::vector<TraceNode>& segment(int i) const { return segments_[i]; }
  double duration(int i) const { return durations_[i]; }

  // Hermite interpolant on step j of segment i (nodes j and j+1) at local time t.
  Vector Interpolate(int i, int j, double t) const;

  // num_samples points per segment-weighted period, uniformly in global time (|t_i| summed), plus every
  // segment's end points. Only meaningful for orbits with non-negative durations.
  std::vector<OrbitSample> Sample(int num_samples) const;

 private:
  std::vector<std::vector<TraceNode>> segments_;
  std::vector<double> durations_;
  std::string message_;
};

}  // namespace hybridcont

#endif  // HYBRIDCONT_ORBIT_TRACE_H_
