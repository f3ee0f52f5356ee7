// Krein collisions (floquet.h, krein_test): a symplectic return map with two pairs of multipliers on the
// unit circle of opposite Krein signature, whose collisions open and close intervals of instability. The
// model: a ball bouncing elastically (the first integral's carrier) beside two unit-frequency oscillators of
// energies +1/2(p1² + q1²) and −1/2(p2² + q2²), mixed at each impact by a hyperbolic rotation of angle b
// (q -> L q, p -> L^-T p, L = [[cosh b, sinh b], [sinh b, cosh b]]: symplectic, and it keeps q1² − q2² and
// p1² − p2², so H), then the first oscillator turned by the angle phi (without it the two pairs of
// multipliers coincide for every H). On the family with the oscillators at rest (period T = 2 sqrt(2H) for
// g = 1) the oscillators' monodromy is similar to S R(T), R the rotation of both by T: its multipliers are
// computed here independently (a 4 x 4 eigenproblem) and the collisions located by bisection.
#include <gtest/gtest.h>

#include "hybridcont/study.h"

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>


#include "hybridcont/floquet.h"

namespace hybridcont {
namespace {

namespace fs = std::filesystem;

constexpr double kBoost = 0.3;
constexpr double kTurn = 0.7;

// The model file, with its start at H = 0.3 (apex height 0.3, each half of the period sqrt(0.6)).
std::string KreinModelText() {
  return R"toml(hybridcont = 1
name = "krein-oscillators"
[parameters]
g = { value = 1.0, range = "(0, inf)" }
b = { value = 0.3, description = "hyperbolic angle mixing the oscillators at each impact" }
phi = { value = 0.7, description = "angle the first oscillator is turned by at each impact" }
[[phases]]
name = "flight"
states = ["y", "dy", "q1", "p1", "q2", "p2"]
typical = [0.5, 0.3, 0.1, 0.1, 0.1, 0.1]
ode = { y = "dy", dy = "-g", q1 = "p1", p1 = "-q1", q2 = "p2", p2 = "-q2" }
energy = "0.5*dy^2 + g*y + 0.5*(p1^2 + q1^2) - 0.5*(p2^2 + q2^2)"
event = "y"
anchor = "dy"
let = { Q1 = "cosh(b)*q1 + sinh(b)*q2", P1 = "cosh(b)*p1 - sinh(b)*p2" }
reset = { y = "y", dy = "-dy", q1 = "cos(phi)*Q1 + sin(phi)*P1", p1 = "-sin(phi)*Q1 + cos(phi)*P1", q2 = "sinh(b)*q1 + cosh(b)*q2", p2 = "-sinh(b)*p1 + cosh(b)*p2" }
[start]
kind = "guess"
values = { t1 = 0.7745966692414834, t2 = 0.7745966692414834, x1_y = 0.3, x2_dy = 0.7745966692414834, H = 0.3 }
[run]
bounds = { xi = [-1, 1], H = [0.05, 3] }
max_branches = 2
)toml";
}

// Largest modulus of the multipliers of S R(T).
double LargestMultiplier(double T) {
  const double c = std::cosh(kBoost), s = std::sinh(kBoost);
  Eigen::Matrix4d S = Eigen::Matrix4d::Zero(), R = Eigen::Matrix4d::Zero();  // order q1, p1, q2, p2
  S(0, 0) = c, S(0, 2) = s, S(2, 0) = s, S(2, 2) = c;      // q -> L q
  S(1, 1) = c, S(1, 3) = -s, S(3, 1) = -s, S(3, 3) = c;    // p -> L^-T p
  Eigen::Matrix4d turn = Eigen::Matrix4d::Identity();       // (q1, p1) turned by phi
  turn(0, 0) = std::cos(kTurn), turn(0, 1) = std::sin(kTurn), turn(1, 0) = -std::sin(kTurn), turn(1, 1) = std::cos(kTurn);
  S = turn * S;
  for (const int i : {0, 2}) {
    R(i, i) = std::cos(T), R(i, i + 1) = std::sin(T), R(i + 1, i) = -std::sin(T), R(i + 1, i + 1) = std::cos(T);
  }
  const Eigen::VectorXcd mu = Eigenvalues(S * R);
  return mu.cwiseAbs().maxCoeff();
}

TEST(KreinCollision, LocatedWhereTheIndependentMultipliersLeaveTheUnitCircle) {
  // Independent: the H where S R(T) becomes unstable or stable again, T = 2 sqrt(2H), H in [0.05, 3].
  std::vector<double> expected;
  const auto unstable = [](double H) { return LargestMultiplier(2 * std::sqrt(2 * H)) > 1 + 1e-9; };
  const int n = 6000;
  for (int i = 0; i < n; ++i) {
    double a = 0.05 + (3 - 0.05) * i / n, b = 0.05 + (3 - 0.05) * (i + 1) / n;
    if (unstable(a) == unstable(b)) continue;
    const bool ua = unstable(a);
    for (int it = 0; it < 60; ++it) {
      const double mid = 0.5 * (a + b);
      (unstable(mid) == ua ? a : b) = mid;
    }
    expected.push_back(0.5 * (a + b));
  }
  ASSERT_GE(expected.size(), 2u);
  const fs::path dir = fs::temp_directory_path() / "hybridcont_krein";
  fs::create_directories(dir);
  const fs::path file = dir / "krein.toml";
  std::ofstream(file) << KreinModelText();
  StudyOptions options;
  options.model = file.string();
  const StudyResult study = RunStudy(options);
  ASSERT_EQ(study.status, ExplorationStatus::kCompleted) << study.message;
  std::vector<double> located;
  for (const StudySpecialPoint& sp : study.special_points) {
    if (sp.type == SpecialPointType::kKreinCollision && sp.duplicate_of == -1) located.push_back(sp.H);
  }
  std::sort(located.begin(), located.end());
  located.erase(std::unique(located.begin(), located.end(), [](double x, double y) { return std::abs(x - y) < 1e-7; }),
                located.end());
  ASSERT_EQ(located.size(), expected.size()) << study.report;
  double worst = 0;
  for (std::size_t i = 0; i < expected.size(); ++i) worst = std::max(worst, std::abs(located[i] - expected[i]));
  // The bisection on |mu| > 1 + 1e-9 sees the collision late by the square root of that threshold's
  // worth of H (the quadruplet leaves the circle like sqrt(H − H*)): about 1e-9 in H here.
  EXPECT_LT(worst, 1e-7);
  std::printf("Krein collisions: %zu located, at H =", located.size());
  for (double H : located) std::printf(" %.10f", H);
  std::printf("; independent eigenvalues agree to %.1e\n", worst);
}

}  // namespace
}  // namespace hybridcont
