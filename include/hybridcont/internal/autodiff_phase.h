// Automatic differentiation of user-written phase functions (included by model_builder.h and
// expression_model.h; not used directly).
//
// A user functor F has static templates VectorField, FirstIntegral(s), Event and Reset over the scalar T.
// AutoDiffPhase<F, P> instantiates them with
//   - double                       for values,
//   - Jet  = AutoDiffScalar<dual>  for first derivatives (df, dH, de, D): one forward sweep over n seeds,
//   - a second-order jet           for the Hessians of H (needed by A = df~/dx when xi != 0):
//     HessianJet<n> (internal/hessian_jet.h) for n <= kMaxFixedJetDim, Jet2 = AutoDiffScalar<Jet> above.
// Derivative vectors are fixed-capacity (kMaxPhaseDim) stack storage, so no evaluation allocates on the
// heap. Eigen's AutoDiff module is the well-kept library this builds on (conventions §4).
#ifndef HYBRIDCONT_AUTODIFF_PHASE_H_
#define HYBRIDCONT_AUTODIFF_PHASE_H_

#include <algorithm>
#include <array>
#include <functional>
#include <cmath>
#include <concepts>
#include <memory>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include <Eigen/Core>
#include <unsupported/Eigen/AutoDiff>

#include "hybridcont/internal/hessian_jet.h"
#include "hybridcont/invariant.h"
#include "hybridcont/model.h"

