#include "hybridcont/invariant.h"

#include <cstdio>
#include <cstdlib>

#include "hybridcont/version.h"

namespace hybridcont::internal {

void InvariantViolated(const char* condition, const char* file, int line, const char* function) {
  std::fprintf(stderr,
               "hybridcont %s: internal invariant violated: %s\n  at %s:%d in %s\n"
               "This is a bug in hybridcont, not in your input; please report it with the command that "
               "led here.\n",
               HYBRIDCONT_VERSION, condition, file, line, function);
  std::fflush(stderr);
  std::abort();
}

}  // namespace hybridcont::internal
