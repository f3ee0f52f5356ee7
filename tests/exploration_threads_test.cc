// Explorations on several threads give the serial diagram to the last bit (exploration.h, "Threads"):
// the same branches in the same order, points and special points compared with ==, the same switches,
// and the same progress reports in the same order. The algebraic cases drive every serial decision the
// merge replays (a closed loop, a ray already known, a branch found already traced, max_branches); the
// models are the paper's runs.
#include <gtest/gtest.h>

#include <memory>
#include <mutex>
#include <set>
#include <stdexcept>
#include <thread>
#include <string>
#include <tuple>
#include <vector>

#include "continuation_test_problems.h"
#include "hybridcont/exploration.h"
#include "hybridcont/models.h"
#include "study/engine/model_exploration.h"

namespace hybridcont {
namespace {

// An algebraic test problem that can be cloned: it holds no state, so a copy is independent.
template <class Problem>
class Cloneable : public Problem {
 public:
  std::unique_ptr<ZeroProblem> Clone() const override { return std::make_unique<Cloneable>(*this); }
};

void ExpectSameVector(const Vector& a, const Vector& b, const std::string& what) {
  EXPECT_TRUE(a.size() == b.size() && a == b) << what;
}

// The scalar fields, compared with == at once (vectors apart: Eigen compares only equal sizes).
auto Fields(const SpecialPoint& p) {
  return std::tie(p.id, p.type, p.status, p.branch_id, p.index, p.arclength, p.component, p.test_value,
                  p.interval_lo, p.interval_hi, p.residual_norm, p.iterations, p.duplicate_of, p.message);
}
auto Fields(const ContinuationPoint& p) {
  return std::tie(p.arclength, p.step, p.newton_iterations, p.contraction, p.sb_test);
}
auto Fields(const Branch& b) {
  return std::tie(b.id, b.direction, b.parent_special_point, b.depth, b.termination, b.message,
                  b.newton_iterations, b.rejected_steps, b.located_iterations, b.image_of, b.symmetry,
                  b.reflected_from);
}
auto Fields(const SwitchRecord& r) { return std::tie(r.special_point, r.traced, r.skipped, r.result.status); }

void ExpectSamePoint(const SpecialPoint& a, const SpecialPoint& b, const std::string& what) {
  EXPECT_TRUE(Fields(a) == Fields(b)) << what;
  ExpectSameVector(a.u, b.u, what + " u");
  ExpectSameVector(a.tangent, b.tangent, what + " tangent");
}

void ExpectSameDiagram(const BifurcationDiagram& a, const BifurcationDiagram& b) {
  EXPECT_EQ(a.status, b.status);
  EXPECT_EQ(a.message, b.message);
  EXPECT_EQ(a.warnings, b.warnings);
  ASSERT_EQ(a.branches.size(), b.branches.size()) << a.FullReport() << b.FullReport();
  for (size_t i = 0; i < a.branches.size(); ++i) {
    const Branch& x = a.branches[i];
    const Branch& y = b.branches[i];
    const std::string what = "branch " + std::to_string(i);
    EXPECT_TRUE(Fields(x) == Fields(y)) << what;
    ASSERT_EQ(x.points.size(), y.points.size()) << what;
    for (size_t k = 0; k < x.points.size(); ++k) {
      const std::string at = what + " point " + std::to_string(k);
      EXPECT_TRUE(Fields(x.points[k]) == Fields(y.points[k])) << at;
      ExpectSameVector(x.points[k].u, y.points[k].u, at + " u");
      ExpectSameVector(x.points[k].tangent, y.points[k].tangent, at + " tangent");
    }
    ASSERT_EQ(x.special_points.size(), y.special_points.size()) << what;
    for (size_t k = 0; k < x.special_points.size(); ++k) {
      ExpectSamePoint(x.special_points[k], y.special_points[k], what + " special point " + std::to_string(k));
    }
  }
  ASSERT_EQ(a.special_points.size(), b.special_points.size());
  for (size_t k = 0; k < a.special_points.size(); ++k) {
    ExpectSamePoint(a.special_points[k], b.special_points[k], "diagram special point " + std::to_string(k));
  }
  ASSERT_EQ(a.switches.size(), b.switches.size());
  for (size_t k = 0; k < a.switches.size(); ++k) {
    EXPECT_TRUE(Fields(a.switches[k]) == Fields(b.switches[k])) << "switch " << k;
    ExpectSameVector(a.switches[k].result.direction, b.switches[k].result.direction, "switch direction");
  }
  EXPECT_EQ(a.FullReport(), b.FullReport());
}

// One progress report, all its numbers.
struct Report {
  int branch_id, point_index, newton_iterations, rejected_steps;
  std::vector<double> values;
  double step, next_step;
  bool operator==(const Report&) const = default;
};

struct Run {
  BifurcationDiagram diagram;
  std::vector<Report> reports;
};

template <class Problem>
Run ExploreWith(int threads, const Vector& u0, ExplorationOptions options) {
  Cloneable<Problem> problem;
  Run run;
  options.threads = threads;
  options.continuation.progress = [&run](const ProgressInfo& p) {
    run.reports.push_back({p.branch_id, p.point_index, p.newton_iterations, p.rejected_steps, p.values, p.step,
                           p.next_step});
  };
  run.diagram = Explore(&problem, u0, options);
  return run;
}

// Serial against 2 and 3 threads (3: more half-branches in flight than the cases have at a time).
template <class Problem>
BifurcationDiagram ExpectSameOnThreads(const Vector& u0, const ExplorationOptions& options) {
  const Run serial = ExploreWith<Problem>(1, u0, options);
  for (const int threads : {2, 3}) {
    SCOPED_TRACE("threads = " + std::to_string(threads));
    const Run concurrent = ExploreWith<Problem>(threads, u0, options);
    ExpectSameDiagram(serial.diagram, concurrent.diagram);
    EXPECT_TRUE(serial.reports == concurrent.reports);
  }
  return serial.diagram;
}

int CountTerminations(const BifurcationDiagram& d, TerminationReason reason) {
  int count = 0;
  for (const Branch& b : d.branches) count += b.termination == reason;
  return count;
}

TEST(ExplorationThreads, AlgebraicDiagramsAreTheSerialOnes) {
  ExplorationOptions options;
  options.continuation.bounds = {{"lambda", -1, 1}};
  ExpectSameOnThreads<testing::Pitchfork>(Eigen::Vector2d(0, -0.5), options);      // regular start, SB
  ExpectSameOnThreads<testing::Pitchfork>(Eigen::Vector2d(0, 0), options);         // singular start
  ExpectSameOnThreads<testing::Transcritical>(Eigen::Vector2d(0, 0.4), options);
  // Symmetries: the image is mapped at its merge, the same on every thread count.
  ExpectSameOnThreads<testing::SymmetricPitchfork>(Eigen::Vector2d(0, -0.5), options);
  ExpectSameOnThreads<testing::SymmetricPitchfork>(Eigen::Vector2d(0, 0), options);
  ExpectSameOnThreads<testing::FalselySymmetricPitchfork>(Eigen::Vector2d(0, -0.5), options);
  ExplorationOptions loop;  // a loop completed by reflection on a worker
  loop.continuation.bounds = {{"x", -2, 2}};
  ExpectSameOnThreads<testing::CircleOnAxis>(Eigen::Vector2d(0.3, 0), loop);

  // Two SB points on the line: at the second one both line rays are known, its half-branches skipped.
  ExplorationOptions parabola;
  parabola.continuation.bounds = {{"x", -2.5, 2.5}, {"lambda", -3, 3}};
  parabola.continuation.turning_point_components = {"lambda"};
  const BifurcationDiagram d = ExpectSameOnThreads<testing::ParabolaAndLine>(Eigen::Vector2d(-0.5, 0.75), parabola);
  int skipped = 0;
  for (const SwitchRecord& record : d.switches) skipped += record.skipped;
  EXPECT_GT(skipped, 0) << d.FullReport();

  // max_branches ends the exploration inside a switch.
  ExplorationOptions few = options;
  few.max_branches = 3;
  EXPECT_EQ(ExpectSameOnThreads<testing::Pitchfork>(Eigen::Vector2d(0, -0.5), few).status,
            ExplorationStatus::kMaxBranches);
}

TEST(ExplorationThreads, ClosedLoopAndKnownBranchAreDecidedAsSerially) {
  // The circle closes: the second half-branch, traced concurrently, is dropped.
  ExplorationOptions options;
  options.continuation.turning_point_components = {"y"};
  const BifurcationDiagram closed = ExpectSameOnThreads<testing::Circle>(Eigen::Vector2d(0.6, 0.8), options);
  EXPECT_EQ(closed.branches.size(), 1u);
  // Without loop detection the first half-branch runs around the circle until max_points; the second,
  // traced concurrently before the first was known, is found on it at its first point and ends there.
  options.continuation.detect_closed_loop = false;
  options.continuation.max_points = 120;
  const BifurcationDiagram known = ExpectSameOnThreads<testing::Circle>(Eigen::Vector2d(0.6, 0.8), options);
  ASSERT_EQ(known.branches.size(), 2u) << known.FullReport();
  EXPECT_EQ(known.branches[1].termination, TerminationReason::kKnownBranch) << known.FullReport();
  EXPECT_EQ(CountTerminations(known, TerminationReason::kKnownBranch), 1);
}

// The circle closes: the start's second half-branch, in flight when the SB points' half-branches were
// launched, is dropped, and those are renumbered one down. The line from the first SB point passes the
// second one, whose rays are then all known.
TEST(ExplorationThreads, HalfBranchesLaunchedAfterADroppedOneAreRenumbered) {
  ExplorationOptions options;
  options.continuation.bounds = {{"x", -2, 2}, {"lambda", -2, 2}};
  const BifurcationDiagram d = ExpectSameOnThreads<testing::CircleAndLine>(Eigen::Vector2d(0.6, 0.8), options);
  ASSERT_EQ(d.branches.size(), 3u) << d.FullReport();
  EXPECT_EQ(d.branches[0].termination, TerminationReason::kClosedLoop);
  ASSERT_EQ(d.switches.size(), 2u) << d.FullReport();
  EXPECT_EQ(d.switches[0].traced, 2);
  EXPECT_EQ(d.switches[1].skipped, 2);
}

// The lines x = i and λ = j, i, j = −2…2: 25 SB points, most found again on crossing branches
// (duplicates the serial run never switches at). The problem throws where the exploring thread asks for
// dr alone (switching) at a point the serial run did not: a speculative switch group at a duplicate must
// not turn that into an exception of the run (without that, 8–12 of 180 runs threw).
// Timing decides whether a run speculates at a duplicate, so the test catches a regression only in some
// runs (measured without the fix: 1 failing run of 3); it never fails when the code is right.
class LineGrid : public ZeroProblem {
 public:
  int num_equations() const override { return 1; }
  std::vector<std::string> unknown_names() const override { return {"x", "lambda"}; }
  EvaluationStatus Evaluate(const Vector& u, Vector* r, Matrix* dr) override {
    if (r == nullptr && std::this_thread::get_id() == exploring_thread) {
      const std::vector<double> key(u.data(), u.data() + u.size());
      const std::lock_guard<std::mutex> lock(mutex);
      if (recording) {
        seen.insert(key);
      } else if (seen.count(key) == 0) {
        throw std::runtime_error("dr alone asked at a point the serial run never switched at");
      }
    }
    double p = 1, px = 0, pl = 0;  // product of the factors x − i and λ − j, and its gradient
    for (int i = -2; i <= 2; ++i) {
      for (const auto& [f, fx, fl] : {std::tuple{u(0) - i, 1.0, 0.0}, std::tuple{u(1) - i, 0.0, 1.0}}) {
        px = px * f + p * fx;
        pl = pl * f + p * fl;
        p *= f;
      }
    }
    if (r) *r = Vector::Constant(1, p);
    if (dr) {
      dr->resize(1, 2);
      *dr << px, pl;
    }
    return {};
  }
  std::unique_ptr<ZeroProblem> Clone() const override { return std::make_unique<LineGrid>(*this); }

