// Each built-in model's set-up (model_setup.h), declared in its own source file, evaluated generically:
// DefaultScenario gives the paper's runs to the last bit (the values the run command used when they were
// written per model in the application), families and quantities name orbits, the drawing places the
// mechanism, parameter ranges refuse what has no physical meaning, and the results files carry it all.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "hybridcont/models.h"
#include "hybridcont/setup_evaluation.h"
#include "study/io/results_writer.h"
#include "study/engine/scenario.h"

namespace hybridcont {
namespace {

struct Bound {
  std::string component;
  double lower, upper;
};

void ExpectBounds(const study::Scenario& s, const std::vector<Bound>& expected) {
  ASSERT_EQ(s.bounds.size(), expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i) {
    EXPECT_EQ(s.bounds[i].component, expected[i].component);
    EXPECT_EQ(s.bounds[i].lower, expected[i].lower) << expected[i].component;
    EXPECT_EQ(s.bounds[i].upper, expected[i].upper) << expected[i].component;
  }
}

// At most one sum bound, over all durations t1..t<m+1>.
void ExpectPeriodBound(const study::Scenario& s, int num_phases, double lower, double upper) {
  ASSERT_EQ(s.sum_bounds.size(), 1u);
  std::vector<std::string> durations;
  for (int i = 1; i <= num_phases + 1; ++i) durations.push_back("t" + std::to_string(i));
  EXPECT_EQ(s.sum_bounds[0].components, durations);
  EXPECT_EQ(s.sum_bounds[0].lower, lower);
  EXPECT_EQ(s.sum_bounds[0].upper, upper);
}

void ExpectDefaultLimits(const study::Scenario& s, double max_step) {
  EXPECT_EQ(s.max_branches, 64);
  EXPECT_EQ(s.max_depth, 3);
  EXPECT_EQ(s.max_points, 600);
  EXPECT_EQ(s.initial_step, 0.02);
  EXPECT_EQ(s.max_step, max_step);
  EXPECT_EQ(s.max_keyframe_orbits, 4);
}

Vector WithValues(const HybridModel& model, const std::vector<std::pair<std::string, double>>& values) {
  const ShootingLayout layout(model);
  const std::vector<std::string>& names = layout.unknown_names();
  Vector u = Vector::Zero(layout.num_unknowns());
  for (const auto& [name, value] : values) {
    const auto it = std::find(names.begin(), names.end(), name);
    EXPECT_NE(it, names.end()) << name;
    if (it != names.end()) u(it - names.begin()) = value;
  }
  return u;
}

TEST(ModelSetup, BouncingBallScenarioIsThePapers) {
  const HybridModel model = MakeBuiltinModel("bouncing-ball");
  const study::Scenario s = study::DefaultScenario(model);
  ExpectBounds(s, {{"xi", -1.0, 1.0}, {"H", -1.0, 1.0}});
  EXPECT_TRUE(s.sum_bounds.empty());
  EXPECT_TRUE(s.unknown_scales.empty());
  EXPECT_TRUE(s.start_conditions.empty());
  ExpectDefaultLimits(s, 0.1);
  EXPECT_EQ(s.keyframes.component, "H");
  EXPECT_EQ(s.keyframes.value, 0.5);
  EXPECT_EQ(s.start, Vector(Vector::Zero(ShootingLayout(model).num_unknowns())));  // the equilibrium
  EXPECT_EQ(s.describe(s.start), "periodic orbit");                      // no families declared
}

void ExpectRockingBlockScenario(const HybridModel& model) {
  const double m = model.parameter("m"), g = model.parameter("g"), l0 = model.parameter("l0"),
               beta = model.parameter("beta");
  const double H_max = m * g * l0 * (1.0 - std::cos(beta));
  const study::Scenario s = study::DefaultScenario(model);
  ExpectBounds(s, {{"xi", -1.0, 1.0}, {"H", -1.0, H_max}});
  ExpectPeriodBound(s, 1, -20.0, 20.0);
  EXPECT_EQ(s.keyframes.component, "H");
  EXPECT_EQ(s.keyframes.value, 0.5 * H_max);
  const std::vector<std::pair<std::string, double>> scales = {
      {"H", H_max},
      {"x1_alpha", beta},
      {"x1_dalpha", std::sqrt(H_max / m) / l0},
      {"x2_alpha", beta},
      {"x2_dalpha", std::sqrt(H_max / m) / l0}};
  EXPECT_EQ(s.unknown_scales, scales);
  ExpectDefaultLimits(s, 0.5);
  EXPECT_TRUE(s.start_conditions.empty());
  EXPECT_EQ(s.start, Vector(Vector::Zero(ShootingLayout(model).num_unknowns())));
}

TEST(ModelSetup, RockingBlockScenarioFollowsTheParameters) {
  HybridModel model = MakeBuiltinModel("rocking-block");
  ExpectRockingBlockScenario(model);
  EXPECT_EQ(study::DefaultScenario(model).bounds[1].upper, 1.0 - std::cos(0.3));  // H_max at the defaults
  model.SetParameter("beta", 0.2);
  model.SetParameter("m", 2.5);
  model.SetParameter("l0", 0.7);
  ExpectRockingBlockScenario(model);
  EXPECT_EQ(study::DefaultScenario(model).bounds[1].upper, 2.5 * 1.0 * 0.7 * (1.0 - std::cos(0.2)));
}

void ExpectBouncingRodScenario(const HybridModel& model) {
  const study::Scenario s = study::DefaultScenario(model);
  ExpectBounds(s, {{"xi", -1.0, 1.0}, {"H", -1.0, 0.6}});
  ExpectPeriodBound(s, 2, -10.0, 10.0);
  ASSERT_EQ(s.start_conditions.size(), 1u);
  const std::vector<std::pair<std::string, double>> terms = {{"t2", 1.0}, {"t1", -1.0}, {"t3", -1.0}};
  EXPECT_EQ(s.start_conditions[0].terms, terms);
  EXPECT_EQ(s.start_conditions[0].description, "t2 = t1 + t3");
  EXPECT_EQ(s.keyframes.component, "T");
  EXPECT_EQ(s.keyframes.value, 0.8);
  const double scale = model.parameter("l0") / model.parameter("r");
  const std::vector<std::pair<std::string, double>> scales = {
      {"x1_dalpha", scale}, {"x2_dalpha", scale}, {"x3_dalpha", scale}};
  EXPECT_EQ(s.unknown_scales, scales);
  ExpectDefaultLimits(s, 0.1);
  EXPECT_EQ(s.start, Vector(Vector::Zero(ShootingLayout(model).num_unknowns())));
}

TEST(ModelSetup, BouncingRodScenarioIsThePapers) {
  HybridModel model = MakeBuiltinModel("bouncing-rod");
  ExpectBouncingRodScenario(model);
  model.SetParameter("r", 0.02);
  ExpectBouncingRodScenario(model);
}

void ExpectSlipScenario(const HybridModel& model) {
  const double m = model.parameter("m"), g = model.parameter("g"), k = model.parameter("k"),
               l0 = model.parameter("l0");
  const study::Scenario s = study::DefaultScenario(model);
  ExpectBounds(s, {{"xi", -1.0, 1.0}, {"H", 0.0, 2.0}});
  ExpectPeriodBound(s, 2, -20.0, 20.0);
  EXPECT_EQ(s.keyframes.component, "H");
  EXPECT_EQ(s.keyframes.value, 1.8);
  EXPECT_TRUE(s.unknown_scales.empty());
  EXPECT_TRUE(s.start_conditions.empty());
  ExpectDefaultLimits(s, 0.1);
  // The vertical oscillation with zero flight time: t1 = t3 = pi sqrt(m/k), x1_l = l0 - 2mg/k, H = m g l0.
  const double half_period = M_PI * std::sqrt(m / k);
  const Vector expected = WithValues(model, {{"t1", half_period},
                                             {"t3", half_period},
                                             {"x1_l", l0 - 2.0 * m * g / k},
                                             {"x2_y", l0},
                                             {"x3_l", l0},
                                             {"H", m * g * l0}});
  EXPECT_EQ(s.start, expected);
  EXPECT_EQ(BuiltinStartPoint(model), expected);
}

TEST(ModelSetup, SlipScenarioFollowsTheParameters) {
  HybridModel model = MakeBuiltinModel("slip");
  ExpectSlipScenario(model);
  model.SetParameter("k", 20.0);
  model.SetParameter("m", 1.5);
  model.SetParameter("l0", 0.8);
  ExpectSlipScenario(model);
}

TEST(ModelSetup, BallChainStartsOnItsClosedFormOrbit) {
  for (const int m : {1, 3, 10}) {
    HybridModel chain = MakeBallChain(m);
    EXPECT_EQ(StartPoint(chain), BallChainOrbit(chain, 0.5)) << m;
    chain.SetParameter("g", 2.0);
    chain.SetParameter("m", 0.5);
    EXPECT_EQ(StartPoint(chain), BallChainOrbit(chain, 0.5)) << m;
  }
  const study::Scenario s = study::DefaultScenario(MakeBuiltinModel("ball-chain"));
  ExpectBounds(s, {{"xi", -1.0, 1.0}, {"H", -1.0, 1.0}});
  EXPECT_EQ(s.keyframes.value, 0.5);
}

TEST(ModelSetup, SlipFamiliesFollowTheForwardSpeed) {
  const HybridModel model = MakeBuiltinModel("slip");
  const OrbitPresentation presentation(model);
  EXPECT_EQ(presentation.family_names(),
            (std::vector<std::string>{"hopping in place", "forward hopping", "backward hopping"}));
  EXPECT_EQ(presentation.Family(WithValues(model, {{"x2_dx", 0.0}})), "hopping in place");
  EXPECT_EQ(presentation.Family(WithValues(model, {{"x2_dx", 5e-7}})), "hopping in place");
  EXPECT_EQ(presentation.Family(WithValues(model, {{"x2_dx", 0.3}})), "forward hopping");
  EXPECT_EQ(presentation.Family(WithValues(model, {{"x2_dx", -2e-6}})), "backward hopping");
  EXPECT_EQ(study::DefaultScenario(model).describe(WithValues(model, {{"x2_dx", 0.3}})), "forward hopping");
}

TEST(ModelSetup, RodFamiliesAndAsymmetry) {
  const HybridModel model = MakeBuiltinModel("bouncing-rod");
  const OrbitPresentation presentation(model);
  ASSERT_EQ(presentation.quantity_names(), std::vector<std::string>{"asym"});
  const Vector symmetric = WithValues(model, {{"t1", 0.1}, {"t2", 0.3}, {"t3", 0.2}});
  const Vector longer = WithValues(model, {{"t1", 0.1}, {"t2", 0.5}, {"t3", 0.2}});
  const Vector shorter = WithValues(model, {{"t1", 0.25}, {"t2", 0.3}, {"t3", 0.2}});
  EXPECT_EQ(presentation.Family(symmetric), "symmetric orbit (t2 = t1 + t3)");
  EXPECT_EQ(presentation.Family(longer), "non-symmetric orbit (t2 > t1 + t3)");
  EXPECT_EQ(presentation.Family(shorter), "non-symmetric orbit (t2 < t1 + t3)");
  EXPECT_EQ(presentation.Quantities(longer), std::vector<double>{0.5 - (0.1 + 0.2)});
  EXPECT_EQ(presentation.Quantities(shorter), std::vector<double>{0.3 - (0.25 + 0.2)});
}

TEST(ModelSetup, EveryBuiltinModelHasAPresentationThatEvaluates) {
  for (const std::string& name : BuiltinModelNames()) {
    SCOPED_TRACE(name);
    const HybridModel model = MakeBuiltinModel(name);
    EXPECT_FALSE(model.setup().title.empty());
    const OrbitPresentation presentation(model);
    EXPECT_TRUE(presentation.has_drawing());
    const Vector u0 = StartPoint(model);
    EXPECT_FALSE(presentation.Family(u0).empty());
    const ShootingLayout layout(model);
    for (int i = 0; i < layout.num_segments(); ++i) {
      const Vector x = model.phase(i).typical_state();
      const Matrix points = presentation.DrawingPoints(i, x, 0.0);
      EXPECT_TRUE(points.allFinite()) << "segment " << i;  // every phase of the built-ins draws every point
      EXPECT_TRUE(std::isfinite(presentation.XVelocity(i, x)));
    }
  }
}

TEST(ModelSetup, SlipDrawingPlacesBodyAndFoot) {
  const HybridModel model = MakeBuiltinModel("slip");
  const OrbitPresentation presentation(model);
  ASSERT_EQ(presentation.point_names(), (std::vector<std::string>{"body", "foot"}));
  // Stance (segment 0): alpha = 0.2, l = 0.9, dalpha = 0.5, dl = -0.3 at X = 0.4. The body is at X, the
  // foot l sin(alpha) ahead of it on the ground; X moves with -dl sin(alpha) - dalpha l cos(alpha).
  Vector stance(4);
  stance << 0.2, 0.9, 0.5, -0.3;
  Matrix p = presentation.DrawingPoints(0, stance, 0.4);
  EXPECT_DOUBLE_EQ(p(0, 0), 0.4);
  EXPECT_DOUBLE_EQ(p(1, 0), 0.9 * std::cos(0.2));
  EXPECT_DOUBLE_EQ(p(0, 1), 0.4 + 0.9 * std::sin(0.2));
  EXPECT_DOUBLE_EQ(p(1, 1), 0.0);
  EXPECT_DOUBLE_EQ(presentation.XVelocity(0, stance), 0.3 * std::sin(0.2) - 0.5 * 0.9 * std::cos(0.2));
  // The same for the return to stance (segment 2).
  EXPECT_EQ(presentation.DrawingPoints(2, stance, 0.4), p);
  // Flight (segment 1): y = 1.1, alpha = -0.1, dx = 0.7, dy = 0.2, dalpha = 0.3 at X = 1.5; the leg of
  // length l0 = 1 hangs from the body at angle alpha.
  Vector flight(5);
  flight << 1.1, -0.1, 0.7, 0.2, 0.3;
  p = presentation.DrawingPoints(1, flight, 1.5);
  EXPECT_DOUBLE_EQ(p(0, 0), 1.5);
  EXPECT_DOUBLE_EQ(p(1, 0), 1.1);
  EXPECT_DOUBLE_EQ(p(0, 1), 1.5 + std::sin(-0.1));
  EXPECT_DOUBLE_EQ(p(1, 1), 1.1 - std::cos(-0.1));
  EXPECT_DOUBLE_EQ(presentation.XVelocity(1, flight), 0.7);
}

// X integrates x_velocity by the trapezoidal rule, 0 at t = 0 and continuous across a reset (the two
// samples of a reset share their time).
TEST(ModelSetup, DrawOrbitIntegratesXAlongTheSamples) {
  const HybridModel model = MakeBuiltinModel("slip");
  const OrbitPresentation presentation(model);
  Vector stance(4), flight_a(5), flight_b(5);
  stance << 0.2, 1.0, 0.5, 0.3;  // lift-off state, horizontal speed v0
  const double v0 = -0.3 * std::sin(0.2) - 0.5 * std::cos(0.2);
  flight_a << std::cos(0.2), 0.2, v0, 0.1, 0.5;
  flight_b << 1.0, 0.1, v0, -0.1, 0.4;
  const std::vector<OrbitSample> samples = {{0.0, 0, stance}, {0.0, 1, flight_a}, {0.25, 1, flight_b}};
  const std::vector<Matrix> drawn = presentation.DrawOrbit(samples);
  ASSERT_EQ(drawn.size(), 3u);
  EXPECT_EQ(drawn[0](0, 0), 0.0);
  EXPECT_EQ(drawn[1](0, 0), 0.0);
  EXPECT_DOUBLE_EQ(drawn[2](0, 0), 0.25 * v0);
  // At lift-off the stance foot and the flight foot coincide.
  EXPECT_NEAR(drawn[0](0, 1), drawn[1](0, 1), 1e-15);
  EXPECT_NEAR(drawn[0](1, 1), drawn[1](1, 1), 1e-15);
}

// The block's motion about the right corner is folded onto the left one: drawn mirrored after the impact.
TEST(ModelSetup, RockingBlockIsDrawnMirroredAfterTheImpact) {
  const HybridModel model = MakeBuiltinModel("rocking-block");
  const OrbitPresentation presentation(model);
  const double w = 2.0 * std::sin(0.3), h = 2.0 * std::cos(0.3), a = 0.1;
  const Vector x = Eigen::Vector2d(a, 0.0);
  const Matrix before = presentation.DrawingPoints(0, x, 0.0), after = presentation.DrawingPoints(1, x, 0.0);
  const std::vector<std::string>& names = presentation.point_names();
  const auto column = [&](const std::string& name) {
    return std::find(names.begin(), names.end(), name) - names.begin();
  };
  EXPECT_EQ(before(0, column("pivot")), 0.0);
  EXPECT_DOUBLE_EQ(after(0, column("pivot")), w);
  EXPECT_DOUBLE_EQ(before(0, column("corner3")), w * std::cos(a) - h * std::sin(a));
  EXPECT_DOUBLE_EQ(before(1, column("corner3")), w * std::sin(a) + h * std::cos(a));
  EXPECT_DOUBLE_EQ(after(0, column("corner3")), w - (w * std::cos(a) - h * std::sin(a)));
  EXPECT_TRUE(after.row(1) == before.row(1));
}

TEST(ModelSetup, ParameterRangesRefuseUnphysicalValues) {
  HybridModel slip = MakeBuiltinModel("slip");
  try {
    slip.SetParameter("k", -40);
    FAIL() << "k = -40 accepted";
  } catch (const std::invalid_argument& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("'k'"), std::string::npos) << message;
    EXPECT_NE(message.find("-40"), std::string::npos) << message;
    EXPECT_NE(message.find("(0, inf)"), std::string::npos) << message;
  }
  EXPECT_EQ(slip.parameter("k"), 40.0);
  HybridModel block = MakeBuiltinModel("rocking-block");
  EXPECT_THROW(block.SetParameter("beta", M_PI / 2), std::invalid_argument);
  EXPECT_THROW(block.SetParameter("beta", 0.0), std::invalid_argument);
  block.SetParameter("beta", 1.5);
  for (const std::string& name : BuiltinModelNames()) {
    HybridModel model = MakeBuiltinModel(name);
    for (const ParameterInfo& p : model.parameters()) {
      EXPECT_THROW(model.SetParameter(p.name, -1.0), std::invalid_argument) << name << " " << p.name;
    }
  }
}

TEST(ModelSetup, BadSetupValuesNameTheirField) {
  const HybridModel model = MakeBuiltinModel("slip");
  try {
    EvaluateSetupValue(model, SetupValue("m*q"), "run.bounds.H[1]");
    FAIL();
  } catch (const ModelInputError& e) {
    EXPECT_NE(std::string(e.what()).find("run.bounds.H[1]"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("q"), std::string::npos) << e.what();
  }
  try {
    EvaluateSetupValue(model, SetupValue("sqrt(-k)"), "run.scales.H");
    FAIL();
  } catch (const ModelInputError& e) {
    EXPECT_NE(std::string(e.what()).find("run.scales.H"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("sqrt(-k)"), std::string::npos) << e.what();
  }
  EXPECT_EQ(EvaluateSetupValue(model, SetupValue("pi*sqrt(m/k)")), M_PI * std::sqrt(1.0 / 40.0));
}

// A model file's [definitions]: named values over parameters and other definitions, usable everywhere.
TEST(ModelSetup, DefinitionsAreUsableInEveryExpression) {
  HybridModel block = MakeBuiltinModel("rocking-block");
  const double H_max = study::DefaultScenario(block).bounds[1].upper;
  ModelSetup setup = block.setup();
  setup.definitions = {{"H_half", "0.5*H_max"}, {"H_max", "m*g*l0*(1 - cos(beta))"}};
  setup.run.bounds[1].upper = "H_max";
  setup.run.keyframe_value = "H_half";
  setup.quantities = {{"fill", "H/H_max", "energy as a fraction of the homoclinic one"}};
  setup.families = {{"high", "fill > 0.5"}, {"low", "1"}};
  setup.drawing.phases[0].points[0].y = "H_max";
  block.SetSetup(setup);
  const study::Scenario s = study::DefaultScenario(block);
  EXPECT_EQ(s.bounds[1].upper, H_max);
  EXPECT_EQ(s.keyframes.value, 0.5 * H_max);
  const OrbitPresentation presentation(block);
  const Vector u = WithValues(block, {{"H", 0.75 * H_max}});
  EXPECT_EQ(presentation.Quantities(u), std::vector<double>{0.75 * H_max / H_max});
  EXPECT_EQ(presentation.Family(u), "high");
  EXPECT_EQ(presentation.DrawingPoints(0, Eigen::Vector2d(0.1, 0.0), 0.0)(1, 0), H_max);

  setup.definitions = {{"a", "2*b"}, {"b", "a + 1"}};
  block.SetSetup(setup);
  try {
    EvaluateSetupValue(block, SetupValue("a"));
    FAIL() << "a cyclic definition accepted";
  } catch (const ModelInputError& e) {
    EXPECT_NE(std::string(e.what()).find("defined in terms of itself"), std::string::npos) << e.what();
  }
}

std::vector<std::string> ReadHeader(const std::filesystem::path& file) {
  std::ifstream in(file);
  std::string line;
  std::getline(in, line);
  std::vector<std::string> cells;
  std::stringstream ss(line);
  for (std::string cell; std::getline(ss, cell, ',');) cells.push_back(cell);
  return cells;
}

// The files the figure script reads: quantities as branch columns, the phase and the drawing in orbit
// files, the presentation in summary.json.
TEST(ModelSetup, ResultsCarryThePresentation) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "hybridcont_model_setup_test";
  std::filesystem::remove_all(dir);
  study::ResultsWriter::PrepareDirectory(dir);
  const HybridModel model = MakeBuiltinModel("bouncing-rod");
  study::ResultsWriter writer(dir, model, nlohmann::json::object(), StudyModelSource{});
  study::PointRecord point;
  point.u = WithValues(model, {{"t1", 0.1}, {"t2", 0.5}, {"t3", 0.2}, {"H", 0.3}});
  point.extra = {{"stable", 1.0}};
  writer.AddPoint(0, point);
  const std::vector<std::string> header = ReadHeader(dir / BranchFileName(0));
  ASSERT_GE(header.size(), 2u);
  EXPECT_EQ(header[header.size() - 2], "stable");
  EXPECT_EQ(header.back(), "asym");

  const HybridModel slip = MakeBuiltinModel("slip");
  study::ResultsWriter slip_writer(dir, slip, nlohmann::json::object(), StudyModelSource{});
  const Vector u0 = StartPoint(slip);
  const OrbitTrace trace(slip, u0, IntegratorOptions{});
  ASSERT_TRUE(trace.ok()) << trace.message();
  const std::string file = slip_writer.AddOrbit(trace, 0, 0, 1.0, 1.0, "hopping in place");
  const std::vector<std::string> columns = ReadHeader(dir / file);
  ASSERT_GE(columns.size(), 3u);
  EXPECT_EQ(columns[0], "t");
  EXPECT_EQ(columns[1], "segment");
  EXPECT_EQ(columns[2], "phase");
  const std::vector<std::string> draw(columns.end() - 4, columns.end());
  EXPECT_EQ(draw, (std::vector<std::string>{"draw.body.x", "draw.body.y", "draw.foot.x", "draw.foot.y"}));
  slip_writer.WriteSummary();
  std::ifstream summary_file(dir / "summary.json");
  const nlohmann::json summary = nlohmann::json::parse(summary_file);
  const nlohmann::json& p = summary["presentation"];
  EXPECT_EQ(p["title"], "SLIP hopper");
  EXPECT_EQ(p["quantities"], nlohmann::json::array());
  EXPECT_EQ(p["families"], nlohmann::json({"hopping in place", "forward hopping", "backward hopping"}));
  ASSERT_EQ(p["figures"].size(), 2u);
  EXPECT_EQ(p["figures"][0], nlohmann::json({{"file", "slip_durations.png"},
                                             {"title", "stance durations t1, t3 over the flight time t2"},
                                             {"x", "t2"},
                                             {"y", {"t1", "t3"}},
                                             {"zoom", false}}));
  EXPECT_EQ(p["drawing"]["ground"], true);
  EXPECT_EQ(p["drawing"]["mass_radius"], 0.075);
  EXPECT_EQ(p["drawing"]["phases"]["stance"]["lines"], nlohmann::json::array({nlohmann::json::array({"foot", "body"})}));
  EXPECT_EQ(p["drawing"]["phases"]["flight"]["masses"], nlohmann::json({"body"}));
  EXPECT_EQ(summary["orbits"][0]["label"], "hopping in place");
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace hybridcont
