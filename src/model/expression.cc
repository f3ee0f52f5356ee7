#include "hybridcont/expression.h"

#include <cctype>
#include <cstring>
#include <map>
#include <tuple>
#include <unordered_map>

namespace hybridcont {

std::string SourceLocation::ToString() const {
  std::string s = file;
  if (line > 0) s += (s.empty() ? "line " : ":") + std::to_string(line);
  if (!field.empty()) s += (s.empty() ? "" : ": ") + field;
  return s;
}

ModelInputError::ModelInputError(const SourceLocation& where, const std::string& what)
    : std::invalid_argument(where.ToString().empty() ? what : where.ToString() + ": " + what), where_(where) {}

ExprPtr MakeConstant(double value) {
  auto n = std::make_shared<ExprNode>();
  n->op = ExprOp::kConstant;
  n->value = value;
  return n;
}
ExprPtr MakeInput(int index) {
  auto n = std::make_shared<ExprNode>();
  n->op = ExprOp::kInput;
  n->index = index;
  return n;
}
ExprPtr MakeParameter(int index) {
  auto n = std::make_shared<ExprNode>();
  n->op = ExprOp::kParameter;
  n->index = index;
  return n;
}
ExprPtr MakeNode(ExprOp op, std::vector<ExprPtr> args) {
  auto n = std::make_shared<ExprNode>();
  n->op = op;
  n->args = std::move(args);
  return n;
}

namespace {

bool IsNonSmooth(ExprOp op) {
  switch (op) {
    case ExprOp::kNot: case ExprOp::kLess: case ExprOp::kLessEqual: case ExprOp::kGreater:
    case ExprOp::kGreaterEqual: case ExprOp::kEqual: case ExprOp::kNotEqual: case ExprOp::kAnd: case ExprOp::kOr:
    case ExprOp::kMin: case ExprOp::kMax:
      return true;
    default:
      return false;
  }
}

template <class Pred>
bool AnyNode(const ExprPtr& e, Pred pred, std::unordered_map<const ExprNode*, bool>* seen) {
  if (auto it = seen->find(e.get()); it != seen->end()) return it->second;
  bool result = pred(*e);
  for (const ExprPtr& a : e->args) result = result || AnyNode(a, pred, seen);
  (*seen)[e.get()] = result;
  return result;
}

// Recursive-descent parser over the grammar of expression.h. Positions are 1-based columns for messages.
class Parser {
 public:
  Parser(const std::string& text, const SymbolResolver& resolve, const SourceLocation& where)
      : s_(text), resolve_(resolve), where_(where) {}

  ExprPtr Parse() {
    Skip();
    if (pos_ >= s_.size()) Fail("empty expression");
    ExprPtr e = Or();
    Skip();
    if (pos_ < s_.size()) Fail("unexpected '" + std::string(1, s_[pos_]) + "'");
    return e;
  }

 private:
  // Nesting deeper than this is refused: it bounds the recursion for hostile input.
  static constexpr int kMaxDepth = 200;
  // Operations on the longest path of the tree, resolved symbols (definitions, let quantities) included:
  // compiling and destroying a tree recurse that deep, and a long sum "a+a+...+a" is a chain as deep as
  // it has terms (50000 overflowed the stack).
  static constexpr int kMaxTreeDepth = 10000;
  // Operations written in one expression: the work of compiling a model grows with them (a 10,000-operation
  // expression compiled for 29 s), and a hand- or CAS-written expression above this is better split.
  static constexpr int kMaxOperations = 4000;
  int operations_ = 0;

  [[noreturn]] void Fail(const std::string& what) const {
    throw ModelInputError(where_, "in expression '" + Excerpt() + "' at column " + std::to_string(pos_ + 1) +
                                      ": " + what);
  }
  std::string Excerpt() const { return s_.size() <= 80 ? s_ : s_.substr(0, 77) + "..."; }
  void Skip() {
    while (pos_ < s_.size() && std::isspace(static_cast<unsigned char>(s_[pos_]))) ++pos_;
  }
  bool Accept(const char* token) {
    Skip();
    const std::size_t n = std::strlen(token);
    if (s_.compare(pos_, n, token) != 0) return false;
    // '*' must not swallow the first half of '**', '<' the first half of '<=' etc.
    if (n == 1 && pos_ + 1 < s_.size()) {
      const char next = s_[pos_ + 1];
      if ((token[0] == '*' && next == '*') || ((token[0] == '<' || token[0] == '>' || token[0] == '!') && next == '=')) {
        return false;
      }
    }
    pos_ += n;
    return true;
  }
  struct DepthGuard {
    explicit DepthGuard(Parser* p) : p_(p) {
      if (++p_->depth_ > kMaxDepth) p_->Fail("nested more than " + std::to_string(kMaxDepth) + " levels deep");
    }
    ~DepthGuard() { --p_->depth_; }
    Parser* p_;
  };

