#include "hybridcont/hybrid_automaton.h"

#include <set>
#include <stdexcept>

#include "hybridcont/model.h"

namespace hybridcont {

std::shared_ptr<HybridAutomaton> HybridAutomaton::Create(std::string name, std::vector<AutomatonMode> modes,
                                                         std::vector<AutomatonTransition> transitions, int anchor_mode,
                                                         WordModelFactory factory) {
  for (const AutomatonTransition& t : transitions) {
    if (!t.guard) throw std::invalid_argument("automaton '" + name + "', transition '" + t.name + "': no guard");
  }
  if (!factory) throw std::invalid_argument("automaton '" + name + "': no model factory");
  std::shared_ptr<HybridAutomaton> a = Graph(std::move(name), std::move(modes), std::move(transitions), anchor_mode);
  a->factory_ = std::move(factory);
  return a;
}

std::shared_ptr<HybridAutomaton> HybridAutomaton::Graph(std::string name, std::vector<AutomatonMode> modes,
                                                        std::vector<AutomatonTransition> transitions, int anchor_mode) {
  const std::string where = "automaton '" + name + "'";
  const int num_modes = static_cast<int>(modes.size());
  if (num_modes == 0) throw std::invalid_argument(where + ": no modes");
  std::set<std::string> names;
  for (const AutomatonMode& m : modes) {
    if (m.name.empty() || !names.insert(m.name).second) {
      throw std::invalid_argument(where + ": mode name '" + m.name + "' is empty or used twice");
    }
  }
  if (anchor_mode < 0 || anchor_mode >= num_modes) throw std::invalid_argument(where + ": no anchor mode");
  names.clear();
  std::vector<int> outgoing(num_modes, 0);
  for (const AutomatonTransition& t : transitions) {
    if (t.name.empty() || !names.insert(t.name).second) {
      throw std::invalid_argument(where + ": transition name '" + t.name + "' is empty or used twice");
    }
    if (t.from < 0 || t.from >= num_modes || t.to < 0 || t.to >= num_modes) {
      throw std::invalid_argument(where + ", transition '" + t.name + "': its modes are not modes of the automaton");
    }
    ++outgoing[t.from];
  }
  for (int m = 0; m < num_modes; ++m) {
    if (outgoing[m] == 0) {
      throw std::invalid_argument(where + ": mode '" + modes[m].name + "' has no transition out of it");
    }
  }
  std::shared_ptr<HybridAutomaton> a(new HybridAutomaton());
  a->name_ = std::move(name);
  a->modes_ = std::move(modes);
  a->transitions_ = std::move(transitions);
  a->anchor_mode_ = anchor_mode;
  return a;
}

int HybridAutomaton::FindTransition(const std::string& name) const {
  for (std::size_t k = 0; k < transitions_.size(); ++k) {
    if (transitions_[k].name == name) return static_cast<int>(k);
  }
  return -1;
}

int HybridAutomaton::FindMode(const std::string& name) const {
  for (std::size_t k = 0; k < modes_.size(); ++k) {
    if (modes_[k].name == name) return static_cast<int>(k);
  }
  return -1;
}

std::vector<int> HybridAutomaton::TransitionsFrom(int mode) const {
  std::vector<int> out;
  for (std::size_t k = 0; k < transitions_.size(); ++k) {
    if (transitions_[k].from == mode) out.push_back(static_cast<int>(k));
  }
  return out;
}

void HybridAutomaton::CheckWord(const Word& word) const {
  const std::string where = "automaton '" + name_ + "', word";
  if (word.empty()) throw std::invalid_argument(where + ": empty (a word takes at least one transition)");
  const int n = static_cast<int>(word.size());
  for (int i = 0; i < n; ++i) {
    if (word[i] < 0 || word[i] >= static_cast<int>(transitions_.size())) {
      throw std::invalid_argument(where + ": transition " + std::to_string(word[i]) + " does not exist");
    }
  }
  if (transitions_[word[0]].from != anchor_mode_) {
    throw std::invalid_argument(where + " " + WordName(word) + ": does not start at the anchor mode '" +
                                modes_[anchor_mode_].name + "'");
  }
  for (int i = 0; i < n; ++i) {
    const AutomatonTransition& a = transitions_[word[i]];
    const AutomatonTransition& b = transitions_[word[(i + 1) % n]];
    if (a.to != b.from) {
      throw std::invalid_argument(where + ": transition '" + a.name + "' leads into mode '" + modes_[a.to].name +
                                  "', but the next one, '" + b.name + "', leaves mode '" + modes_[b.from].name + "'");
    }
  }
}

Word HybridAutomaton::WordOf(const std::vector<std::string>& names) const {
  const std::string where = "automaton '" + name_ + "', word";
  if (names.empty()) throw std::invalid_argument(where + ": no modes");
  // Per entry: its mode, and the transition it names (-1: a mode).
  std::vector<int> modes, named;
  for (const std::string& name : names) {
    const int m = FindMode(name), t = FindTransition(name);
    if (m < 0 && t < 0) throw std::invalid_argument(where + ": '" + name + "' is neither a mode nor a transition");
    modes.push_back(m >= 0 ? m : transitions_[t].from);
    named.push_back(m >= 0 ? -1 : t);
  }
  Word word;
  const int n = static_cast<int>(modes.size());
  for (int i = 0; i < n; ++i) {
    if (named[i] >= 0) {
      word.push_back(named[i]);
      continue;
    }
    const int from = modes[i], to = modes[(i + 1) % n];
    std::vector<std::string> between;
    int found = -1;
    for (int k : TransitionsFrom(from)) {
      if (transitions_[k].to == to) found = k, between.push_back(transitions_[k].name);
    }
    if (between.empty()) {
      throw std::invalid_argument(where + ": no transition from mode '" + modes_[from].name + "' to mode '" +
                                  modes_[to].name + "'");
    }
    if (between.size() > 1) {
      std::string list;
      for (const std::string& b : between) list += (list.empty() ? "" : ", ") + b;
      throw std::invalid_argument(where + ": modes '" + modes_[from].name + "' and '" + modes_[to].name +
                                  "' are joined by several transitions (" + list + "): name the transition instead " +
                                  "of the mode '" + modes_[from].name + "'");
    }
    word.push_back(found);
  }
  CheckWord(word);
  return word;
}

std::vector<std::string> HybridAutomaton::ModeNames(const Word& word) const {
  std::vector<std::string> names;
  for (int k : word) names.push_back(modes_[transitions_[k].from].name);
  return names;
}

std::string HybridAutomaton::WordName(const Word& word) const {
  std::string text;
  for (int k : word) {
    const AutomatonTransition& t = transitions_[k];
    int parallel = 0;
    for (const AutomatonTransition& u : transitions_) parallel += u.from == t.from && u.to == t.to;
    text += (text.empty() ? "" : " > ") + modes_[t.from].name + (parallel > 1 ? " (" + t.name + ")" : "");
  }
  return text;
}

HybridModel HybridAutomaton::ModelForWord(const Word& word) const {
  CheckWord(word);
  HYBRIDCONT_DEMAND(factory_ != nullptr);  // an automaton made by Create, not Graph
  HybridModel model = factory_(word);
  HYBRIDCONT_DEMAND(model.num_phases() == static_cast<int>(word.size()));
  for (std::size_t k = 0; k < transitions_.size(); ++k) {
    const AutomatonTransition& t = transitions_[k];
    if (t.cut) continue;
    std::vector<std::shared_ptr<const SmoothFunction>> phases(word.size());
    bool competes = false;
    for (std::size_t i = 0; i < word.size(); ++i) {
      if (transitions_[word[i]].from == t.from && word[i] != static_cast<int>(k)) phases[i] = t.guard, competes = true;
    }
    if (!competes) continue;
    Observable o;
    o.name = GuardConstraintName(t);
    o.description = "the guard of transition '" + t.name + "' stays >= 0 until the phase's own transition";
    o.kind = ObservableKind::kMinimum;
    o.phases = std::move(phases);
    o.constraint = true;
    o.guard = true;
    model.AddObservable(std::move(o));
  }
  model.SetAutomaton(shared_from_this(), word);
  return model;
}

int HybridAutomaton::GuardConstraintTransition(const std::string& constraint) const {
  for (std::size_t k = 0; k < transitions_.size(); ++k) {
    if (GuardConstraintName(transitions_[k]) == constraint) return static_cast<int>(k);
  }
  return -1;
}

}  // namespace hybridcont
