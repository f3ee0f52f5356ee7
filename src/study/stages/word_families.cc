#include "study/stages/word_families.h"

#include "study/io/summary_json.h"

#include <fmt/format.h>

#include <cmath>
#include <algorithm>
#include <deque>
#include <memory>
#include <vector>

#include "study/engine/family_boundaries.h"
#include "study/engine/start_carry.h"
#include "study/stages/families.h"
#include "hybridcont/automaton_words.h"
#include "hybridcont/corrector.h"
#include "hybridcont/orbit_observables.h"
#include "hybridcont/setup_evaluation.h"
#include "hybridcont/timebased_shooting.h"
#include "hybridcont/word_change.h"
#include "study/engine/model_exploration.h"
#include "study/engine/point_analysis.h"
#include "study/engine/scenario.h"
#include "study/stages/special_points.h"

namespace hybridcont::study {
namespace {

// One explored word: its model, an exploration of it (for BranchThrough) and its diagrams' branches (run ids).
struct WordEntry {
  Word word;
  std::unique_ptr<HybridModel> owned;  // null for the run's own word
  const HybridModel* model = nullptr;
  std::unique_ptr<ModelExploration> exploration;
  BifurcationDiagram branches;  // every branch of this word traced so far, ids of the run
};

// Where a family of a word degenerates: a phase's zero duration or a competing guard touched.
struct Degeneracy {
  int branch = -1;
  Vector u;
  int segment = -1;
  int transition = -1;  // a guard touched; -1: a zero duration
  double t = 0;         // where in the segment (guards)
  std::string where;
};

// The first branch id of an explored diagram (renumbered after the run's).
int FirstId(const BifurcationDiagram& d) { return d.branches.empty() ? -1 : d.branches.front().id; }

// Zero durations of phases 2..m on the physical families of `d`, located with the duration held at 0.
void ZeroDurations(const HybridModel& model, const BifurcationDiagram& d, const IntegratorOptions& integrator,
                   std::vector<Degeneracy>* out) {
  const ShootingLayout layout(model);
  const int m = model.num_phases();
  TimeBasedShooting map(model, integrator);
  Corrector corrector(&map);
  for (const DurationCrossing& c : DurationCrossings(model, d, integrator, /*zero_points=*/true)) {
    if (c.segment < 1 || c.segment >= m) continue;  // phases 2..m: phase 1 holds the section
    Degeneracy g;
    g.branch = c.branch;
    g.segment = c.segment;
    g.where = fmt::format("branch {} between points {} and {}", c.branch, c.point, c.point + 1);
    if (c.at_point) {
      g.u = c.u;
    } else if (corrector.CorrectFixedComponent(c.u, layout.time_index(c.segment), 0.0, &g.u).status !=
               CorrectorStatus::kConverged) {
      continue;
    }
    out->push_back(std::move(g));
  }
}

// Located CB points of the competing guards' constraints (hybrid_automaton.h).
void TouchedGuards(const HybridModel& model, const BifurcationDiagram& d, const IntegratorOptions& integrator,
                   std::vector<Degeneracy>* out) {
  const HybridAutomaton& a = *model.automaton();
  const ShootingLayout layout(model);
  ObservableEvaluator evaluator(model, layout, integrator);
  for (const SpecialPoint& sp : d.special_points) {
    if (sp.type != SpecialPointType::kConstraintBoundary || sp.duplicate_of >= 0 || sp.u.size() == 0) continue;
    const Vector u = sp.u.head(layout.num_unknowns());
    const int best = VanishingObservable(model, evaluator, u, [](const Observable& o) { return o.guard; },
                                         /*interior_only=*/false);
    if (best < 0) continue;
    const int segment = evaluator.last_extremum_segment();
    const double t = evaluator.last_extremum_time();
    // Only where the orbit is physical but for this guard: a boundary crossed by a non-physical family hands
    // nothing over.
    const Classification c = ClassifyPoint(model, u, integrator);
    if (!c.physical && !(c.reason == OrbitClass::kConstraintViolated &&
                         c.detail.find("'" + model.observables()[best].name + "'") != std::string::npos)) {
      continue;
    }
    Degeneracy g;
    g.branch = sp.branch_id;
    g.u = u;
    g.segment = segment;
    g.t = t;
    g.transition = a.GuardConstraintTransition(model.observables()[best].name);
    g.where = fmt::format("special point {} (CB of {})", sp.id, model.observables()[best].name);
    out->push_back(std::move(g));
  }
}

// Where a physical family of a word ends without a change of its phase sequence to offer: the first point
// beyond is classified missed-event (the phase's own guard crossed from above before its end: a tangential
// touch-down inside the phase), wrong-direction or grazing (the event met with zero crossing speed at the
// phase's end). The orbit that takes the transition at the touch point is another orbit of the same word (a
// grazing bifurcation), so these ends are recorded with their reason, bracketed by the two points.
struct PhysicalEnd {
  int branch = -1;
  double H_physical = 0, H_beyond = 0;
  int index_physical = 0, index_beyond = 0;
  Classification beyond;
};

std::vector<PhysicalEnd> PhysicalEnds(const HybridModel& model, const BifurcationDiagram& d, const ResultsWriter& writer) {
  const ShootingLayout layout(model);
  std::vector<PhysicalEnd> ends;
  for (const Branch& b : d.branches) {
    if (b.image_of >= 0) continue;  // an image's ends are the images of its source's
    const std::vector<StudyPoint>* listed = writer.PointsOf(b.id);
    if (listed == nullptr) continue;
    const std::vector<StudyPoint>& points = *listed;
    for (std::size_t i = 0; i + 1 < points.size(); ++i) {
      const bool a = points[i].analysis.classification.physical, z = points[i + 1].analysis.classification.physical;
      if (a == z) continue;
      const StudyPoint& in = a ? points[i] : points[i + 1];
      const StudyPoint& out = a ? points[i + 1] : points[i];
      const OrbitClass c = out.analysis.classification.reason;
      if (c != OrbitClass::kMissedEvent && c != OrbitClass::kWrongDirection && c != OrbitClass::kGrazing) continue;
      if (out.index == 0 && b.parent_special_point < 0) continue;  // the start itself (declared or handed over)
      ends.push_back({b.id, in.u(layout.H_index()), out.u(layout.H_index()), in.index, out.index,
                      out.analysis.classification});
    }
  }
  return ends;
}

std::string EndReason(OrbitClass c) {
  if (c == OrbitClass::kMissedEvent) {
    return "a phase's own guard is touched from above before the phase's end (a tangential touch-down inside the "
           "phase): beyond, this word's orbit crosses that guard early; the orbit that takes the transition at the "
           "touch point is another orbit of the same word (a grazing bifurcation), not a change of the phase "
           "sequence";
  }
  return "a phase's event is met with zero crossing speed at the phase's end (grazing at the transition): beyond, "
         "the guard is met from below, which no transition of the automaton takes";
}

// The run's options on another word's layout: bounds and targets on unknowns it has, the period's bound (a sum
// of every duration) on its own durations.
// The run's turning-point components that are unknowns of `layout` (a word's families are traced in the model's
// own layout: the observables the run joined for their extrema are none of its unknowns).
ExplorationOptions WithTurningComponentsOf(ExplorationOptions o, const ShootingLayout& layout) {
  std::erase_if(o.continuation.turning_point_components,
                [&](const std::string& name) { return layout.UnknownIndex(name) < 0; });
  return o;
}

ExplorationOptions WordOptions(const ExplorationOptions& run, const ShootingLayout& from, const ShootingLayout& to) {
  ExplorationOptions o = WithTurningComponentsOf(run, to);
  o.start_conditions.clear();
  const auto has = [&](const std::string& name) {
    const int index = to.UnknownIndex(name);
    return index >= 0 && index < to.num_unknowns();
  };
  ContinuationOptions& c = o.continuation;
  c.bounds.clear();
  for (const ComponentBound& b : run.continuation.bounds) {
    if (has(b.component)) c.bounds.push_back(b);
  }
  c.targets.clear();
  for (const ComponentTarget& t : run.continuation.targets) {
    if (has(t.component)) c.targets.push_back(t);
  }
  std::vector<std::string> from_durations, to_durations;
  for (int s = 0; s < from.num_segments(); ++s) from_durations.push_back(from.unknown_names()[from.time_index(s)]);
  for (int s = 0; s < to.num_segments(); ++s) to_durations.push_back(to.unknown_names()[to.time_index(s)]);
  c.sum_bounds.clear();
  for (const SumBound& b : run.continuation.sum_bounds) {
    if (b.components == from_durations) {
      c.sum_bounds.push_back({to_durations, b.lower, b.upper});
    } else if (std::all_of(b.components.begin(), b.components.end(), has)) {
      c.sum_bounds.push_back(b);
    }
  }
  return o;
}

// The exploration of an automaton's words, one family at a time: the words the model's starts declare, then
// every degeneracy of every physical family scanned, its candidate changes of word checked and the accepted
// ones explored in their word, until no family is left to scan (or kMaxWords words).
class WordExplorer {
 public:
  WordExplorer(const HybridModel& model, const RunSetup& setup, std::vector<StudySpecialPoint>* special_points,
               WordRecord* record, ResultsWriter& writer, const StudyHooks& hooks)
      : model_(model), setup_(setup), integrator_(setup.integrator), replay_(ReplayOptionsFor(setup.integrator)),
        automaton_(*model.automaton()), special_points_(special_points), words_out_(&record->words),
        changes_(&record->changes), writer_(writer), hooks_(hooks) {}