namespace hybridcont::internal {

using DerivativeVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxPhaseDim, 1>;
using Jet = Eigen::AutoDiffScalar<DerivativeVector>;
using Jet2 = Eigen::AutoDiffScalar<Eigen::Matrix<Jet, Eigen::Dynamic, 1, 0, kMaxPhaseDim, 1>>;

// AD scalars for a phase of dimension N: fixed-size derivative vectors for small N (unrolled and
// vectorized by Eigen), bounded-dynamic ones otherwise. Second order: HessianJet for small N (cheaper than
// nested fixed-size AutoDiffScalars: docs/design/shooting.md), nested bounded-dynamic jets otherwise.
template <int N>
struct JetTypes {
  using J = Eigen::AutoDiffScalar<Eigen::Matrix<double, N, 1>>;
  using J2 = HessianJet<N>;
};
template <>
struct JetTypes<Eigen::Dynamic> {
  using J = Jet;
  using J2 = Jet2;
};
inline constexpr int kMaxFixedJetDim = 8;

// Calls fn(std::integral_constant<int, N>) with N = n for n <= kMaxFixedJetDim, Eigen::Dynamic otherwise.
template <class Fn>
decltype(auto) DispatchOnDimension(int n, Fn&& fn) {
  switch (n) {
    case 1: return fn(std::integral_constant<int, 1>{});
    case 2: return fn(std::integral_constant<int, 2>{});
    case 3: return fn(std::integral_constant<int, 3>{});
    case 4: return fn(std::integral_constant<int, 4>{});
    case 5: return fn(std::integral_constant<int, 5>{});
    case 6: return fn(std::integral_constant<int, 6>{});
    case 7: return fn(std::integral_constant<int, 7>{});
    case 8: return fn(std::integral_constant<int, 8>{});
    default: return fn(std::integral_constant<int, Eigen::Dynamic>{});
  }
}

// A functor may declare its state dimension, static constexpr int kDimension: its derivatives are then
// compiled for that dimension only (DispatchOnDimension compiles every one of 1..kMaxFixedJetDim and the
// bounded-dynamic path, most of a model file's compile time). The same jets as the dispatch would choose.
// kDimension = Eigen::Dynamic declares the bounded-dynamic path alone, for any dimension up to kMaxPhaseDim.
template <class F>
concept DeclaresDimension = requires {
  { F::kDimension } -> std::convertible_to<int>;
};

// fn(std::integral_constant<int, N>) for F's declared dimension n (DeclaresDimension), else
// DispatchOnDimension(n, fn). n must be the declared dimension (checked where the phase is built).
template <class F, class Fn>
decltype(auto) DispatchFor(int n, Fn&& fn) {
  if constexpr (DeclaresDimension<F>) {
    HYBRIDCONT_DEMAND(F::kDimension == Eigen::Dynamic || n == F::kDimension);
    constexpr int N = F::kDimension <= kMaxFixedJetDim ? F::kDimension : Eigen::Dynamic;
    return fn(std::integral_constant<int, N>{});
  } else {
    return DispatchOnDimension(n, std::forward<Fn>(fn));
  }
}

// Scalars for derivatives with respect to one model parameter p: ParamJet carries d/dp; MixedJet is the
// second-order jet in two variables (one state x_i, variable 0, and p, variable 1) whose mixed entry is
// ∂²H/∂x_i∂p (the ξ-term of ∂f~/∂p). Both convert implicitly from double, so parameter structs over them
// keep their default member initializers.
using ParamJet = Eigen::AutoDiffScalar<Eigen::Matrix<double, 1, 1>>;
using MixedJet = HessianJet<2>;

// The parameters a functor reads, over the scalar S. A parameter struct that is a template over its scalar
// (template <class T> struct SlipParameters { T k = 40; ... }, used as SlipParameters<double>) becomes
// SlipParameters<S>; the expression models specialize this for their data. Any other P has no `type`: its
// model cannot differentiate with respect to its parameters.
template <class P, class S>
struct ParametersAs {};
template <template <class> class PT, class S>
struct ParametersAs<PT<double>, S> {
  using type = PT<S>;
};
template <class P>
concept DifferentiableParameters =
    requires { typename ParametersAs<P, ParamJet>::type; typename ParametersAs<P, MixedJet>::type; };

// Made by a model's parameter block: its parameters as ParamJets or MixedJets, the derivative seed on
// parameter `index` (the others constant).
template <class P>
class ParameterSeeding {
 public:
  virtual ~ParameterSeeding() = default;
  // False when some parameter cannot be seeded (registered by a member pointer of the double struct).
  virtual bool can_seed() const = 0;
  // `values` is the P the phase reads (ParameterBlock::BindingFor of its slot).
  virtual typename ParametersAs<P, ParamJet>::type SeedParamJets(const P& values, int index) const = 0;
  virtual typename ParametersAs<P, MixedJet>::type SeedMixedJets(const P& values, int index) const = 0;
};
struct NoParameterSeeding {};
// ParametersAs<P, S>::type, or an empty placeholder for parameters that are not differentiable.
struct NotDifferentiable {};
template <class P, class S>
using ParametersAsOr = typename std::conditional_t<DifferentiableParameters<P>, ParametersAs<P, S>,
                                                   std::type_identity<NotDifferentiable>>::type;
template <class P>
using ParameterSeedingBase = std::conditional_t<DifferentiableParameters<P>, ParameterSeeding<P>, NoParameterSeeding>;

// The functor F accepts the parameters as ParamJets (it is written over a generic parameter type): a
// phase functor through its vector field, an anchor functor through its anchor.
template <class F, class Q>
concept TakesParameterJets = requires(const StateVector<ParamJet>& x, const Q& q) {
  { F::template VectorField<ParamJet>(x, q) };
} || requires(const StateVector<ParamJet>& x, const Q& q) {
  { F::template Anchor<ParamJet>(x, q) };
};

// A ParamJet with value v and derivative `seed`; a MixedJet that is variable 1 (p) when seeded.
inline ParamJet MakeParamJet(double v, double seed) {
  return ParamJet(v, Eigen::Matrix<double, 1, 1>::Constant(seed));
}
inline MixedJet MakeMixedJet(double v, double seed) { return seed != 0.0 ? MixedJet::Variable(v, 1) : MixedJet(v); }

// Seeds are written in place, each derivative vector by one wide copy of a unit vector: a seeded temporary
// copied in, or a unit vector written entry by entry, stalled on store forwarding when the jets were read
// back as vectors (~9% of a SLIP r + dr, ~30% of a bouncing-ball one).
template <int N>
struct UnitVectors {
  // [0, ..., 0, 1, 0, ..., 0] with the 1 at N - 1: e_i is the N entries from N - 1 - i.
  static constexpr std::array<double, 2 * N - 1> kOneHot = [] {
    std::array<double, 2 * N - 1> a{};
    a[N - 1] = 1.0;
    return a;
  }();
  static const double* e(int i) { return kOneHot.data() + (N - 1 - i); }
};

// x as n independent variables: seed x(i) with the i-th unit derivative.
template <class J>
StateVector<J> SeedJets(const Eigen::Ref<const Vector>& x) {
  using D = typename J::DerType;
  const int n = static_cast<int>(x.size());
  StateVector<J> xj(n);
  for (int i = 0; i < n; ++i) {
    xj(i).value() = x(i);
    if constexpr (D::SizeAtCompileTime == Eigen::Dynamic) {
      xj(i).derivatives() = D::Unit(n, i);
    } else {
      xj(i).derivatives() = Eigen::Map<const D>(UnitVectors<D::SizeAtCompileTime>::e(i));
    }
  }
  return xj;
}

template <class J2>
StateVector<J2> SeedJets2(const Eigen::Ref<const Vector>& x) {
  const int n = static_cast<int>(x.size());
  StateVector<J2> xj(n);
  for (int i = 0; i < n; ++i) {
    if constexpr (std::is_same_v<J2, Jet2>) {
      xj(i).value() = Jet(x(i), n, i);
      xj(i).derivatives().resize(n);
      for (int j = 0; j < n; ++j) xj(i).derivatives()(j) = Jet(i == j ? 1.0 : 0.0, DerivativeVector::Zero(n));
    } else {
      constexpr int N = static_cast<int>(std::tuple_size_v<decltype(J2::gradient)>);
      J2& v = xj(i);
      v.value = x(i);
      std::copy_n(UnitVectors<N>::e(i), N, v.gradient.begin());
      v.hessian.fill(0.0);
    }
  }
  return xj;
}

// Value and gradient (into a row) of a second-order jet, and its Hessian times weight added to *hessian
// (weight 1 on zeros: d2H_j itself; weight xi_j on df: A = df + sum_j xi_j d2H_j, the unfolded field's).
template <int N, class Row, class M>
void UnpackSecondOrder(const HessianJet<N>& h, double* value, Row&& gradient, double weight, M* hessian) {
  *value = h.value;
  for (int a = 0; a < N; ++a) {
    gradient(a) = h.gradient[a];
    for (int b = a; b < N; ++b) {
      const double w = weight * h.hessian[HessianJet<N>::Packed(a, b)];
      (*hessian)(a, b) += w;
      if (b != a) (*hessian)(b, a) += w;
    }
  }
}
// A nested jet that never met an input (a constant) has empty derivative vectors: it adds nothing.
template <class Row, class M>
void UnpackSecondOrder(const Jet2& h, double* value, Row&& gradient, double weight, M* hessian) {
  *value = h.value().value();
  const int n = static_cast<int>(hessian->rows());
  if (h.derivatives().size() != n) return;
  for (int a = 0; a < n; ++a) {
    const auto& g = h.derivatives()(a);
    gradient(a) = g.value();
    if (g.derivatives().size() == n) hessian->row(a) += weight * g.derivatives().transpose();
  }
}

// Value and Jacobian rows of a vector of jets. A jet that never met an input (a constant output) has an
// empty (dynamic) or zero (fixed) derivative vector: its row is zero.
template <class J>
void Unpack(const StateVector<J>& y, int n, Vector* value, Matrix* jacobian) {
  const int rows = static_cast<int>(y.size());
  if (value) value->resize(rows);
  if (jacobian) jacobian->resize(rows, n);
  for (int i = 0; i < rows; ++i) {
    if (value) (*value)(i) = y(i).value();
    if (jacobian) {
      if (y(i).derivatives().size() == n) {
        jacobian->row(i) = y(i).derivatives().transpose();
      } else {
        jacobian->row(i).setZero();
      }
    }
  }
}

// Detects the user's choice between FirstIntegral (k = 1) and FirstIntegrals (k >= 1).
template <class F, class P>
concept HasScalarFirstIntegral = requires(const StateVector<double>& x, const P& p) {
  { F::template FirstIntegral<double>(x, p) };
};

// The first integrals of F at x, with the parameters q (P itself or P over a jet; P decides the form).
template <class F, class P, class T, class Q = P>
StateVector<T> EvaluateFirstIntegrals(const StateVector<T>& x, const Q& p) {
  if constexpr (HasScalarFirstIntegral<F, P>) {
    StateVector<T> h(1);
    h(0) = F::template FirstIntegral<T>(x, p);
    return h;
  } else {
    return F::template FirstIntegrals<T>(x, p);
  }
}

// The parameters that phase or anchor `slot` of a model reads, from its block (ParameterBlock::BindingFor),
// and the block's seeding when it has one.
template <class P>
struct ParameterBinding {
  const P* values = nullptr;
  const ParameterSeedingBase<P>* seeding = nullptr;
  ParameterBinding(const ParameterBlock* block, int slot)
      : values(static_cast<const P*>(block->BindingFor(slot))) {
    if constexpr (DifferentiableParameters<P>) seeding = dynamic_cast<const ParameterSeeding<P>*>(block);
  }
  template <class F>
  bool differentiable() const {
    if constexpr (DifferentiableParameters<P>) {
      if constexpr (TakesParameterJets<F, typename ParametersAs<P, ParamJet>::type>) {
        return seeding != nullptr && seeding->can_seed();
      }
    }
    return false;
  }
};

// The ParamJet derivatives (d/dp) of a vector of ParamJets.
inline void UnpackParameterDerivative(const StateVector<ParamJet>& y, Vector* out) {
  out->resize(y.size());
  for (int i = 0; i < y.size(); ++i) (*out)(i) = y(i).derivatives()(0);
}

template <class F, class P>
class AutoDiffPhase final : public Phase {
 public:
  // Reads its parameters from `block` (ParameterBlock::BindingFor(slot)); slot is the phase's index.
  AutoDiffPhase(std::string name, std::vector<std::string> state_names, int next_dim, Vector typical_state,
                const ParameterBlock* block, int slot)
      : Phase(std::move(name), std::move(state_names), next_dim,
              static_cast<int>(EvaluateFirstIntegrals<F, P, double>(StateVector<double>(typical_state),
                                                                    *ParameterBinding<P>(block, slot).values)
                                   .size()),
              typical_state),
        binding_(block, slot),
        p_(binding_.values),
        slot_(slot),
        differentiable_(binding_.template differentiable<F>()) {
    if constexpr (DeclaresDimension<F>) {
      if (F::kDimension != Eigen::Dynamic && dim() != F::kDimension) {
        throw std::invalid_argument("phase '" + this->name() + "': its functions declare kDimension = " +
                                    std::to_string(F::kDimension) + ", but " + std::to_string(dim()) +
                                    " state names are given");
      }
    }
  }

