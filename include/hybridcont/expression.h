// Expressions in ordinary notation, parsed once and evaluated over any scalar type.
//
// This is how a model file states its phase functions ("-2*dalpha*dl/l + g/l*sin(alpha)"), its run set-up
// ("m*g*l0*(1 - cos(beta))") and its presentation ("abs(x2_dx) < 1e-6"). An expression is parsed into a
// tree whose symbols are resolved at parse time (a name that means nothing is an error naming it), then
// compiled into an ExpressionProgram: a straight-line list of instructions over registers that computes
// several outputs at once, with common subexpressions computed once and every subexpression that depends
// on parameters only computed in double precision before the rest.
//
// Grammar (precedence from low to high; all binary operators left-associative except ^):
//   expr    := or
//   or      := and ('||' and)*          and := cmp ('&&' cmp)*
//   cmp     := sum (('<'|'<='|'>'|'>='|'=='|'!=') sum)?
//   sum     := product (('+'|'-') product)*
//   product := unary (('*'|'/') unary)*
//   unary   := ('-'|'+'|'!') unary | power
//   power   := primary (('^'|'**') unary)?          (-x^2 = -(x^2); 2^-1 = 0.5; a^b^c = a^(b^c))
//   primary := number | name | name '(' expr (',' expr)* ')' | '(' expr ')'
// Functions: sin cos tan asin acos atan sinh cosh tanh exp log sqrt abs (one argument), atan2(y, x),
// pow(x, y), min(a, b), max(a, b). Constants: pi. Comparisons and logic give 1 or 0; they are not
// differentiable and are refused where a derivative is taken (ExpressionProgram with differentiable =
// true), as are min and max, whose derivative jumps where the arguments cross.
//
// Evaluation is exact automatic differentiation when T is a jet (internal/autodiff_phase.h): every instruction is an
// operation of the scalar type, so Evaluate<Jet> gives the value and the exact derivative.
#ifndef HYBRIDCONT_EXPRESSION_H_
#define HYBRIDCONT_EXPRESSION_H_

#include <cmath>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

namespace hybridcont {

// Where an expression came from, for messages: "models/slip.toml:42: phases.stance.ode.dalpha".
struct SourceLocation {
  std::string file;
  int line = 0;
  std::string field;
  // "file:line: field" with the parts that are known.
  std::string ToString() const;
};

// Bad input in an expression or a model file: the message names the place (SourceLocation), the field
// and the offending text.
class ModelInputError : public std::invalid_argument {
 public:
  ModelInputError(const SourceLocation& where, const std::string& what);
  const SourceLocation& where() const { return where_; }

 private:
  SourceLocation where_;
};

enum class ExprOp {
  kConstant, kInput, kParameter,
  kNeg, kNot,
  kAdd, kSub, kMul, kDiv, kPow,
  kLess, kLessEqual, kGreater, kGreaterEqual, kEqual, kNotEqual, kAnd, kOr,
  kSin, kCos, kTan, kAsin, kAcos, kAtan, kSinh, kCosh, kTanh, kExp, kLog, kSqrt, kAbs,
  kAtan2, kMin, kMax,
};

struct ExprNode;
using ExprPtr = std::shared_ptr<const ExprNode>;

// A node of a parsed expression. kInput and kParameter refer to slots of the arrays Evaluate receives.
struct ExprNode {
  ExprOp op = ExprOp::kConstant;
  double value = 0.0;  // kConstant
  int index = -1;      // kInput, kParameter
  std::vector<ExprPtr> args;
};

// What a name means: an input (differentiated variable), a parameter, or a whole expression (a named
// intermediate quantity, already parsed). Return nullptr for an unknown name.
using SymbolResolver = std::function<ExprPtr(const std::string& name)>;

// Parses text; throws ModelInputError naming `where`, the column and the problem (unknown symbol, unknown
// function, wrong number of arguments, malformed number, unbalanced parenthesis, trailing text, empty).
ExprPtr ParseExpression(const std::string& text, const SymbolResolver& resolve, const SourceLocation& where);

// Node constructors, for code that builds expressions without text.
ExprPtr MakeConstant(double value);
ExprPtr MakeInput(int index);
ExprPtr MakeParameter(int index);
ExprPtr MakeNode(ExprOp op, std::vector<ExprPtr> args);

// True if the tree uses a comparison, logic, min or max (not differentiable).
bool HasNonSmoothOperation(const ExprPtr& e);
// True if the tree depends on some input.
bool DependsOnInputs(const ExprPtr& e);

// A compiled list of expressions over inputs x (type T) and parameters p (double).
class ExpressionProgram {
 public:
  // One instruction: dst = op(a, b). Operands refer to the double registers (kind 'c', parameter-only
  // values) or to the T registers (kind 'r').
  struct Operand {
    char kind = 'c';
    int index = 0;
  };
  struct Instruction {
    ExprOp op;
    int dst;
    Operand a, b;
    double value = 0.0;  // kConstant
  };