  // The tree depth of e, memoized; trees of resolved symbols were bounded when they were parsed.
  int TreeDepth(const ExprPtr& e) {
    if (const auto it = tree_depth_.find(e.get()); it != tree_depth_.end()) return it->second;
    int depth = 0;
    for (const ExprPtr& a : e->args) depth = std::max(depth, TreeDepth(a));
    return tree_depth_[e.get()] = depth + 1;
  }
  ExprPtr Node(ExprOp op, std::vector<ExprPtr> args) {
    if (++operations_ > kMaxOperations) {
      Fail("more than " + std::to_string(kMaxOperations) +
           " operations in one expression (split it into `let` quantities or definitions)");
    }
    int depth = 0;
    for (const ExprPtr& a : args) depth = std::max(depth, TreeDepth(a));
    if (depth + 1 > kMaxTreeDepth) {
      Fail("more than " + std::to_string(kMaxTreeDepth) +
           " operations deep (counting the definitions and let quantities it uses)");
    }
    ExprPtr e = MakeNode(op, std::move(args));
    tree_depth_[e.get()] = depth + 1;
    return e;
  }

  ExprPtr Or() {
    ExprPtr e = And();
    while (Accept("||")) e = Node(ExprOp::kOr, {e, And()});
    return e;
  }
  ExprPtr And() {
    ExprPtr e = Comparison();
    while (Accept("&&")) e = Node(ExprOp::kAnd, {e, Comparison()});
    return e;
  }
  ExprPtr Comparison() {
    ExprPtr e = Sum();
    static const std::pair<const char*, ExprOp> kOps[] = {
        {"<=", ExprOp::kLessEqual}, {">=", ExprOp::kGreaterEqual}, {"==", ExprOp::kEqual},
        {"!=", ExprOp::kNotEqual},  {"<", ExprOp::kLess},          {">", ExprOp::kGreater}};
    for (const auto& [token, op] : kOps) {
      if (Accept(token)) return Node(op, {e, Sum()});
    }
    return e;
  }
  ExprPtr Sum() {
    ExprPtr e = Product();
    for (;;) {
      if (Accept("+")) e = Node(ExprOp::kAdd, {e, Product()});
      else if (Accept("-")) e = Node(ExprOp::kSub, {e, Product()});
      else return e;
    }
  }
  ExprPtr Product() {
    ExprPtr e = Unary();
    for (;;) {
      if (Accept("*")) e = Node(ExprOp::kMul, {e, Unary()});
      else if (Accept("/")) e = Node(ExprOp::kDiv, {e, Unary()});
      else return e;
    }
  }
  ExprPtr Unary() {
    DepthGuard guard(this);
    if (Accept("-")) return Node(ExprOp::kNeg, {Unary()});
    if (Accept("+")) return Unary();
    if (Accept("!")) return Node(ExprOp::kNot, {Unary()});
    return Power();
  }
  ExprPtr Power() {
    ExprPtr base = Primary();
    if (Accept("^") || Accept("**")) return Node(ExprOp::kPow, {base, Unary()});
    return base;
  }
  ExprPtr Primary() {
    DepthGuard guard(this);
    Skip();
    if (pos_ >= s_.size()) Fail("expression ends where an operand is expected");
    const char ch = s_[pos_];
    if (Accept("(")) {
      ExprPtr e = Or();
      if (!Accept(")")) Fail("expected ')'");
      return e;
    }
    if (std::isdigit(static_cast<unsigned char>(ch)) || ch == '.') return Number();
    if (std::isalpha(static_cast<unsigned char>(ch)) || ch == '_') {
      const std::size_t start = pos_;
      while (pos_ < s_.size() && (std::isalnum(static_cast<unsigned char>(s_[pos_])) || s_[pos_] == '_')) ++pos_;
      const std::string name = s_.substr(start, pos_ - start);
      Skip();
      if (pos_ < s_.size() && s_[pos_] == '(') return Call(name, start);
      if (ExprPtr e = resolve_ ? resolve_(name) : nullptr) return e;
      if (name == "pi") return MakeConstant(M_PI);
      pos_ = start;
      Fail("unknown symbol '" + name + "'");
    }
    Fail("unexpected '" + std::string(1, ch) + "'");
  }
  ExprPtr Number() {
    const std::size_t start = pos_;
    while (pos_ < s_.size() && (std::isdigit(static_cast<unsigned char>(s_[pos_])) || s_[pos_] == '.')) ++pos_;
    if (pos_ < s_.size() && (s_[pos_] == 'e' || s_[pos_] == 'E')) {
      std::size_t q = pos_ + 1;
      if (q < s_.size() && (s_[q] == '+' || s_[q] == '-')) ++q;
      if (q < s_.size() && std::isdigit(static_cast<unsigned char>(s_[q]))) {
        pos_ = q;
        while (pos_ < s_.size() && std::isdigit(static_cast<unsigned char>(s_[pos_]))) ++pos_;
      }
    }
    const std::string text = s_.substr(start, pos_ - start);
    char* end = nullptr;
    const double v = std::strtod(text.c_str(), &end);
    if (end != text.c_str() + text.size() || text == ".") {
      pos_ = start;
      Fail("malformed number '" + text + "'");
    }
    if (!std::isfinite(v)) {
      pos_ = start;
      Fail("number '" + text + "' is out of range");
    }
    return MakeConstant(v);
  }
  ExprPtr Call(const std::string& name, std::size_t start) {
    static const std::map<std::string, std::pair<ExprOp, int>> kFunctions = {
        {"sin", {ExprOp::kSin, 1}},   {"cos", {ExprOp::kCos, 1}},     {"tan", {ExprOp::kTan, 1}},
        {"asin", {ExprOp::kAsin, 1}}, {"acos", {ExprOp::kAcos, 1}},   {"atan", {ExprOp::kAtan, 1}},
        {"sinh", {ExprOp::kSinh, 1}}, {"cosh", {ExprOp::kCosh, 1}},   {"tanh", {ExprOp::kTanh, 1}},
        {"exp", {ExprOp::kExp, 1}},   {"log", {ExprOp::kLog, 1}},     {"sqrt", {ExprOp::kSqrt, 1}},
        {"abs", {ExprOp::kAbs, 1}},   {"atan2", {ExprOp::kAtan2, 2}}, {"pow", {ExprOp::kPow, 2}},
        {"min", {ExprOp::kMin, 2}},   {"max", {ExprOp::kMax, 2}}};
    const auto it = kFunctions.find(name);
    if (it == kFunctions.end()) {
      pos_ = start;
      std::string known;
      for (const auto& [fn, unused] : kFunctions) known += (known.empty() ? "" : " ") + fn;
      Fail("unknown function '" + name + "' (known: " + known + ")");
    }
    Accept("(");
    std::vector<ExprPtr> args;
    if (!Accept(")")) {
      do {
        args.push_back(Or());
      } while (Accept(","));
      if (!Accept(")")) Fail("expected ',' or ')' in the arguments of " + name);
    }
    if (static_cast<int>(args.size()) != it->second.second) {
      pos_ = start;
      Fail(name + " takes " + std::to_string(it->second.second) + " argument(s), got " + std::to_string(args.size()));
    }
    return Node(it->second.first, std::move(args));
  }

