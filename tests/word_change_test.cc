// Changes of the phase sequence (word_change.h, src/study/stages/word_families.h) against closed forms: the ball between
// a floor and a ceiling (models/ball-ceiling.toml: one word below H = g h, another above) and the SLIP's
// hopping in place handed over to the stance-only oscillation where its flight time vanishes (models/slip.toml).
#include "hybridcont/word_change.h"

#include <gtest/gtest.h>

#include "hybridcont/automaton_words.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "cli_runner.h"
#include "edited_model.h"
#include "csv_columns.h"
#include "hybridcont/model_builder.h"
#include "hybridcont/model_file.h"
#include "hybridcont/shooting_layout.h"
#include "models/ball_flight.h"

namespace hybridcont {
namespace {

namespace fs = std::filesystem;
using app::CliResult;
using app::RunTool;

nlohmann::json RunModel(const std::string& file, const fs::path& dir) {
  const CliResult r = RunTool({"run", std::string(HYBRIDCONT_SOURCE_DIR) + "/models/" + file, "--out", dir.string(),
                               "--quiet", "--no-plots", "--threads", "1", "--overwrite"});
  EXPECT_EQ(r.code, 0) << r.err;
  std::ifstream in(dir / "summary.json");
  return nlohmann::json::parse(in);
}

// A start in another word is checked for energy conservation like the file's word: the bipedal model's
// landing (a transition of the running word only) placing the foot 0.01 off the leg's rest length is refused
// before anything is written.
TEST(WordChange, StartInAnotherWordHasItsResetsCheckedForConservation) {
  const fs::path dir = fs::temp_directory_path() / "hybridcont_word_conservation";
  ASSERT_TRUE(WriteEditedModel("bipedal-slip.toml", "reset.x = \"-l0*sin(beta)\"",
                               "reset.x = \"-l0*sin(beta) + 0.01\"", dir / "biped.toml"));
  const CliResult r = RunTool({"run", (dir / "biped.toml").string(), "--out", (dir / "out").string(), "--quiet",
                               "--no-plots"});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("reset 'flight' -> 'stance'"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "out"));
}

// A transition that only a change of the phase sequence reaches (the ball's ceiling, above H = g h) has its
// reset checked before anything runs: a ceiling that takes a tenth of the speed is refused, naming it, and
// `check` shows the word through it.
TEST(WordChange, TransitionReachedOnlyByAHandOverIsCheckedForConservation) {
  const fs::path dir = fs::temp_directory_path() / "hybridcont_word_handover_conservation";
  ASSERT_TRUE(WriteEditedModel("ball-ceiling.toml", "event = \"h - y\"\nreset.v = \"-v\"",
                               "event = \"h - y\"\nreset.v = \"-0.9*v\"", dir / "ball.toml"));
  const CliResult r = RunTool({"run", (dir / "ball.toml").string(), "--out", (dir / "out").string(), "--quiet",
                               "--no-plots"});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("transition 'ceiling'"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("does not conserve its energy"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "out"));
  const CliResult check = RunTool({"check", (dir / "ball.toml").string()});
  EXPECT_EQ(check.code, 1);
  EXPECT_NE(check.out.find("word fly (ceiling) (checked for its transitions; takes ceiling)"), std::string::npos)
      << check.out;
  EXPECT_NE(check.out.find("2 words checked, 2 of 2 transitions taken: FAILURES above"), std::string::npos) << check.out;
  // The model as shipped passes on both words.
  const CliResult shipped = RunTool({"check", std::string(HYBRIDCONT_SOURCE_DIR) + "/models/ball-ceiling.toml"});
  EXPECT_EQ(shipped.code, 0) << shipped.out;
  EXPECT_NE(shipped.out.find("2 words checked, 2 of 2 transitions taken: all pass"), std::string::npos) << shipped.out;
}

// Words through every transition: a shortest cycle from the anchor mode through each transition that the
// given words do not take; a transition out of a mode the anchor cannot reach is on no cycle.
TEST(WordChange, WordsThroughEveryTransitionAreShortestCycles) {
  // A (anchor) -a-> B -b-> A, B -c-> C -d-> A, C -e-> C (a cut), D -f-> A with D unreachable.
  std::vector<AutomatonMode> modes = {{"A", {"x"}}, {"B", {"x"}}, {"C", {"x"}}, {"D", {"x"}}};
  std::vector<AutomatonTransition> transitions = {{"a", 0, 1}, {"b", 1, 0}, {"c", 1, 2}, {"d", 2, 0},
                                                  {"e", 2, 2, nullptr, true}, {"f", 3, 0}};
  const auto graph = HybridAutomaton::Graph("g", modes, transitions, 0);
  std::vector<int> untaken;
  const std::vector<Word> words = WordsThroughEveryTransition(*graph, {{0, 1}}, &untaken);
  ASSERT_EQ(words.size(), 2u);
  EXPECT_EQ(words[0], (Word{0, 2, 3}));     // a, c, d
  EXPECT_EQ(words[1], (Word{0, 2, 4, 3}));  // a, c, the cut e, d
  EXPECT_EQ(untaken, (std::vector<int>{5}));
  for (const Word& w : words) EXPECT_NO_THROW(graph->CheckWord(w));
  EXPECT_EQ(TransitionsOf(Word{0, 2, 4, 2}), (std::vector<int>{0, 2, 4}));
}

// Floor only (g = h = 1): period 2 sqrt(2H); floor and ceiling: twice the time from the floor up to h.
TEST(WordChange, BallBetweenFloorAndCeilingChangesItsWordAtGh) {
  const fs::path dir = fs::temp_directory_path() / "hybridcont_word_ball";
  const nlohmann::json s = RunModel("ball-ceiling.toml", dir);
  ASSERT_EQ(s["word_changes"].size(), 1u) << s["word_changes"].dump(1);
  const nlohmann::json& c = s["word_changes"][0];
  EXPECT_TRUE(c["accepted"].get<bool>());
  EXPECT_EQ(c["from_word"], nlohmann::json({"fly"}));
  EXPECT_EQ(c["to_word"], nlohmann::json({"fly", "fly"}));
  EXPECT_NEAR(c["H"].get<double>(), 1.0, 1e-10);  // the apex touches the ceiling at H = g h
  EXPECT_LT(c["state_difference"].get<double>(), 1e-10);
  EXPECT_LT(c["period_difference"].get<double>(), 1e-10);
  ASSERT_EQ(c["to_branches"].size(), 2u);
  int floor_points = 0, ceiling_points = 0, violated = 0;
  for (const nlohmann::json& b : s["branches"]) {
    const auto col = ReadColumns(dir / b["file"].get<std::string>());
    const bool ceiling = b["word"].size() == 2;
    for (std::size_t i = 0; i < col.at("H").size(); ++i) {
      const double H = col.at("H")[i], T = col.at("T")[i], v0 = std::sqrt(2 * H);
      if (col.at("physical")[i] != 1) {
        // The floor-only orbit above g h: the ceiling's guard is crossed (constraint-violated).
        violated += !ceiling && H > 1 + 1e-6;
        continue;
      }
      // The automaton's own simulation (the first guard crossed wins) takes the word and returns to the orbit.
      EXPECT_LT(col.at("automaton_replay_error")[i], 1e-8) << "H = " << H;
      if (ceiling) {
        EXPECT_GT(H, 1 - 1e-9);
        EXPECT_NEAR(T, 2 * (v0 - std::sqrt(v0 * v0 - 2)), 1e-9) << "H = " << H;
        ++ceiling_points;
      } else {
        EXPECT_LT(H, 1 + 1e-9);
        EXPECT_NEAR(T, 2 * v0, 1e-9) << "H = " << H;
        ++floor_points;
      }
    }
  }
  EXPECT_GT(floor_points, 5);
  EXPECT_GT(ceiling_points, 10);
  EXPECT_GT(violated, 5);
  fs::remove_all(dir);
}

// The SLIP (k = 40): hopping in place reaches t2 = 0 at H = 1, where the flight phase is removed; the
// stance-only family is the vertical oscillation, period 2π sqrt(m/k) whatever its amplitude, nadir
// l = l0 − m g/k − A with ½ k A² = H − H_eq, H_eq = m g (l0 − m g/(2k)).
TEST(WordChange, SlipHoppingInPlaceHandedOverToTheStanceOnlyOscillationAndBack) {
  const fs::path dir = fs::temp_directory_path() / "hybridcont_word_slip";
  const nlohmann::json s = RunModel("slip.toml", dir);
  const double k = 40, H_eq = 1 - 1 / (2 * k);
  int removed = 0, back = 0;
  for (const nlohmann::json& c : s["word_changes"]) {
    if (c["at"] == "t2 = 0") {
      ++removed;
      EXPECT_TRUE(c["accepted"].get<bool>());
      EXPECT_EQ(c["to_word"], nlohmann::json({"stance"}));
      EXPECT_NEAR(c["H"].get<double>(), 1.0, 1e-12);
      EXPECT_LT(c["state_difference"].get<double>(), 1e-10);
      EXPECT_LT(c["period_difference"].get<double>(), 1e-10);
    } else if (c["accepted"].get<bool>()) {
      ++back;  // the liftoff guard touched at the apex: flight inserted, onto the traced word stance > flight
      EXPECT_EQ(c["to_word"], nlohmann::json({"stance", "flight"}));
      EXPECT_NEAR(c["H"].get<double>(), 1.0, 1e-9);
      ASSERT_EQ(c["to_branches"].size(), 1u);
    }
  }
  EXPECT_EQ(removed, 1);
  EXPECT_EQ(back, 1);
  ASSERT_EQ(s["words"].size(), 2u);  // each word explored once
  int stance_points = 0;
  for (const nlohmann::json& b : s["branches"]) {
    if (b["word"] != nlohmann::json({"stance"})) continue;
    const auto col = ReadColumns(dir / b["file"].get<std::string>());
    for (std::size_t i = 0; i < col.at("H").size(); ++i) {
      if (col.at("physical")[i] != 1) continue;
      const double H = col.at("H")[i];
      EXPECT_NEAR(col.at("T")[i], 2 * M_PI / std::sqrt(k), 1e-10) << "H = " << H;
      EXPECT_NEAR(col.at("x1_l")[i], 1 - 1 / k - std::sqrt(2 * (H - H_eq) / k), 1e-9) << "H = " << H;
      EXPECT_LT(col.at("replay_error")[i], 1e-8);  // the event-driven simulation returns to the orbit
      EXPECT_LT(col.at("automaton_replay_error")[i], 1e-8);  // and the automaton's, by the first guard crossed
      ++stance_points;
    }
  }
  // The physical stance-only family spans H from the equilibrium, 0.9875, to 1: three accepted points at the
  // run's step sizes (beyond the equilibrium the same family has its section at the apex: wrong-direction).
  EXPECT_GE(stance_points, 3);
  fs::remove_all(dir);
}

// The library's check at the closed-form orbit itself, and the refusal of a word that does not fit.
TEST(WordChange, RemovedFlightPhaseGivesTheSameOrbitAndAMismatchIsNamed) {
  ModelFileOptions options;
  options.compile = false;
  const HybridModel slip = LoadModelFile(std::string(HYBRIDCONT_SOURCE_DIR) + "/models/slip.toml", options);
  const ShootingLayout layout(slip);
  const double k = 40, half = M_PI / std::sqrt(k);
  Vector u = Vector::Zero(layout.num_unknowns());
  u(layout.time_index(0)) = half;
  u(layout.time_index(2)) = half;
  u(layout.state_offset(0) + 1) = 1 - 2 / k;  // nadir
  u(layout.state_offset(1)) = 1;              // flight: y = l0
  u(layout.state_offset(2) + 1) = 1;          // back in stance at l = l0
  u(layout.H_index()) = 1;
  std::string why;
  const std::vector<WordChange> c = WordsWithoutPhase(slip, u, 1, IntegratorOptions{}, &why);
  ASSERT_EQ(c.size(), 1u) << why;
  EXPECT_TRUE(c[0].accepted) << c[0].reason;
  EXPECT_LT(c[0].residual, 1e-9);
  EXPECT_LT(c[0].state_difference, 1e-10);
  EXPECT_LT(c[0].period_difference, 1e-10);
  // Off the hand-over (a longer stance, so the leg is not at its natural length where the flight starts), the
  // same change is refused and the failing transition named (its reset here: the leg is not at l0).
  u(layout.time_index(0)) = 0.8 * half;
  const std::vector<WordChange> off = WordsWithoutPhase(slip, u, 1, IntegratorOptions{}, &why);
  ASSERT_EQ(off.size(), 1u);
  EXPECT_FALSE(off[0].accepted);
  EXPECT_NE(off[0].reason.find("of 'apex'"), std::string::npos) << off[0].reason;
}


// Written as a new user would, from the format reference alone: Shaw & Holmes' linear oscillator against a
// rigid wall at x = d. Below H = d²/2 it swings freely (word: the cut `top`), above it hits the wall: period
// 2π − 2 arccos(d/A), A = √(2H). The free swing's guard v crosses zero upwards inside its phase: a cut's
// guard marks a time and does not bound the state, so the free family is physical.
TEST(WordChange, OscillatorAgainstAWallChangesItsWordAtHalfDSquared) {
  const fs::path dir = fs::temp_directory_path() / "hybridcont_word_wall";
  fs::create_directories(dir);
  {
    std::ofstream f(dir / "wall.toml");
    f << R"toml(hybridcont = 1
name = "wall-oscillator"
description = "Shaw & Holmes: a linear oscillator against a rigid wall at x = d, which it reaches above H = d^2/2"
word = ["top"]

[parameters]
d = { value = 0.5, range = "(0, inf)", description = "wall position" }

[[modes]]
name = "swing"
states = ["x", "v"]
ode = { x = "v", v = "-x" }
energy = "0.5*(v^2 + x^2)"
anchor = "x"

[[transitions]]
name = "top"
from = "swing"
to = "swing"
event = "v"

[[transitions]]
name = "wall"
from = "swing"
to = "swing"
event = "d - x"
reset.v = "-v"

[start]
kind = "guess"
values = { H = 0.05, t1 = 4.71238898038469, t2 = 1.5707963267949, x1_x = 0, x1_v = -0.316227766016838, x2_x = 0.316227766016838, x2_v = 0 }

[run]
bounds = { xi = [-1, 1], H = [0.02, 0.5], period = [-20, 20] }
)toml";
  }
  const CliResult r = RunTool({"run", (dir / "wall.toml").string(), "--out", (dir / "out").string(), "--quiet",
                               "--no-plots", "--threads", "1", "--overwrite"});
  ASSERT_EQ(r.code, 0) << r.err;
  std::ifstream in(dir / "out" / "summary.json");
  const nlohmann::json s = nlohmann::json::parse(in);
  ASSERT_EQ(s["word_changes"].size(), 1u);
  EXPECT_TRUE(s["word_changes"][0]["accepted"].get<bool>());
  EXPECT_NEAR(s["word_changes"][0]["H"].get<double>(), 0.125, 1e-10);
  int free_points = 0, wall_points = 0;
  for (const nlohmann::json& b : s["branches"]) {
    const auto col = ReadColumns(dir / "out" / b["file"].get<std::string>());
    for (std::size_t i = 0; i < col.at("H").size(); ++i) {
      if (col.at("physical")[i] != 1) continue;
      const double H = col.at("H")[i], T = col.at("T")[i];
      if (H < 0.125 - 1e-9) {
        EXPECT_NEAR(T, 2 * M_PI, 1e-10) << "H = " << H;
        ++free_points;
      } else if (H > 0.125 + 1e-9) {
        EXPECT_NEAR(T, 2 * M_PI - 2 * std::acos(0.5 / std::sqrt(2 * H)), 1e-9) << "H = " << H;
        ++wall_points;
      }
      EXPECT_LT(col.at("automaton_replay_error")[i], 1e-8);
    }
  }
  EXPECT_GT(free_points, 5);
  EXPECT_GT(wall_points, 5);
  fs::remove_all(dir);
}
}  // namespace
}  // namespace hybridcont