  ExpressionProgram() = default;
  // Compiles outputs over num_inputs inputs. With differentiable = true, an output that uses a comparison,
  // logic, min or max is refused (ModelInputError at where[i], or at where[0] if where has one entry).
  ExpressionProgram(const std::vector<ExprPtr>& outputs, int num_inputs, bool differentiable,
                    const std::vector<SourceLocation>& where);

  int num_inputs() const { return num_inputs_; }
  int num_outputs() const { return static_cast<int>(outputs_.size()); }

  // out[i] = output i at (x, p). x has num_inputs() entries, out num_outputs().
  template <class T>
  void Evaluate(const T* x, const double* p, T* out) const;
  // The same with the parameters as values of the scalar type (derivatives with respect to a parameter);
  // always interpreted.
  template <class T>
  void EvaluateWithParameterJets(const T* x, const T* p, T* out) const;
  // One output in double precision (for set-up values and presentation rules).
  double EvaluateScalar(const double* x, const double* p, int output = 0) const;

  // The instructions, for code generation (model_codegen).
  const std::vector<Instruction>& constant_code() const { return constant_code_; }
  const std::vector<Instruction>& code() const { return code_; }
  const std::vector<Operand>& outputs() const { return outputs_; }
  int num_constant_registers() const { return num_c_; }
  int num_registers() const { return num_r_; }

