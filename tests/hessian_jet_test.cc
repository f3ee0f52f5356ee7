// The second-order jet agrees with nested Eigen AutoDiffScalars (the reference it replaced) where those
// apply, and with differenced first-order gradients on the functions only it offers.
#include <gtest/gtest.h>

#include "hybridcont/internal/autodiff_phase.h"
#include "hybridcont/model.h"

namespace hybridcont::internal {
namespace {

// The operations nested AutoDiffScalars support, with double constants on both sides.
template <class T>
T Smooth(const StateVector<T>& x) {
  using std::acos;
  using std::asin;
  using std::atan2;
  using std::cos;
  using std::cosh;
  using std::exp;
  using std::log;
  using std::sin;
  using std::sinh;
  using std::sqrt;
  using std::tan;
  using std::tanh;
  T r = sin(x(0)) * cos(x(1)) + tan(0.3 * x(2)) - asin(0.5 * x(0)) * acos(0.2 * x(1));
  r += atan2(x(2), x(0)) + atan2(-x(1), x(2)) * sinh(x(1)) - cosh(x(2)) / tanh(x(0) + 1.0);
  r -= exp(x(0) * x(1)) * log(2.0 + x(2)) + sqrt(3.0 + x(0) * x(2));
  r *= 2.0 - x(0) / x(1) + 1.0 / x(2) - x(2) / 3.0;
  r /= x(1) * x(1) + 0.5;
  return r + (3.0 - x(0) * x(1)) * x(0) - 1.0;
}

// The rest (first-order AutoDiffScalars only): abs, abs2, pow, min, max.
template <class T>
T Piecewise(const StateVector<T>& x) {
  using std::abs;
  using std::pow;
  using std::max;
  using std::min;
  using Eigen::numext::abs2;
  return pow(1.5 + x(1), 2.5) * abs(-x(1)) + abs2(x(2)) * abs(x(0)) + max(x(0), x(1)) * min(x(1), 0.25) +
         max(0.7, x(2)) * x(0) - min(x(0), x(2)) * x(2) + min(0.9, x(1)) * x(1) + max(x(2), 0.1) * x(0);
}

constexpr int kN = 3;
Vector Point() {
  Vector x(kN);
  x << 0.4, 0.6, 0.8;
  return x;
}

TEST(HessianJet, AgreesWithNestedAutoDiff) {
  const Vector x = Point();
  const HessianJet<kN> h = Smooth<HessianJet<kN>>(SeedJets2<HessianJet<kN>>(x));
  const Jet2 ref = Smooth<Jet2>(SeedJets2<Jet2>(x));
  auto tol = [](double want, double rel) { return rel * std::max(1.0, std::abs(want)); };
  EXPECT_NEAR(h.value, ref.value().value(), tol(ref.value().value(), 1e-14));
  for (int a = 0; a < kN; ++a) {
    const Jet& g = ref.derivatives()(a);
    EXPECT_NEAR(h.gradient[a], g.value(), tol(g.value(), 1e-13)) << "gradient " << a;
    for (int b = 0; b < kN; ++b) {
      const double want = g.derivatives()(b);
      EXPECT_NEAR(h.hessian[HessianJet<kN>::Packed(std::min(a, b), std::max(a, b))], want, tol(want, 1e-12))
          << "Hessian " << a << "," << b;
    }
  }
}

TEST(HessianJet, AgreesWithDifferencedGradients) {
  using J = JetTypes<kN>::J;
  const Vector x = Point();
  const HessianJet<kN> h = Piecewise<HessianJet<kN>>(SeedJets2<HessianJet<kN>>(x));
  auto gradient = [](const Vector& y) { return Vector(Piecewise<J>(SeedJets<J>(y)).derivatives()); };
  EXPECT_NEAR(h.value, Piecewise<double>(x), 1e-14);
  const Vector g = gradient(x);
  const double step = 1e-5;
  for (int b = 0; b < kN; ++b) {
    EXPECT_NEAR(h.gradient[b], g(b), 1e-14) << "gradient " << b;
    Vector up = x, down = x;
    up(b) += step;
    down(b) -= step;
    const Vector column = (gradient(up) - gradient(down)) / (2.0 * step);
    for (int a = 0; a < kN; ++a) {
      EXPECT_NEAR(h.hessian[HessianJet<kN>::Packed(std::min(a, b), std::max(a, b))], column(a), 1e-8)
          << "Hessian " << a << "," << b;
    }
  }
}

TEST(HessianJet, ComparesByValue) {
  const HessianJet<2> x = HessianJet<2>::Variable(1.0, 0), y = HessianJet<2>::Variable(2.0, 1);
  EXPECT_TRUE(x < y);
  EXPECT_TRUE(x <= 1.0);
  EXPECT_TRUE(2.0 >= y);
  EXPECT_TRUE(x != y);
  EXPECT_TRUE(x == 1.0);
  EXPECT_TRUE(+x == x);
  EXPECT_FALSE(3.0 < y);
}

TEST(HessianJet, PackedIndexCoversTheUpperTriangle) {
  constexpr int n = 5;
  int expected = 0;
  for (int i = 0; i < n; ++i) {
    for (int j = i; j < n; ++j) EXPECT_EQ(HessianJet<n>::Packed(i, j), expected++);
  }
  EXPECT_EQ(expected, HessianJet<n>::kPackedSize);
}

}  // namespace
}  // namespace hybridcont::internal