  // The report section; the words and changes recorded and annotated into the summary.
  std::string Run(const BifurcationDiagram& diagram) {
    words_.push_back({model_.word(), nullptr, &model_, nullptr, diagram});
    words_.back().exploration = std::make_unique<ModelExploration>(
        model_, setup_.scenario, integrator_, WithTurningComponentsOf(setup_.exploration, ShootingLayout(model_)));
    to_scan_.push_back({0, diagram});
    StartDeclaredWords();
    while (!to_scan_.empty()) {
      const int entry = to_scan_.front().first;
      const BifurcationDiagram scan = std::move(to_scan_.front().second);
      to_scan_.pop_front();
      Scan(entry, scan);
    }
    for (const WordEntry& w : words_) {
      StudyWord word{automaton_.WordName(w.word), w.model->WordModeNames(), {}};
      for (const Branch& b : w.branches.branches) word.branches.push_back(b.id);
      words_out_->push_back(std::move(word));
    }
    writer_.SetWords(*words_out_, *changes_);
    if (changes_->empty()) report_ += "  none (no physical family reaches a zero duration or a competing guard)\n";
    if (!word_ranges_.empty()) {
      report_ += "Physical families of the other words (where their orbits are physical and where stable, in H):\n" +
                 word_ranges_;
    }
    return report_;
  }