  std::unique_ptr<Phase> CloneWith(const ParameterBlock& parameters) const override {
    return std::make_unique<AutoDiffPhase>(name(), state_names(), next_dim(), typical_state(), &parameters, slot_);
  }

  bool has_parameter_derivatives() const override { return differentiable_; }

  // F may explain a non-finite vector field: static std::string ExplainNonFinite(const Vector&, const P&).
  std::string ExplainNonFinite(const Eigen::Ref<const Vector>& x) const override {
    if constexpr (requires(const Vector& v) { F::ExplainNonFinite(v, *p_); }) {
      return F::ExplainNonFinite(Vector(x), *p_);
    } else {
      return Phase::ExplainNonFinite(x);
    }
  }

  void ParameterDerivatives(const Eigen::Ref<const Vector>& x, int parameter, Vector* field, Vector* integrals,
                            double* event, Vector* reset) const override {
    HYBRIDCONT_DEMAND(differentiable_);
    if constexpr (DifferentiableParameters<P>) {
      if constexpr (TakesParameterJets<F, typename ParametersAs<P, ParamJet>::type>) {
        const auto q = binding_.seeding->SeedParamJets(*p_, parameter);
        const StateVector<ParamJet> xs = x.template cast<ParamJet>();
        if (field) UnpackParameterDerivative(F::template VectorField<ParamJet>(xs, q), field);
        if (integrals) UnpackParameterDerivative(EvaluateFirstIntegrals<F, P, ParamJet>(xs, q), integrals);
        if (event) *event = F::template Event<ParamJet>(xs, q).derivatives()(0);
        if (reset) UnpackParameterDerivative(F::template Reset<ParamJet>(xs, q), reset);
      }
    }
  }

