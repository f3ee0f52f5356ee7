// Words through every transition of an automaton (automaton_words.h).
#include "hybridcont/automaton_words.h"

#include <algorithm>
#include <deque>
#include <optional>

#include "hybridcont/invariant.h"

namespace hybridcont {
namespace {

// The shortest sequence of non-cut transitions from mode `from` to mode `to` (empty when they are the same
// mode), breadth first in declaration order; nullopt when `to` cannot be reached.
std::optional<Word> ShortestPath(const HybridAutomaton& automaton, int from, int to) {
  if (from == to) return Word{};
  const int modes = static_cast<int>(automaton.modes().size());
  std::vector<int> via(modes, -1);  // the transition by which a mode was first reached
  std::vector<bool> seen(modes, false);
  std::deque<int> queue = {from};
  seen[from] = true;
  while (!queue.empty()) {
    const int mode = queue.front();
    queue.pop_front();
    for (const int k : automaton.TransitionsFrom(mode)) {
      const AutomatonTransition& t = automaton.transitions()[k];
      if (t.cut || seen[t.to]) continue;
      seen[t.to] = true;
      via[t.to] = k;
      if (t.to == to) {
        Word path;
        for (int m = to; m != from; m = automaton.transitions()[via[m]].from) path.push_back(via[m]);
        std::reverse(path.begin(), path.end());
        return path;
      }
      queue.push_back(t.to);
    }
  }
  return std::nullopt;
}

}  // namespace

HybridModel WordModelAt(const HybridModel& model, const Word& word) {
  HYBRIDCONT_DEMAND(model.automaton() != nullptr);
  HybridModel word_model = model.automaton()->ModelForWord(word);
  for (int p = 0; p < static_cast<int>(model.parameters().size()); ++p) {
    word_model.SetParameterValue(p, model.parameter_value(p));
  }
  return word_model;
}

std::vector<int> TransitionsOf(const Word& word) {
  std::vector<int> taken;
  for (const int k : word) {
    if (std::find(taken.begin(), taken.end(), k) == taken.end()) taken.push_back(k);
  }
  return taken;
}

std::vector<Word> WordsThroughEveryTransition(const HybridAutomaton& automaton, const std::vector<Word>& given,
                                              std::vector<int>* untaken) {
  const int n = static_cast<int>(automaton.transitions().size());
  std::vector<bool> taken(n, false);
  for (const Word& word : given) {
    for (const int k : word) taken[k] = true;
  }
  std::vector<Word> words;
  for (int k = 0; k < n; ++k) {
    if (taken[k]) continue;
    const AutomatonTransition& t = automaton.transitions()[k];
    const std::optional<Word> to_source = ShortestPath(automaton, automaton.anchor_mode(), t.from);
    const std::optional<Word> back = ShortestPath(automaton, t.to, automaton.anchor_mode());
    if (!to_source || !back) {
      if (untaken != nullptr) untaken->push_back(k);
      continue;
    }
    Word word = *to_source;
    word.push_back(k);
    word.insert(word.end(), back->begin(), back->end());
    for (const int j : word) taken[j] = true;
    words.push_back(std::move(word));
  }
  return words;
}

}  // namespace hybridcont
