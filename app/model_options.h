// Parsing of model selection and `--set NAME=VALUE` overrides shared by the CLI commands.
#ifndef HYBRIDCONT_APP_MODEL_OPTIONS_H_
#define HYBRIDCONT_APP_MODEL_OPTIONS_H_

#include <string>
#include <utility>
#include <vector>

#include "hybridcont/model.h"

namespace hybridcont::app {

// Parses "NAME=VALUE" (VALUE a finite real number). Throws std::invalid_argument naming the option and
// the offending text, e.g. "--set 'k=abc': value 'abc' is not a number".
std::pair<std::string, double> ParseAssignment(const std::string& option, const std::string& text);

// Builds the named built-in model and applies the overrides; throws std::invalid_argument on an unknown
// model or parameter.
HybridModel MakeModelWithOverrides(const std::string& name, const std::vector<std::string>& assignments);

// Parses a real number that must be finite; names the option in the error.
double ParseFinite(const std::string& option, const std::string& text);

}  // namespace hybridcont::app

#endif  // HYBRIDCONT_APP_MODEL_OPTIONS_H_
