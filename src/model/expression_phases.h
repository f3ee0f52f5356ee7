// The templated phases and anchors of expression models (private to src/model), made by dimension in three
// translation units of their own: AutoDiffPhase instantiated for one fixed jet dimension each (1..4 in
// expression_phases_1_4.cc, 5..8 in expression_phases_5_8.cc) and for the bounded-dynamic jets (9..
// kMaxPhaseDim, expression_phases_bounded.cc). The same classes and numbers as one AutoDiffPhase dispatching
// on the dimension (internal/autodiff_phase.h, DispatchOnDimension), compiled in parallel and rebuilt apart
// from the model's reading and binding (expression_model.cc). Above kMaxPhaseDim: large_expression_phase.h.
#ifndef HYBRIDCONT_SRC_MODEL_EXPRESSION_PHASES_H_
#define HYBRIDCONT_SRC_MODEL_EXPRESSION_PHASES_H_

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "hybridcont/expression_model.h"
#include "hybridcont/internal/autodiff_phase.h"
#include "hybridcont/invariant.h"

namespace hybridcont::internal {

// ExpressionFunctions with a declared dimension N (a fixed jet size, or Eigen::Dynamic for the bounded jets).
template <int N>
struct ExpressionFunctionsOf : ExpressionFunctions {
  static constexpr int kDimension = N;
};

template <int N>
std::unique_ptr<Phase> MakeExpressionPhaseOf(const ExpressionPhaseSpec& p, int next_dim, const ParameterBlock* block,
                                             int slot) {
  return std::make_unique<AutoDiffPhase<ExpressionFunctionsOf<N>, ExpressionPhaseData>>(
      p.name, p.state_names, next_dim, p.typical_state, block, slot);
}
template <int N>
std::unique_ptr<Anchor> MakeExpressionAnchorOf(const ParameterBlock* block, int slot) {
  return std::make_unique<AutoDiffAnchor<ExpressionFunctionsOf<N>, ExpressionPhaseData>>(block, slot);
}

// The phase (anchor) of fixed jet dimension n among First, First + 1, ..., First + Count - 1.
template <int First, int... Offsets>
std::unique_ptr<Phase> MakeExpressionPhaseIn(std::integer_sequence<int, Offsets...>, int n,
                                             const ExpressionPhaseSpec& p, int next_dim, const ParameterBlock* block,
                                             int slot) {
  std::unique_ptr<Phase> phase;
  ((n == First + Offsets ? (phase = MakeExpressionPhaseOf<First + Offsets>(p, next_dim, block, slot), 0) : 0), ...);
  HYBRIDCONT_DEMAND(phase != nullptr);
  return phase;
}
template <int First, int... Offsets>
std::unique_ptr<Anchor> MakeExpressionAnchorIn(std::integer_sequence<int, Offsets...>, int n,
                                               const ParameterBlock* block, int slot) {
  std::unique_ptr<Anchor> anchor;
  ((n == First + Offsets ? (anchor = MakeExpressionAnchorOf<First + Offsets>(block, slot), 0) : 0), ...);
  HYBRIDCONT_DEMAND(anchor != nullptr);
  return anchor;
}

// Phase `slot` of dimension n (1..kMaxPhaseDim), its programs bound in block; the anchor on a phase of
// dimension n. Each range's pair is defined in its own file.
std::unique_ptr<Phase> MakeExpressionPhase1To4(int n, const ExpressionPhaseSpec& p, int next_dim,
                                               const ParameterBlock* block, int slot);
std::unique_ptr<Anchor> MakeExpressionAnchor1To4(int n, const ParameterBlock* block, int slot);
std::unique_ptr<Phase> MakeExpressionPhase5To8(int n, const ExpressionPhaseSpec& p, int next_dim,
                                               const ParameterBlock* block, int slot);
std::unique_ptr<Anchor> MakeExpressionAnchor5To8(int n, const ParameterBlock* block, int slot);
std::unique_ptr<Phase> MakeBoundedExpressionPhase(const ExpressionPhaseSpec& p, int next_dim,
                                                  const ParameterBlock* block, int slot);
std::unique_ptr<Anchor> MakeBoundedExpressionAnchor(const ParameterBlock* block, int slot);

inline std::unique_ptr<Phase> MakeExpressionPhase(int n, const ExpressionPhaseSpec& p, int next_dim,
                                                  const ParameterBlock* block, int slot) {
  if (n <= 4) return MakeExpressionPhase1To4(n, p, next_dim, block, slot);
  if (n <= kMaxFixedJetDim) return MakeExpressionPhase5To8(n, p, next_dim, block, slot);
  return MakeBoundedExpressionPhase(p, next_dim, block, slot);
}
inline std::unique_ptr<Anchor> MakeExpressionAnchor(int n, const ParameterBlock* block, int slot) {
  if (n <= 4) return MakeExpressionAnchor1To4(n, block, slot);
  if (n <= kMaxFixedJetDim) return MakeExpressionAnchor5To8(n, block, slot);
  return MakeBoundedExpressionAnchor(block, slot);
}

}  // namespace hybridcont::internal

#endif  // HYBRIDCONT_SRC_MODEL_EXPRESSION_PHASES_H_
