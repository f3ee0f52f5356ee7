// A forward-mode jet with value, gradient and Hessian over N seeds (included by internal/autodiff_phase.h; not used
// directly). It is the scalar type a model's FirstIntegral(s) see when the library needs d2H:
//
//   using J = HessianJet<2>;
//   const J x = J::Variable(3.0, 0), y = J::Variable(2.0, 1);
//   const J h = x * x * y;  // h.value = 18, gradient (12, 9), Hessian [[4, 6], [6, 0]]
//
// The Hessian is symmetric, so only its upper triangle is stored, packed row by row (hessian[Packed(i, j)]).
// Every operation applies the second-order product or chain rule:
//   (f g)''   = f g'' + g f'' + f' g'^T + g' f'^T,
//   phi(f)''  = phi'(f) f'' + phi''(f) f' f'^T,
//   phi(f, g)'' = phi_f f'' + phi_g g'' + phi_ff f' f'^T + phi_gg g' g'^T + phi_fg (f' g'^T + g' f'^T).
// It offers the operators and functions of Eigen's AutoDiffScalar (the first-order jet), so a model that
// compiles for one compiles for the other.
//
// Why hand-written (conventions §4 prefers a well-kept library): nested Eigen AutoDiffScalars, the
// library way, cost about twice as much per SLIP evaluation, and Ceres' Jet cannot be nested for this
// (docs/design/shooting.md, "A hand-written second-order jet").
#ifndef HYBRIDCONT_HESSIAN_JET_H_
#define HYBRIDCONT_HESSIAN_JET_H_

#include <array>
#include <cmath>
#include <limits>

#include <Eigen/Core>

// Fully unrolled loops over the fixed N: 12% off the SLIP's unfolded vector field with its Hessian term
// (GCC 12 does not unroll the triangular loops by itself).
#if defined(__clang__)
#define HYBRIDCONT_UNROLL _Pragma("unroll")
#elif defined(__GNUC__)
#define HYBRIDCONT_UNROLL _Pragma("GCC unroll 64")
#else
#define HYBRIDCONT_UNROLL
#endif

namespace hybridcont::internal {

template <int N>
struct HessianJet {
  static constexpr int kPackedSize = N * (N + 1) / 2;
  // Index of H(i, j), i <= j, in the packed upper triangle.
  static constexpr int Packed(int i, int j) { return i * N - i * (i - 1) / 2 + (j - i); }

  // Uninitialized, like double and AutoDiffScalar: Eigen's bounded-dynamic vectors of jets construct all
  // kMaxPhaseDim entries, and zeroing them cost more than the Hessian arithmetic.
  HessianJet() = default;
  // A constant (implicit, like AutoDiffScalar: `T(0)`, `2.0 * x`, `x + 1.0`).
  HessianJet(double v) : value(v), gradient{}, hessian{} {}  // NOLINT(google-explicit-constructor)
  // The i-th independent variable at v.
  static HessianJet Variable(double v, int i) {
    HessianJet x(v);
    x.gradient[i] = 1.0;
    return x;
  }

  HessianJet& operator+=(const HessianJet& g) { return *this = *this + g; }
  HessianJet& operator-=(const HessianJet& g) { return *this = *this - g; }
  HessianJet& operator*=(const HessianJet& g) { return *this = *this * g; }
  HessianJet& operator/=(const HessianJet& g) { return *this = *this / g; }
  HessianJet& operator+=(double s) { value += s; return *this; }
  HessianJet& operator-=(double s) { value -= s; return *this; }
  HessianJet& operator*=(double s) { return *this = *this * s; }
  HessianJet& operator/=(double s) { return *this = *this * (1.0 / s); }