 private:
  const HybridModel& model_;
  const RunSetup& setup_;
  const IntegratorOptions& integrator_;
  const ReplayOptions replay_;
  const HybridAutomaton& automaton_;
  std::vector<StudySpecialPoint>* special_points_;
  std::vector<StudyWord>* words_out_;        // the words explored, in the order of words_
  std::vector<StudyWordChange>* changes_;    // every change considered (summary.json's "word_changes")
  ResultsWriter& writer_;
  const StudyHooks& hooks_;
  std::deque<WordEntry> words_;
  std::deque<std::pair<int, BifurcationDiagram>> to_scan_;  // (word entry, its families still to scan)
  std::vector<std::pair<int, Vector>> handled_;             // (word entry, orbit) of the degeneracies seen
  std::string report_ = "Phase-sequence changes (words of the automaton):\n";
  std::string word_ranges_;  // the answer per family of the other words (families.h)

  void Say(const std::string& message) {
    if (hooks_.on_progress) hooks_.on_progress({"words", writer_.next_branch_id(), 0, message});
  }

  // Whether the degeneracy at u of word entry `entry` was seen before (recorded if not).
  bool Seen(int entry, const Vector& u) {
    for (const auto& [e, v] : handled_) {
      if (e == entry && v.size() == u.size() && (v - u).norm() <= 1e-6 * (1 + u.norm())) return true;
    }
    handled_.emplace_back(entry, u);
    return false;
  }

