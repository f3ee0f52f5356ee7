// A SmoothFunction (observable.h) given by an expression: g(x, p) over inputs x and the model's
// parameters p, with exact gradients by symbolic differentiation (expression_derivative.h), compiled once
// into one ExpressionProgram of outputs [g, ∂g/∂x_1.., ∂g/∂p_1..]. Model files state their observables and
// constraints this way.
//
//   ExpressionFunction g(ParseExpression("y - l0*cos(alpha)", resolve, where), /*num_inputs=*/5,
//                        /*num_parameters=*/5, where);
//   double v = g.Evaluate(x, p, &dx, &dp);
#ifndef HYBRIDCONT_EXPRESSION_FUNCTION_H_
#define HYBRIDCONT_EXPRESSION_FUNCTION_H_

#include "hybridcont/expression.h"
#include "hybridcont/observable.h"

namespace hybridcont {

class ExpressionFunction : public SmoothFunction {
 public:
  // e over inputs 0..num_inputs−1 and parameters 0..num_parameters−1. Throws ModelInputError at `where`
  // when e is not differentiable (a comparison, min, max).
  ExpressionFunction(const ExprPtr& e, int num_inputs, int num_parameters, const SourceLocation& where);
  double Evaluate(const Eigen::Ref<const Vector>& x, const Eigen::Ref<const Vector>& p, RowVector* dx,
                  RowVector* dp) const override;

 private:
  int num_inputs_;
  int num_parameters_;
  ExpressionProgram program_;
};

}  // namespace hybridcont

#endif  // HYBRIDCONT_EXPRESSION_FUNCTION_H_