  const std::string& s_;
  const SymbolResolver& resolve_;
  const SourceLocation& where_;
  std::size_t pos_ = 0;
  int depth_ = 0;
  std::unordered_map<const ExprNode*, int> tree_depth_;
};

// Compiles trees into the two instruction lists, sharing identical subtrees (by node identity first, then
// by structure: the same operation on the same operands is one register).
class Compiler {
 public:
  using Operand = ExpressionProgram::Operand;
  using Instruction = ExpressionProgram::Instruction;

  Operand Compile(const ExprPtr& e) {
    if (auto it = by_node_.find(e.get()); it != by_node_.end()) return it->second;
    Operand result;
    if (e->op == ExprOp::kConstant) {
      result = Intern({ExprOp::kConstant, -1, {}, {}, e->value}, 'c');
    } else if (e->op == ExprOp::kParameter) {
      result = Intern({ExprOp::kParameter, -1, {'c', e->index}, {}, 0.0}, 'c');
    } else if (e->op == ExprOp::kInput) {
      result = Intern({ExprOp::kInput, -1, {'r', e->index}, {}, 0.0}, 'r');
    } else {
      std::vector<Operand> args;
      for (const ExprPtr& a : e->args) args.push_back(Compile(a));
      Instruction in{e->op, -1, args[0], args.size() > 1 ? args[1] : Operand{'c', -1}, 0.0};
      const bool all_constant = std::all_of(args.begin(), args.end(), [](const Operand& o) { return o.kind == 'c'; });
      // Rewrite x^n by multiplication for n = 2 (ApplyBinary does it); x^(-y) etc. stay powers.
      result = Intern(in, all_constant ? 'c' : 'r');
    }
    by_node_[e.get()] = result;
    return result;
  }

