#include "model_options.h"

#include <cmath>
#include <stdexcept>

#include "hybridcont/models.h"

namespace hybridcont::app {

double ParseFinite(const std::string& option, const std::string& text) {
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

HybridModel MakeModelWithOverrides(const std::string& name, const std::vector<std::string>& assignments) {
  HybridModel model = MakeBuiltinModel(name);
  for (const std::string& a : assignments) {
    const auto [parameter, value] = ParseAssignment("--set", a);
    model.SetParameter(parameter, value);
  }
  return model;
}

}  // namespace hybridcont::app
