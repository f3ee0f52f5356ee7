#include "cli.h"

namespace hybridcont::app {
int RunCli(int, const char* const*, std::ostream&, std::ostream&) { return 0; }
}  // namespace hybridcont::app