namespace hybridcont {
namespace {

// The same automaton in C++: phases written once as templates (model_builder.h), a factory that builds the
// cyclic model of any word, and the guards as smooth functions.
template <class T>
struct CeilingParameters {
  T m = 1.0;
  T g = 1.0;
  T h = 1.0;
};
// The built-in ball's flight (models/ball_flight.h) ends at the floor; the same flight ends at the ceiling.
using FlyToFloor = internal::BallFlight;
struct FlyToCeiling : internal::BallFlight {
  template <class T, class Q>
  static T Event(const StateVector<T>& x, const Q& p) {
    return p.h - x(0);
  }
};
struct Section {  // the ball passing y = 1/4 downwards
  static constexpr int kDimension = 2;
  template <class T, class Q>
  static T Anchor(const StateVector<T>& x, const Q&) {
    return x(0) - 0.25;
  }
};
class Guard : public SmoothFunction {  // y (floor) or h − y (ceiling); parameters [m, g, h]
 public:
  explicit Guard(bool ceiling) : ceiling_(ceiling) {}
  double Evaluate(const Eigen::Ref<const Vector>& x, const Eigen::Ref<const Vector>& p, RowVector* dx,
                  RowVector* dp) const override {
    const double s = ceiling_ ? -1 : 1;
    if (dx) *dx = RowVector::Zero(2), (*dx)(0) = s;
    if (dp) *dp = RowVector::Zero(p.size()), (*dp)(2) = ceiling_ ? 1 : 0;
    return ceiling_ ? p(2) - x(0) : x(0);
  }

