#include "expression_phases.h"

namespace hybridcont::internal {

static_assert(kMaxFixedJetDim >= 8);

std::unique_ptr<Phase> MakeExpressionPhase5To8(int n, const ExpressionPhaseSpec& p, int next_dim,
                                               const ParameterBlock* block, int slot) {
  return MakeExpressionPhaseIn<5>(std::make_integer_sequence<int, 4>(), n, p, next_dim, block, slot);
}

std::unique_ptr<Anchor> MakeExpressionAnchor5To8(int n, const ParameterBlock* block, int slot) {
  return MakeExpressionAnchorIn<5>(std::make_integer_sequence<int, 4>(), n, block, slot);
}

}  // namespace hybridcont::internal
