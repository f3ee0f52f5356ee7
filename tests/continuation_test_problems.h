// Algebraic zero problems with exact answers, shared by the continuation and exploration tests.
#ifndef HYBRIDCONT_TESTS_CONTINUATION_TEST_PROBLEMS_H_
#define HYBRIDCONT_TESTS_CONTINUATION_TEST_PROBLEMS_H_

#include <cmath>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "hybridcont/zero_problem.h"

namespace hybridcont::testing {

// x² + y² = 1: a closed curve, turning points in y at (0, ±1) and in x at (±1, 0).
class Circle : public ZeroProblem {
 public:
  int num_equations() const override { return 1; }
  std::vector<std::string> unknown_names() const override { return {"x", "y"}; }
  EvaluationStatus Evaluate(const Vector& u, Vector* r, Matrix* dr) override {
    if (r) *r = Vector::Constant(1, u.squaredNorm() - 1.0);
    if (dr) *dr = 2.0 * u.transpose();
    return {};
  }
};

// The unit circle with a smooth "discretization error" ε·sin(7x + 3y) that shrinks with the tolerances
// as an integrator's does: Refined(f) is the same curve with ε·f. Its turning point in x lies at
// x ≈ 1 − 0.33ε, y ≈ −1.13ε (∂r/∂y = 2y + 3ε cos(7x + 3y) = 0), the exact one (ε = 0) at (1, 0).
class PerturbedCircle : public ZeroProblem {
 public:
  explicit PerturbedCircle(double epsilon) : epsilon_(epsilon) {}
  int num_equations() const override { return 1; }
  std::vector<std::string> unknown_names() const override { return {"x", "y"}; }
  EvaluationStatus Evaluate(const Vector& u, Vector* r, Matrix* dr) override {
    const double x = u(0), y = u(1), phase = 7 * x + 3 * y;
    if (r) *r = Vector::Constant(1, x * x + y * y - 1 + epsilon_ * std::sin(phase));
    if (dr) {
      dr->resize(1, 2);
      *dr << 2 * x + 7 * epsilon_ * std::cos(phase), 2 * y + 3 * epsilon_ * std::cos(phase);
    }
    return {};
  }
  std::unique_ptr<ZeroProblem> Refined(double factor) const override {
    return std::make_unique<PerturbedCircle>(epsilon_ * factor);
  }