  // The entry of `word`, made on first use; -1 (and why) where its exploration cannot be set up.
  int EntryOf(const Word& word, std::string* why) {
    for (std::size_t e = 0; e < words_.size(); ++e) {
      if (words_[e].word == word) return static_cast<int>(e);
    }
    if (static_cast<int>(words_.size()) >= kMaxWords) {
      *why = fmt::format("{} words explored already", kMaxWords);
      return -1;
    }
    WordEntry w;
    w.word = word;
    w.owned = std::make_unique<HybridModel>(WordModelAt(model_, word));
    w.model = w.owned.get();
    try {
      w.exploration = std::make_unique<ModelExploration>(
          *w.model, DefaultScenario(*w.model), integrator_,
          WordOptions(setup_.exploration, ShootingLayout(model_), ShootingLayout(*w.model)));
    } catch (const std::invalid_argument& e) {
      *why = e.what();
      return -1;
    }
    words_.push_back(std::move(w));
    return static_cast<int>(words_.size()) - 1;
  }

  // The family of word entry `target` through the orbit u, both directions: its points analysed and written,
  // its branches and special points numbered after the run's so far, its families named by their word (the
  // [[families]] rules are written for the file's word).
  BifurcationDiagram Explore(int target, const Vector& u) {
    WordEntry& w = words_[target];
    const int offset = writer_.next_branch_id();
    w.exploration->set_branch_store(writer_.resume_store(), offset);
    TimeBasedShooting floquet_map(*w.model, integrator_);
    const ShootingLayout word_layout(*w.model);
    int skipped = 0;
    BifurcationDiagram d = w.exploration->RunFromStarts({u}, [&](const ProgressInfo& info, const Vector& v) {
      const int branch = info.branch_id + offset;
      if (info.point_index == 0) writer_.SetBranchModel(branch, *w.model, automaton_.WordName(w.word));
      PointRecord record = RecordOf(info, v);
      const auto known = w.exploration->KnownBranchPointAnalysis(v);
      AnalyzePoint(*w.model, integrator_, floquet_map, replay_, &record, known ? &*known : nullptr);
      writer_.AddPoint(branch, record);
    }, &skipped);
    if (d.status == ExplorationStatus::kStartFailed) return d;
    RenumberDiagram(offset, static_cast<int>(special_points_->size()), &d);
    for (StudySpecialPoint& p : RecordSpecialPoints(d, word_layout, w.model, integrator_)) {
      p.word = w.model->WordModeNames();
      special_points_->push_back(std::move(p));
    }
    const std::string word_name = automaton_.WordName(w.word);
    // The word's family rules ([[families]] with its `word`) name its orbits; where none holds, the word does.
    const OrbitPresentation presentation(*w.model);
    const FamilyNamer namer = [&](const Vector& u) {
      const std::string family = presentation.Family(u);
      return family == kUnnamedFamily ? word_name : family;
    };
    for (const Branch& b : d.branches) {
      if (writer_.FindBranch(b.id) == nullptr) writer_.SetBranchModel(b.id, *w.model, word_name);  // without points
      writer_.EndBranch(b);
      w.branches.branches.push_back(b);
      word_ranges_ += AssignBranchFamily(b, word_layout, namer, writer_);
    }
    return d;
  }

