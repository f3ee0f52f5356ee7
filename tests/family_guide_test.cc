// A study guided by the families of a saved study at other parameter values (StudyOptions::families_of,
// src/study/stages/family_guide.h): it traces only the half-branches that led to a family there, and its families
// are those of the whole exploration at its own parameters, range for range and point for point.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "study/stages/family_guide.h"
#include "hybridcont/shooting_layout.h"
#include "hybridcont/study.h"

namespace hybridcont {
namespace {

namespace fs = std::filesystem;

fs::path Scratch(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("hybridcont_guide_" + name + "_" + std::to_string(getpid()));
  fs::remove_all(dir);
  return dir;
}

StudyOptions SlipAt(double k, const fs::path& out = {}) {
  StudyOptions o;
  o.model = "slip";
  o.parameters = {{"k", k}};
  o.out_dir = out.string();
  return o;
}

// Per family: its branches' physical and stable ranges and the located special points on them (type and H), in
// the order the branches have in the study.
struct FamilyFacts {
  std::vector<std::vector<double>> physical, stable;
  std::vector<std::pair<std::string, double>> special_points;
};
std::map<std::string, FamilyFacts> Families(const StudyResult& s) {
  std::map<std::string, FamilyFacts> out;
  for (const StudyBranch& b : s.branches) {
    if (b.family.empty()) continue;
    FamilyFacts& f = out[b.family];
    std::vector<double> physical, stable;
    for (const Range& r : b.ranges.physical) physical.insert(physical.end(), {r.from.value, r.to.value});
    for (const Range& r : b.ranges.stable) stable.insert(stable.end(), {r.from.value, r.to.value});
    f.physical.push_back(physical);
    f.stable.push_back(stable);
    for (const StudySpecialPoint& p : s.special_points) {
      if (p.branch == b.id && p.status == "located" && p.code != "start") f.special_points.push_back({p.code, p.H});
    }
  }
  return out;
}

void ExpectSameFamilies(const StudyResult& guided, const StudyResult& whole) {
  const auto g = Families(guided), w = Families(whole);
  ASSERT_EQ(g.size(), w.size());
  for (const auto& [family, facts] : w) {
    ASSERT_TRUE(g.count(family)) << family;
    const FamilyFacts& other = g.at(family);
    // The same half-branches traced from the same switch points: the same numbers to the last bit.
    EXPECT_EQ(other.physical, facts.physical) << family;
    EXPECT_EQ(other.stable, facts.stable) << family;
    EXPECT_EQ(other.special_points, facts.special_points) << family;
  }
}

TEST(FamilyGuide, TheSlipsFamiliesAtAnotherStiffnessAreTheWholeExplorations) {
  const fs::path guide = Scratch("k40"), guided = Scratch("k25"), second = Scratch("k20");
  const StudyResult at40 = RunStudy(SlipAt(40, guide));
  ASSERT_EQ(at40.status, ExplorationStatus::kCompleted);
  ASSERT_EQ(at40.branches.size(), 23u);  // the whole exploration: 3 families on 5 of its half-branches

  StudyOptions o = SlipAt(25, guided);
  o.families_of = guide.string();
  const StudyResult at25 = RunStudy(o);
  const StudyResult whole25 = RunStudy(SlipAt(25));
  ASSERT_EQ(at25.status, ExplorationStatus::kCompleted);
  EXPECT_EQ(at25.branches.size(), 5u);
  EXPECT_EQ(whole25.branches.size(), 23u);
  ExpectSameFamilies(at25, whole25);
  EXPECT_EQ(Families(at25).size(), 3u);
  const nlohmann::json summary = nlohmann::json::parse(at25.summary_json);
  EXPECT_EQ(summary["guided"]["from"], guide.string());
  EXPECT_EQ(summary["guided"]["rays"], 23);
  EXPECT_EQ(summary["guided"]["rays_to_families"], 5);
  // The singular start's three lines without a physical orbit (and with them their 15 descendants).
  EXPECT_EQ(summary["guided"]["pruned_half_branches"], 3);
  EXPECT_EQ(summary["guided"]["pruned"].size(), 3u);

  // A guided study guides the next one: the rays it pruned are the guide's too.
  o = SlipAt(20, second);
  o.families_of = guided.string();
  const StudyResult at20 = RunStudy(o);
  EXPECT_EQ(at20.branches.size(), 5u);
  ExpectSameFamilies(at20, RunStudy(SlipAt(20)));
  EXPECT_EQ(nlohmann::json::parse(at20.summary_json)["guided"]["pruned_half_branches"], 3);
  for (const fs::path& d : {guide, guided, second}) fs::remove_all(d);
}

TEST(FamilyGuide, ARayWithoutAClearCounterpartIsTraced) {
  const fs::path guide = Scratch("rays");
  RunStudy(SlipAt(40, guide));
  const HybridModel model = MakeStudyModel("slip", {{"k", 40}});
  const ShootingLayout layout(model);
  study::FamilyGuide g = study::FamilyGuide::Load(guide.string(), model, layout);
  EXPECT_EQ(g.num_rays(), 23);
  EXPECT_EQ(g.num_fruitful(), 5);
  const StudyResult saved = LoadStudy(guide.string());
  const Vector scales = Vector::Ones(layout.num_unknowns());
  // From the start: branch 3 found no physical orbit (nor did any branch below it), branch 2, the other
  // side of its line, is hopping in place.
  const StudyBranch& unfruitful = saved.branch(3);
  ASSERT_TRUE(unfruitful.family.empty());
  ASSERT_EQ(saved.branch(2).family, "hopping in place");
  ASSERT_EQ(saved.branch(2).parent_special_point, unfruitful.parent_special_point);
  const Vector u = saved.special_points[unfruitful.parent_special_point].u;
  const Vector v = unfruitful.points[1].u - unfruitful.points[0].u;
  EXPECT_TRUE(g.Prune(u, v, scales));
  EXPECT_FALSE(g.Prune(u, -v, scales)) << "its opposite is another half-branch, one that led to a family";
  // Far from every saved switch point: a point the saved study did not have.
  EXPECT_FALSE(g.Prune(u + Vector::Constant(u.size(), 10.0), v, scales));
  // A direction no saved half-branch took from there.
  Vector w = Vector::Zero(v.size());
  w(layout.H_index()) = -1;
  for (const StudyBranch& b : saved.branches) {
    if (b.parent_special_point == unfruitful.parent_special_point) {
      const Vector d = (b.points[1].u - b.points[0].u).normalized();
      ASSERT_LT(std::abs(d.dot(w.normalized())), 0.9) << "the test's direction must be new";
    }
  }
  EXPECT_FALSE(g.Prune(u, w, scales));
  fs::remove_all(guide);
}

TEST(FamilyGuide, RefusedGuidesAreNamedAndNothingIsWritten) {
  const fs::path ball = Scratch("ball"), slip = Scratch("slip"), out = Scratch("out");
  StudyOptions b;
  b.model = "bouncing-ball";
  b.out_dir = ball.string();
  RunStudy(b);
  RunStudy(SlipAt(40, slip));
  const auto refused = [&](StudyOptions o, const std::string& text) {
    o.out_dir = out.string();
    try {
      RunStudy(o);
      ADD_FAILURE() << "accepted: " << text;
    } catch (const StudyOptionError& e) {
      EXPECT_EQ(e.field(), "families_of");
      EXPECT_NE(std::string(e.what()).find(text), std::string::npos) << e.what();
    }
    EXPECT_FALSE(fs::exists(out)) << text;
  };
  StudyOptions o = SlipAt(30);
  o.families_of = (slip / "none").string();
  refused(o, "not a saved study");
  o.families_of = ball.string();
  refused(o, "the saved study is of model 'bouncing-ball', not 'slip'");
  o.families_of = slip.string();
  o.free = "k";
  o.fix = NamedValue{"H", 1.5};
  refused(o, "not with free 'k'");
  o = SlipAt(30);
  o.families_of = slip.string();
  o.formulation = Formulation::kStateBased;
  refused(o, "needs the time-based formulation");
  o = SlipAt(40);
  o.families_of = slip.string();
  o.restart = RestartSpec{slip.string(), "PD4", RestartSpec::Kind::kAuto};
  refused(o, "not with a restart");
  for (const fs::path& d : {ball, slip, out}) fs::remove_all(d);
}

}  // namespace
}  // namespace hybridcont