  void UnfoldedFieldParameterDerivative(const Eigen::Ref<const Vector>& x, const Eigen::Ref<const Vector>& xi,
                                        int parameter, Vector* dfdp, bool include_mixed_term) const override {
    HYBRIDCONT_DEMAND(differentiable_);
    if constexpr (DifferentiableParameters<P>) {
      if constexpr (TakesParameterJets<F, typename ParametersAs<P, ParamJet>::type>) {
        const StateVector<ParamJet> xs = x.template cast<ParamJet>();
        UnpackParameterDerivative(F::template VectorField<ParamJet>(xs, binding_.seeding->SeedParamJets(*p_, parameter)),
                                  dfdp);
        if (!include_mixed_term || (xi.array() == 0.0).all()) return;
        // ∂²H_j/∂x_i∂p, one state at a time: x_i variable 0, p variable 1.
        const int n = dim();
        const auto q = binding_.seeding->SeedMixedJets(*p_, parameter);
        StateVector<MixedJet> xm(n);
        for (int i = 0; i < n; ++i) xm(i) = MixedJet(x(i));
        for (int i = 0; i < n; ++i) {
          xm(i) = MixedJet::Variable(x(i), 0);
          const auto h = EvaluateFirstIntegrals<F, P, MixedJet>(xm, q);
          for (int j = 0; j < h.size(); ++j) (*dfdp)(i) += xi(j) * h(j).hessian[MixedJet::Packed(0, 1)];
          xm(i) = MixedJet(x(i));
        }
      }
    }
  }

