// The study API (study.h): the whole run as one library call, its typed result, the saved study read back,
// and restarts from labelled points of a saved study.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include <nlohmann/json.hpp>

#include "hybridcont/study.h"
#include "hybridcont/study_answer.h"
#include "hybridcont/study_report.h"
#include "hybridcont/timebased_shooting.h"

namespace hybridcont {
namespace {

namespace fs = std::filesystem;

fs::path Scratch(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("hybridcont_study_" + name + "_" + std::to_string(getpid()));
  fs::remove_all(dir);
  return dir;
}

std::string Contents(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// The rows of a CSV file without its header.
std::string Rows(const fs::path& file) {
  const std::string text = Contents(file);
  return text.substr(text.find('\n') + 1);
}

StudyOptions Slip() {
  StudyOptions o;
  o.model = "slip";
  return o;
}

// An analysis value read back from the folder: written in its shortest exact form (docs/results-format.md), so
// read back to the bit.
void ExpectWritten(double saved, double computed, const std::string& what) {
  if (std::isnan(computed)) {
    EXPECT_TRUE(std::isnan(saved)) << what;
  } else {
    EXPECT_EQ(saved, computed) << what;
  }
}

// Every typed field of a study, compared with the same study read back from its folder: every number to the bit.
void ExpectSameStudy(const StudyResult& a, const StudyResult& b) {
  const auto same = [](double x, double y) { return (std::isnan(x) && std::isnan(y)) || x == y; };
  EXPECT_EQ(b.model, a.model);
  EXPECT_EQ(b.version, a.version);
  EXPECT_EQ(b.parameters.size(), a.parameters.size());
  EXPECT_EQ(b.unknown_names, a.unknown_names);
  EXPECT_EQ(b.status, a.status);
  EXPECT_EQ(b.families, a.families);
  EXPECT_EQ(b.words, a.words);
  EXPECT_EQ(b.word_changes.size(), a.word_changes.size());
  EXPECT_EQ(b.parameter_starts, a.parameter_starts);
  EXPECT_EQ(b.curve_parameter, a.curve_parameter);
  ASSERT_EQ(b.branches.size(), a.branches.size());
  for (std::size_t i = 0; i < a.branches.size(); ++i) {
    const StudyBranch& x = a.branches[i];
    const StudyBranch& y = b.branches[i];
    const std::string what = "branch " + std::to_string(i);
    EXPECT_EQ(y.id, x.id) << what;
    EXPECT_EQ(y.model, x.model) << what;
    EXPECT_EQ(y.origin, x.origin) << what;
    EXPECT_EQ(y.unknown_names, x.unknown_names) << what;
    EXPECT_EQ(y.continued, x.continued) << what;
    EXPECT_EQ(y.word, x.word) << what;
    EXPECT_EQ(y.direction, x.direction) << what;
    EXPECT_EQ(y.parent_special_point, x.parent_special_point) << what;
    EXPECT_EQ(y.newton_iterations, x.newton_iterations) << what;
    EXPECT_EQ(y.rejected_steps, x.rejected_steps) << what;
    EXPECT_EQ(y.depth, x.depth) << what;
    EXPECT_EQ(y.image_of, x.image_of) << what;
    EXPECT_EQ(y.symmetry, x.symmetry) << what;
    EXPECT_EQ(y.reflected_from, x.reflected_from) << what;
    EXPECT_EQ(y.termination, x.termination) << what;
    EXPECT_EQ(y.message, x.message) << what;
    EXPECT_EQ(y.family, x.family) << what;
    EXPECT_EQ(y.period_doubled_from, x.period_doubled_from) << what;
    EXPECT_EQ(y.handed_over_from, x.handed_over_from) << what;
    EXPECT_EQ(y.started_in_word, x.started_in_word) << what;
    ASSERT_EQ(y.ranges.physical.size(), x.ranges.physical.size()) << what;
    ASSERT_EQ(y.ranges.stable.size(), x.ranges.stable.size()) << what;
    for (const auto& [p, q] : {std::pair{&x.ranges.physical, &y.ranges.physical}, {&x.ranges.stable, &y.ranges.stable}}) {
      for (std::size_t k = 0; k < p->size(); ++k) {
        EXPECT_EQ((*q)[k].from.value, (*p)[k].from.value) << what;
        EXPECT_EQ((*q)[k].to.value, (*p)[k].to.value) << what;
        EXPECT_EQ((*q)[k].from.how, (*p)[k].from.how) << what;
        EXPECT_EQ((*q)[k].to.special_point, (*p)[k].to.special_point) << what;
        EXPECT_EQ((*q)[k].first_point, (*p)[k].first_point) << what;
        EXPECT_EQ((*q)[k].last_point, (*p)[k].last_point) << what;
        EXPECT_EQ((*q)[k].family, (*p)[k].family) << what;
      }
    }
    ASSERT_EQ(y.points.size(), x.points.size()) << what;
    for (std::size_t k = 0; k < x.points.size(); ++k) {
      const StudyPoint& p = x.points[k];
      const StudyPoint& q = y.points[k];
      const std::string at = what + " point " + std::to_string(k);
      EXPECT_EQ(q.index, p.index) << at;
      EXPECT_EQ(q.u, p.u) << at;
      EXPECT_TRUE(same(q.T, p.T)) << at;
      EXPECT_EQ(q.newton_iterations, p.newton_iterations) << at;
      EXPECT_EQ(q.analysis.classification.physical, p.analysis.classification.physical) << at;
      EXPECT_EQ(q.analysis.classification.reason, p.analysis.classification.reason) << at;
      EXPECT_EQ(q.analysis.stability, p.analysis.stability) << at;
      EXPECT_EQ(q.analysis.floquet, p.analysis.floquet) << at;
      ExpectWritten(q.period_slope, p.period_slope, at + " period slope");
      ExpectWritten(q.step, p.step, at + " step");
      ExpectWritten(q.analysis.residual, p.analysis.residual, at + " residual");
      ExpectWritten(q.analysis.replay_error, p.analysis.replay_error, at + " replay error");
      ExpectWritten(q.analysis.max_multiplier, p.analysis.max_multiplier, at + " largest multiplier");
      ExpectWritten(q.analysis.pd_test, p.analysis.pd_test, at + " PD test");
      ASSERT_EQ(q.analysis.multipliers.size(), p.analysis.multipliers.size()) << at;
      for (std::size_t m = 0; m < p.analysis.multipliers.size(); ++m) {
        EXPECT_EQ(q.analysis.multipliers[m], p.analysis.multipliers[m]) << at;
      }
      ASSERT_EQ(q.quantities.size(), p.quantities.size()) << at;
      for (std::size_t m = 0; m < p.quantities.size(); ++m) {
        EXPECT_EQ(q.quantities[m].name, p.quantities[m].name) << at;
        EXPECT_TRUE(same(q.quantities[m].value, p.quantities[m].value)) << at << " " << p.quantities[m].name;
      }
      ASSERT_EQ(q.analysis.observables.size(), p.analysis.observables.size()) << at;
    }
  }
  ASSERT_EQ(b.special_points.size(), a.special_points.size());
  for (std::size_t i = 0; i < a.special_points.size(); ++i) {
    const StudySpecialPoint& x = a.special_points[i];
    const StudySpecialPoint& y = b.special_points[i];
    EXPECT_EQ(y.Label(), x.Label());
    EXPECT_EQ(y.u, x.u) << x.Label();
    EXPECT_EQ(std::tie(y.status, y.branch, y.index, y.component, y.duplicate_of, y.message, y.word, y.period_doubled_from),
              std::tie(x.status, x.branch, x.index, x.component, x.duplicate_of, x.message, x.word, x.period_doubled_from))
        << x.Label();
    for (const auto& [p, q] : {std::pair{x.H, y.H}, {x.T, y.T}, {x.precision, y.precision},
                               {x.precision_arclength, y.precision_arclength}, {x.precision_H, y.precision_H},
                               {x.residual, y.residual}}) {
      EXPECT_TRUE(same(q, p)) << x.Label();  // JSON keeps 17 digits; NaN, written as null, reads back as NaN
    }
    ASSERT_EQ(y.named_unknowns.size(), x.named_unknowns.size()) << x.Label();
    ASSERT_EQ(y.observables.size(), x.observables.size()) << x.Label();
  }
  ASSERT_EQ(b.curves.size(), a.curves.size());
  for (std::size_t i = 0; i < a.curves.size(); ++i) {
    const StudyCurve& x = a.curves[i];
    const StudyCurve& y = b.curves[i];
    EXPECT_EQ(y.id, x.id);
    EXPECT_EQ(y.type, x.type);
    EXPECT_EQ(y.name, x.name);
    EXPECT_EQ(y.special_point, x.special_point);
    EXPECT_EQ(y.status, x.status);
    EXPECT_EQ(y.message, x.message);
    EXPECT_EQ(y.termination, x.termination);
    EXPECT_EQ(y.codim_two, x.codim_two);
    EXPECT_EQ(y.columns, x.columns);
    EXPECT_EQ(y.points, x.points);
  }
  ASSERT_EQ(b.orbits.size(), a.orbits.size());
  for (std::size_t i = 0; i < a.orbits.size(); ++i) {
    const StudyOrbit& x = a.orbits[i];
    const StudyOrbit& y = b.orbits[i];
    EXPECT_EQ(std::tie(y.branch, y.index, y.family, y.t, y.segment), std::tie(x.branch, x.index, x.family, x.t, x.segment));
    EXPECT_TRUE(same(y.H, x.H) && same(y.T, x.T)) << "orbit " << i;
    EXPECT_EQ(y.x, x.x) << "orbit " << i;
    EXPECT_EQ(y.monodromy, x.monodromy) << "orbit " << i;
  }
}

TEST(Study, RunsWithoutAFolderAndItsFolderReadsBackAsTheSameStudy) {
  const fs::path dir = Scratch("roundtrip");
  StudyOptions options = Slip();
  const StudyResult memory = RunStudy(options);  // nothing written
  options.out_dir = dir.string();
  const StudyResult written = RunStudy(options);
  const StudyResult loaded = LoadStudy(dir.string());
  EXPECT_EQ(memory.status, ExplorationStatus::kCompleted);
  EXPECT_EQ(loaded.status, ExplorationStatus::kCompleted);
  EXPECT_EQ(memory.model, "slip");
  EXPECT_EQ(loaded.version, Version());
  ASSERT_EQ(memory.branches.size(), 23u);  // the SLIP's diagram to H = 2
  // The study in memory, the study written and the study read back: the same, field by field, to the bit.
  ExpectSameStudy(memory, written);
  ExpectSameStudy(memory, loaded);
  // The families, folded once, are the same in memory, as written and as read back (to the last bit).
  for (const StudyResult* other : {&written, &loaded}) {
    EXPECT_EQ(other->families, memory.families);
    EXPECT_EQ(other->model_source.name, "slip");
  }
  EXPECT_EQ(written.model_source.kind, StudyModelSource::Kind::kBuiltin);
  EXPECT_EQ(loaded.model_source.kind, StudyModelSource::Kind::kBuiltin);
  // The typed ranges say what the report says: hopping in place is stable from its PD to its BP.
  const StudyBranch& hopping = memory.branch(2);
  EXPECT_EQ(hopping.family, "hopping in place");
  ASSERT_EQ(hopping.ranges.stable.size(), 1u);
  EXPECT_NEAR(hopping.ranges.stable[0].from.value, 1.282809324, 1e-9);
  EXPECT_NEAR(hopping.ranges.stable[0].to.value, 1.614433285, 1e-9);
  const StudySpecialPoint* pd = memory.FindSpecialPoint("PD4");
  ASSERT_NE(pd, nullptr);
  EXPECT_NEAR(pd->H, 1.282809323809, 1e-9);
  EXPECT_FALSE(memory.orbits.empty());
  EXPECT_FALSE(memory.orbits.front().t.empty());  // sampled in memory (and read back exactly: ExpectSameStudy)
  EXPECT_THROW(memory.branch(23), std::out_of_range);
  EXPECT_THROW(memory.branch(-1), std::out_of_range);
  fs::remove_all(dir);
}

// The study in memory is the record its folder serializes: read back, every typed field is the same — the
// period-doubled families (another model's branches, their stability changes), the curves, the words of an
// automaton and their families.
TEST(Study, EveryTypedFieldReadsBackAsTheStudyThatWroteIt) {
  StudyOptions doubled = Slip();
  doubled.period_doubling = true;
  doubled.curves = "k";
  StudyOptions words;
  words.model = (fs::path(HYBRIDCONT_SOURCE_DIR) / "models" / "slip.toml").string();
  for (StudyOptions options : {doubled, words}) {
    const fs::path dir = Scratch("every_field");
    options.out_dir = dir.string();
    const StudyResult study = RunStudy(options);
    SCOPED_TRACE(options.model);
    const StudyResult loaded = LoadStudy(dir.string());
    ExpectSameStudy(study, loaded);
    EXPECT_EQ(loaded.report, study.report);  // (two runs differ in their wall times)
    fs::remove_all(dir);
  }
}

TEST(Study, HooksSeeEveryPointAndBranchInOrder) {
  int points = 0, branches = 0, last_branch = -1;
  bool ordered = true;
  StudyHooks hooks;
  hooks.on_point = [&](const StudyPoint& p, const StudyBranch& b) {
    ++points;
    ordered = ordered && b.id >= last_branch && b.points.empty() && p.index >= 0;
    last_branch = b.id;
  };
  hooks.on_branch = [&](const StudyBranch& b) {
    ++branches;
    EXPECT_NE(b.termination, "running");
    EXPECT_FALSE(b.points.empty());  // a finished branch comes with its points
  };
  StudyOptions options;
  options.model = "bouncing-ball";
  const StudyResult r = RunStudy(options, hooks);
  int total = 0;
  for (const StudyBranch& b : r.branches) total += static_cast<int>(b.points.size());
  EXPECT_EQ(points, total);
  EXPECT_EQ(branches, static_cast<int>(r.branches.size()));
  EXPECT_TRUE(ordered);
}

TEST(Study, AStopRequestEndsTheStudyWithTheWorkSoFar) {
  const fs::path dir = Scratch("stop");
  std::atomic<int> points{0};
  StudyHooks hooks;
  hooks.on_point = [&](const StudyPoint&, const StudyBranch&) { ++points; };
  hooks.stop_requested = [&] { return points.load() >= 60; };
  StudyOptions options = Slip();
  options.out_dir = dir.string();
  const StudyResult r = RunStudy(options, hooks);
  EXPECT_EQ(r.status, ExplorationStatus::kCancelled);
  EXPECT_GE(r.branches.size(), 2u);
  EXPECT_LT(r.branches.size(), 23u);
  EXPECT_TRUE(fs::exists(dir / ".resume"));  // it can be resumed
  // Resumed: the whole diagram, the branches traced before the stop taken as they were.
  options.resume = true;
  const StudyResult resumed = RunStudy(options);
  EXPECT_EQ(resumed.status, ExplorationStatus::kCompleted);
  EXPECT_EQ(resumed.branches.size(), 23u);
  EXPECT_GE(resumed.work.resumed_branches, 2);
  fs::remove_all(dir);
}

// Every option is declared once (study_options.h): set from its command-line text, it reads back as that value,
// every member it names changes from its default, and the roles split the results from how and where a study runs.
// An automaton's words and every change of word considered, and a free parameter's starts, are typed in the
// result; the folder read back holds the same, field by field.
TEST(Study, WordChangesAndParameterStartsAreTypedAndReadBackEqual) {
  const auto same = [](double a, double b) { return (std::isnan(a) && std::isnan(b)) || a == b; };
  const fs::path dir = Scratch("typed_words"), free_dir = Scratch("typed_starts");
  StudyOptions o;
  o.model = (fs::path(HYBRIDCONT_SOURCE_DIR) / "models" / "slip.toml").string();
  o.out_dir = dir.string();
  o.threads = 2;
  const StudyResult study = RunStudy(o);
  ASSERT_GE(study.words.size(), 2u);
  ASSERT_FALSE(study.word_changes.empty());
  EXPECT_EQ(study.words[0].branches.front(), 0);
  const StudyResult loaded = LoadStudy(dir.string());
  EXPECT_EQ(loaded.words, study.words);
  ASSERT_EQ(loaded.word_changes.size(), study.word_changes.size());
  int accepted = 0;
  for (std::size_t i = 0; i < study.word_changes.size(); ++i) {
    const StudyWordChange &a = study.word_changes[i], &b = loaded.word_changes[i];
    EXPECT_EQ(a.from_word, b.from_word);
    EXPECT_EQ(a.from_branch, b.from_branch);
    EXPECT_EQ(a.at, b.at);
    EXPECT_EQ(a.rule, b.rule);
    EXPECT_EQ(a.to_word, b.to_word);
    EXPECT_EQ(a.accepted, b.accepted);
    EXPECT_EQ(a.reason, b.reason);
    EXPECT_EQ(a.detail, b.detail);
    EXPECT_EQ(a.to_branches, b.to_branches);
    for (const auto& [x, y] : {std::pair{a.H, b.H}, {a.H_physical, b.H_physical}, {a.H_beyond, b.H_beyond},
                               {a.residual, b.residual}, {a.state_difference, b.state_difference},
                               {a.period_difference, b.period_difference}}) {
      EXPECT_TRUE(same(x, y)) << i << ": " << x << " vs " << y;
    }
    accepted += a.accepted;
    for (const int to : a.to_branches) {  // a family explored from the change is handed over from it
      ASSERT_LT(to, static_cast<int>(study.branches.size()));
      if (study.branches[to].handed_over_from >= 0) EXPECT_EQ(study.branches[to].handed_over_from, static_cast<int>(i));
    }
  }
  EXPECT_GT(accepted, 0);
  o.out_dir = free_dir.string();
  o.free = "k";
  o.fix = NamedValue{"H", 1.5};
  const StudyResult free = RunStudy(o);
  ASSERT_TRUE(free.parameter_starts);
  EXPECT_GT(free.parameter_starts->crossings, 0);
  EXPECT_EQ(LoadStudy(free_dir.string()).parameter_starts, free.parameter_starts);
  EXPECT_FALSE(study.parameter_starts);
  fs::remove_all(dir);
  fs::remove_all(free_dir);
}

TEST(StudyOptions, EveryDeclaredOptionIsSetFromItsTextAndReadBack) {
  const std::map<std::string, std::vector<std::string>> texts = {
      {"model", {"slip.toml"}},     {"parameters", {"k=30", "w2=5"}}, {"until", {"H=1.5"}},
      {"monitors", {"apex=1,2"}},   {"extrema", {"speed", "apex"}},   {"bounds", {"H=0:", "k=:40"}},
      {"rtol", {"1e-9"}},
      {"atol", {"2e-9"}},           {"max_branches", {"3"}},          {"formulation", {"state"}},
      {"free", {"k"}},              {"fix", {"H=1.25"}},              {"curves", {"w2"}},
      {"use_symmetries", {"true"}}, {"period_doubling", {"true"}},    {"follow_word_changes", {"true"}},
      {"restart.from", {"saved"}},  {"restart.label", {"PD4"}},       {"restart.kind", {"switch"}},
      {"families_of", {"near"}},    {"families", {"a", "b"}},         {"start_must_converge", {"false"}},
      {"threads", {"4"}},           {"out_dir", {"out"}},             {"overwrite", {"true"}},
      {"resume", {"true"}}};
  StudyOptions o;
  std::set<std::string> run_settings;
  for (const StudyOptionSpec& spec : StudyOptionSpecs()) {
    ASSERT_TRUE(texts.count(spec.field)) << spec.field << ": no text in this test";
    const StudyOptionValue value = ParseStudyOption(spec, texts.at(spec.field));
    const StudyOptionValue before = spec.get(o);
    SetStudyOption(&o, spec.field, value);
    EXPECT_TRUE(spec.get(o) == value) << spec.field;
    EXPECT_FALSE(spec.get(o) == before) << spec.field << ": the text sets its default";
    EXPECT_EQ(OptionFlag(spec.field), spec.flag.empty() ? spec.field : spec.flag);
    if (spec.role == OptionRole::kRunSetting) run_settings.insert(spec.field);
  }
  EXPECT_EQ(texts.size(), StudyOptionSpecs().size());
  EXPECT_EQ(run_settings, (std::set<std::string>{"threads", "out_dir", "overwrite", "resume"}));
  EXPECT_EQ(o.model, "slip.toml");
  EXPECT_EQ(o.parameters, (std::vector<NamedValue>{{"k", 30}, {"w2", 5}}));
  EXPECT_EQ(o.monitors, (std::vector<NamedValue>{{"apex", 1}, {"apex", 2}}));
  EXPECT_EQ(o.bounds[0].lower, 0);
  EXPECT_EQ(o.bounds[0].upper, std::numeric_limits<double>::infinity());
  EXPECT_EQ(o.bounds[1].lower, -std::numeric_limits<double>::infinity());
  EXPECT_EQ(*o.rtol, 1e-9);
  EXPECT_EQ(*o.max_branches, 3);
  EXPECT_EQ(o.formulation, Formulation::kStateBased);
  EXPECT_EQ(o.fix->value, 1.25);
  EXPECT_FALSE(o.use_symmetries);
  EXPECT_FALSE(o.follow_word_changes);
  EXPECT_FALSE(o.start_must_converge);
  ASSERT_TRUE(o.restart);
  EXPECT_EQ(o.restart->from, "saved");
  EXPECT_EQ(o.restart->label, "PD4");
  EXPECT_EQ(o.restart->kind, RestartSpec::Kind::kSwitch);
  EXPECT_EQ(o.families, (std::vector<std::string>{"a", "b"}));
  EXPECT_EQ(o.threads, 4);
  // Unset: the default again.
  SetStudyOption(&o, "rtol", std::monostate{});
  EXPECT_FALSE(o.rtol);
  SetStudyOption(&o, "use_symmetries", std::monostate{});
  EXPECT_TRUE(o.use_symmetries);
}

// The text forms are checked once, for every front end, and a refusal names the option, the occurrence and the
// text; the options a message mentions are said in the caller's words.
TEST(StudyOptions, RefusalsNameTheOptionAndTheTextInTheCallersWords) {
  const auto refusal = [](const std::string& field, const std::vector<std::string>& texts) {
    try {
      ParseStudyOption(*FindStudyOption(field), texts);
    } catch (const StudyOptionError& e) {
      EXPECT_EQ(e.field(), field);
      return std::string(e.what());
    }
    return std::string("(accepted)");
  };
  EXPECT_EQ(refusal("parameters", {"k=1", "k=nan"}), "parameters[1] 'k=nan': value 'nan' is not finite");
  EXPECT_EQ(refusal("parameters", {"=1"}), "parameters[0] '=1': expected NAME=VALUE");
  EXPECT_EQ(refusal("out_dir", {"a", "b"}), "out_dir[1] 'b': given twice (first 'a'); give it once");
  EXPECT_EQ(refusal("threads", {"-"}), "threads[0] '-': not a whole number");
  EXPECT_EQ(refusal("formulation", {"fast"}), "formulation[0] 'fast': expected 'time' or 'state'");
  EXPECT_EQ(refusal("curves", {""}),
            "curves[0] '': an empty value (give a value, or leave the option out)");
  EXPECT_EQ(refusal("monitors", {"apex=1,2", "speed=3"}), "(accepted)");
  StudyOptions o;
  o.model = "slip";
  o.fix = NamedValue{"H", 1.5};
  try {
    CheckStudyOptions(o);
    ADD_FAILURE() << "fix without free accepted";
  } catch (const StudyOptionError& e) {
    EXPECT_EQ(std::string(e.what()), "fix 'H=1.5': needs free PARAMETER (the parameter that varies)");
    EXPECT_EQ(e.Say(OptionFlag), "--fix 'H=1.5': needs --free PARAMETER (the parameter that varies)");
    EXPECT_EQ(e.Say(OptionKeyword), "fix 'H=1.5': needs free PARAMETER (the parameter that varies)");
  }
  EXPECT_EQ(SayOptions("give " + MentionOption("bounds") + " H=0:1", OptionFlag), "give --bound H=0:1");
  EXPECT_EQ(SayOptions("give " + MentionOption("bounds") + " H=0:1", OptionKeyword), "give bound H=0:1");
  EXPECT_EQ(OptionFlag("restart"), "--from/--at");
  EXPECT_EQ(OptionKeyword("restart"), "from_/at");
}

TEST(Study, OptionErrorsNameTheFieldAndWriteNothing) {
  const fs::path dir = Scratch("bad");
  const auto refused = [&](StudyOptions o, const std::string& field, const std::string& text) {
    o.out_dir = dir.string();
    try {
      RunStudy(o);
      ADD_FAILURE() << "accepted: " << field;
    } catch (const StudyOptionError& e) {
      EXPECT_EQ(e.field(), field);
      EXPECT_NE(std::string(e.what()).find(text), std::string::npos) << e.what();
    }
    EXPECT_FALSE(fs::exists(dir)) << field;
  };
  StudyOptions o = Slip();
  o.until = {{"H", 2.5}};
  o.bounds = {{"H", 0, 2}};
  refused(o, "until", "until[0] 'H=2.5' lies outside bounds 'H=0:2'");
  o = Slip();
  o.threads = 0;
  refused(o, "threads", "threads 0: must be >= 1");
  o = Slip();
  o.parameters = {{"k", 20}, {"k", 30}};
  refused(o, "parameters", "parameters[1] 'k=30': 'k' is given twice");
  o = Slip();
  o.fix = NamedValue{"H", 1.5};
  refused(o, "fix", "needs free PARAMETER");
  o = Slip();
  o.bounds = {{"H", 2, 1}};
  refused(o, "bounds", "the lower end must be below the upper end");
  o = Slip();
  o.restart = RestartSpec{dir.string() + "-none", "PD4", RestartSpec::Kind::kAuto};
  refused(o, "restart", "not a saved study");
}

// The bipedal model's walking guess (written for k = 25.5, beta = 0.367) does not converge at k = 15,
// beta = 0.42, and its running guess converges there to an orbit that runs backward in time: both are carried
// from the model's own values (start_carry.h), and walking and running are found. At k = 40, beta = 0.1 (a leg
// nearly vertical at touch-down) walking reaches k = 40 at another level (its family at the start's level turns
// back at k = 34.13), but its orbits stop being physical at beta = 0.235 on the way to 0.1 at every level tried:
// a numerical outcome at valid parameters (the study's status, never bad input).
TEST(Study, AStartIsCarriedToTheParametersSetOrSaysWhereItsFamilyTurnsBack) {
  StudyOptions o;
  o.model = "bipedal-slip";
  o.models_directory = HYBRIDCONT_SOURCE_DIR "/models";
  o.parameters = {{"k", 15}, {"beta", 0.42}};
  o.max_branches = 12;
  std::vector<std::string> notes;
  StudyHooks hooks;
  hooks.on_note = [&](const std::string& line) { notes.push_back(line); };
  const auto families = [](const StudyResult& s) {
    std::set<std::string> names;
    for (const StudyFamily& f : s.families) names.insert(f.name);
    return names;
  };
  const StudyResult carried = RunStudy(o, hooks);
  EXPECT_EQ(carried.start_note,
            "start carried from the model's own k = 25.4842, beta = 0.366519 to 15, 0.42 at H = 1.044852192 (23 "
            "continuation steps)");
  EXPECT_EQ(families(carried), (std::set<std::string>{"walking", "running"}));
  // The answer wraps its lines at 100 characters: read as one text.
  const std::string answer = std::regex_replace(OneScreenAnswer(carried, 0), std::regex("\n +"), " ");
  EXPECT_NE(answer.find(carried.start_note), std::string::npos);
  // Both gaits are two steps: the answer says what T and the multipliers are of.
  EXPECT_NE(answer.find("(T and the multipliers are of the whole cycle: stance > double twice, stance > flight twice;"),
            std::string::npos)
      << answer;
  o.parameters = {{"k", 40}, {"beta", 0.1}};
  const StudyResult folded = RunStudy(o);
  EXPECT_EQ(folded.status, ExplorationStatus::kStartFailed);
  EXPECT_NE(folded.message.find("the start could not be carried from beta = 0.3665191429 to 0.1: at H = "),
            std::string::npos)
      << folded.message;
  EXPECT_NE(folded.message.find("its orbits are no longer physical beyond beta = 0.2353"), std::string::npos)
      << folded.message;
  EXPECT_TRUE(families(folded).empty());
}

// The vibrating table's branch from its start turns at a fold from late to early impacts: each stretch of the
// answer names its family where it is not the branch's.
TEST(Study, TheAnswerNamesTheFamilyOfEachStretch) {
  StudyOptions o;
  o.model = HYBRIDCONT_SOURCE_DIR "/models/vibrating-table.toml";
  const std::string answer = OneScreenAnswer(RunStudy(o), 0);
  EXPECT_NE(answer.find("(TP0 .. CB1)  period one, early impact\n"), std::string::npos) << answer;
}

// Every declared start is carried, not only one that fails at the values set: at m = 2, gamma = 0.01 Newton from
// the compass gait's long-step guess converges to the short-step gait (its other start), so a run that corrected
// the guesses there found one gait only. Carried from m = 5, gamma = 0.03 (the run's parameter gamma held while m
// moves), the two starts give the two gaits; the long-step gait is stable at small slopes and loses it at a PD.
TEST(Study, EveryStartOfAModelWithoutFirstIntegralIsCarried) {
  StudyOptions o;
  o.model = HYBRIDCONT_SOURCE_DIR "/models/compass-gait.toml";
  o.parameters = {{"m", 2}, {"gamma", 0.01}};
  const StudyResult s = RunStudy(o);
  std::set<std::string> names;
  int pd = 0;
  for (const StudyFamily& f : s.families) names.insert(f.name);
  for (const StudySpecialPoint& p : s.special_points) pd += p.type == SpecialPointType::kPeriodDoubling;
  EXPECT_EQ(names, (std::set<std::string>{"long-step gait", "short-step gait"}));
  EXPECT_GE(pd, 1);
  EXPECT_NE(s.report.find("start carried from the model's own m = 5, gamma = 0.03 to 2, 0.01"), std::string::npos)
      << s.report.substr(0, 2000);
}

// A monitored observable joins the map's unknowns; the families of the automaton's other words are followed all
// the same (on the orbit part of the points): the bipedal model's running, declared in its own word, is found.
TEST(Study, AMonitoredObservableKeepsEveryWordsFamilies) {
  StudyOptions o;
  o.model = "bipedal-slip";
  o.models_directory = HYBRIDCONT_SOURCE_DIR "/models";
  o.max_branches = 6;
  o.monitors = {{"speed", 1}};
  const StudyResult r = RunStudy(o);
  std::set<std::string> names;
  for (const StudyFamily& f : r.families) names.insert(f.name);
  EXPECT_EQ(names, (std::set<std::string>{"walking", "running"})) << r.report;
  EXPECT_NE(r.report.find("the monitored observables are located in the study's own word only"), std::string::npos);
  // An observable that ends the run would have to end every word's families: the other words are not followed,
  // and the study says so before it runs.
  o.monitors.clear();
  o.until = {{"speed", 0.3}};
  const std::vector<std::string> notes = CheckStudyOptions(o);
  ASSERT_FALSE(notes.empty());
  EXPECT_NE(notes.back().find("the automaton's other words are not followed: the observable 'speed' ends the run"),
            std::string::npos)
      << notes.back();
}

// Period doubling on a model with one phase: the doubled model has two phases of one name (copies), which its
// drawing names once; the study completes (it failed as bad input after the whole run before).
TEST(Study, PeriodDoublingOfAOnePhaseModelIsDrawn) {
  StudyOptions o;
  o.model = "rocking-block";
  o.period_doubling = true;
  const StudyResult r = RunStudy(o);
  EXPECT_EQ(r.status, ExplorationStatus::kCompleted);
  EXPECT_EQ(r.branches.size(), 4u);
  o.model = "bouncing-rod";  // PD points: its period-doubled families are traced and drawn
  const StudyResult rod = RunStudy(o);
  int doubled = 0;
  for (const StudyBranch& b : rod.branches) doubled += b.period_doubled_from >= 0;
  EXPECT_GT(doubled, 0);
}

// The options checked without running: the notes a study would say, nothing computed or written.
TEST(Study, CheckStudyOptionsSaysWhatTheStudyWouldChange) {
  StudyOptions o = Slip();
  o.until = {{"H", 2.5}};
  const std::vector<std::string> notes = CheckStudyOptions(o);
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_NE(notes[0].find("until H=2.5 lies outside the bound [0, 2] of H: the bound is widened to [0, 2.5]"),
            std::string::npos)
      << notes[0];
  o.until = {{"H", 2.5}, {"H", 3}};
  EXPECT_THROW(CheckStudyOptions(o), StudyOptionError);
}

// Each accepted point is integrated for its analysis no more: its class, replay, multipliers and residual are
// those the Floquet test functions found there (at the study's tolerances), equal to an analysis of its own:
// the class, stability and replay to the bit (they are u's own), the multipliers to 1e-6 (they are those of
// the corrector's last evaluation, at an iterate within 1e-8 (1 + |u|) of u), the residual to 1e-12.
TEST(Study, APointsAnalysisIsTheTestFunctionsAndEqualsItsOwn) {
  const StudyResult study = RunStudy(Slip());
  int points = 0;
  for (const StudyBranch& b : study.branches) points += static_cast<int>(b.points.size());
  // Only the starts at singular points are evaluated again (their multipliers classified as at a branch point).
  EXPECT_LE(study.work.analysis_map_evaluations, 8);
  EXPECT_GT(points, 1000);
  const HybridModel model = MakeStudyModel("slip");
  TimeBasedShooting map(model, IntegratorOptions{});
  int compared = 0;
  for (const StudyPoint& p : study.branch(2).points) {  // hopping in place: physical, stable and unstable
    if (p.at_branch_point) continue;
    const OrbitAnalysis own = AnalyzeOrbit(model, map, p.u, OrbitAnalysisOptions::For(IntegratorOptions{}));
    EXPECT_EQ(p.analysis.classification.reason, own.classification.reason);
    EXPECT_EQ(p.analysis.stability, own.stability);
    EXPECT_EQ(p.analysis.replay_error, own.replay_error);
    ASSERT_EQ(p.analysis.multipliers.size(), own.multipliers.size());
    for (std::size_t j = 0; j < own.multipliers.size(); ++j) {
      EXPECT_LE(std::abs(p.analysis.multipliers[j] - own.multipliers[j]), 1e-6) << j << " " << own.multipliers[j];
    }
    EXPECT_NEAR(p.analysis.residual, own.residual, 1e-12);
    ++compared;
  }
  EXPECT_GE(compared, 30);
}

TEST(Study, OptionsArePlainData) {
  StudyOptions a = Slip();
  a.until = {{"H", 1.5}};
  a.fix = NamedValue{"H", 1.2};
  const StudyOptions b = a;  // copyable: no callbacks, no references
  EXPECT_EQ(b.until.size(), 1u);
  EXPECT_EQ(b.fix->value, 1.2);
  EXPECT_EQ(StudyOptions().threads, 1);  // a library caller's study takes one core
}

// A study records which model it ran (study.h, StudyModelSource): a model file named like a built-in model is
// rebuilt from that file, never from the built-in of its name; a file that has changed or gone since is
// refused with the reason; model text is rebuilt from the text the folder keeps.
TEST(Study, AFolderRebuildsItsOwnModelOrSaysWhyNot) {
  const fs::path dir = Scratch("identity"), elsewhere = Scratch("identity_model");
  fs::create_directories(elsewhere);
  std::string text = Contents(fs::path(HYBRIDCONT_SOURCE_DIR) / "models" / "slip.toml");
  const std::string description = "description = \"spring-loaded inverted pendulum hopper with swing leg (paper §4.4), as a model file\"";
  ASSERT_NE(text.find(description), std::string::npos);
  text.replace(text.find(description), description.size(), "description = \"a SLIP of the user's own\"");
  const fs::path file = elsewhere / "slip.toml";
  std::ofstream(file) << text;
  StudyOptions o;
  o.model = file.string();
  o.max_branches = 2;
  o.out_dir = dir.string();
  const StudyResult study = RunStudy(o);
  EXPECT_EQ(study.model, "slip");
  const StudyResult loaded = LoadStudy(dir.string());
  EXPECT_EQ(loaded.model_source.kind, StudyModelSource::Kind::kFile);
  EXPECT_EQ(loaded.model_source.path, fs::absolute(file).lexically_normal().string());
  EXPECT_EQ(loaded.model_source.sha256.size(), 64u);
  EXPECT_EQ(ModelOfStudy(loaded).description(), "a SLIP of the user's own");  // not the built-in's
  EXPECT_NE(MakeStudyModel("slip").description(), "a SLIP of the user's own");
  std::ofstream(file, std::ios::app) << "# edited\n";
  try {
    ModelOfStudy(loaded);
    ADD_FAILURE() << "a changed model file is used";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("has changed since the study"), std::string::npos) << e.what();
  }
  fs::remove(file);
  try {
    ModelOfStudy(loaded);
    ADD_FAILURE() << "a model file that has gone is replaced";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("is gone"), std::string::npos) << e.what();
  }
  // Model text: rebuilt from the folder alone.
  o.model = "mine";
  o.model_text = text;
  o.overwrite = true;
  RunStudy(o);
  const StudyResult from_text = LoadStudy(dir.string());
  EXPECT_EQ(from_text.model_source.kind, StudyModelSource::Kind::kText);
  EXPECT_EQ(ModelOfStudy(from_text).description(), "a SLIP of the user's own");
  // A model the caller built without text cannot be rebuilt: said, not guessed.
  StudyOptions caller;
  caller.max_branches = 2;
  caller.out_dir = dir.string();
  caller.overwrite = true;
  RunStudy(MakeStudyModel("slip"), caller);
  EXPECT_THROW(ModelOfStudy(LoadStudy(dir.string())), std::invalid_argument);
  fs::remove_all(dir);
  fs::remove_all(elsewhere);
}

// A special point of a study in a free parameter carries the parameter by name and the model's observables
// there, in memory and read back alike.
TEST(Study, SpecialPointsKeepTheirNamedUnknownsAndObservables) {
  const fs::path dir = Scratch("named");
  const auto round_trip = [&](const StudyOptions& o,
                              const std::function<void(const StudySpecialPoint&, const StudyBranch&)>& check) {
    const StudyResult study = RunStudy(o);
    const StudyResult loaded = LoadStudy(o.out_dir);
    ASSERT_FALSE(study.special_points.empty());
    ASSERT_EQ(loaded.special_points.size(), study.special_points.size());
    for (std::size_t i = 0; i < study.special_points.size(); ++i) {
      const StudySpecialPoint& a = study.special_points[i];
      const StudySpecialPoint& b = loaded.special_points[i];
      ASSERT_EQ(b.named_unknowns.size(), a.named_unknowns.size());
      for (std::size_t j = 0; j < a.named_unknowns.size(); ++j) {
        EXPECT_EQ(b.named_unknowns[j].name, a.named_unknowns[j].name);
        EXPECT_EQ(b.named_unknowns[j].value, a.named_unknowns[j].value);
      }
      ASSERT_EQ(b.observables.size(), a.observables.size());
      for (std::size_t j = 0; j < a.observables.size(); ++j) {
        EXPECT_EQ(b.observables[j].name, a.observables[j].name);
        EXPECT_TRUE((std::isnan(a.observables[j].value) && std::isnan(b.observables[j].value)) ||
                    a.observables[j].value == b.observables[j].value);
      }
      if (a.branch >= 0) check(a, study.branch(a.branch));  // a start point belongs to no branch
    }
  };
  // The family in k at H = 1.5: k by name, the value of u's k.
  StudyOptions o = Slip();
  o.free = "k";
  o.fix = NamedValue{"H", 1.5};
  o.out_dir = dir.string();
  round_trip(o, [&](const StudySpecialPoint& p, const StudyBranch& b) {
    const auto k = std::find(b.unknown_names.begin(), b.unknown_names.end(), "k") - b.unknown_names.begin();
    ASSERT_EQ(p.named_unknowns.size(), 1u);
    EXPECT_EQ(p.named_unknowns[0].name, "k");
    EXPECT_EQ(p.named_unknowns[0].value, p.u(k));
  });
  // A model file with observables and constraints: evaluated at every special point of its own layout.
  o = StudyOptions();
  o.model = std::string(HYBRIDCONT_SOURCE_DIR) + "/models/slip.toml";
  o.max_branches = 4;
  o.out_dir = dir.string();
  o.overwrite = true;
  int evaluated = 0;
  round_trip(o, [&](const StudySpecialPoint& p, const StudyBranch&) { evaluated += !p.observables.empty(); });
  EXPECT_GT(evaluated, 0);
  fs::remove_all(dir);
}

// The fold of the branches' ranges into families: overlapping stretches of one family (two directions from a
// start, a branch and its image) join, disjoint ones stay apart, each end as the answer says it.
TEST(Study, FamiliesJoinOverlappingStretchesAndKeepDisjointOnesApart) {
  const auto range = [](double from, double to, const std::string& family, int first, int last, int special_from = -1) {
    Range r;
    r.from.value = from, r.from.how = "start of the branch", r.from.special_point = special_from, r.from.located = true;
    r.to.value = to, r.to.how = "end of the branch, bound-reached";
    r.first_point = first, r.last_point = last, r.family = family;
    return r;
  };
  std::vector<StudyBranch> branches(3);
  for (int i = 0; i < 3; ++i) branches[i].id = i, branches[i].continued = "H";
  branches[0].family = "A";
  branches[0].ranges.physical = {range(1.0, 1.2, "A", 0, 4, 0), range(1.5, 1.8, "A", 8, 12)};
  branches[0].ranges.stable = {range(1.05, 1.1, "A", 1, 2)};
  branches[1].family = "A";
  branches[1].ranges.physical = {range(1.3, 1.1, "A", 0, 5), range(2.5, 3.0, "B", 7, 9)};
  branches[2].family = "B";
  branches[2].ranges.physical = {range(2.0, 2.6, "B", 0, 6)};
  std::vector<StudySpecialPoint> special(2);
  special[0].id = 0, special[0].code = "PD", special[0].branch = 0, special[0].index = 3, special[0].status = "located";
  special[1].id = 1, special[1].code = "BP", special[1].branch = 1, special[1].index = 20, special[1].status = "located";
  const std::vector<StudyFamily> families = FoldFamilies(branches, special);
  ASSERT_EQ(families.size(), 2u);
  const StudyFamily& a = families[0];
  EXPECT_EQ(a.name, "A");
  EXPECT_EQ(a.continued, "H");
  EXPECT_EQ(a.branches, (std::vector<int>{0, 1}));
  ASSERT_EQ(a.physical.size(), 2u);  // [1.0, 1.3] and [1.5, 1.8]: the gap between stays a gap
  EXPECT_EQ(a.physical[0].from, 1.0);
  EXPECT_EQ(a.physical[0].to, 1.3);
  EXPECT_EQ(a.physical[0].from_end, "PD0");
  EXPECT_EQ(a.physical[0].to_end, "start of the branch");  // branch 1 runs down from 1.3
  EXPECT_EQ(a.physical[1].from, 1.5);
  EXPECT_EQ(a.physical[1].to, 1.8);
  ASSERT_EQ(a.stable.size(), 1u);
  EXPECT_EQ(a.special_points, (std::vector<std::string>{"PD0"}));  // BP1 lies on no physical stretch
  const StudyFamily& b = families[1];
  EXPECT_EQ(b.name, "B");
  EXPECT_EQ(b.branches, (std::vector<int>{1, 2}));
  ASSERT_EQ(b.physical.size(), 1u);
  EXPECT_EQ(b.physical[0].from, 2.0);
  EXPECT_EQ(b.physical[0].to, 3.0);
  EXPECT_TRUE(b.stable.empty());
}

// The period-doubled family restarted from PD4 of a saved study is the family a run with period doubling
// traces from it: the same rows, without recomputing the rest of the diagram.
TEST(Study, RestartFromAPdPointGivesThePeriodDoubledFamilyOfTheFullRun) {
  const fs::path full = Scratch("pd_full"), saved = Scratch("pd_saved"), restarted = Scratch("pd_restarted");
  StudyOptions o = Slip();
  o.period_doubling = true;
  o.out_dir = full.string();
  const StudyResult whole = RunStudy(o);
  o = Slip();
  o.out_dir = saved.string();
  RunStudy(o);
  o = Slip();
  o.out_dir = restarted.string();
  o.restart = RestartSpec{saved.string(), "PD4", RestartSpec::Kind::kAuto};
  const StudyResult r = RunStudy(o);
  ASSERT_EQ(r.branches.size(), 2u);  // both halves of the family, nothing else
  int matched = 0;
  for (const StudyBranch& b : whole.branches) {
    if (b.period_doubled_from != 4) continue;
    const int k = matched++;
    ASSERT_LT(k, 2);
    EXPECT_EQ(r.branches[k].period_doubled_from, 4);
    EXPECT_EQ(r.branches[k].origin, "period-doubled");
    EXPECT_EQ(Rows(restarted / ("branch-" + std::to_string(k) + ".csv")),
              Rows(full / ("branch-" + std::to_string(b.id) + ".csv")));
  }
  EXPECT_EQ(matched, 2);
  // Its family, from the one place families are decided (families.h): named, physical and stable over the
  // same ranges as in the whole run, in the result, the answer and the folder alike.
  const auto family_of = [](const StudyResult& study) -> const StudyFamily* {
    for (const StudyFamily& f : study.families) {
      if (f.name == "period-doubled backward hopping / forward hopping") return &f;
    }
    return nullptr;
  };
  const StudyFamily* doubled = family_of(r);
  const StudyFamily* in_whole = family_of(whole);
  ASSERT_NE(doubled, nullptr);
  ASSERT_NE(in_whole, nullptr);
  ASSERT_FALSE(doubled->physical.empty());
  ASSERT_EQ(doubled->physical.size(), in_whole->physical.size());
  ASSERT_EQ(doubled->stable.size(), in_whole->stable.size());
  for (std::size_t i = 0; i < doubled->physical.size(); ++i) {
    EXPECT_DOUBLE_EQ(doubled->physical[i].from, in_whole->physical[i].from);
    EXPECT_DOUBLE_EQ(doubled->physical[i].to, in_whole->physical[i].to);
  }
  for (const StudyBranch& b : r.branches) {
    EXPECT_EQ(b.family, "period-doubled backward hopping / forward hopping");
    EXPECT_FALSE(b.ranges.physical.empty());
    int physical = 0;
    for (const StudyPoint& p : b.points) physical += p.analysis.classification.physical;
    EXPECT_GT(physical, 0);
  }
  // It leaves PD4 (H = 1.2828...) down to its fold (TP, H = 1.2827) and turns up to where an event grazes (GR):
  // one stretch of H over its two halves, stable only between the fold and PD4.
  ASSERT_EQ(doubled->physical.size(), 1u);
  EXPECT_NEAR(doubled->physical.front().from, 1.282699643, 1e-7);
  EXPECT_NEAR(doubled->physical.front().to, 1.427197748, 1e-8);
  ASSERT_EQ(doubled->stable.size(), 1u);
  EXPECT_NEAR(doubled->stable.front().to, 1.282809323809, 1e-8);
  const std::string answer = OneScreenAnswer(r, 0);
  EXPECT_NE(answer.find("2 branches with physical orbits of 2"), std::string::npos) << answer;
  EXPECT_NE(answer.find("  period-doubled backward hopping / forward hopping: physical H "), std::string::npos) << answer;
  EXPECT_EQ(LoadStudy(restarted.string()).families.size(), r.families.size());
  const nlohmann::json summary = nlohmann::json::parse(Contents(restarted / "summary.json"));
  ASSERT_TRUE(summary["families"].is_array());
  EXPECT_EQ(summary["families"][0]["name"], "period-doubled backward hopping / forward hopping");
  EXPECT_EQ(summary["families"][0]["physical"][0]["from"].get<double>(), doubled->physical.front().from);
  EXPECT_EQ(summary["restarted_from"]["label"], "PD4");
  EXPECT_EQ(summary["restarted_from"]["kind"], "period-doubled");
  // The same restart from the saved study in memory (no folder on either side): the same family.
  StudyOptions in_memory = Slip();
  in_memory.restart = RestartSpec{"", "PD4", RestartSpec::Kind::kAuto, std::make_shared<const StudyResult>(RunStudy(Slip()))};
  const StudyResult m = RunStudy(in_memory);
  ASSERT_EQ(m.branches.size(), r.branches.size());
  for (std::size_t k = 0; k < r.branches.size(); ++k) {
    ASSERT_EQ(m.branches[k].points.size(), r.branches[k].points.size());
    for (std::size_t i = 0; i < r.branches[k].points.size(); ++i) EXPECT_EQ(m.branches[k].points[i].u, r.branches[k].points[i].u);
  }
  EXPECT_EQ(m.families, r.families);
  for (const fs::path& d : {full, saved, restarted}) fs::remove_all(d);
}

// A branch that ended at its bound, continued beyond it from its last point: it begins where the saved
// branch ended and reaches the new target; its orbits are those of the same family.
TEST(Study, RestartContinuesABranchPastItsBound) {
  const fs::path saved = Scratch("continue_saved"), restarted = Scratch("continue_restarted");
  StudyOptions o = Slip();
  o.out_dir = saved.string();
  const StudyResult before = RunStudy(o);
  const StudyBranch& hopping = before.branch(2);
  ASSERT_EQ(hopping.termination, "bound-reached");
  o = Slip();
  o.out_dir = restarted.string();
  o.until = {{"H", 2.5}};
  o.restart = RestartSpec{saved.string(), "B2", RestartSpec::Kind::kAuto};
  const StudyResult r = RunStudy(o);
  ASSERT_EQ(r.branches.size(), 1u);  // one way: beyond the end only
  const StudyBranch& beyond = r.branches[0];
  EXPECT_EQ(beyond.termination, "target-reached");
  EXPECT_EQ(beyond.family, "hopping in place");
  ASSERT_GE(beyond.points.size(), 2u);
  EXPECT_LT((beyond.points.front().u - hopping.points.back().u).norm(), 1e-9);
  const int H = static_cast<int>(std::find(r.unknown_names.begin(), r.unknown_names.end(), "H") - r.unknown_names.begin());
  EXPECT_DOUBLE_EQ(beyond.points.back().u(H), 2.5);
  // The wrong labels are refused with what the saved study has.
  o.restart = RestartSpec{saved.string(), "B99", RestartSpec::Kind::kAuto};
  EXPECT_THROW(RunStudy(o), StudyOptionError);
  o.restart = RestartSpec{saved.string(), "PD99", RestartSpec::Kind::kAuto};
  EXPECT_THROW(RunStudy(o), StudyOptionError);
  o.restart = RestartSpec{saved.string(), "SB1", RestartSpec::Kind::kPeriodDoubled};
  EXPECT_THROW(RunStudy(o), StudyOptionError);
  o.restart = RestartSpec{saved.string(), "B2", RestartSpec::Kind::kAuto};
  o.parameters = {{"k", 25}};
  EXPECT_THROW(RunStudy(o), StudyOptionError);  // the saved orbits are orbits at the saved k
  for (const fs::path& d : {saved, restarted}) fs::remove_all(d);
}

// A resume with other options than the interrupted study's is refused before anything is written.
TEST(Study, ResumeRefusesOtherOptions) {
  const fs::path dir = Scratch("resume_other");
  StudyHooks stop;
  stop.stop_requested = [] { return true; };
  StudyOptions o = Slip();
  o.out_dir = dir.string();
  RunStudy(o, stop);
  const std::string before = Contents(dir / "summary.json");
  o.resume = true;
  o.until = {{"H", 1.5}};
  try {
    RunStudy(o);
    ADD_FAILURE() << "resumed with other options";
  } catch (const StudyOptionError& e) {
    EXPECT_EQ(e.field(), "resume");
    EXPECT_NE(std::string(e.what()).find("'until'"), std::string::npos) << e.what();
  }
  EXPECT_EQ(Contents(dir / "summary.json"), before);
  // A damaged stored branch is named.
  std::ofstream(dir / ".resume" / "branch-0.json") << "{\"format\": 2, \"branch\": {\"id\": \"x\"}}";
  o.until.clear();
  try {
    RunStudy(o);
    ADD_FAILURE() << "resumed from a damaged store";
  } catch (const StudyOptionError& e) {
    EXPECT_NE(std::string(e.what()).find("branch-0.json"), std::string::npos) << e.what();
  }
  fs::remove_all(dir);
}

// A stored branch that is not the one the resumed exploration is about to trace (another start's, moved under
// another id) is not taken: that half-branch is traced, and the study is the uninterrupted one.
TEST(Study, ResumeTakesOnlyTheBranchesItGaveBefore) {
  const fs::path dir = Scratch("resume_swapped"), reference = Scratch("resume_reference");
  StudyOptions o = Slip();
  o.out_dir = reference.string();
  const StudyResult whole = RunStudy(o);
  std::atomic<int> points{0};
  StudyHooks stop;
  stop.on_point = [&](const StudyPoint&, const StudyBranch&) { ++points; };
  stop.stop_requested = [&] { return points.load() >= 200; };
  o.out_dir = dir.string();
  RunStudy(o, stop);
  ASSERT_TRUE(fs::exists(dir / ".resume" / "branch-2.json"));
  ASSERT_TRUE(fs::exists(dir / ".resume" / "branch-3.json"));
  fs::rename(dir / ".resume" / "branch-2.json", dir / ".resume" / "swap.tmp");
  fs::rename(dir / ".resume" / "branch-3.json", dir / ".resume" / "branch-2.json");
  fs::rename(dir / ".resume" / "swap.tmp", dir / ".resume" / "branch-3.json");
  o.resume = true;
  const StudyResult resumed = RunStudy(o);
  ASSERT_EQ(resumed.branches.size(), whole.branches.size());
  for (std::size_t i = 0; i < whole.branches.size(); ++i) {
    ASSERT_EQ(resumed.branches[i].points.size(), whole.branches[i].points.size()) << i;
    for (std::size_t k = 0; k < whole.branches[i].points.size(); ++k) {
      EXPECT_EQ(resumed.branches[i].points[k].u, whole.branches[i].points[k].u) << i << " " << k;
    }
  }
  for (const fs::path& d : {dir, reference}) fs::remove_all(d);
}

// A stored branch whose content changed after it was stored (one point moved by 1e-3) is refused with the file's
// name: never resumed from, so never a study whose files are off by the change.
TEST(Study, ResumeRefusesAStoredBranchThatChanged) {
  const fs::path dir = Scratch("resume_moved");
  std::atomic<int> points{0};
  StudyHooks stop;
  stop.on_point = [&](const StudyPoint&, const StudyBranch&) { ++points; };
  stop.stop_requested = [&] { return points.load() >= 200; };
  StudyOptions o = Slip();
  o.out_dir = dir.string();
  RunStudy(o, stop);
  const fs::path stored = dir / ".resume" / "branch-2.json";
  ASSERT_TRUE(fs::exists(stored));
  nlohmann::json j = nlohmann::json::parse(Contents(stored));
  nlohmann::json& u = j["branch"]["points"][3]["u"];
  ASSERT_TRUE(u.is_array());
  u[0] = u[0].get<double>() + 1e-3;
  std::ofstream(stored) << j.dump();
  const std::string before = Contents(dir / "summary.json");
  o.resume = true;
  try {
    RunStudy(o);
    ADD_FAILURE() << "resumed from a stored branch that changed";
  } catch (const StudyOptionError& e) {
    EXPECT_EQ(e.field(), "resume");
    EXPECT_NE(std::string(e.what()).find("branch-2.json: the stored branch does not match its digest"),
              std::string::npos) << e.what();
  }
  EXPECT_EQ(Contents(dir / "summary.json"), before);  // nothing written
  fs::remove_all(dir);
}

// A stop while the period-doubled families are explored ends the study as cancelled, resumable.
TEST(Study, AStopAfterTheExplorationIsNotComplete) {
  const fs::path dir = Scratch("stop_late");
  int branches = 0;
  StudyHooks hooks;
  hooks.on_branch = [&](const StudyBranch&) { ++branches; };
  hooks.stop_requested = [&] { return branches >= 23; };  // the run's own 23, then the families
  StudyOptions o = Slip();
  o.period_doubling = true;
  o.out_dir = dir.string();
  const StudyResult r = RunStudy(o, hooks);
  EXPECT_EQ(r.status, ExplorationStatus::kCancelled);
  EXPECT_TRUE(fs::exists(dir / ".resume"));
  EXPECT_EQ(LoadStudy(dir.string()).status, ExplorationStatus::kCancelled);
  fs::remove_all(dir);
}

// Damaged files are refused with their name, never a crash: a number out of double's range, a stored branch
// whose vectors disagree in size.
TEST(Study, DamagedFilesAreRefusedByName) {
  const fs::path dir = Scratch("damaged");
  StudyHooks stop;
  stop.stop_requested = [] { return true; };
  StudyOptions o = Slip();
  o.out_dir = dir.string();
  RunStudy(o, stop);
  std::ofstream(dir / ".resume" / "branch-0.json") << "{\"format\": 1, \"branch\": 1e999}";
  o.resume = true;
  try {
    RunStudy(o);
    ADD_FAILURE() << "resumed from a damaged store";
  } catch (const StudyOptionError& e) {
    EXPECT_NE(std::string(e.what()).find("branch-0.json"), std::string::npos) << e.what();
  }
  std::ofstream(dir / ".resume" / "branch-0.json")
      << "{\"format\": 2, \"branch\": {\"id\": 0, \"direction\": 1, \"parent_special_point\": -1, \"depth\": 0, "
         "\"points\": [{\"u\": [1, 2], \"tangent\": [1], \"arclength\": 0, \"step\": 0, \"newton_iterations\": 0, "
         "\"contraction\": 0, \"sb_test\": 0, \"test_values\": []}], \"special_points\": [], \"termination\": 1, "
         "\"message\": \"\", \"newton_iterations\": 0, \"rejected_steps\": 0, \"located_iterations\": 0, "
         "\"image_of\": -1, \"symmetry\": \"\", \"reflected_from\": -1}}";
  try {
    RunStudy(o);
    ADD_FAILURE() << "resumed from a branch of mismatched sizes";
  } catch (const StudyOptionError& e) {
    EXPECT_NE(std::string(e.what()).find("u and tangent must have the branch's one size"), std::string::npos) << e.what();
  }
  std::ofstream(dir / "summary.json") << "{\"model\": \"slip\", \"branches\": [], \"x\": 1e999}";
  try {
    LoadStudy(dir.string());
    ADD_FAILURE();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("summary.json: not JSON"), std::string::npos) << e.what();
  }
  fs::remove_all(dir);
}