  std::vector<Instruction> constant_code, code;
  int num_c = 0, num_r = 0;

 private:
  using Key = std::tuple<int, char, int, char, int, std::uint64_t>;
  Operand Intern(Instruction in, char kind) {
    std::uint64_t bits = 0;
    std::memcpy(&bits, &in.value, sizeof bits);
    const Key key{static_cast<int>(in.op), in.a.kind, in.a.index, in.b.kind, in.b.index, bits};
    if (auto it = by_key_.find(key); it != by_key_.end()) return it->second;
    Operand dst{kind, kind == 'c' ? num_c++ : num_r++};
    in.dst = dst.index;
    (kind == 'c' ? constant_code : code).push_back(in);
    by_key_[key] = dst;
    return dst;
  }
  std::unordered_map<const ExprNode*, Operand> by_node_;
  std::map<Key, Operand> by_key_;
};

}  // namespace

ExprPtr ParseExpression(const std::string& text, const SymbolResolver& resolve, const SourceLocation& where) {
  return Parser(text, resolve, where).Parse();
}

bool HasNonSmoothOperation(const ExprPtr& e) {
  std::unordered_map<const ExprNode*, bool> seen;
  return AnyNode(e, [](const ExprNode& n) { return IsNonSmooth(n.op); }, &seen);
}

bool DependsOnInputs(const ExprPtr& e) {
  std::unordered_map<const ExprNode*, bool> seen;
  return AnyNode(e, [](const ExprNode& n) { return n.op == ExprOp::kInput; }, &seen);
}

ExpressionProgram::ExpressionProgram(const std::vector<ExprPtr>& outputs, int num_inputs, bool differentiable,
                                     const std::vector<SourceLocation>& where)
    : num_inputs_(num_inputs) {
  Compiler compiler;
  for (std::size_t i = 0; i < outputs.size(); ++i) {
    const SourceLocation at = where.empty() ? SourceLocation{} : where[std::min(i, where.size() - 1)];
    if (!outputs[i]) throw ModelInputError(at, "missing expression");
    if (differentiable && HasNonSmoothOperation(outputs[i])) {
      throw ModelInputError(at, "comparisons, logic, min and max are not differentiable and cannot be used here");
    }
    outputs_.push_back(compiler.Compile(outputs[i]));
  }
  constant_code_ = std::move(compiler.constant_code);
  code_ = std::move(compiler.code);
  num_c_ = compiler.num_c;
  num_r_ = compiler.num_r;
}

double ExpressionProgram::EvaluateScalar(const double* x, const double* p, int output) const {
  std::vector<double> c(num_c_), r(num_r_);
  for (const Instruction& in : constant_code_) {
    if (in.op == ExprOp::kParameter) c[in.dst] = p[in.a.index];
    else if (in.op == ExprOp::kConstant) c[in.dst] = in.value;
    else c[in.dst] = internal::ApplyDouble(in.op, c[in.a.index], in.b.index >= 0 ? c[in.b.index] : 0.0);
  }
  const auto value = [&](const Operand& o) { return o.kind == 'c' ? c[o.index] : r[o.index]; };
  for (const Instruction& in : code_) {
    if (in.op == ExprOp::kInput) r[in.dst] = x[in.a.index];
    else r[in.dst] = internal::ApplyDouble(in.op, value(in.a), in.b.index >= 0 ? value(in.b) : 0.0);
  }
  return value(outputs_.at(output));
}


}  // namespace hybridcont
