// The command line's text forms of the study's options: NAME=VALUE, NAME=LOWER:UPPER and numbers. Each
// error names the option and the text, e.g. "--set 'k=abc': value 'abc' is not a number".
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

// The command-line flag of a StudyOptions field ("until" -> "--until").
std::string FlagOf(const std::string& field);
// A study's message in the command line's words: fields as flags ("bounds[0] " -> "--bound ").
std::string CommandLineWords(std::string text);
// A study's refusal as the command line says it: the flag and the value ("--until 'H=5': ...").
std::invalid_argument CommandLineError(const StudyOptionError& e);

}  // namespace hybridcont::app

#endif  // HYBRIDCONT_APP_OPTION_PARSING_H_