  // The starts the model declares in other words: their families first, scanned like the rest.
  void StartDeclaredWords() {
    for (const StartSpec& start : model_.setup().word_starts) {
      std::string why;
      const int target = EntryOf(start.word, &why);
      const std::string name = automaton_.WordName(start.word);
      if (target < 0) {
        report_ += fmt::format("  start in word {}: not explored, {}\n", name, why);
        continue;
      }
      const HybridModel& word_model = *words_[target].model;
      const ShootingLayout layout(word_model);
      const Vector guess = StartPoint(word_model, start);
      TimeBasedShooting map(word_model, integrator_);
      Corrector corrector(&map);
      Vector u;
      const CorrectorResult corrected = corrector.CorrectFixedComponent(guess, layout.H_index(), guess(layout.H_index()), &u);
      // At parameters the user set the start is carried there from the model's own values (start_carry.h); where
      // that fails, Newton's orbit from the guess at the values set is kept if it is physical.
      if (!setup_.own_parameters.empty()) {
        const CarriedStart carried =
            CarryGuess(word_model, setup_.own_parameters, guess, integrator_, {{}, LevelBound(setup_, "H")});
        if (carried.ok) {
          u = carried.u;
          report_ += fmt::format("  start in word {}: {}\n", name, carried.report);
          Say(fmt::format("word {}: {}", name, carried.report));
        } else if (!corrected.converged() || !IsPhysical(word_model, u, integrator_)) {
          report_ += fmt::format("  start in word {}: {}; {}\n", name,
                                 corrected.converged() ? std::string("the guess converges to an orbit that is not physical")
                                                       : fmt::format("the guess does not converge to an orbit at H = {}: {}",
                                                                     guess(layout.H_index()), corrected.message),
                                 carried.why);
          continue;
        } else {
          report_ += fmt::format("  start in word {}: {}; Newton's orbit from the guess at the values set is the start\n",
                                 name, carried.why);
        }
      } else if (!corrected.converged()) {
        report_ += fmt::format("  start in word {}: the guess does not converge to an orbit at H = {}: {}\n", name,
                               guess(layout.H_index()), corrected.message);
        continue;
      }
      Say(fmt::format("word {} from its start:", name));
      const BifurcationDiagram d = Explore(target, u);
      if (d.status == ExplorationStatus::kStartFailed) {
        report_ += fmt::format("  start in word {}: not explored, {}\n", name, d.message);
        continue;
      }
      for (const Branch& b : d.branches) writer_.SetStartedInWord(b.id);
      report_ += fmt::format("  start in word {} (H = {:.10f}): {} branches ({} to {}), {} special points\n", name,
                             u(layout.H_index()), d.branches.size(), FirstId(d),
                             FirstId(d) + static_cast<int>(d.branches.size()) - 1, d.special_points.size());
      to_scan_.emplace_back(target, d);
    }
  }

  // The families of `scan` (of word entry `entry`): where they end without a change to offer, and every
  // degeneracy followed.
  void Scan(int entry, const BifurcationDiagram& scan) {
    const HybridModel& word_model = *words_[entry].model;
    std::vector<Degeneracy> found;
    ZeroDurations(word_model, scan, integrator_, &found);
    TouchedGuards(word_model, scan, integrator_, &found);
    for (const PhysicalEnd& e : PhysicalEnds(word_model, scan, writer_)) {
      const std::string at = fmt::format("end of a physical family ({})", ToString(e.beyond.reason));
      report_ += fmt::format("  word {}: {} at H in [{:.10f}, {:.10f}] (branch {} between points {} and {}; {}):\n    "
                             "refused: {}\n",
                             automaton_.WordName(words_[entry].word), at, std::min(e.H_physical, e.H_beyond),
                             std::max(e.H_physical, e.H_beyond), e.branch, std::min(e.index_physical, e.index_beyond),
                             std::max(e.index_physical, e.index_beyond), e.beyond.detail, EndReason(e.beyond.reason));
      StudyWordChange end;
      end.from_word = word_model.WordModeNames();
      end.from_branch = e.branch;
      end.at = at;
      end.H = 0.5 * (e.H_physical + e.H_beyond);
      end.H_physical = e.H_physical;
      end.H_beyond = e.H_beyond;
      end.detail = e.beyond.detail;
      end.reason = EndReason(e.beyond.reason);
      changes_->push_back(std::move(end));
    }
    for (const Degeneracy& g : found) {
      if (!Seen(entry, g.u)) Follow(entry, g);
    }
  }

