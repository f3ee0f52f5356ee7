// Internal: the progress report of one branch point (ContinuationOptions::progress), shared by the
// stepper and the exploration's images (points mapped through a symmetry report as traced ones do).
#ifndef HYBRIDCONT_SRC_CONTINUATION_PROGRESS_REPORT_H_
#define HYBRIDCONT_SRC_CONTINUATION_PROGRESS_REPORT_H_

#include <string>
#include <vector>

#include "hybridcont/continuation.h"
#include "hybridcont/zero_problem.h"

namespace hybridcont::internal {

// Indices of ContinuationOptions::progress_components (empty: all of u is reported).
inline std::vector<int> ProgressIndices(const ContinuationOptions& options, const ZeroProblem& problem) {
  std::vector<int> indices;
  for (const std::string& name : options.progress_components) indices.push_back(problem.UnknownIndex(name));
  return indices;
}

inline ProgressInfo PointProgress(const ContinuationPoint& point, int branch_id, int point_index,
                                  const std::vector<int>& indices, double next_step, int rejected_steps) {
  ProgressInfo info;
  info.branch_id = branch_id;
  info.point_index = point_index;
  if (indices.empty()) {
    info.values.assign(point.u.data(), point.u.data() + point.u.size());
  } else {
    for (const int k : indices) info.values.push_back(point.u(k));
  }
  info.step = point.step;
  info.next_step = next_step;
  info.newton_iterations = point.newton_iterations;
  info.rejected_steps = rejected_steps;
  info.tangent = point.tangent;
  return info;
}

}  // namespace hybridcont::internal

#endif  // HYBRIDCONT_SRC_CONTINUATION_PROGRESS_REPORT_H_