namespace hybridcont {
namespace {

TEST(FamilyGuide, AnIncompleteGuideIsRefused) {
  const fs::path limited = Scratch("limited"), out = Scratch("limited_out");
  StudyOptions o = SlipAt(40, limited);
  o.max_branches = 5;  // stops before the families' branches below the first branch points are all followed
  ASSERT_EQ(RunStudy(o).status, ExplorationStatus::kMaxBranches);
  o = SlipAt(30, out);
  o.families_of = limited.string();
  try {
    RunStudy(o);
    ADD_FAILURE() << "an incomplete guide accepted";
  } catch (const StudyOptionError& e) {
    EXPECT_EQ(e.field(), "families_of");
    EXPECT_NE(std::string(e.what()).find("did not complete (its exploration: max-branches)"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(out));
  for (const fs::path& d : {limited, out}) fs::remove_all(d);
}

// A study that continued one family pruned the half-branches of the others: as a guide it serves a study of
// that family, not one of every family (which would lose forward and backward hopping).
TEST(FamilyGuide, RaysPrunedForOneFamilyDoNotPruneTheOthers) {
  const fs::path whole = Scratch("whole"), one = Scratch("one"), all = Scratch("all");
  RunStudy(SlipAt(40, whole));
  StudyOptions o = SlipAt(35, one);
  o.families_of = whole.string();
  o.families = {"hopping in place"};
  const StudyResult hopping = RunStudy(o);
  EXPECT_EQ(Families(hopping).size(), 1u);
  EXPECT_EQ(hopping.branches.size(), 1u);
  const nlohmann::json guided = nlohmann::json::parse(hopping.summary_json)["guided"];
  EXPECT_EQ(guided["families"], nlohmann::json::array({"hopping in place"}));
  // Three at the start; at SB1 and at SB5 both directions, forward and backward hopping.
  EXPECT_EQ(guided["pruned_half_branches"], 7);
  o = SlipAt(30, all);
  o.families_of = one.string();
  o.families = {};
  const StudyResult every = RunStudy(o);
  ExpectSameFamilies(every, RunStudy(SlipAt(30)));
  EXPECT_EQ(Families(every).size(), 3u);
  // The same guide, asked for the family it continued, prunes what it pruned.
  o.out_dir.clear();
  o.families = {"hopping in place"};
  EXPECT_EQ(RunStudy(o).branches.size(), 1u);
  for (const fs::path& d : {whole, one, all}) fs::remove_all(d);
}

// What a guided study says it pruned does not depend on its threads (speculative switches ask about rays the
// serial exploration never reaches).
TEST(FamilyGuide, WhatIsPrunedIsTheSameOnOneThreadAndTwo) {
  const fs::path whole = Scratch("threads_whole");
  RunStudy(SlipAt(40, whole));
  nlohmann::json guided[2];
  for (const int threads : {1, 2}) {
    StudyOptions o = SlipAt(25);
    o.families_of = whole.string();
    o.threads = threads;
    const StudyResult s = RunStudy(o);
    guided[threads - 1] = nlohmann::json::parse(s.summary_json)["guided"];
    EXPECT_EQ(s.branches.size(), 5u) << threads;
  }
  EXPECT_EQ(guided[0], guided[1]);
  fs::remove_all(whole);
}

}  // namespace
}  // namespace hybridcont
