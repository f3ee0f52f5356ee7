#include "expression_phases.h"

namespace hybridcont::internal {

static_assert(kMaxFixedJetDim >= 4);

std::unique_ptr<Phase> MakeExpressionPhase1To4(int n, const ExpressionPhaseSpec& p, int next_dim,
                                               const ParameterBlock* block, int slot) {
  return MakeExpressionPhaseIn<1>(std::make_integer_sequence<int, 4>(), n, p, next_dim, block, slot);
}

std::unique_ptr<Anchor> MakeExpressionAnchor1To4(int n, const ParameterBlock* block, int slot) {
  return MakeExpressionAnchorIn<1>(std::make_integer_sequence<int, 4>(), n, block, slot);
}

}  // namespace hybridcont::internal