  static inline std::thread::id exploring_thread;
  static inline std::mutex mutex;
  static inline std::set<std::vector<double>> seen;
  static inline bool recording = true;
};

TEST(ExplorationThreads, SpeculativeSwitchingThrowsNothingTheSerialRunDoesNot) {
  ExplorationOptions options;
  options.continuation.bounds = {{"x", -2.5, 2.5}, {"lambda", -2.5, 2.5}};
  LineGrid::exploring_thread = std::this_thread::get_id();
  LineGrid::seen.clear();
  LineGrid::recording = true;
  const auto serial = ExploreWith<LineGrid>(1, Eigen::Vector2d(0.5, 0.0), options);
  ASSERT_GT(serial.diagram.switches.size(), 5u) << serial.diagram.FullReport();
  LineGrid::recording = false;
  for (int run = 0; run < 30; ++run) {
    for (const int threads : {2, 3}) {
      SCOPED_TRACE("run " + std::to_string(run) + ", threads = " + std::to_string(threads));
      BifurcationDiagram concurrent;
      ASSERT_NO_THROW(concurrent = ExploreWith<LineGrid>(threads, Eigen::Vector2d(0.5, 0.0), options).diagram);
      ExpectSameDiagram(serial.diagram, concurrent);
      ASSERT_FALSE(HasFailure());
    }
  }
}

TEST(ExplorationThreads, ThreadsAreValidated) {
  ExplorationOptions options;
  EXPECT_GE(options.threads, 1);
  options.threads = 0;
  EXPECT_EQ(options.Validate(), "ExplorationOptions::threads = 0 must be >= 1");
}

// A model's default scenario (the run command's exploration) on 1 and 2 threads; what on_point sees too.
void ExpectModelRunIsTheSerialOne(const std::string& name) {
  SCOPED_TRACE(name);
  const HybridModel model = MakeBuiltinModel(name);
  const study::Scenario scenario = study::DefaultScenario(model);
  Run runs[2];
  long rhs[2];
  for (const int threads : {1, 2}) {
    ExplorationOptions options = study::ScenarioExplorationOptions(scenario);
    options.threads = threads;
    study::ModelExploration exploration(model, scenario, IntegratorOptions{}, options);
    Run& run = runs[threads - 1];
    run.diagram = exploration.Run([&run](const ProgressInfo& p, const Vector& u) {
      run.reports.push_back({p.branch_id, p.point_index, p.newton_iterations, p.rejected_steps,
                             std::vector<double>(u.data(), u.data() + u.size()), p.step, p.next_step});
    });
    rhs[threads - 1] = exploration.counters().rhs_evaluations;
  }
  ExpectSameDiagram(runs[0].diagram, runs[1].diagram);
  EXPECT_TRUE(runs[0].reports == runs[1].reports);
  EXPECT_GT(runs[0].diagram.branches.size(), 4u);
  // The workers' clones hand their work back: at least what the serial run did.
  EXPECT_GE(rhs[1], rhs[0]);
}

TEST(ExplorationThreads, BouncingRodRunIsTheSerialOne) { ExpectModelRunIsTheSerialOne("bouncing-rod"); }

TEST(ExplorationThreads, SlipRunIsTheSerialOne) { ExpectModelRunIsTheSerialOne("slip"); }

}  // namespace
}  // namespace hybridcont
