// A downstream program of the installed study library: the bouncing ball's whole study, in memory (no
// folder), gives its four half-branches, and its one physical family is named. Exits 1 otherwise.
#include <hybridcont/study.h>

#include <iostream>

int main() {
  hybridcont::StudyOptions options;
  options.model = "bouncing-ball";
  const hybridcont::StudyResult study = hybridcont::RunStudy(options);
  int physical = 0;
  for (const hybridcont::StudyBranch& b : study.branches) physical += !b.family.empty();
  std::cout << "bouncing-ball study: " << study.branches.size() << " branches, " << physical
            << " with physical orbits, hybridcont " << hybridcont::Version() << "\n";
  const bool ok = study.status == hybridcont::ExplorationStatus::kCompleted && study.branches.size() == 4 &&
                  physical >= 1;
  if (!ok) std::cerr << "FAILED: expected a completed study of 4 branches with a physical family\n";
  return ok ? 0 : 1;
}