  void VectorField(const Eigen::Ref<const Vector>& x, Vector* f, Matrix* df) const override {
    if (!df) {
      *f = F::template VectorField<double>(StateVector<double>(x), *p_);
      return;
    }
    DispatchFor<F>(dim(), [&](auto N) {
      using J = typename JetTypes<decltype(N)::value>::J;
      Unpack(F::template VectorField<J>(SeedJets<J>(x), *p_), dim(), f, df);
    });
  }

  void FirstIntegrals(const Eigen::Ref<const Vector>& x, Vector* H, Matrix* dH,
                      std::vector<Matrix>* d2H) const override {
    const int n = dim();
    if (d2H) {
      DispatchFor<F>(n, [&](auto N) { Hessians<typename JetTypes<decltype(N)::value>::J2>(x, H, dH, d2H); });
      return;
    }
    if (!dH) {
      *H = EvaluateFirstIntegrals<F, P, double>(StateVector<double>(x), *p_);
      return;
    }
    DispatchFor<F>(n, [&](auto N) {
      using J = typename JetTypes<decltype(N)::value>::J;
      Unpack(EvaluateFirstIntegrals<F, P, J>(SeedJets<J>(x), *p_), n, H, dH);
    });
  }

  double Event(const Eigen::Ref<const Vector>& x, RowVector* de) const override {
    if (!de) return F::template Event<double>(StateVector<double>(x), *p_);
    return DispatchFor<F>(dim(), [&](auto N) {
      using J = typename JetTypes<decltype(N)::value>::J;
      StateVector<J> e(1);
      e(0) = F::template Event<J>(SeedJets<J>(x), *p_);
      Vector value;
      Matrix jac;
      Unpack(e, dim(), &value, &jac);
      *de = jac.row(0);
      return value(0);
    });
  }