 private:
  double epsilon_;
};

// x³ − λx = 0: the trivial branch x = 0 and the parabola λ = x², crossing at the SB point (0, 0).
class Pitchfork : public ZeroProblem {
 public:
  int num_equations() const override { return 1; }
  std::vector<std::string> unknown_names() const override { return {"x", "lambda"}; }
  EvaluationStatus Evaluate(const Vector& u, Vector* r, Matrix* dr) override {
    const double x = u(0), l = u(1);
    if (r) *r = Vector::Constant(1, x * x * x - l * x);
    if (dr) {
      dr->resize(1, 2);
      *dr << 3 * x * x - l, -x;
    }
    return {};
  }
};

// The pitchfork with its symmetry x -> −x declared (exploration: the x < 0 half-branch is mapped).
class SymmetricPitchfork : public Pitchfork {
 public:
  std::vector<Symmetry> symmetries() const override { return {{"x-flip", Eigen::Vector2d(-1, 1)}}; }
};

// The pitchfork with a false declaration, (x, λ) -> (−x, −λ): it maps the SB point's ray along +x onto
// the one along −x, but r(−x, −λ) = −(x³ + λx) does not vanish on λ = x².
class FalselySymmetricPitchfork : public Pitchfork {
 public:
  std::vector<Symmetry> symmetries() const override { return {{"both-flip", Eigen::Vector2d(-1, -1)}}; }
};

// x(λ − x) = 0: the lines x = 0 and x = λ, crossing at the SB point (0, 0).
class Transcritical : public ZeroProblem {
 public:
  int num_equations() const override { return 1; }
  std::vector<std::string> unknown_names() const override { return {"x", "lambda"}; }
  EvaluationStatus Evaluate(const Vector& u, Vector* r, Matrix* dr) override {
    const double x = u(0), l = u(1);
    if (r) *r = Vector::Constant(1, x * (l - x));
    if (dr) {
      dr->resize(1, 2);
      *dr << l - 2 * x, x;
    }
    return {};
  }
};

// (x² + λ − 1)(x − λ) = 0: the parabola λ = 1 − x² (fold in λ at (0, 1)) and the line x = λ, crossing at
// the SB points x = λ = (−1 ± √5)/2.
class ParabolaAndLine : public ZeroProblem {
 public:
  int num_equations() const override { return 1; }
  std::vector<std::string> unknown_names() const override { return {"x", "lambda"}; }
  EvaluationStatus Evaluate(const Vector& u, Vector* r, Matrix* dr) override {
    const double x = u(0), l = u(1);
    const double p = x * x + l - 1, q = x - l;
    if (r) *r = Vector::Constant(1, p * q);
    if (dr) {
      dr->resize(1, 2);
      *dr << 2 * x * q + p, q - p;
    }
    return {};
  }
};

// (x² + λ² − 1)(x − λ) = 0: the unit circle and the line x = λ, crossing at the SB points ±(1, 1)/√2.
class CircleAndLine : public ZeroProblem {
 public:
  int num_equations() const override { return 1; }
  std::vector<std::string> unknown_names() const override { return {"x", "lambda"}; }
  EvaluationStatus Evaluate(const Vector& u, Vector* r, Matrix* dr) override {
    const double x = u(0), l = u(1);
    const double p = x * x + l * l - 1, q = x - l;
    if (r) *r = Vector::Constant(1, p * q);
    if (dr) {
      dr->resize(1, 2);
      *dr << 2 * x * q + p, 2 * l * q - p;
    }
    return {};
  }
};

// λ(x² + λ² − 1) = 0 with its symmetry λ -> −λ: the axis λ = 0 and the unit circle, crossing at the SB
// points (±1, 0). From (1, 0) the circle is a loop that the symmetry maps onto itself reversed, with its
// midpoint at the SB point (−1, 0) (the exploration completes it by reflection).
class CircleOnAxis : public ZeroProblem {
 public:
  int num_equations() const override { return 1; }
  std::vector<std::string> unknown_names() const override { return {"x", "lambda"}; }
  EvaluationStatus Evaluate(const Vector& u, Vector* r, Matrix* dr) override {
    const double x = u(0), l = u(1);
    const double p = x * x + l * l - 1;
    if (r) *r = Vector::Constant(1, l * p);
    if (dr) {
      dr->resize(1, 2);
      *dr << 2 * x * l, p + 2 * l * l;
    }
    return {};
  }
  std::vector<Symmetry> symmetries() const override { return {{"lambda-flip", Eigen::Vector2d(1, -1)}}; }
};

// [x·y; λ(x − y)] = 0: the three coordinate axes, all through the origin, where dr = 0 (kernel of
// dimension 3, cokernel of dimension 2).
class ThreeAxes : public ZeroProblem {
 public:
  int num_equations() const override { return 2; }
  std::vector<std::string> unknown_names() const override { return {"x", "y", "lambda"}; }
  EvaluationStatus Evaluate(const Vector& u, Vector* r, Matrix* dr) override {
    const double x = u(0), y = u(1), l = u(2);
    if (r) {
      r->resize(2);
      *r << x * y, l * (x - y);
    }
    if (dr) {
      dr->resize(2, 3);
      *dr << y, x, 0, l, -l, x - y;
    }
    return {};
  }
};

// Wraps a problem and fails every evaluation with component `index` above `limit` (an integrator that
// gives up): continuation must end with kStepTooSmall and keep its points.
class FailsAbove : public ZeroProblem {
 public:
  FailsAbove(ZeroProblem* inner, int index, double limit) : inner_(inner), index_(index), limit_(limit) {}
  int num_equations() const override { return inner_->num_equations(); }
  std::vector<std::string> unknown_names() const override { return inner_->unknown_names(); }
  EvaluationStatus Evaluate(const Vector& u, Vector* r, Matrix* dr) override {
    if (u(index_) > limit_) return EvaluationStatus::Failure("component above its limit");
    return inner_->Evaluate(u, r, dr);
  }

 private:
  ZeroProblem* inner_;
  int index_;
  double limit_;
};

// Wraps a problem and fails every evaluation whose residual norm exceeds `limit` (an integrator that
// gives up on orbits far from periodic): the corrector fails for predictors too far off the curve.
class FailsFarFromCurve : public ZeroProblem {
 public:
  // Only where component `index` is above `from` (the whole space by default).
  FailsFarFromCurve(ZeroProblem* inner, double limit, int index = 0, double from = -1e300)
      : inner_(inner), limit_(limit), index_(index), from_(from) {}
  int num_equations() const override { return inner_->num_equations(); }
  std::vector<std::string> unknown_names() const override { return inner_->unknown_names(); }
  EvaluationStatus Evaluate(const Vector& u, Vector* r, Matrix* dr) override {
    Vector residual;
    inner_->Evaluate(u, &residual, nullptr);
    if (u(index_) > from_ && residual.norm() > limit_) return EvaluationStatus::Failure("residual above its limit");
    return inner_->Evaluate(u, r, dr);
  }

 private:
  ZeroProblem* inner_;
  double limit_;
  int index_;
  double from_;
};

}  // namespace hybridcont::testing

#endif  // HYBRIDCONT_TESTS_CONTINUATION_TEST_PROBLEMS_H_