TEST(Study, LoadStudyNamesWhatIsWrongInAFolder) {
  const fs::path dir = Scratch("load_bad");
  fs::create_directories(dir);
  EXPECT_THROW(LoadStudy(dir.string()), std::invalid_argument);  // no summary.json
  std::ofstream(dir / "summary.json") << "{\"model\": \"slip\", \"branches\": [{\"id\": 0, \"termination\": 3}]}";
  try {
    LoadStudy(dir.string());
    ADD_FAILURE();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("branches[0].termination: expected a string"), std::string::npos) << e.what();
  }
  std::ofstream(dir / "summary.json") << "{\"model\": \"slip\", \"unknowns\": [\"H\"], \"branches\": [{\"id\": 0, "
                                         "\"termination\": \"running\", \"file\": \"branch-0.csv\"}]}";
  std::ofstream(dir / "branch-0.csv") << "index,H,T,physical,classification,stability,residual,newton_iterations,step\n"
                                         "0,1.5,2,1,physical,,1e-12,2\n";
  try {
    LoadStudy(dir.string());
    ADD_FAILURE();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("branch-0.csv: line 2: 8 fields, the header has 9"), std::string::npos)
        << e.what();
  }
  // A range's end that is no finite number (a hand-edited folder) is refused, not folded into a family.
  std::ofstream(dir / "summary.json") << "{\"model\": \"slip\", \"unknowns\": [\"H\"], \"branches\": [{\"id\": 0, "
                                         "\"termination\": \"running\", \"family\": \"a\", \"physical_ranges\": [{\"from\": "
                                         "null, \"to\": 1, \"first_point\": 0, \"last_point\": 1}]}]}";
  fs::remove(dir / "branch-0.csv");
  try {
    LoadStudy(dir.string());
    ADD_FAILURE();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("physical_ranges[0].from: expected a finite number"), std::string::npos)
        << e.what();
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace hybridcont