  void Reset(const Eigen::Ref<const Vector>& x, Vector* x_next, Matrix* D) const override {
    if (!D) {
      *x_next = F::template Reset<double>(StateVector<double>(x), *p_);
      return;
    }
    DispatchFor<F>(dim(), [&](auto N) {
      using J = typename JetTypes<decltype(N)::value>::J;
      Unpack(F::template Reset<J>(SeedJets<J>(x), *p_), dim(), x_next, D);
    });
  }

 private:
  template <class J2>
  void Hessians(const Eigen::Ref<const Vector>& x, Vector* H, Matrix* dH, std::vector<Matrix>* d2H) const {
    const int n = dim();
    const StateVector<J2> h = EvaluateFirstIntegrals<F, P, J2>(SeedJets2<J2>(x), *p_);
    const int k = static_cast<int>(h.size());
    if (H) H->resize(k);
    if (dH) dH->resize(k, n);
    d2H->resize(k);
    Eigen::Matrix<double, 1, Eigen::Dynamic, Eigen::RowMajor, 1, kMaxPhaseDim> gradient(n);
    for (int j = 0; j < k; ++j) {
      double value;
      gradient.setZero();
      (*d2H)[j].setZero(n, n);
      UnpackSecondOrder(h(j), &value, gradient, 1.0, &(*d2H)[j]);
      if (H) (*H)(j) = value;
      if (dH) dH->row(j) = gradient;
    }
  }

  // Phase's version in one pass over fixed-size jets: the Hessian term goes straight into A, no dynamic
  // temporaries (the generic version's plumbing was ~15% of its cost on the SLIP).
  void ComputeUnfoldedVectorField(const Eigen::Ref<const Vector>& x, const Eigen::Ref<const Vector>& xi,
                                  Vector* f_tilde, Matrix* A, Matrix* B, bool include_hessian_term) const override {
    const bool dissipative = (xi.array() != 0.0).any();
    if (!dissipative && !B) {
      VectorField(x, f_tilde, A);
      return;
    }
    const bool need_hessians = A != nullptr && dissipative && include_hessian_term;
    DispatchFor<F>(dim(), [&](auto N) {
      Unfolded<decltype(N)::value>(x, xi, f_tilde, A, B, dissipative, need_hessians);
    });
  }

  template <int N>
  // Flattened for the same reason as UnfoldedFirstOrder below (with the Hessian term: 2.63 -> 2.59 G
  // instructions on the SLIP exploration, whose SB trial points need the exact Jacobian).
  [[gnu::flatten]] void Unfolded(const Eigen::Ref<const Vector>& x, const Eigen::Ref<const Vector>& xi, Vector* f_tilde, Matrix* A,
                Matrix* B, bool dissipative, bool need_hessians) const {
    using Types = JetTypes<N>;
    using Gradients = Eigen::Matrix<double, Eigen::Dynamic, N, 0, kMaxPhaseDim, N == Eigen::Dynamic ? kMaxPhaseDim : N>;
    const int n = dim();
    const int k = num_first_integrals();
    if constexpr (N != Eigen::Dynamic) {
      if (!need_hessians) {
        UnfoldedFirstOrder<N>(x, xi, f_tilde, A, B, dissipative);
        return;
      }
    }
    VectorField(x, f_tilde, A);
    // dH (k x n), rows filled from the jets; a row of a constant first integral stays zero.
    Gradients dH = Gradients::Zero(k, n);
    if (need_hessians) {
      const auto h = EvaluateFirstIntegrals<F, P, typename Types::J2>(SeedJets2<typename Types::J2>(x), *p_);
      double value;
      for (int j = 0; j < k; ++j) UnpackSecondOrder(h(j), &value, dH.row(j), xi(j), A);
    } else {
      const auto h = EvaluateFirstIntegrals<F, P, typename Types::J>(SeedJets<typename Types::J>(x), *p_);
      for (int j = 0; j < k; ++j) {
        if (h(j).derivatives().size() == n) dH.row(j) = h(j).derivatives().transpose();
      }
    }
    if (dissipative) {
      for (int i = 0; i < n; ++i) (*f_tilde)(i) += dH.col(i).dot(xi);
    }
    if (B) *B = dH.transpose();
  }