  // The words a degeneracy offers, each checked and, where accepted, explored or connected.
  void Follow(int entry, const Degeneracy& g) {
    const HybridModel& word_model = *words_[entry].model;
    const ShootingLayout layout(word_model);
    const double H = layout.has_level() ? g.u(layout.H_index()) : std::nan("");
    std::string why;
    const std::vector<WordChange> candidates =
        g.transition < 0 ? WordsWithoutPhase(word_model, g.u, g.segment, integrator_, &why)
                         : WordsWithTransition(word_model, g.u, g.transition, g.segment, g.t, integrator_, &why);
    const std::string kind = g.transition < 0 ? fmt::format("t{} = 0", g.segment + 1)
                                              : fmt::format("guard of {} touched", automaton_.transitions()[g.transition].name);
    report_ += fmt::format("  word {}: {} at H = {:.10f} ({}):\n", automaton_.WordName(words_[entry].word), kind, H, g.where);
    if (candidates.empty()) {
      report_ += "    refused: " + why + "\n";
      StudyWordChange none;
      none.from_word = word_model.WordModeNames();
      none.from_branch = g.branch;
      none.at = kind;
      none.H = H;
      none.reason = why;
      changes_->push_back(std::move(none));
      return;
    }
    for (const WordChange& c : candidates) {
      StudyWordChange change;
      change.from_word = word_model.WordModeNames();
      change.from_branch = g.branch;
      change.at = kind;
      change.H = H;
      change.rule = c.rule;
      change.to_word = automaton_.ModeNames(c.word);
      change.residual = c.residual;
      change.accepted = c.accepted;
      if (!c.accepted) {
        change.reason = c.reason;
        report_ += fmt::format("    {}: refused, {}\n", c.rule, c.reason);
      } else {
        Take(c, &change);
      }
      changes_->push_back(std::move(change));
    }
  }