 private:
  bool ceiling_;
};

TEST(WordChange, CppAutomatonInsertsTheCeilingWhereTheApexTouchesIt) {
  const auto factory = [](const Word& word) {
    ModelBuilder<CeilingParameters<double>> b("ball-ceiling-cpp", "ball between floor and ceiling");
    b.Parameter("m", [](auto& p) -> auto& { return p.m; }, "mass", ParameterRange::Positive())
        .Parameter("g", [](auto& p) -> auto& { return p.g; }, "gravity", ParameterRange::Positive())
        .Parameter("h", [](auto& p) -> auto& { return p.h; }, "ceiling", ParameterRange::Positive());
    for (int t : word) {
      if (t == 0) b.AddPhase<FlyToFloor>("fly", {"y", "v"}, Vector(Eigen::Vector2d(0.5, -0.3)));
      else b.AddPhase<FlyToCeiling>("fly", {"y", "v"}, Vector(Eigen::Vector2d(0.5, 0.3)));
    }
    b.SetAnchor<Section>();
    return b.Build();
  };
  const auto automaton =
      HybridAutomaton::Create("ball-ceiling-cpp", {{"fly", {"y", "v"}}},
                              {{"floor", 0, 0, std::make_shared<Guard>(false)},
                               {"ceiling", 0, 0, std::make_shared<Guard>(true)}},
                              0, factory);
  const Word floor_only = automaton->WordOf({"floor"});
  EXPECT_EQ(floor_only, Word({0}));
  const HybridModel model = automaton->ModelForWord(floor_only);
  ASSERT_EQ(model.observables().size(), 1u);  // the ceiling competes with the floor
  EXPECT_EQ(model.observables()[0].name, "ceiling_guard");
  // The floor-only orbit at H = g h = 1: down from y = 1/4 to the floor, up to the apex y = 1 (time √2) and
  // down to y = 1/4.
  const ShootingLayout layout(model);
  const double v_section = std::sqrt(2 * 0.75), t_down = std::sqrt(2.0) - std::sqrt(2 * 0.75);
  Vector u = Vector::Zero(layout.num_unknowns());
  u(layout.time_index(0)) = t_down;
  u(layout.state_offset(0)) = 0.25;
  u(layout.state_offset(0) + 1) = -v_section;
  u(layout.time_index(1)) = 2 * std::sqrt(2.0) - t_down;
  u(layout.state_offset(1) + 1) = std::sqrt(2.0);
  u(layout.H_index()) = 1;
  std::string why;
  const std::vector<WordChange> c = WordsWithTransition(model, u, 1, 1, std::sqrt(2.0), IntegratorOptions{}, &why);
  ASSERT_EQ(c.size(), 1u) << why;
  EXPECT_TRUE(c[0].accepted) << c[0].reason;
  EXPECT_FALSE(c[0].singular);  // a fold of the new word's family, a regular point of its map
  EXPECT_EQ(c[0].word, Word({0, 1}));
  EXPECT_LT(c[0].residual, 1e-9);
  EXPECT_LT(c[0].state_difference, 1e-10);
  EXPECT_LT(c[0].period_difference, 1e-10);
  EXPECT_EQ(automaton->WordName(c[0].word), "fly (floor) > fly (ceiling)");
}

}  // namespace
}  // namespace hybridcont
