#include "hybridcont/option_text.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace hybridcont {

double ParseFinite(const std::string& option, const std::string& text) {
  // Decimal numbers only ("1.5", "-2e-3"): strtod would also take hexadecimal ("0x10").
  std::string word = text.substr(text.find_first_not_of("+-") == std::string::npos ? 0 : text.find_first_not_of("+-"));
  std::transform(word.begin(), word.end(), word.begin(), [](unsigned char c) { return std::tolower(c); });
  if (word == "inf" || word == "infinity" || word == "nan") {
    throw std::invalid_argument(option + ": value '" + text + "' is not finite");
  }
  if (text.find_first_not_of("0123456789+-.eE") != std::string::npos) {
    throw std::invalid_argument(option + ": value '" + text + "' is not a number");
  }
  std::size_t used = 0;
  double value = 0.0;
  try {
    value = std::stod(text, &used);
  } catch (const std::out_of_range&) {
    throw std::invalid_argument(option + ": value '" + text + "' is not finite (out of range)");
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != text.size()) {
    throw std::invalid_argument(option + ": value '" + text + "' is not a number");
  }
  if (!std::isfinite(value)) throw std::invalid_argument(option + ": value '" + text + "' is not finite");
  return value;
}

std::pair<std::string, double> ParseAssignment(const std::string& option, const std::string& text) {
  const std::size_t eq = text.find('=');
  if (eq == std::string::npos || eq == 0) {
    throw std::invalid_argument(option + " '" + text + "': expected NAME=VALUE");
  }
  const std::string name = text.substr(0, eq);
  return {name, ParseFinite(option + " '" + text + "'", text.substr(eq + 1))};
}

std::vector<NamedValue> ParseAssignments(const std::string& option, const std::string& text) {
  const std::size_t eq = text.find('=');
  if (eq == std::string::npos) ParseAssignment(option, text);  // refused: expected NAME=VALUE
  std::vector<NamedValue> values;
  for (std::size_t begin = eq + 1;;) {
    const std::size_t comma = std::min(text.find(',', begin), text.size());
    const auto [name, value] = ParseAssignment(option, text.substr(0, eq + 1) + text.substr(begin, comma - begin));
    values.push_back({name, value});
    if (comma == text.size()) break;
    begin = comma + 1;
  }
  return values;
}

NamedInterval ParseBound(const std::string& option, const std::string& text) {
  const std::size_t eq = text.find('=');
  const std::size_t colon = text.find(':', eq == std::string::npos ? 0 : eq);
  if (eq == std::string::npos || eq == 0 || colon == std::string::npos) {
    throw std::invalid_argument(option + " '" + text + "': expected NAME=LOWER:UPPER (e.g. H=0:2.7; an empty end is unbounded)");
  }
  NamedInterval b{text.substr(0, eq), -std::numeric_limits<double>::infinity(),
                    std::numeric_limits<double>::infinity()};
  const std::string lower = text.substr(eq + 1, colon - eq - 1), upper = text.substr(colon + 1);
  if (lower.empty() && upper.empty()) {
    throw std::invalid_argument(option + " '" + text + "': both ends are empty (an unknown without any bound is "
                                "never reached; give at least one end, e.g. H=0:)");
  }
  if (!lower.empty()) b.lower = ParseFinite(option + " '" + text + "' (lower end)", lower);
  if (!upper.empty()) b.upper = ParseFinite(option + " '" + text + "' (upper end)", upper);
  if (!(b.lower < b.upper)) throw std::invalid_argument(option + " '" + text + "': the lower end must be below the upper end");
  return b;
}

}  // namespace hybridcont
