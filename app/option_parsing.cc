#include "option_parsing.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>

#include "install_paths.h"

namespace hybridcont::app {

HybridModel MakeModelWithOverrides(const std::string& name, const std::vector<std::string>& assignments,
                                   std::ostream* log, bool compile) {
  std::vector<NamedValue> parameters;
  for (const std::string& a : assignments) {
    const auto [parameter, value] = ParseAssignment("--set", a);
    parameters.push_back({parameter, value});
  }
  try {
    return MakeStudyModel(name, parameters, ModelsDirectory().string(), log, compile);
  } catch (const StudyOptionError& e) {
    throw CommandLineError(e);
  }
}

std::string FlagOf(const std::string& field) { return OptionFlag(field); }

std::invalid_argument CommandLineError(const StudyOptionError& e) { return std::invalid_argument(e.Say(FlagOf)); }

}  // namespace hybridcont::app
