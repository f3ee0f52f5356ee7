#include "hybridcont/expression_derivative.h"

#include "hybridcont/mechanics.h"

#include <unordered_map>

namespace hybridcont {
namespace {

bool IsNumber(const ExprPtr& e) { return e->op == ExprOp::kConstant; }

}  // namespace

bool IsConstant(const ExprPtr& e, double value) { return e && e->op == ExprOp::kConstant && e->value == value; }

ExprPtr Add(const ExprPtr& a, const ExprPtr& b) {
  if (IsNumber(a) && IsNumber(b)) return MakeConstant(a->value + b->value);
  if (IsZero(a)) return b;
  if (IsZero(b)) return a;
  if (b->op == ExprOp::kNeg) return Sub(a, b->args[0]);
  return MakeNode(ExprOp::kAdd, {a, b});
}

ExprPtr Sub(const ExprPtr& a, const ExprPtr& b) {
  if (IsNumber(a) && IsNumber(b)) return MakeConstant(a->value - b->value);
  if (a.get() == b.get()) return MakeConstant(0.0);
  if (IsZero(b)) return a;
  if (IsZero(a)) return Neg(b);
  if (b->op == ExprOp::kNeg) return Add(a, b->args[0]);
  return MakeNode(ExprOp::kSub, {a, b});
}

ExprPtr Mul(const ExprPtr& a, const ExprPtr& b) {
  if (IsNumber(a) && IsNumber(b)) return MakeConstant(a->value * b->value);
  if (IsZero(a) || IsZero(b)) return MakeConstant(0.0);
  if (IsConstant(a, 1.0)) return b;
  if (IsConstant(b, 1.0)) return a;
  if (IsConstant(a, -1.0)) return Neg(b);
  if (IsConstant(b, -1.0)) return Neg(a);
  if (a->op == ExprOp::kNeg) return Neg(Mul(a->args[0], b));
  if (b->op == ExprOp::kNeg) return Neg(Mul(a, b->args[0]));
  return MakeNode(ExprOp::kMul, {a, b});
}

ExprPtr Div(const ExprPtr& a, const ExprPtr& b) {
  if (IsNumber(a) && IsNumber(b) && b->value != 0.0) return MakeConstant(a->value / b->value);
  if (IsZero(a)) return MakeConstant(0.0);
  if (IsConstant(b, 1.0)) return a;
  if (a->op == ExprOp::kNeg) return Neg(Div(a->args[0], b));
  return MakeNode(ExprOp::kDiv, {a, b});
}

ExprPtr Neg(const ExprPtr& a) {
  if (IsNumber(a)) return MakeConstant(-a->value);
  if (a->op == ExprOp::kNeg) return a->args[0];
  return MakeNode(ExprOp::kNeg, {a});
}

ExprPtr Sqrt(const ExprPtr& a) { return MakeNode(ExprOp::kSqrt, {a}); }

ExprPtr Dot(const std::vector<ExprPtr>& a, const std::vector<ExprPtr>& b) {
  ExprPtr sum = MakeConstant(0.0);
  for (std::size_t k = 0; k < a.size() && k < b.size(); ++k) {
    if (a[k] && b[k]) sum = Add(sum, Mul(a[k], b[k]));
  }
  return sum;
}

bool DependsOnInput(const ExprPtr& e, int index) {
  std::unordered_map<const ExprNode*, bool> seen;
  const std::function<bool(const ExprPtr&)> visit = [&](const ExprPtr& n) {
    if (auto it = seen.find(n.get()); it != seen.end()) return it->second;
    bool result = n->op == ExprOp::kInput && n->index == index;
    for (const ExprPtr& a : n->args) result = result || visit(a);
    seen[n.get()] = result;
    return result;
  };
  return visit(e);
}

namespace {

// The chain rule over a DAG: each node's derivative is formed once (memo), so shared subexpressions give
// shared derivatives.
class Differentiator {
 public:
  Differentiator(int input, const SourceLocation& where) : input_(input), where_(where) {}

  ExprPtr D(const ExprPtr& e) {
    if (auto it = memo_.find(e.get()); it != memo_.end()) return it->second;
    ExprPtr d = Rule(e);
    memo_[e.get()] = d;
    return d;
  }

