// The text forms of a study's options, as a person types them: NAME=VALUE, NAME=V1,V2,... (several values of
// one name), NAME=LOWER:UPPER, and finite numbers. One definition for every front end that reads text (the
// command line, a sweep's command line, Python's): each refusal names the option and the text, e.g.
// "--set 'k=abc': value 'abc' is not a number".
//
//   const auto [name, value] = ParseAssignment("--set", "k=60");        // {"k", 60}
//   std::vector<NamedValue> m = ParseAssignments("--monitor", "H=1,2");  // {"H", 1}, {"H", 2}
#ifndef HYBRIDCONT_OPTION_TEXT_H_
#define HYBRIDCONT_OPTION_TEXT_H_

#include <string>
#include <utility>
#include <vector>

#include "hybridcont/study.h"

namespace hybridcont {

// A real number in decimal notation ("1.5", "-2e-3"; not "0x10", "nan" or "inf"), finite. Throws
// std::invalid_argument naming `option` otherwise.
double ParseFinite(const std::string& option, const std::string& text);

// "NAME=VALUE": a non-empty name and a finite value.
std::pair<std::string, double> ParseAssignment(const std::string& option, const std::string& text);

// "NAME=V1,V2,...": one entry per value, each checked as NAME=Vi.
std::vector<NamedValue> ParseAssignments(const std::string& option, const std::string& text);

// "NAME=LOWER:UPPER" (either end may be empty for an unbounded side; not both); lower below upper.
NamedInterval ParseBound(const std::string& option, const std::string& text);

}  // namespace hybridcont

#endif  // HYBRIDCONT_OPTION_TEXT_H_
