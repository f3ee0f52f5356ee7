// What the tool tells a person about its numbers, checked against values that do not come from the
// shooting code:
//   - the vibrating table's fold, a turning point in the amplitude at the closed form A_sn = (1 − e) g π /
//     ((1 + e) w²), reported once (as the fold, not also as a Floquet BP), and its impact phase against the
//     closed form cos(th_i) = A_sn / A at every physical point, the two halves named by that phase;
//   - the forced impact oscillator's family: every physical point has positive durations and a positive
//     impact speed, and its orbit is confirmed by a simulation written here (odeint, events by bisection);
//   - family names and the period: the walkers' key frames are named by the rule on T;
//   - a branch switched at an SB point starts neutrally stable (its colliding multipliers are unit), the
//     Lagrangian rod as the built-in one;
//   - starts that are not orbits are refused before anything is written, saying which part of the cycle
//     does not close; a guess Newton moves is reported.
#include <gtest/gtest.h>

#include <array>
#include <boost/numeric/odeint.hpp>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <nlohmann/json.hpp>
#include <numbers>
#include <set>
#include <string>

#include "cli_runner.h"
#include "csv_columns.h"
#include "edited_model.h"

namespace hybridcont::app {
namespace {

namespace fs = std::filesystem;
namespace odeint = boost::numeric::odeint;

std::string ModelPath(const std::string& name) { return std::string(HYBRIDCONT_SOURCE_DIR) + "/models/" + name; }

nlohmann::json RunQuietly(const std::vector<std::string>& model_and_options, const fs::path& dir) {
  std::vector<std::string> args = {"run"};
  args.insert(args.end(), model_and_options.begin(), model_and_options.end());
  for (const char* a : {"--quiet", "--no-plots", "--overwrite"}) args.push_back(a);
  args.push_back("--out");
  args.push_back(dir.string());
  const CliResult r = RunTool(args);
  EXPECT_EQ(r.code, 0) << r.err;
  std::ifstream in(dir / "summary.json");
  return nlohmann::json::parse(in);
}

// The ball on a vibrating table (g = w = 1, restitution e): where its early-impact period-one orbit ends.
// Leaving the table at phase th = -acos(A_sn/A) with speed pi, the gap after time t is
// G(t) = A sin th + pi t - t^2/2 - A sin(th + t); the orbit ends at the A where G's interior minimum (where
// G' = pi - t - A cos(th + t) goes from - to +) is 0: the ball's path touches the rising table. Bisection
// in A on the minimum, each found by bisection on G'.
double EarlyImpactEnd(double e) {
  const double A_sn = (1 - e) * std::numbers::pi / (1 + e);
  const auto interior_minimum = [&](double A) {
    const double th = -std::acos(A_sn / A);
    const auto slope = [&](double t) { return std::numbers::pi - t - A * std::cos(th + t); };
    double smallest = 1e300;
    constexpr int kSamples = 4000;
    for (int i = 1; i < kSamples; ++i) {
      double a = 2 * std::numbers::pi * (i - 1) / kSamples, b = 2 * std::numbers::pi * i / kSamples;
      if (!(slope(a) < 0 && slope(b) > 0)) continue;
      for (int it = 0; it < 100; ++it) (slope(0.5 * (a + b)) < 0 ? a : b) = 0.5 * (a + b);
      smallest = std::min(smallest, A * std::sin(th) + std::numbers::pi * a - a * a / 2 - A * std::sin(th + a));
    }
    return smallest;
  };
  double lo = 2.0, hi = 3.0;
  for (int it = 0; it < 60; ++it) (interior_minimum(0.5 * (lo + hi)) > 0 ? lo : hi) = 0.5 * (lo + hi);
  return lo;
}

TEST(VibratingTable, FoldIsOneTurningPointAtTheClosedFormAndImpactPhasesAreExact) {
  const fs::path dir = fs::temp_directory_path() / "hybridcont_true_table";
  const nlohmann::json summary = RunQuietly({ModelPath("vibrating-table.toml")}, dir);
  const double e = 0.5, A_sn = (1 - e) * std::numbers::pi / (1 + e);
  int folds = 0, bps_at_fold = 0;
  for (const nlohmann::json& sp : summary["special_points"]) {
    const double A = sp["A"].get<double>();
    if (sp["type"] == "TP") {
      ++folds;
      EXPECT_EQ(sp["status"], "located");
      EXPECT_NEAR(A, A_sn, 1e-10);
      EXPECT_LT(sp["precision"].get<double>(), 1e-8);
    }
    if (sp["type"] == "BP" && std::abs(A - A_sn) < 1e-6) ++bps_at_fold;
  }
  EXPECT_EQ(folds, 1);
  EXPECT_EQ(bps_at_fold, 0);  // the fold's multiplier +1 is the fold itself
  int physical = 0;
  for (const nlohmann::json& b : summary["branches"]) {
    auto c = ReadColumns(dir / b["file"].get<std::string>());
    for (std::size_t i = 0; i < c["A"].size(); ++i) {
      if (c["physical"][i] != 1) continue;
      ++physical;
      const double exact = std::acos(A_sn / c["A"][i]);
      EXPECT_NEAR(std::abs(c["impact_phase"][i]), exact, 1e-9) << "A = " << c["A"][i];
      EXPECT_NEAR(c["T"][i], 2 * std::numbers::pi, 1e-9);
    }
  }
  EXPECT_GT(physical, 50);
  // Stable (late impact) from the fold, where it meets the saddle of early impact, to a period doubling: both
  // ends the located points, in summary.json's stable ranges.
  std::set<std::string> stable_ends;
  for (const nlohmann::json& b : summary["branches"]) {
    if (!b.contains("stable_ranges")) continue;
    for (const nlohmann::json& r : b["stable_ranges"]) {
      for (const char* end : {"from", "to"}) {
        const std::string how = r[std::string(end) + "_how"].get<std::string>();
        if (how.rfind("TP #", 0) == 0) {
          EXPECT_NEAR(r[end].get<double>(), A_sn, 1e-10);
          stable_ends.insert("TP");
        }
        if (how.rfind("PD #", 0) == 0) stable_ends.insert("PD");
      }
    }
  }
  EXPECT_EQ(stable_ends, (std::set<std::string>{"TP", "PD"}));
  // The two key frames: one orbit of each half of the fold, named by the sign of the impact phase.
  std::set<std::string> labels;
  for (const nlohmann::json& o : summary["orbits"]) labels.insert(o["label"].get<std::string>());
  EXPECT_EQ(labels, (std::set<std::string>{"period one, late impact", "period one, early impact"}));
  // The early-impact family ends where the ball's path touches the rising table during the rebound (the
  // file's constraint 'gap', CB), at the closed form.
  const double lo = EarlyImpactEnd(e);
  int boundaries = 0;
  double tool_end = std::nan("");
  for (const nlohmann::json& sp : summary["special_points"]) {
    if (sp["type"] != "CB" || sp["duplicate_of"] != -1) continue;
    ++boundaries;
    tool_end = sp["A"].get<double>();
    EXPECT_EQ(sp["status"], "located");
    EXPECT_NEAR(sp["A"].get<double>(), lo, 1e-10) << "closed form " << lo;
  }
  EXPECT_EQ(boundaries, 1);
  bool early_ends_at_cb = false;
  for (const nlohmann::json& b : summary["branches"]) {
    for (const nlohmann::json& r : b.value("physical_ranges", nlohmann::json::array())) {
      if (r["family"] != "period one, early impact") continue;
      for (const char* end : {"from", "to"}) {
        if (r[std::string(end) + "_how"].get<std::string>().rfind("CB #", 0) == 0) {
          early_ends_at_cb = std::abs(r[end].get<double>() - lo) < 1e-10;
        }
      }
    }
  }
  EXPECT_TRUE(early_ends_at_cb) << summary["report"];
  std::printf("vibrating table: early impact ends at A = %.12f (closed form %.12f)\n", tool_end, lo);
  fs::remove_all(dir);
}

// The same ball and table written as one phase from impact to impact (the table's phase as a point on a
// stable limit cycle (c, s), so that nothing is wrapped): the early-impact orbit's own event, the gap, is
// touched inside the flight where the family ends. That end is located as a grazing inside the phase (GR),
// at the closed form within its stated precision, and the family's physical range ends there.
TEST(VibratingTable, AnEventTouchedInsideItsPhaseEndsTheFamilyAtALocatedGrazing) {
  const fs::path dir = fs::temp_directory_path() / "hybridcont_true_table_one_phase";
  fs::create_directories(dir);
  std::ofstream(dir / "table1.toml") << R"toml(hybridcont = 1
name = "table-one-phase"
conservative = false

[parameters]
A = { value = 1.4, range = "(0, inf)" }
e = { value = 0.5, range = "[0, 1)" }

[definitions]
A_sn = "(1 - e)*pi/(1 + e)"
th_i = "acos(A_sn/A)"

[[phases]]
name = "flight"
states = ["y", "v", "c", "s"]
typical = [2.0, -1.0, 0.5, 0.5]
ode = { y = "v", v = "-1", c = "-s + c*(1 - c^2 - s^2)", s = "c + s*(1 - c^2 - s^2)" }
event = "y - A*s"
anchor = "v"
reset = { y = "y", v = "(1 + e)*A*c - e*v", c = "c", s = "s" }

[start]
kind = "simulation"
cycles = 1
values = { x1_y = "A*sin(th_i) + pi^2/2", x1_v = 0, x1_c = "cos(th_i + pi)", x1_s = "sin(th_i + pi)" }

[run]
parameter = "A"
bounds = { A = [0.5, 3.0], period = [0, 20] }

[[families]]
name = "late impact"
when = "x1_s < 0"

[[families]]
name = "early impact"
)toml";
  const nlohmann::json summary = RunQuietly({(dir / "table1.toml").string()}, dir / "out");
  const double exact = EarlyImpactEnd(0.5);
  int grazings = 0, gr_id = -1;
  for (const nlohmann::json& sp : summary["special_points"]) {
    if (sp["type"] != "GR" || sp["duplicate_of"] != -1) continue;
    ++grazings;
    gr_id = sp["id"].get<int>();
    EXPECT_EQ(sp["status"], "located");
    const double precision = sp["precision"].get<double>();
    EXPECT_LT(precision, 1e-8);
    EXPECT_LE(std::abs(sp["A"].get<double>() - exact), precision) << "closed form " << exact;
    std::printf("one-phase table: GR at A = %.12f, precision %.1e (closed form %.12f)\n", sp["A"].get<double>(),
                precision, exact);
  }
  EXPECT_EQ(grazings, 1);
  bool ends_there = false;
  for (const nlohmann::json& b : summary["branches"]) {
    for (const nlohmann::json& r : b.value("physical_ranges", nlohmann::json::array())) {
      ends_there = ends_there || (r["family"] == "early impact" && r["to_special_point"] == gr_id);
    }
  }
  EXPECT_TRUE(ends_there) << summary["report"];
  fs::remove_all(dir);
}

// The forced impact oscillator (models/forced-impact-oscillator.toml) simulated here: the approach from x1
// until x reaches d (bisection on the dense output), v -> -e v, the rebound until the forcing phase
// reaches pi (wrapped by 2 pi), the approach until v crosses 0 upward. Returns the state back at the section.
struct Oscillator {
  double k = 1, c = 0.1, A = 0.3, w, d = 1, e = 0.8;
  using State = std::array<double, 3>;
  void operator()(const State& s, State& ds, double) const {
    ds = {s[1], -k * s[0] - c * s[1] + A * std::cos(s[2]), w};
  }
  // Runs from s until g crosses from > 0 to <= 0; false if it does not within 50 time units.
  template <class G>
  bool Until(State* s, double* t, G g) const {
    auto stepper = odeint::make_dense_output(1e-13, 1e-13, odeint::runge_kutta_dopri5<State>());
    stepper.initialize(*s, 0.0, 1e-3);
    double g_prev = g(*s);
    while (stepper.current_time() < 50) {
      stepper.do_step(*this);
      const double g_now = g(stepper.current_state());
      if (g_prev > 0 && g_now <= 0) {
        double a = stepper.previous_time(), b = stepper.current_time();
        for (int i = 0; i < 200 && b - a > 1e-15; ++i) {
          const double mid = 0.5 * (a + b);
          State x;
          stepper.calc_state(mid, x);
          (g(x) > 0 ? a : b) = mid;
        }
        stepper.calc_state(b, *s);
        *t = b;
        return true;
      }
      g_prev = g_now;
    }
    return false;
  }
};

TEST(ForcedImpactOscillator, PhysicalPointsHavePositiveDurationsAndAreConfirmedBySimulation) {
  const fs::path dir = fs::temp_directory_path() / "hybridcont_true_oscillator";
  const nlohmann::json summary = RunQuietly({ModelPath("forced-impact-oscillator.toml")}, dir);
  int physical = 0, simulated = 0;
  for (const nlohmann::json& b : summary["branches"]) {
    auto c = ReadColumns(dir / b["file"].get<std::string>());
    for (std::size_t i = 0; i < c["w"].size(); ++i) {
      if (c["physical"][i] != 1) {
        // Not physical: the impact is met from the wrong side or the orbit crosses the stop before it.
        continue;
      }
      ++physical;
      for (const char* t : {"t1", "t2", "t3"}) EXPECT_GT(c[t][i], 0) << t << " at w = " << c["w"][i];
      EXPECT_GT(c["impact_speed"][i], 0) << "w = " << c["w"][i];
      if (i % 5 != 0) continue;
      Oscillator o;
      o.w = c["w"][i];
      Oscillator::State s = {c["x1_x"][i], c["x1_v"][i], c["x1_s"][i]};
      const Oscillator::State x1 = s;
      double t1 = 0, t2 = 0, t3 = 0;
      ASSERT_TRUE(o.Until(&s, &t1, [&](const Oscillator::State& x) { return o.d - x[0]; }));
      s[1] = -o.e * s[1];
      ASSERT_TRUE(o.Until(&s, &t2, [](const Oscillator::State& x) { return std::numbers::pi - x[2]; }));
      s[2] -= 2 * std::numbers::pi;
      ASSERT_TRUE(o.Until(&s, &t3, [](const Oscillator::State& x) { return -x[1]; }));
      EXPECT_NEAR(t1, c["t1"][i], 1e-8);
      EXPECT_NEAR(t2, c["t2"][i], 1e-8);
      EXPECT_NEAR(t3, c["t3"][i], 1e-8);
      for (int j = 0; j < 3; ++j) EXPECT_NEAR(s[j], x1[j], 1e-8) << "w = " << o.w;
      ++simulated;
    }
  }
  EXPECT_GT(physical, 40);
  EXPECT_GT(simulated, 8);
  std::printf("%d physical points, %d of them simulated\n", physical, simulated);
  fs::remove_all(dir);
}

TEST(FamilyNames, TheSimplestWalkersGaitsAreNamedByTheirPeriod) {
  const fs::path dir = fs::temp_directory_path() / "hybridcont_true_names_walker";
  const nlohmann::json summary = RunQuietly({ModelPath("simplest-walker.toml")}, dir);
  std::set<std::string> labels;
  for (const nlohmann::json& o : summary["orbits"]) {
    labels.insert(o["label"].get<std::string>());
    // The file's rule: the long-period gait has T > 3.2 (its period, not its last phase's duration).
    const bool long_gait = o["label"].get<std::string>().rfind("long", 0) == 0;
    EXPECT_EQ(long_gait, o["T"].get<double>() > 3.2) << o.dump();
  }
  EXPECT_EQ(labels, (std::set<std::string>{"long-period gait", "short-period gait"}));
  fs::remove_all(dir);
}

// The compass gait's two gaits, with the file's uniform-bar legs and with Goswami's point-mass legs
// (--set I=0, where the long-step gait is faster than the bars' threshold of the period): both are found
// from the shipped starts, and at gamma = 0.03, where each branch starts, the one named "long-step" has the
// longer step (half inter-leg angle at heel strike, |x2_th_st|) and is the stable one. No branch changes
// its name along the way.
TEST(FamilyNames, TheCompassGaitsAreNamedByTheirStepWithBarAndPointMassLegs) {
  for (const char* inertia : {"0.4166666666666667", "0"}) {
    const fs::path dir = fs::temp_directory_path() / (std::string("hybridcont_true_names_compass_") + inertia);
    const nlohmann::json summary = RunQuietly({ModelPath("compass-gait.toml"), "--set", std::string("I=") + inertia}, dir);
    std::map<std::string, double> step;  // name -> |x2_th_st| at gamma = 0.03
    std::map<std::string, bool> stable;
    for (const nlohmann::json& b : summary["branches"]) {
      const auto c = ReadColumns(dir / b["file"].get<std::string>());
      ASSERT_NEAR(c.at("gamma").front(), 0.03, 1e-12);
      const std::string name = b["family"].get<std::string>();
      for (const nlohmann::json& r : b["physical_ranges"]) EXPECT_EQ(r["family"], name) << b.dump();
      step[name] = std::abs(c.at("x2_th_st").front());
      stable[name] = c.at("stable").front() == 1;
      // Every nontrivial multiplier of a model without first integral (4 states: 3) has its columns.
      for (const char* col : {"mu1_re", "mu2_re", "mu3_re", "mu3_im"}) EXPECT_EQ(c.count(col), 1u) << col;
    }
    ASSERT_EQ(step.size(), 2u) << inertia << " " << summary["report"];
    EXPECT_GT(step.at("long-step gait"), step.at("short-step gait") + 0.01) << inertia;
    EXPECT_TRUE(stable.at("long-step gait")) << inertia;
    EXPECT_FALSE(stable.at("short-step gait")) << inertia;
    std::printf("compass gait, I = %s: steps |x2_th_st| long %.6f, short %.6f at gamma = 0.03\n", inertia,
                step.at("long-step gait"), step.at("short-step gait"));
    fs::remove_all(dir);
  }
}

TEST(BranchPointStability, SwitchedBranchesStartNeutralInBothRodModels) {
  for (const std::string model : {"bouncing-rod.toml", "bouncing-rod-lagrangian.toml"}) {
    const fs::path dir = fs::temp_directory_path() / ("hybridcont_true_sb_" + model);
    const nlohmann::json summary = RunQuietly({ModelPath(model)}, dir);
    int checked = 0;
    for (const nlohmann::json& b : summary["branches"]) {
      if (b["parent"].get<int>() < 0 || b["depth"].get<int>() < 2) continue;  // switched at an SB point
      std::ifstream csv(dir / b["file"].get<std::string>());
      std::string header, first;
      std::getline(csv, header);
      std::getline(csv, first);
      if (first.find(",1,physical,") == std::string::npos) continue;
      EXPECT_NE(first.find("neutrally stable"), std::string::npos) << model << " branch " << b["id"] << ": " << first;
      ++checked;
    }
    EXPECT_GE(checked, 2) << model;
    fs::remove_all(dir);
  }
}

// The state-based formulation's located points are where they say, to their stated precision: every SB,
// BP and PD point of the SLIP lies within its precision (in H) of the same point of a time-based run at 1000
// times finer tolerances (accurate to ~1e-13). Before, the refined evaluation behind a BP's or PD's error
// estimate expanded the refined point into the time-based layout with the coarse map, and the points were up
// to 1.75 times their stated precision away.
TEST(StateFormulation, LocatedPointsLieWithinTheirPrecisionOfAFinerRun) {
  const fs::path dir = fs::temp_directory_path() / "hybridcont_true_state";
  const nlohmann::json state = RunQuietly({"slip", "--formulation", "state"}, dir / "state");
  const nlohmann::json fine = RunQuietly({"slip", "--rtol", "1e-13", "--atol", "1e-13"}, dir / "fine");
  int compared = 0;
  for (const nlohmann::json& p : state["special_points"]) {
    const std::string type = p["type"].get<std::string>();
    if (p["duplicate_of"] != -1 || p["status"] != "located" || (type != "SB" && type != "BP" && type != "PD")) continue;
    double nearest = 1e300;
    for (const nlohmann::json& q : fine["special_points"]) {
      if (q["type"] == type && q["status"] == "located") {
        nearest = std::min(nearest, std::abs(q["H"].get<double>() - p["H"].get<double>()));
      }
    }
    EXPECT_LE(nearest, p["precision_H"].get<double>()) << p.dump();
    EXPECT_LT(p["precision_H"].get<double>(), 1e-8) << p.dump();
    ++compared;
  }
  EXPECT_GE(compared, 6);
  fs::remove_all(dir);
}

TEST(Starts, ASingularStartThatIsNoOrbitIsRefusedPerSegmentBeforeAnythingIsWritten) {
  const fs::path file = fs::temp_directory_path() / "hybridcont_true_start" / "slip.toml";
  ASSERT_TRUE(WriteEditedModel("slip.toml", "x3_l = \"l0\", H = \"m*g*l0\"", "x3_l = \"l0\", H = \"m*g*l0 + 0.05\"", file));
  const fs::path out = file.parent_path() / "out";
  const CliResult r = RunTool({"run", file.string(), "--out", out.string(), "--quiet", "--no-plots"});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("slip.toml:"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("is not a periodic orbit: max |r| = 0.05"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("the first integral at x1 differs from the level H by -0.05"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
  EXPECT_EQ(r.out.find("figures written"), std::string::npos);
}

TEST(Starts, UnsetStatesAreNamedWhenTheCycleCannotBeIntegrated) {
  const fs::path file = fs::temp_directory_path() / "hybridcont_true_unset" / "slip.toml";
  ASSERT_TRUE(WriteEditedModel("slip.toml", ", x2_y = \"l0\", x3_l = \"l0\"", "", file));
  const fs::path out = file.parent_path() / "out";
  const CliResult r = RunTool({"run", file.string(), "--out", out.string(), "--quiet", "--no-plots"});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("the cycle cannot be integrated from it"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("not given (taken as 0): x3_alpha, x3_l,"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
}

TEST(Starts, AGuessNewtonMovesIsReported) {
  const fs::path file = fs::temp_directory_path() / "hybridcont_true_guess" / "ball-ceiling.toml";
  ASSERT_TRUE(WriteEditedModel("ball-ceiling.toml", "values = { H = 0.5,", "values = { H = 0.55,", file));
  const fs::path out = file.parent_path() / "out";
  const CliResult r = RunTool({"run", file.string(), "--out", out.string(), "--no-plots", "--one-word"});
  EXPECT_EQ(r.code, 0) << r.err;
  const std::string text = std::regex_replace(r.out, std::regex("\n +"), " ");  // the answer's wrapped lines, joined
  // At H = 0.55 the ball passes the section (y = 1/4) at speed sqrt(2 (0.55 - 0.25)) = 0.774597.
  EXPECT_NE(text.find("start: the guess is not an orbit (max |r| = 0.05); Newton moved it at H = 0.55"),
            std::string::npos)
      << r.out.substr(0, 600);
  EXPECT_NE(text.find("x1_v -0.707107 -> -0.774597"), std::string::npos) << r.out.substr(0, 600);
  fs::remove_all(file.parent_path());
}

// A guess start (the bipedal model's walking) is corrected the same way whatever the number of threads: the
// branch files of one and two threads are the same bytes.
TEST(Threads, AGuessStartGivesTheSameBitsOnOneAndTwoThreads) {
  const fs::path dir = fs::temp_directory_path() / "hybridcont_true_threads";
  std::string files[2];
  for (const int threads : {1, 2}) {
    const fs::path out = dir / std::to_string(threads);
    const CliResult r = RunTool({"run", ModelPath("bipedal-slip.toml"), "--one-word", "--max-branches", "2", "--threads",
                                 std::to_string(threads), "--out", out.string(), "--quiet", "--no-plots", "--overwrite"});
    ASSERT_EQ(r.code, 0) << r.err;
    for (const char* name : {"branch-0.csv", "branch-1.csv"}) {
      std::ifstream in(out / name);
      files[threads - 1] += std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    }
  }
  EXPECT_GT(files[0].size(), 1000u);
  EXPECT_TRUE(files[0] == files[1]);
  fs::remove_all(dir);
}

// A model without first integral continued in another parameter than its file's (`--free I`): the file's
// bound on its own parameter (gamma) no longer stops the run. The compass gait's two gaits reach point-mass
// legs (I -> 0), both physical there.
TEST(FreeParameter, AnotherParameterOfAModelWithoutFirstIntegral) {
  const fs::path out = fs::temp_directory_path() / "hybridcont_true_free_I";
  const nlohmann::json summary = RunQuietly({ModelPath("compass-gait.toml"), "--free", "I", "--bound", "I=0:0.5"}, out);
  int near_zero = 0;
  for (const nlohmann::json& b : summary["branches"]) {
    for (const nlohmann::json& r : b.value("physical_ranges", nlohmann::json::array())) {
      near_zero += std::min(r["from"].get<double>(), r["to"].get<double>()) < 1e-3;
    }
  }
  EXPECT_EQ(near_zero, 2) << summary["report"];
  fs::remove_all(out);
}

// The rod's start (at rest on both ends) has a kernel of dimension 3 without its file's condition t2 = t1 + t3;
// one of its directions is the ξ axis, into the rest states of the unfolding, which the tool excludes itself:
// the same diagram as with the condition.
TEST(Starts, TheXiAxisOfASingularStartIsExcludedByTheToolItself) {
  const fs::path file = fs::temp_directory_path() / "hybridcont_true_rod" / "bouncing-rod.toml";
  ASSERT_TRUE(WriteEditedModel("bouncing-rod.toml",
                               "conditions = [{ terms = { t2 = 1, t1 = -1, t3 = -1 }, description = \"t2 = t1 + t3\" }]",
                               "", file));
  const fs::path out = file.parent_path() / "out";
  const CliResult r = RunTool({"run", file.string(), "--out", out.string(), "--no-plots", "--quiet", "--verbose"});
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("the condition direction[xi] = 0 added"), std::string::npos) << r.out.substr(0, 2000);
  std::ifstream in(out / "summary.json");
  const nlohmann::json summary = nlohmann::json::parse(in);
  EXPECT_EQ(summary["branches"].size(), 8u);
  int sb = 0;
  for (const nlohmann::json& sp : summary["special_points"]) sb += sp["type"] == "SB" && sp["duplicate_of"] == -1;
  EXPECT_EQ(sb, 2);
  fs::remove_all(file.parent_path());
}

}  // namespace
}  // namespace hybridcont::app