 private:
  int num_inputs_ = 0;
  int num_c_ = 0;
  int num_r_ = 0;
  // Parameter-only instructions (all operands 'c'; constants and parameters are loads into 'c').
  std::vector<Instruction> constant_code_;
  // The rest: inputs are loaded into 'r' registers by kInput instructions.
  std::vector<Instruction> code_;
  std::vector<Operand> outputs_;
};

namespace internal {

template <class T>
T ApplyUnary(ExprOp op, const T& a) {
  using std::abs, std::acos, std::asin, std::atan2, std::cos, std::cosh, std::exp, std::log, std::sin, std::sinh,
      std::sqrt, std::tan, std::tanh;
  switch (op) {
    case ExprOp::kNeg: return -a;
    case ExprOp::kSin: return sin(a);
    case ExprOp::kCos: return cos(a);
    case ExprOp::kTan: return tan(a);
    case ExprOp::kAsin: return asin(a);
    case ExprOp::kAcos: return acos(a);
    case ExprOp::kAtan: return atan2(a, T(1.0));
    case ExprOp::kSinh: return sinh(a);
    case ExprOp::kCosh: return cosh(a);
    case ExprOp::kTanh: return tanh(a);
    case ExprOp::kExp: return exp(a);
    case ExprOp::kLog: return log(a);
    case ExprOp::kSqrt: return sqrt(a);
    case ExprOp::kAbs:
      if constexpr (std::is_same_v<T, double>) return std::abs(a);
      else return a < 0.0 ? T(-a) : a;  // nested jets have no abs of their own
    default: break;
  }
  return a;  // not reached: the compiler emits unary instructions for the operations above only
}

// x^n for an integer n by repeated squaring (exact for negative x, unlike exp(n log x); nested jets have
// no pow of their own).
template <class T>
T IntegerPower(const T& x, long n) {
  if (n < 0) return T(1.0 / IntegerPower(x, -n));
  T result(1.0), base = x;
  bool first = true;
  while (n > 0) {
    if (n & 1) {
      result = first ? base : T(result * base);
      first = false;
    }
    n >>= 1;
    if (n > 0) base = T(base * base);
  }
  return result;
}

// Binary operations with both operands of the scalar type, or one of them a double (A, B in {T, double}).
template <class T, class A, class B>
T ApplyBinary(ExprOp op, const A& a, const B& b) {
  using std::atan2, std::exp, std::log, std::pow;
  switch (op) {
    case ExprOp::kAdd: return a + b;
    case ExprOp::kSub: return a - b;
    case ExprOp::kMul: return a * b;
    case ExprOp::kDiv: return a / b;
    case ExprOp::kPow:
      if constexpr (std::is_same_v<B, double>) {
        if (b == 2.0) return T(a * a);
        if (b == std::floor(b) && std::abs(b) <= 64.0) return IntegerPower(T(a), static_cast<long>(b));
        if constexpr (std::is_same_v<T, double>) return std::pow(a, b);
        else return T(exp(b * log(T(a))));
      } else {
        return T(exp(b * log(a)));
      }
    case ExprOp::kAtan2: return T(atan2(T(a), T(b)));
    default: break;
  }
  return T(a);  // not reached: comparisons and min/max are never differentiated (see the constructor)
}

// Every operation in double precision, comparisons and logic included (1 true, 0 false).
inline double ApplyDouble(ExprOp op, double a, double b) {
  switch (op) {
    case ExprOp::kNot: return a == 0.0 ? 1.0 : 0.0;
    case ExprOp::kLess: return a < b;
    case ExprOp::kLessEqual: return a <= b;
    case ExprOp::kGreater: return a > b;
    case ExprOp::kGreaterEqual: return a >= b;
    case ExprOp::kEqual: return a == b;
    case ExprOp::kNotEqual: return a != b;
    case ExprOp::kAnd: return (a != 0.0 && b != 0.0) ? 1.0 : 0.0;
    case ExprOp::kOr: return (a != 0.0 || b != 0.0) ? 1.0 : 0.0;
    case ExprOp::kMin: return a < b ? a : b;
    case ExprOp::kMax: return a < b ? b : a;
    case ExprOp::kAdd: case ExprOp::kSub: case ExprOp::kMul: case ExprOp::kDiv: case ExprOp::kPow:
    case ExprOp::kAtan2:
      return ApplyBinary<double>(op, a, b);
    default:
      return ApplyUnary(op, a);
  }
}

}  // namespace internal

template <class T>
void ExpressionProgram::Evaluate(const T* x, const double* p, T* out) const {
  // Registers live in per-thread scratch: an evaluation runs once per right-hand side of the integrator,
  // so it allocates nothing after the first call on a thread.
  thread_local std::vector<double> c;
  thread_local std::vector<T> r;
  if (static_cast<int>(c.size()) < num_c_) c.resize(num_c_);
  if (static_cast<int>(r.size()) < num_r_) r.resize(num_r_);
  for (const Instruction& in : constant_code_) {
    if (in.op == ExprOp::kParameter) {
      c[in.dst] = p[in.a.index];
    } else if (in.op == ExprOp::kConstant) {
      c[in.dst] = in.value;
    } else {
      c[in.dst] = internal::ApplyDouble(in.op, c[in.a.index], in.b.index >= 0 ? c[in.b.index] : 0.0);
    }
  }
  for (const Instruction& in : code_) {
    switch (in.op) {
      case ExprOp::kInput: r[in.dst] = x[in.a.index]; break;
      case ExprOp::kAdd: case ExprOp::kSub: case ExprOp::kMul: case ExprOp::kDiv: case ExprOp::kPow:
      case ExprOp::kAtan2:
        if (in.a.kind == 'r' && in.b.kind == 'r') {
          r[in.dst] = internal::ApplyBinary<T>(in.op, r[in.a.index], r[in.b.index]);
        } else if (in.a.kind == 'r') {
          r[in.dst] = internal::ApplyBinary<T>(in.op, r[in.a.index], c[in.b.index]);
        } else {
          r[in.dst] = internal::ApplyBinary<T>(in.op, c[in.a.index], r[in.b.index]);
        }
        break;
      default: r[in.dst] = internal::ApplyUnary(in.op, r[in.a.index]); break;
    }
  }
  for (int i = 0; i < num_outputs(); ++i) {
    const Operand& o = outputs_[i];
    out[i] = o.kind == 'r' ? r[o.index] : T(c[o.index]);
  }
}

namespace internal {
// The double inside a (possibly nested) jet.
template <class T>
double PlainValue(const T& v) {
  if constexpr (std::is_same_v<T, double>) {
    return v;
  } else if constexpr (requires { v.value(); }) {
    return PlainValue(v.value());  // AutoDiffScalar
  } else {
    return v.value;  // HessianJet
  }
}
}  // namespace internal

template <class T>
void ExpressionProgram::EvaluateWithParameterJets(const T* x, const T* p, T* out) const {
  // Differentiable programs have no comparisons, logic, min or max (see the constructor), so the
  // parameter-only code runs over T with the operations of Evaluate's double registers. An exponent that is
  // a literal (no parameter in it) stays a double, so that x^2 and (-g)^3 are the exact products Evaluate
  // forms, not exp(n log x).
  thread_local std::vector<T> c;
  thread_local std::vector<T> r;
  thread_local std::vector<char> literal;
  if (static_cast<int>(c.size()) < num_c_) c.resize(num_c_);
  if (static_cast<int>(literal.size()) < num_c_) literal.resize(num_c_);
  if (static_cast<int>(r.size()) < num_r_) r.resize(num_r_);
  const auto binary = [&](const Instruction& in, const T& a, const T& b, bool b_literal) {
    if (b_literal) return internal::ApplyBinary<T>(in.op, a, internal::PlainValue(b));
    return internal::ApplyBinary<T>(in.op, a, b);
  };
  for (const Instruction& in : constant_code_) {
    if (in.op == ExprOp::kParameter) {
      c[in.dst] = p[in.a.index];
      literal[in.dst] = false;
    } else if (in.op == ExprOp::kConstant) {
      c[in.dst] = T(in.value);
      literal[in.dst] = true;
    } else if (in.b.index >= 0) {
      c[in.dst] = binary(in, c[in.a.index], c[in.b.index], literal[in.b.index]);
      literal[in.dst] = literal[in.a.index] && literal[in.b.index];
    } else {
      c[in.dst] = internal::ApplyUnary(in.op, c[in.a.index]);
      literal[in.dst] = literal[in.a.index];
    }
  }
  for (const Instruction& in : code_) {
    switch (in.op) {
      case ExprOp::kInput: r[in.dst] = x[in.a.index]; break;
      case ExprOp::kAdd: case ExprOp::kSub: case ExprOp::kMul: case ExprOp::kDiv: case ExprOp::kPow:
      case ExprOp::kAtan2:
        r[in.dst] = binary(in, in.a.kind == 'r' ? r[in.a.index] : c[in.a.index],
                           in.b.kind == 'r' ? r[in.b.index] : c[in.b.index], in.b.kind == 'c' && literal[in.b.index]);
        break;
      default: r[in.dst] = internal::ApplyUnary(in.op, r[in.a.index]); break;
    }
  }
  for (int i = 0; i < num_outputs(); ++i) {
    const Operand& o = outputs_[i];
    out[i] = o.kind == 'r' ? r[o.index] : c[o.index];
  }
}

}  // namespace hybridcont

#endif  // HYBRIDCONT_EXPRESSION_H_
