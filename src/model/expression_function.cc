#include "hybridcont/expression_function.h"

#include <vector>

#include "hybridcont/expression_derivative.h"
#include "hybridcont/invariant.h"

namespace hybridcont {

namespace {
// e with parameter j read as input offset + j, so that it is differentiated like the inputs.
ExprPtr ParametersAsInputs(const ExprPtr& e, int offset) {
  if (e->op == ExprOp::kParameter) return MakeInput(offset + e->index);
  if (e->args.empty()) return e;
  std::vector<ExprPtr> args;
  bool changed = false;
  for (const ExprPtr& a : e->args) {
    args.push_back(ParametersAsInputs(a, offset));
    changed = changed || args.back() != a;
  }
  return changed ? MakeNode(e->op, std::move(args)) : e;
}
}  // namespace

ExpressionFunction::ExpressionFunction(const ExprPtr& e, int num_inputs, int num_parameters,
                                       const SourceLocation& where)
    : num_inputs_(num_inputs), num_parameters_(num_parameters) {
  const ExprPtr g = ParametersAsInputs(e, num_inputs);
  std::vector<ExprPtr> outputs = {g};
  for (int i = 0; i < num_inputs + num_parameters; ++i) outputs.push_back(Differentiate(g, i, where));
  program_ = ExpressionProgram(outputs, num_inputs + num_parameters, /*differentiable=*/true, {where});
}

double ExpressionFunction::Evaluate(const Eigen::Ref<const Vector>& x, const Eigen::Ref<const Vector>& p,
                                    RowVector* dx, RowVector* dp) const {
  HYBRIDCONT_DEMAND(x.size() == num_inputs_ && p.size() == num_parameters_);
  thread_local std::vector<double> in, out;
  in.resize(num_inputs_ + num_parameters_);
  out.resize(1 + num_inputs_ + num_parameters_);
  for (int i = 0; i < num_inputs_; ++i) in[i] = x(i);
  for (int j = 0; j < num_parameters_; ++j) in[num_inputs_ + j] = p(j);
  program_.Evaluate<double>(in.data(), nullptr, out.data());
  if (dx) *dx = Eigen::Map<const RowVector>(out.data() + 1, num_inputs_);
  if (dp) *dp = Eigen::Map<const RowVector>(out.data() + 1 + num_inputs_, num_parameters_);
  return out[0];
}

}  // namespace hybridcont