  // The first-order case at a fixed dimension N, the one almost every right-hand side takes (the Hessian
  // term is left out below the map's Jacobian tolerance): f and H from one seeding, values and derivatives
  // written straight into f~, A and B. Flattened, so that the compiler sees the model's sin(a), cos(a) in f
  // and cos(a) in H on the same jet and evaluates them by one sincos (SLIP exploration: 2.99 -> 2.63 G
  // instructions, sincos calls 215M -> 90M instructions; without flatten the separate VectorField/H calls
  // made it 1.5x the sincos calls of the generic path and the gain was 1.6%). Same arithmetic, same bits.
  template <int N>
  [[gnu::flatten]] void UnfoldedFirstOrder(const Eigen::Ref<const Vector>& x, const Eigen::Ref<const Vector>& xi,
                                           Vector* f_tilde, Matrix* A, Matrix* B, bool dissipative) const {
    using J = typename JetTypes<N>::J;
    const int k = num_first_integrals();
    const StateVector<J> xj = SeedJets<J>(x);
    const StateVector<J> fj = F::template VectorField<J>(xj, *p_);
    const StateVector<J> h = EvaluateFirstIntegrals<F, P, J>(xj, *p_);
    if (f_tilde->size() != N) f_tilde->resize(N);
    if (A != nullptr && (A->rows() != N || A->cols() != N)) A->resize(N, N);
    if (B != nullptr && (B->rows() != N || B->cols() != k)) B->resize(N, k);
    for (int i = 0; i < N; ++i) {
      double sum = 0;
      for (int j = 0; j < k; ++j) {
        const double gradient = h(j).derivatives()(i);
        if (dissipative) sum += gradient * xi(j);
        if (B != nullptr) (*B)(i, j) = gradient;
      }
      (*f_tilde)(i) = dissipative ? fj(i).value() + sum : fj(i).value();
      if (A != nullptr) A->row(i) = fj(i).derivatives().transpose();
    }
  }

  ParameterBinding<P> binding_;
  const P* p_;
  int slot_;
  bool differentiable_;
};

template <class A, class P>
class AutoDiffAnchor final : public Anchor {
 public:
  AutoDiffAnchor(const ParameterBlock* block, int slot)
      : binding_(block, slot), p_(binding_.values), slot_(slot), differentiable_(binding_.template differentiable<A>()) {}
  std::unique_ptr<Anchor> CloneWith(const ParameterBlock& parameters) const override {
    return std::make_unique<AutoDiffAnchor>(&parameters, slot_);
  }
  bool has_parameter_derivatives() const override { return differentiable_; }
  double ParameterDerivative(const Eigen::Ref<const Vector>& x, int parameter) const override {
    HYBRIDCONT_DEMAND(differentiable_);
    if constexpr (DifferentiableParameters<P>) {
      if constexpr (TakesParameterJets<A, typename ParametersAs<P, ParamJet>::type>) {
        const StateVector<ParamJet> xs = x.template cast<ParamJet>();
        return A::template Anchor<ParamJet>(xs, binding_.seeding->SeedParamJets(*p_, parameter)).derivatives()(0);
      }
    }
    return 0.0;
  }
  double Evaluate(const Eigen::Ref<const Vector>& x, RowVector* da) const override {
    if (!da) return A::template Anchor<double>(StateVector<double>(x), *p_);
    const int n = static_cast<int>(x.size());
    return DispatchFor<A>(n, [&](auto N) {
      using J = typename JetTypes<decltype(N)::value>::J;
      StateVector<J> a(1);
      a(0) = A::template Anchor<J>(SeedJets<J>(x), *p_);
      Vector value;
      Matrix jac;
      Unpack(a, n, &value, &jac);
      *da = jac.row(0);
      return value(0);
    });
  }