namespace hybridcont {
namespace {

// report.html's data block is the study: every branch with a value of each column per point, the classes,
// the multipliers of physical points, the special points with their labels; and assembling the page keeps a
// "</script" inside a script from ending it.
TEST(StudyReport, DataIsTheStudyAndScriptsStayClosed) {
  const StudyResult study = RunStudy(Slip());
  const nlohmann::json data = nlohmann::json::parse(StudyReportData(study));
  ASSERT_EQ(data["branches"].size(), study.branches.size());
  const nlohmann::json& hopping = data["branches"][2];
  EXPECT_EQ(hopping["family"], "hopping in place");
  EXPECT_EQ(hopping["columns"]["H"].size(), study.branch(2).points.size());
  EXPECT_EQ(hopping["columns"]["T"].size(), study.branch(2).points.size());
  EXPECT_EQ(hopping["ranges"]["stable"].size(), 1u);
  int physical = 0;
  for (std::size_t i = 0; i < hopping["physical"].size(); ++i) {
    if (!hopping["physical"][i].get<bool>()) continue;
    ++physical;
    EXPECT_EQ(hopping["multipliers"][i].size(), 2u) << i;  // the SLIP's two nontrivial multipliers
  }
  EXPECT_GT(physical, 20);
  bool pd4 = false;
  for (const nlohmann::json& sp : data["special_points"]) pd4 = pd4 || sp["label"] == "PD4";
  EXPECT_TRUE(pd4);

  const fs::path dir = fs::temp_directory_path() / "hybridcont_report_assets";
  fs::create_directories(dir);
  const auto write = [&](const std::string& name, const std::string& text) {
    std::ofstream(dir / name) << text;
    return dir / name;
  };
  ReportAssets assets{write("template.html", "<style>/*HYBRIDCONT_STYLE*/</style><script>/*HYBRIDCONT_PLOTLY*/</script>"
                                             "<script>/*HYBRIDCONT_DATA*/</script><script>/*HYBRIDCONT_VIEWER*/</script>"),
                      write("viewer.js", "const s = '</SCRIPT><b>';"), write("viewer.css", "a { color: red }"),
                      write("plotly.js", "var p = 1 </ 2;")};
  EXPECT_EQ(assets.Missing(), "");
  const std::string page = StudyReportHtml(study, assets);
  EXPECT_NE(page.find("const s = '<\\/SCRIPT><b>';"), std::string::npos);
  EXPECT_NE(page.find("var p = 1 </ 2;"), std::string::npos);  // not a script end: left alone
  EXPECT_EQ(page.find("/*HYBRIDCONT_"), std::string::npos);
  EXPECT_EQ(page.find("</SCRIPT>"), std::string::npos);
  // A family's name that holds a marker of the template, or opens an HTML comment in the script, changes
  // nothing of the page: the viewer is inserted once, where the template has it, and no "<" of the data is
  // left for the HTML parser.
  StudyResult hostile = study;
  hostile.branches[2].family = "/*HYBRIDCONT_VIEWER*/<!--<script>";
  const std::string hostile_page = StudyReportHtml(hostile, assets);
  const std::size_t viewer = hostile_page.find("const s = ");
  ASSERT_NE(viewer, std::string::npos);
  EXPECT_EQ(hostile_page.find("const s = ", viewer + 1), std::string::npos);
  EXPECT_EQ(hostile_page.find("<!--"), std::string::npos);
  EXPECT_NE(hostile_page.find("/*HYBRIDCONT_VIEWER*/\\u003c!--\\u003cscript>"), std::string::npos);
  // Saved whole: no temporary file left, in a folder that cannot be written the reason and nothing else.
  const fs::path out = Scratch("report_save");
  fs::create_directories(out);
  EXPECT_EQ(SaveStudyReport(study, out, assets), "");
  EXPECT_EQ(Contents(out / "report.html"), page);
  int files = 0;
  for ([[maybe_unused]] const auto& entry : fs::directory_iterator(out)) ++files;
  EXPECT_EQ(files, 1);
  EXPECT_NE(SaveStudyReport(study, out / "absent", assets), "");
  fs::remove_all(out);
  assets.plotly_js = dir / "absent.js";
  EXPECT_NE(assets.Missing().find("absent.js"), std::string::npos);
  EXPECT_THROW(StudyReportHtml(study, assets), std::runtime_error);
}

}  // namespace
}  // namespace hybridcont

