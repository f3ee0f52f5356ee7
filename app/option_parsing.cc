#include "option_parsing.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <regex>
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

std::string FlagOf(const std::string& field) {
  static const std::map<std::string, std::string> kFlags = {
      {"parameters", "--set"},     {"until", "--until"},       {"bounds", "--bound"},
      {"monitors", "--monitor"},   {"rtol", "--rtol"},         {"atol", "--atol"},
      {"max_branches", "--max-branches"}, {"threads", "--threads"}, {"formulation", "--formulation"},
      {"free", "--free"},          {"fix", "--fix"},           {"curves", "--curves"},
      {"out_dir", "--out"},        {"period_doubling", "--period-doubling"}, {"model", "MODEL"},
      {"restart", "--from/--at"},    {"resume", "--resume"},     {"families_of", "--families-of"},
      {"families", "--family"}};
  const auto it = kFlags.find(field);
  return it == kFlags.end() ? field : it->second;
}

std::string CommandLineWords(std::string text) {
  // Entries of a list field ("bounds[0] ") and the fields the messages name, as their flags.
  static const std::regex kEntry(R"(\b(parameters|until|bounds|monitors)\[\d+\] )");
  std::string spoken;
  std::sregex_iterator it(text.begin(), text.end(), kEntry), end;
  std::size_t last = 0;
  for (; it != end; ++it) {
    spoken += text.substr(last, it->position() - last) + FlagOf((*it)[1].str()) + " ";
    last = it->position() + it->length();
  }
  text = spoken + text.substr(last);
  static const std::pair<std::string, std::string> kPhrases[] = {
      {"needs a free parameter (free)", "needs --free PARAMETER"},
      {"needs an unknown held fixed (fix NAME=VALUE, e.g. H=1.5)", "needs --fix NAME=VALUE (e.g. --fix H=1.5)"},
      {"not with a free parameter (free '", "not with --free '"},
      {"not with a free parameter (free)", "not with --free"},
      {"state: free '", "state: --free '"},
      {"give the bound ", "give --bound "},
      {"(run.bounds or the bound ", "(run.bounds or --bound "},
      {"name the parameter its families are continued in", "name the parameter its families are continued in (--free NAME)"}};
  for (const auto& [from, to] : kPhrases) {
    for (std::size_t at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size())) {
      text.replace(at, from.size(), to);
    }
  }
  if (text.rfind("until ", 0) == 0) text = "--" + text;  // a note on a target
  // "not with --free 'k')" closes the parenthesis the library's wording opened.
  if (const std::size_t at = text.find("not with --free '"); at != std::string::npos) {
    const std::size_t close = text.find("')", at);
    if (close != std::string::npos) text.erase(close + 1, 1);
  }
  return text;
}

std::invalid_argument CommandLineError(const StudyOptionError& e) {
  const std::string detail = e.detail();
  return std::invalid_argument(FlagOf(e.field()) + (detail.rfind(":", 0) == 0 ? "" : " ") + CommandLineWords(detail));
}

}  // namespace hybridcont::app
