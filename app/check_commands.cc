// `hybridcont list` and `hybridcont check`.
#include <fmt/format.h>

#include <algorithm>
#include <filesystem>
#include <iomanip>
#include <random>
#include <sstream>
#include <stdexcept>

#include "commands.h"
#include "hybridcont/automaton_words.h"
#include "hybridcont/conservation_check.h"
#include "hybridcont/derivative_check.h"
#include "hybridcont/model_file.h"
#include "hybridcont/models.h"
#include "install_paths.h"
#include "hybridcont/shooting_layout.h"
#include "option_parsing.h"

namespace hybridcont::app {

int ListCommand(const std::vector<std::string>& models, std::ostream& out, std::ostream& err) {
  for (const std::string& name : models.empty() ? BuiltinModelNames() : models) {
    // Listing reads the model; it never compiles it (the interpreted model has the same phases).
    const HybridModel model = MakeModelWithOverrides(name, {}, &err, /*compile=*/false);
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
  if (!models.empty()) return 0;
  // The model files shipped with the tool, which `run NAME` finds by their name alone.
  std::error_code ec;
  std::vector<std::filesystem::path> files;
  for (const auto& entry : std::filesystem::directory_iterator(ModelsDirectory(), ec)) {
    if (entry.path().extension() == ".toml") files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  if (files.empty()) return 0;
  out << fmt::format("\nmodel files in {} (`hybridcont run NAME` or `list NAME` for their phases):\n",
                     ModelsDirectory().string());
  for (const std::filesystem::path& file : files) {
    std::string description;
    try {
      description = ReadModelFile(file).description;
    } catch (const std::exception& e) {
      description = std::string("(unreadable: ") + e.what() + ")";
    }
    out << fmt::format("  {:<24} {}\n", file.stem().string(), description);
  }
  return 0;
}

namespace {

// The typical state of each phase and `points` − 1 random states around it (seeded, reproducible).
std::vector<std::vector<Vector>> SampleStates(const HybridModel& model, int points, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  std::vector<std::vector<Vector>> states(model.num_phases());
  for (int i = 0; i < model.num_phases(); ++i) {
    const Vector& typical = model.phase(i).typical_state();
    states[i].push_back(typical);
    for (int k = 1; k < points; ++k) {
      Vector x = typical;
      for (int j = 0; j < x.size(); ++j) x(j) += 0.1 * (1.0 + std::abs(x(j))) * uniform(rng);
      states[i].push_back(x);
    }
  }
  return states;
}

std::string ConservationTable(const ConservationReport& report) {
  std::ostringstream os;
  os << "\nconservation of the first integrals (relative, see conservation_check.h)\n";
  std::size_t width = 44;
  for (const auto& e : report.entries) width = std::max(width, e.what.size() + 2);
  const int w = static_cast<int>(width);
  os << std::left << std::setw(w) << "first integral" << std::right << std::setw(12) << "worst" << std::setw(12)
     << "threshold" << "  verdict\n";
  for (const auto& e : report.entries) {
    os << std::left << std::setw(w) << e.what << std::right << std::scientific << std::setprecision(2)
       << std::setw(12) << e.worst << std::setw(12) << ConservationReport::kTolerance << "  "
       << (e.passed(ConservationReport::kTolerance) ? "ok" : "FAIL");
    if (e.num_states == 0) os << " (no state on the guard reached)";
    if (!e.passed(ConservationReport::kTolerance)) os << " at " << e.worst_state;
    os << "\n";
  }
  if (report.entries.empty()) {
    os << "the model has no first integral (conservative = false): nothing to conserve\n";
  } else {
    os << (report.passed() ? "every flow and reset conserves the first integrals\n" : "THE ENERGY IS NOT CONSERVED\n");
  }
  return os.str();
}

// The derivative and conservation tables of one cyclic model; true when both pass.
bool CheckModel(const HybridModel& model, const CheckArguments& args, std::ostream& out) {
  DerivativeCheckOptions options;
  options.num_points = args.points;
  options.seed = args.seed;
  const DerivativeCheckReport report = CheckDerivatives(model, options);
  out << report.Table();
  const ConservationReport conservation = CheckConservation(model, SampleStates(model, args.points, args.seed));
  out << ConservationTable(conservation);
  return report.passed() && conservation.passed();
}

}  // namespace

int CheckCommand(const CheckArguments& args, std::ostream& out, std::ostream& err) {
  if (args.points < 1 || args.points > 1000) {
    throw std::invalid_argument("--points " + std::to_string(args.points) + ": must lie in [1, 1000]");
  }
  const HybridModel model = MakeModelWithOverrides(args.model, args.assignments, &err);
  if (model.automaton() == nullptr) return CheckModel(model, args, out) ? 0 : 1;
  // An automaton: its file's word, the words of its other starts, and words through every transition that
  // none of those takes (a run reaches them by changes of the phase sequence).
  const HybridAutomaton& automaton = *model.automaton();
  std::vector<Word> words = {model.word()};
  for (const StartSpec& start : model.setup().word_starts) {
    if (std::find(words.begin(), words.end(), start.word) == words.end()) words.push_back(start.word);
  }
  std::vector<int> untaken;
  for (Word& word : WordsThroughEveryTransition(automaton, words, &untaken)) words.push_back(std::move(word));
  bool passed = true;
  std::vector<int> taken;
  for (std::size_t w = 0; w < words.size(); ++w) {
    std::string takes;
    for (const int k : TransitionsOf(words[w])) {
      if (std::find(taken.begin(), taken.end(), k) != taken.end()) continue;
      taken.push_back(k);
      takes += (takes.empty() ? "" : ", ") + automaton.transitions()[k].name;
    }
    out << fmt::format("{}word {} ({}; takes {})\n", w == 0 ? "" : "\n", automaton.WordName(words[w]),
                       w == 0 ? "the file's word" : "checked for its transitions", takes.empty() ? "none new" : takes);
    if (w == 0) {
      passed = CheckModel(model, args, out) && passed;
    } else {
      passed = CheckModel(WordModelAt(model, words[w]), args, out) && passed;
    }
  }
  if (!untaken.empty()) {
    std::string names;
    for (const int k : untaken) names += (names.empty() ? "" : ", ") + automaton.transitions()[k].name;
    out << fmt::format("\ntransitions on no cycle through the anchor mode '{}' (no periodic orbit takes them; not "
                       "checked): {}\n", automaton.modes()[automaton.anchor_mode()].name, names);
  }
  out << fmt::format("\n{} words checked, {} of {} transitions taken: {}\n", words.size(), taken.size(),
                     automaton.transitions().size(), passed ? "all pass" : "FAILURES above");
  return passed ? 0 : 1;
}

}  // namespace hybridcont::app
