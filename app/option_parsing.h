// The command line's words for the study's options (study_options.h declares them): each refusal names the
// flag and the text, e.g. "--set 'k=abc': value 'abc' is not a number".
#ifndef HYBRIDCONT_APP_OPTION_PARSING_H_
#define HYBRIDCONT_APP_OPTION_PARSING_H_

#include <iosfwd>
#include <string>
#include <utility>
#include <vector>

#include "hybridcont/option_text.h"
#include "hybridcont/study.h"

namespace hybridcont::app {

// The model named on the command line (a built-in or a model file, also looked up in the installation's
// models folder) with `--set NAME=VALUE` assignments.
HybridModel MakeModelWithOverrides(const std::string& name, const std::vector<std::string>& assignments,
                                   std::ostream* log = nullptr, bool compile = true);

// The command-line flag of an option's field (study_options.h: "until" -> "--until"; a restart, "restart" ->
// "--from/--at/--as"); a field of no flag as it is.
std::string FlagOf(const std::string& field);
// A study's refusal as the command line says it: the flag, the value, and the options it mentions as flags
// ("--until 'H=5': ...").
std::invalid_argument CommandLineError(const StudyOptionError& e);

}  // namespace hybridcont::app

#endif  // HYBRIDCONT_APP_OPTION_PARSING_H_
