// Parsing of model selection and `--set NAME=VALUE` overrides shared by the CLI commands.
#ifndef HYBRIDCONT_APP_MODEL_OPTIONS_H_
#define HYBRIDCONT_APP_MODEL_OPTIONS_H_

#include <iosfwd>
#include <string>
#include <utility>
#include <vector>

#include "hybridcont/model.h"

namespace hybridcont::app {

// Parses "NAME=VALUE" (VALUE a finite real number). Throws std::invalid_argument naming the option and
// the offending text, e.g. "--set 'k=abc': value 'abc' is not a number".
std::pair<std::string, double> ParseAssignment(const std::string& option, const std::string& text);

// Builds the model — a built-in model by name, or a model file (a path ending in .toml, model_file.h; a
// relative path that does not exist is looked up in the installation's models folder, install_paths.h) —
// and applies the overrides; throws std::invalid_argument on an unknown model, a bad model file (file,
// line and field in the message) or an unknown parameter or a value outside its range. Notes on compiling
// a model file (first use, interpreted fall-back) go to `log`; without `compile` a model file is interpreted
// (reading it for a listing needs no compiler).
HybridModel MakeModelWithOverrides(const std::string& name, const std::vector<std::string>& assignments,
                                   std::ostream* log = nullptr, bool compile = true);

// Parses "NAME=LOWER:UPPER" (either end may be empty for an unbounded side). Throws std::invalid_argument
// naming the option and the text.
struct BoundAssignment {
  std::string name;
  double lower, upper;
};
BoundAssignment ParseBound(const std::string& option, const std::string& text);

// Parses a real number that must be finite; names the option in the error.
double ParseFinite(const std::string& option, const std::string& text);

}  // namespace hybridcont::app

#endif  // HYBRIDCONT_APP_MODEL_OPTIONS_H_
