// How an exploration (exploration.h) ended, and so a study (study.h): its own header, so that a study's
// readers need not include the engine.
#ifndef HYBRIDCONT_EXPLORATION_STATUS_H_
#define HYBRIDCONT_EXPLORATION_STATUS_H_

#include <string>

namespace hybridcont {

enum class ExplorationStatus {
  kCompleted,    // every reachable branch within the bounds and depth was traced
  kMaxBranches,  // stopped at max_branches
  kStartFailed,  // no branch could be started (see message)
  kCancelled,    // ContinuationOptions::cancel returned true: the branches traced so far
};
std::string ToString(ExplorationStatus status);

}  // namespace hybridcont

#endif  // HYBRIDCONT_EXPLORATION_STATUS_H_