 private:
  ParameterBinding<P> binding_;
  const P* p_;
  int slot_;
  bool differentiable_;
};

// The parameters of a ModelBuilder model: the values in a P, each registered parameter addressed by an
// accessor that works on P and, when P is a template over its scalar, on P over the jets too.
template <class P>
class TypedParameterBlock final : public ParameterBlock, public ParameterSeedingBase<P> {
 public:
  // A parameter addressed by a member pointer of P: readable and settable; not seedable when P is a
  // template (the member pointer names the double struct's member only).
  void Add(std::string name, double P::*member, std::string description, ParameterRange range) {
    Entry e;
    e.get = [member](P& p) -> double& { return p.*member; };
    if constexpr (DifferentiableParameters<P>) seedable_ = false;
    Register(std::move(name), std::move(e), std::move(description), range);
  }
  // A parameter addressed by a generic accessor, e.g. [](auto& p) -> auto& { return p.k; }.
  template <class Accessor>
  void Add(std::string name, Accessor accessor, std::string description, ParameterRange range) {
    Entry e;
    e.get = [accessor](P& p) -> double& { return accessor(p); };
    if constexpr (DifferentiableParameters<P>) {
      e.seed = [accessor](const P& from, ParametersAsOr<P, ParamJet>& to, bool seed) {
        accessor(to) = MakeParamJet(accessor(const_cast<P&>(from)), seed ? 1.0 : 0.0);
      };
      e.seed_mixed = [accessor](const P& from, ParametersAsOr<P, MixedJet>& to, bool seed) {
        accessor(to) = MakeMixedJet(accessor(const_cast<P&>(from)), seed ? 1.0 : 0.0);
      };
    }
    Register(std::move(name), std::move(e), std::move(description), range);
  }
  const std::vector<ParameterInfo>& infos() const override { return infos_; }
  double Get(int index) const override { return entries_[index].get(const_cast<P&>(values_)); }
  void Set(int index, double value) override { entries_[index].get(values_) = value; }
  std::unique_ptr<ParameterBlock> Clone() const override { return std::make_unique<TypedParameterBlock>(*this); }
  const void* BindingFor(int) const override { return &values_; }
  const P& values() const { return values_; }

  // ParameterSeeding<P> (its overriders when P is differentiable).
  bool can_seed() const { return seedable_; }
  ParametersAsOr<P, ParamJet> SeedParamJets(const P&, int index) const {
    ParametersAsOr<P, ParamJet> q{};
    for (int i = 0; i < static_cast<int>(entries_.size()); ++i) entries_[i].seed(values_, q, i == index);
    return q;
  }
  ParametersAsOr<P, MixedJet> SeedMixedJets(const P&, int index) const {
    ParametersAsOr<P, MixedJet> q{};
    for (int i = 0; i < static_cast<int>(entries_.size()); ++i) entries_[i].seed_mixed(values_, q, i == index);
    return q;
  }

 private:
  struct Empty {};
  template <class S>
  using SeedFn = std::conditional_t<DifferentiableParameters<P>,
                                    std::function<void(const P&, ParametersAsOr<P, S>&, bool)>, Empty>;
  struct Entry {
    std::function<double&(P&)> get;
    // Write the parameter into the struct over ParamJets / MixedJets, seeded or constant.
    SeedFn<ParamJet> seed;
    SeedFn<MixedJet> seed_mixed;
  };
  void Register(std::string name, Entry e, std::string description, ParameterRange range) {
    const double value = e.get(values_);
    infos_.push_back({std::move(name), value, std::move(description), range});
    entries_.push_back(std::move(e));
  }
  P values_{};
  std::vector<ParameterInfo> infos_;
  std::vector<Entry> entries_;
  bool seedable_ = true;
};

// Checks that every reset maps into the next phase's dimension and that all phases have the same number
// of first integrals (Lemma `NH`); throws std::invalid_argument otherwise.
void ValidatePhaseSizes(const std::string& model_name, const std::vector<std::unique_ptr<Phase>>& phases);

}  // namespace hybridcont::internal

#endif  // HYBRIDCONT_AUTODIFF_PHASE_H_