  // An accepted change: the orbit on a branch of its word traced already (the connection), or its family
  // explored in its word (a word entry made for it), unless that cannot be. Completes the change's record.
  void Take(const WordChange& c, StudyWordChange* change) {
    change->state_difference = c.state_difference;
    change->period_difference = c.period_difference;
    const int id = static_cast<int>(changes_->size());
    const auto refuse = [&](const std::string& reason) {
      change->reason = reason;
      report_ += fmt::format("    {}: {}\n", c.rule, reason);
    };
    int target = -1;  // the word's entry, or a new one
    for (std::size_t e = 0; e < words_.size(); ++e) {
      if (words_[e].word == c.word) target = static_cast<int>(e);
    }
    if (target >= 0) {
      const int through = words_[target].exploration->BranchThrough(words_[target].branches, c.u);
      if (through >= 0) {
        change->to_branches = {through};
        report_ += fmt::format("    {}: the orbit continues on branch {} of word {} (already traced); same orbit to "
                               "{:.1e} (state at the section), {:.1e} (period)\n",
                               c.rule, through, automaton_.WordName(c.word), c.state_difference, c.period_difference);
        return;
      }
    }
    if (c.singular) {
      change->accepted = false;
      return refuse("the orbit is a singular point (a branch point) of the new word's map, on no branch of it traced "
                    "so far: not followed from there");
    }
    std::string why;
    if (target < 0 && (target = EntryOf(c.word, &why)) < 0) return refuse("not explored: " + why);
    // Explore the new word's family from the orbit, both directions.
    Say(fmt::format("word {} from {}:", automaton_.WordName(c.word), c.rule));
    BifurcationDiagram d = Explore(target, c.u);
    if (d.status == ExplorationStatus::kStartFailed) return refuse("not explored: " + d.message);
    for (const Branch& b : d.branches) {
      writer_.SetHandedOverFrom(b.id, id);
      change->to_branches.push_back(b.id);
    }
    report_ += fmt::format("    {}: accepted, same orbit to {:.1e} (state at the section), {:.1e} (period); word {}: "
                           "{} branches ({} to {}), {} special points\n",
                           c.rule, c.state_difference, c.period_difference, automaton_.WordName(c.word),
                           d.branches.size(), FirstId(d), FirstId(d) + static_cast<int>(d.branches.size()) - 1,
                           d.special_points.size());
    to_scan_.emplace_back(target, std::move(d));
  }
};

}  // namespace

std::string WordsNotFollowed(const HybridModel& model, const RunSetup& setup) {
  if (!model.automaton()) return "";
  if (!setup.free.empty()) return "a run with free parameters follows its own word only";
  // An observable that bounds or ends the run (--until, --bound) would have to bound every word's families too.
  const ContinuationOptions& c = setup.exploration.continuation;
  for (const std::string& name : setup.free.observables) {
    const bool bounds = std::any_of(c.bounds.begin(), c.bounds.end(), [&](const ComponentBound& b) { return b.component == name; });
    const bool ends = std::any_of(c.targets.begin(), c.targets.end(), [&](const ComponentTarget& t) { return t.component == name; });
    if (bounds || ends) {
      return "the observable '" + name + "' " + (ends ? "ends the run (--until), and it would not end" :
                                                          "bounds the run (--bound), and it would not bound") +
             " the other words' families";
    }
  }
  return "";
}

std::string ExploreWordChanges(const HybridModel& model, const RunSetup& setup, const BifurcationDiagram& diagram,
                               std::vector<StudySpecialPoint>* special_points, WordRecord* record,
                               ResultsWriter& writer, const StudyHooks& hooks) {
  if (!model.automaton()) return "";
  const std::string heading = "Phase-sequence changes (words of the automaton):\n";
  if (const std::string why = WordsNotFollowed(model, setup); !why.empty()) return heading + "  not followed: " + why + "\n";
  if (setup.free.observables.empty()) return WordExplorer(model, setup, special_points, record, writer, hooks).Run(diagram);
  // Observables among the unknowns only because they are monitored (--monitor): the words are followed on the
  // orbit part of the points (the observables are the last unknowns, shooting_layout.h); the monitored values
  // are located in the study's own word.
  const Eigen::Index n = ShootingLayout(model).num_unknowns();
  const auto orbit_part = [n](Vector* v) {
    if (v->size() > n) *v = Vector(v->head(n));
  };
  BifurcationDiagram orbits = diagram;
  orbits.unknown_names.resize(std::min<std::size_t>(orbits.unknown_names.size(), static_cast<std::size_t>(n)));
  for (Branch& b : orbits.branches) {
    for (ContinuationPoint& p : b.points) orbit_part(&p.u), orbit_part(&p.tangent);
    for (SpecialPoint& sp : b.special_points) {
      for (Vector* v : {&sp.u, &sp.tangent, &sp.tangent_before, &sp.tangent_after, &sp.interval_width}) orbit_part(v);
    }
  }
  for (SpecialPoint& sp : orbits.special_points) {
    for (Vector* v : {&sp.u, &sp.tangent, &sp.tangent_before, &sp.tangent_after, &sp.interval_width}) orbit_part(v);
  }
  return WordExplorer(model, setup, special_points, record, writer, hooks).Run(orbits) +
         "  (the monitored observables are located in the study's own word only)\n";
}

}  // namespace hybridcont::study