  double value;
  std::array<double, N> gradient;
  std::array<double, kPackedSize> hessian;
};

// phi(f) from phi(f.value) = v, phi' = d1, phi'' = d2.
template <int N>
inline HessianJet<N> Chain(const HessianJet<N>& f, double v, double d1, double d2) {
  HessianJet<N> r;
  r.value = v;
  HYBRIDCONT_UNROLL for (int i = 0; i < N; ++i) r.gradient[i] = d1 * f.gradient[i];
  int q = 0;
  HYBRIDCONT_UNROLL for (int i = 0; i < N; ++i) {
    const double t = d2 * f.gradient[i];
    HYBRIDCONT_UNROLL for (int j = i; j < N; ++j, ++q) r.hessian[q] = d1 * f.hessian[q] + t * f.gradient[j];
  }
  return r;
}

// phi(f, g) from its value v, first partials (df, dg) and second partials (dff, dgg, dfg).
template <int N>
inline HessianJet<N> Chain(const HessianJet<N>& f, const HessianJet<N>& g, double v, double df, double dg,
                           double dff, double dgg, double dfg) {
  HessianJet<N> r;
  r.value = v;
  HYBRIDCONT_UNROLL for (int i = 0; i < N; ++i) r.gradient[i] = df * f.gradient[i] + dg * g.gradient[i];
  int q = 0;
  HYBRIDCONT_UNROLL for (int i = 0; i < N; ++i) {
    const double fi = f.gradient[i], gi = g.gradient[i];
    HYBRIDCONT_UNROLL for (int j = i; j < N; ++j, ++q) {
      const double fj = f.gradient[j], gj = g.gradient[j];
      r.hessian[q] = df * f.hessian[q] + dg * g.hessian[q] + dff * fi * fj + dgg * gi * gj + dfg * (fi * gj + gi * fj);
    }
  }
  return r;
}

template <int N>
inline HessianJet<N> operator+(const HessianJet<N>& f) {
  return f;
}
template <int N>
inline HessianJet<N> operator-(const HessianJet<N>& f) {
  HessianJet<N> r;
  r.value = -f.value;
  HYBRIDCONT_UNROLL for (int i = 0; i < N; ++i) r.gradient[i] = -f.gradient[i];
  HYBRIDCONT_UNROLL for (int q = 0; q < HessianJet<N>::kPackedSize; ++q) r.hessian[q] = -f.hessian[q];
  return r;
}
template <int N>
inline HessianJet<N> operator+(const HessianJet<N>& f, const HessianJet<N>& g) {
  HessianJet<N> r;
  r.value = f.value + g.value;
  HYBRIDCONT_UNROLL for (int i = 0; i < N; ++i) r.gradient[i] = f.gradient[i] + g.gradient[i];
  HYBRIDCONT_UNROLL for (int q = 0; q < HessianJet<N>::kPackedSize; ++q) r.hessian[q] = f.hessian[q] + g.hessian[q];
  return r;
}
template <int N>
inline HessianJet<N> operator-(const HessianJet<N>& f, const HessianJet<N>& g) {
  HessianJet<N> r;
  r.value = f.value - g.value;
  HYBRIDCONT_UNROLL for (int i = 0; i < N; ++i) r.gradient[i] = f.gradient[i] - g.gradient[i];
  HYBRIDCONT_UNROLL for (int q = 0; q < HessianJet<N>::kPackedSize; ++q) r.hessian[q] = f.hessian[q] - g.hessian[q];
  return r;
}
template <int N>
inline HessianJet<N> operator*(const HessianJet<N>& f, const HessianJet<N>& g) {
  HessianJet<N> r;
  r.value = f.value * g.value;
  HYBRIDCONT_UNROLL for (int i = 0; i < N; ++i) r.gradient[i] = f.value * g.gradient[i] + g.value * f.gradient[i];
  int q = 0;
  HYBRIDCONT_UNROLL for (int i = 0; i < N; ++i) {
    const double fi = f.gradient[i], gi = g.gradient[i];
    HYBRIDCONT_UNROLL for (int j = i; j < N; ++j, ++q) {
      r.hessian[q] = f.value * g.hessian[q] + g.value * f.hessian[q] + fi * g.gradient[j] + gi * f.gradient[j];
    }
  }
  return r;
}
template <int N>
inline HessianJet<N> operator/(const HessianJet<N>& f, const HessianJet<N>& g) {
  const double r = 1.0 / g.value;
  return f * Chain(g, r, -r * r, 2.0 * r * r * r);
}

template <int N>
inline HessianJet<N> operator+(const HessianJet<N>& f, double s) {
  HessianJet<N> r = f;
  r.value += s;
  return r;
}
template <int N>
inline HessianJet<N> operator+(double s, const HessianJet<N>& f) {
  return f + s;
}
template <int N>
inline HessianJet<N> operator-(const HessianJet<N>& f, double s) {
  HessianJet<N> r = f;
  r.value -= s;
  return r;
}
template <int N>
inline HessianJet<N> operator-(double s, const HessianJet<N>& f) {
  HessianJet<N> r = -f;
  r.value += s;
  return r;
}
template <int N>
inline HessianJet<N> operator*(const HessianJet<N>& f, double s) {
  HessianJet<N> r;
  r.value = f.value * s;
  HYBRIDCONT_UNROLL for (int i = 0; i < N; ++i) r.gradient[i] = f.gradient[i] * s;
  HYBRIDCONT_UNROLL for (int q = 0; q < HessianJet<N>::kPackedSize; ++q) r.hessian[q] = f.hessian[q] * s;
  return r;
}
template <int N>
inline HessianJet<N> operator*(double s, const HessianJet<N>& f) {
  return f * s;
}
template <int N>
inline HessianJet<N> operator/(const HessianJet<N>& f, double s) {
  return f * (1.0 / s);
}
template <int N>
inline HessianJet<N> operator/(double s, const HessianJet<N>& g) {
  const double r = 1.0 / g.value;
  return Chain(g, s * r, -s * r * r, 2.0 * s * r * r * r);
}

// Comparisons look at values only (as AutoDiffScalar's do).
#define HYBRIDCONT_HESSIAN_JET_COMPARISON(OP)                                                                   \
  template <int N>                                                                                           \
  inline bool operator OP(const HessianJet<N>& f, const HessianJet<N>& g) { return f.value OP g.value; }     \
  template <int N>                                                                                           \
  inline bool operator OP(const HessianJet<N>& f, double s) { return f.value OP s; }                         \
  template <int N>                                                                                           \
  inline bool operator OP(double s, const HessianJet<N>& g) { return s OP g.value; }
HYBRIDCONT_HESSIAN_JET_COMPARISON(<)
HYBRIDCONT_HESSIAN_JET_COMPARISON(<=)
HYBRIDCONT_HESSIAN_JET_COMPARISON(>)
HYBRIDCONT_HESSIAN_JET_COMPARISON(>=)
HYBRIDCONT_HESSIAN_JET_COMPARISON(==)
HYBRIDCONT_HESSIAN_JET_COMPARISON(!=)
#undef HYBRIDCONT_HESSIAN_JET_COMPARISON

// Elementary functions, found by argument-dependent lookup as `using std::sin; sin(x)` does.
template <int N>
inline HessianJet<N> sin(const HessianJet<N>& f) {
  const double s = std::sin(f.value), c = std::cos(f.value);
  return Chain(f, s, c, -s);
}
template <int N>
inline HessianJet<N> cos(const HessianJet<N>& f) {
  const double s = std::sin(f.value), c = std::cos(f.value);
  return Chain(f, c, -s, -c);
}
template <int N>
inline HessianJet<N> tan(const HessianJet<N>& f) {
  const double t = std::tan(f.value), d1 = 1.0 + t * t;
  return Chain(f, t, d1, 2.0 * t * d1);
}
template <int N>
inline HessianJet<N> asin(const HessianJet<N>& f) {
  const double w = 1.0 / (1.0 - f.value * f.value), d1 = std::sqrt(w);
  return Chain(f, std::asin(f.value), d1, f.value * w * d1);
}
template <int N>
inline HessianJet<N> acos(const HessianJet<N>& f) {
  const double w = 1.0 / (1.0 - f.value * f.value), d1 = std::sqrt(w);
  return Chain(f, std::acos(f.value), -d1, -f.value * w * d1);
}
template <int N>
inline HessianJet<N> atan2(const HessianJet<N>& y, const HessianJet<N>& x) {
  const double w = 1.0 / (x.value * x.value + y.value * y.value), w2 = w * w;
  const double xy = x.value * y.value;
  return Chain(y, x, std::atan2(y.value, x.value), x.value * w, -y.value * w, -2.0 * xy * w2, 2.0 * xy * w2,
               (y.value * y.value - x.value * x.value) * w2);
}
template <int N>
inline HessianJet<N> sinh(const HessianJet<N>& f) {
  const double s = std::sinh(f.value);
  return Chain(f, s, std::cosh(f.value), s);
}
template <int N>
inline HessianJet<N> cosh(const HessianJet<N>& f) {
  const double c = std::cosh(f.value);
  return Chain(f, c, std::sinh(f.value), c);
}
template <int N>
inline HessianJet<N> tanh(const HessianJet<N>& f) {
  const double t = std::tanh(f.value), d1 = 1.0 - t * t;
  return Chain(f, t, d1, -2.0 * t * d1);
}
template <int N>
inline HessianJet<N> exp(const HessianJet<N>& f) {
  const double e = std::exp(f.value);
  return Chain(f, e, e, e);
}
template <int N>
inline HessianJet<N> log(const HessianJet<N>& f) {
  const double r = 1.0 / f.value;
  return Chain(f, std::log(f.value), r, -r * r);
}
template <int N>
inline HessianJet<N> sqrt(const HessianJet<N>& f) {
  const double s = std::sqrt(f.value), d1 = 0.5 / s;
  return Chain(f, s, d1, -0.5 * d1 / f.value);
}
template <int N>
inline HessianJet<N> pow(const HessianJet<N>& f, double y) {
  return Chain(f, std::pow(f.value, y), y * std::pow(f.value, y - 1.0), y * (y - 1.0) * std::pow(f.value, y - 2.0));
}
template <int N>
inline HessianJet<N> abs(const HessianJet<N>& f) {
  return f.value < 0.0 ? -f : f;
}
template <int N>
inline HessianJet<N> abs2(const HessianJet<N>& f) {
  return f * f;
}
template <int N>
inline const HessianJet<N>& conj(const HessianJet<N>& f) {
  return f;
}
template <int N>
inline const HessianJet<N>& real(const HessianJet<N>& f) {
  return f;
}
template <int N>
inline double imag(const HessianJet<N>&) {
  return 0.0;
}
// min/max select one argument, with AutoDiffScalar's tie rules.
template <int N>
inline HessianJet<N> (min)(const HessianJet<N>& f, const HessianJet<N>& g) {
  return f.value < g.value ? f : g;
}
template <int N>
inline HessianJet<N> (max)(const HessianJet<N>& f, const HessianJet<N>& g) {
  return f.value >= g.value ? f : g;
}
template <int N>
inline HessianJet<N> (min)(const HessianJet<N>& f, double s) {
  return f.value <= s ? f : HessianJet<N>(s);
}
template <int N>
inline HessianJet<N> (max)(const HessianJet<N>& f, double s) {
  return f.value >= s ? f : HessianJet<N>(s);
}
template <int N>
inline HessianJet<N> (min)(double s, const HessianJet<N>& g) {
  return s < g.value ? HessianJet<N>(s) : g;
}
template <int N>
inline HessianJet<N> (max)(double s, const HessianJet<N>& g) {
  return s > g.value ? HessianJet<N>(s) : g;
}

}  // namespace hybridcont::internal