namespace hybridcont {
namespace {

// A note said in parts ("compiling model ..." when the compiler starts, the time when it ends) reaches the
// hooks as one line.
TEST(StudyNotes, ACompileNoteIsOneLine) {
  const fs::path cache = fs::temp_directory_path() / "hybridcont_note_cache";
  fs::remove_all(cache);
  const char* before = std::getenv("HYBRIDCONT_CACHE");
  const std::string saved = before ? before : "";
  setenv("HYBRIDCONT_CACHE", cache.c_str(), 1);
  StudyOptions options;
  options.model = std::string(HYBRIDCONT_SOURCE_DIR) + "/models/bouncing-ball.toml";
  std::vector<std::string> notes;
  StudyHooks hooks;
  hooks.on_note = [&](const std::string& line) { notes.push_back(line); };
  RunStudy(options, hooks);
  if (before) setenv("HYBRIDCONT_CACHE", saved.c_str(), 1);
  else unsetenv("HYBRIDCONT_CACHE");
  fs::remove_all(cache);
  ASSERT_FALSE(notes.empty());
  const std::string& line = notes.front();
  EXPECT_EQ(line.rfind("compiling model 'bouncing-ball' (first use of this model; cached in ", 0), 0u) << line;
  EXPECT_EQ(line.substr(line.size() - 2), " s") << line;
}

}  // namespace
}  // namespace hybridcont

