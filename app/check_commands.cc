// `hybridcont list` and `hybridcont check`.
#include <fmt/format.h>

#include <stdexcept>

#include "commands.h"
#include "hybridcont/derivative_check.h"
#include "hybridcont/models.h"
#include "hybridcont/shooting_layout.h"
#include "model_options.h"

namespace hybridcont::app {

int ListCommand(const std::vector<std::string>& models, std::ostream& out, std::ostream& err) {
  for (const std::string& name : models.empty() ? BuiltinModelNames() : models) {
    const HybridModel model = MakeModelWithOverrides(name, {}, &err);
    const ShootingLayout layout(model);
    out << fmt::format("{}: {}\n", name, model.description());
    out << fmt::format("  phases (m = {}, N = {} equations in the time-based map):\n", model.num_phases(),
                       layout.num_equations());
    for (int i = 0; i < model.num_phases(); ++i) {
      const Phase& p = model.phase(i);
      std::string states;
      for (const auto& s : p.state_names()) states += (states.empty() ? "" : ", ") + s;
      out << fmt::format("    {}. {:<14} n = {}  ({})\n", i + 1, p.name(), p.dim(), states);
    }
    out << "  parameters:\n";
    for (const auto& info : model.parameters()) {
      out << fmt::format("    {:<6} = {:<8g} in {:<12} {}\n", info.name, info.default_value, info.range.ToString(),
                         info.description);
    }
  }
  return 0;
}

int CheckCommand(const CheckArguments& args, std::ostream& out, std::ostream& err) {
  if (args.points < 1 || args.points > 1000) {
    throw std::invalid_argument("--points " + std::to_string(args.points) + ": must lie in [1, 1000]");
  }
  const HybridModel model = MakeModelWithOverrides(args.model, args.assignments, &err);
  DerivativeCheckOptions options;
  options.num_points = args.points;
  options.seed = args.seed;
  const DerivativeCheckReport report = CheckDerivatives(model, options);
  out << report.Table();
  return report.passed() ? 0 : 1;
}

}  // namespace hybridcont::app
