#include "expression_phases.h"

namespace hybridcont::internal {

std::unique_ptr<Phase> MakeBoundedExpressionPhase(const ExpressionPhaseSpec& p, int next_dim,
                                                  const ParameterBlock* block, int slot) {
  return MakeExpressionPhaseOf<Eigen::Dynamic>(p, next_dim, block, slot);
}

std::unique_ptr<Anchor> MakeBoundedExpressionAnchor(const ParameterBlock* block, int slot) {
  return MakeExpressionAnchorOf<Eigen::Dynamic>(block, slot);
}

}  // namespace hybridcont::internal