 private:
  ExprPtr Rule(const ExprPtr& e) {
    const auto zero = [] { return MakeConstant(0.0); };
    const auto one = [] { return MakeConstant(1.0); };
    switch (e->op) {
      case ExprOp::kConstant: case ExprOp::kParameter: return zero();
      case ExprOp::kInput: return e->index == input_ ? one() : zero();
      default: break;
    }
    const ExprPtr& a = e->args[0];
    const ExprPtr da = D(a);
    switch (e->op) {
      case ExprOp::kNeg: return Neg(da);
      case ExprOp::kAdd: return Add(da, D(e->args[1]));
      case ExprOp::kSub: return Sub(da, D(e->args[1]));
      case ExprOp::kMul: {
        const ExprPtr& b = e->args[1];
        return Add(Mul(da, b), Mul(a, D(b)));
      }
      case ExprOp::kDiv: {  // (a/b)' = a'/b − (a/b) b'/b
        const ExprPtr& b = e->args[1];
        return Sub(Div(da, b), Div(Mul(e, D(b)), b));
      }
      case ExprOp::kPow: {
        const ExprPtr& b = e->args[1];
        const ExprPtr db = D(b);
        if (IsZero(da) && IsZero(db)) return zero();
        if (IsZero(db)) {  // b a^(b−1) a', with a^1 written as a
          const ExprPtr power = IsConstant(b, 2.0) ? a : MakeNode(ExprOp::kPow, {a, Sub(b, one())});
          return Mul(Mul(b, power), da);
        }
        // a^b (b' log a + b a'/a)
        return Mul(e, Add(Mul(db, MakeNode(ExprOp::kLog, {a})), Div(Mul(b, da), a)));
      }
      case ExprOp::kAtan2: {  // atan2(y, x)' = (x y' − y x') / (x² + y²)
        const ExprPtr& x = e->args[1];
        const ExprPtr dx = D(x);
        if (IsZero(da) && IsZero(dx)) return zero();
        return Div(Sub(Mul(x, da), Mul(a, dx)), Add(Mul(x, x), Mul(a, a)));
      }
      default: break;
    }
    if (IsZero(da)) return zero();
    switch (e->op) {
      case ExprOp::kSin: return Mul(MakeNode(ExprOp::kCos, {a}), da);
      case ExprOp::kCos: return Neg(Mul(MakeNode(ExprOp::kSin, {a}), da));
      case ExprOp::kTan: return Mul(Add(one(), Mul(e, e)), da);
      case ExprOp::kAsin: return Div(da, Sqrt(Sub(one(), Mul(a, a))));
      case ExprOp::kAcos: return Neg(Div(da, Sqrt(Sub(one(), Mul(a, a)))));
      case ExprOp::kAtan: return Div(da, Add(one(), Mul(a, a)));
      case ExprOp::kSinh: return Mul(MakeNode(ExprOp::kCosh, {a}), da);
      case ExprOp::kCosh: return Mul(MakeNode(ExprOp::kSinh, {a}), da);
      case ExprOp::kTanh: return Mul(Sub(one(), Mul(e, e)), da);
      case ExprOp::kExp: return Mul(e, da);
      case ExprOp::kLog: return Div(da, a);
      case ExprOp::kSqrt: return Div(da, Mul(MakeConstant(2.0), e));
      case ExprOp::kAbs: return Mul(Div(a, e), da);
      default: break;
    }
    throw ModelInputError(where_, "comparisons, logic, min and max have no derivative and cannot be used here");
  }

  int input_;
  const SourceLocation& where_;
  std::unordered_map<const ExprNode*, ExprPtr> memo_;
};

}  // namespace

ExprPtr Differentiate(const ExprPtr& e, int input, const SourceLocation& where) {
  return Differentiator(input, where).D(e);
}

ExprPtr SubstituteInputs(const ExprPtr& e, const std::function<ExprPtr(int input)>& replace) {
  std::unordered_map<const ExprNode*, ExprPtr> memo;
  const std::function<ExprPtr(const ExprPtr&)> visit = [&](const ExprPtr& n) -> ExprPtr {
    if (auto it = memo.find(n.get()); it != memo.end()) return it->second;
    ExprPtr out = n;
    if (n->op == ExprOp::kInput) {
      if (ExprPtr r = replace(n->index)) out = r;
    } else if (!n->args.empty()) {
      std::vector<ExprPtr> args;
      bool changed = false;
      for (const ExprPtr& a : n->args) {
        args.push_back(visit(a));
        changed = changed || args.back().get() != a.get();
      }
      if (changed) {
        switch (n->op) {
          case ExprOp::kNeg: out = Neg(args[0]); break;
          case ExprOp::kAdd: out = Add(args[0], args[1]); break;
          case ExprOp::kSub: out = Sub(args[0], args[1]); break;
          case ExprOp::kMul: out = Mul(args[0], args[1]); break;
          case ExprOp::kDiv: out = Div(args[0], args[1]); break;
          default: out = MakeNode(n->op, std::move(args)); break;
        }
      }
    }
    memo[n.get()] = out;
    return out;
  };
  return visit(e);
}

namespace {
// An expression as a scalar of internal::CholeskySolveInto: its operations build simplified trees.
struct Symbol {
  ExprPtr e;
};
Symbol operator-(const Symbol& a, const Symbol& b) { return {Sub(a.e, b.e)}; }
Symbol operator*(const Symbol& a, const Symbol& b) { return {Mul(a.e, b.e)}; }
Symbol operator/(const Symbol& a, const Symbol& b) { return {Div(a.e, b.e)}; }
Symbol sqrt(const Symbol& a) { return {Sqrt(a.e)}; }
}  // namespace

std::vector<ExprPtr> CholeskySolve(const std::vector<std::vector<ExprPtr>>& A, const std::vector<ExprPtr>& b) {
  std::vector<Symbol> x(b.size());
  internal::CholeskySolveInto<Symbol>(
      static_cast<int>(b.size()), [&](int i, int j) { return Symbol{A[i][j]}; }, [&](int i) { return Symbol{b[i]}; },
      [&](int i) -> Symbol& { return x[i]; });
  std::vector<ExprPtr> out;
  for (const Symbol& s : x) out.push_back(s.e);
  return out;
}

}  // namespace hybridcont