namespace hybridcont {
namespace {

// A family continued in a parameter (the compass gait in its slope) is animated too: each physical point's
// orbit drawn on the model at that point's slope, at least kAnimationFrames rows of finite coordinates.
TEST(StudyReport, FamiliesInAParameterAreAnimatedAtEachPointsValue) {
  StudyOptions options;
  options.model = std::string(HYBRIDCONT_SOURCE_DIR) + "/models/compass-gait.toml";
  const StudyResult study = RunStudy(options);
  const HybridModel model = MakeStudyModel(options.model);
  const nlohmann::json data = nlohmann::json::parse(StudyReportData(study, &model));
  int animated = 0;
  for (const nlohmann::json& b : data["branches"]) {
    ASSERT_EQ(b["continued"], "gamma");
    ASSERT_TRUE(b.contains("animation")) << b["id"];
    for (std::size_t i = 0; i < b["physical"].size(); ++i) {
      if (!b["physical"][i].get<bool>()) continue;
      const nlohmann::json& frames = b["animation"][i];
      ASSERT_GE(frames.size(), static_cast<std::size_t>(kAnimationFrames)) << b["id"] << " " << i;  // + event instants
      for (const nlohmann::json& row : frames) {
        for (const nlohmann::json& v : row) ASSERT_TRUE(v.is_number()) << b["id"] << " " << i;
      }
      ++animated;
    }
  }
  EXPECT_GT(animated, 100);
}

}  // namespace
}  // namespace hybridcont