namespace Eigen {

template <int N>
struct NumTraits<hybridcont::internal::HessianJet<N>> : NumTraits<double> {
  using Real = hybridcont::internal::HessianJet<N>;
  using NonInteger = Real;
  using Nested = Real;
  using Literal = double;
  enum {
    IsComplex = 0,
    IsInteger = 0,
    IsSigned = 1,
    RequireInitialization = 1,
    ReadCost = 1 + N + N * (N + 1) / 2,
    AddCost = 1 + N + N * (N + 1) / 2,
    MulCost = 3 * (1 + N + N * (N + 1) / 2),
  };
};
template <int N, typename BinaryOp>
struct ScalarBinaryOpTraits<hybridcont::internal::HessianJet<N>, double, BinaryOp> {
  using ReturnType = hybridcont::internal::HessianJet<N>;
};
template <int N, typename BinaryOp>
struct ScalarBinaryOpTraits<double, hybridcont::internal::HessianJet<N>, BinaryOp> {
  using ReturnType = hybridcont::internal::HessianJet<N>;
};

}  // namespace Eigen

namespace std {

template <int N>
class numeric_limits<hybridcont::internal::HessianJet<N>> : public numeric_limits<double> {};

}  // namespace std

#undef HYBRIDCONT_UNROLL

#endif  // HYBRIDCONT_HESSIAN_JET_H_
