#include "model_compiler.h"

#include "hybridcont/version.h"
#include "model_cache.h"

#include <dlfcn.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <map>
#include <memory>
#include <mutex>
#include <sstream>

namespace hybridcont::internal {
namespace fs = std::filesystem;

namespace {

const char* OpName(ExprOp op) {
  switch (op) {
    case ExprOp::kNeg: return "kNeg";
    case ExprOp::kNot: return "kNot";
    case ExprOp::kAdd: return "kAdd";
    case ExprOp::kSub: return "kSub";
    case ExprOp::kMul: return "kMul";
    case ExprOp::kDiv: return "kDiv";
    case ExprOp::kPow: return "kPow";
    case ExprOp::kLess: return "kLess";
    case ExprOp::kLessEqual: return "kLessEqual";
    case ExprOp::kGreater: return "kGreater";
    case ExprOp::kGreaterEqual: return "kGreaterEqual";
    case ExprOp::kEqual: return "kEqual";
    case ExprOp::kNotEqual: return "kNotEqual";
    case ExprOp::kAnd: return "kAnd";
    case ExprOp::kOr: return "kOr";
    case ExprOp::kSin: return "kSin";
    case ExprOp::kCos: return "kCos";
    case ExprOp::kTan: return "kTan";
    case ExprOp::kAsin: return "kAsin";
    case ExprOp::kAcos: return "kAcos";
    case ExprOp::kAtan: return "kAtan";
    case ExprOp::kSinh: return "kSinh";
    case ExprOp::kCosh: return "kCosh";
    case ExprOp::kTanh: return "kTanh";
    case ExprOp::kExp: return "kExp";
    case ExprOp::kLog: return "kLog";
    case ExprOp::kSqrt: return "kSqrt";
    case ExprOp::kAbs: return "kAbs";
    case ExprOp::kAtan2: return "kAtan2";
    case ExprOp::kMin: return "kMin";
    case ExprOp::kMax: return "kMax";
    default: return "kConstant";
  }
}

std::string Operand(const ExpressionProgram::Operand& o) {
  return std::string(1, o.kind) + std::to_string(o.index);
}

// A program's register code and outputs over T, closing the function; first/second write a binary
// operation's operands.
void EmitRegisters(std::ostringstream& s, const ExpressionProgram& program,
                   const std::function<std::string(const ExpressionProgram::Operand&)>& first,
                   const std::function<std::string(const ExpressionProgram::Operand&)>& second) {
  for (const auto& in : program.code()) {
    s << "  const T r" << in.dst << " = ";
    if (in.op == ExprOp::kInput) {
      s << "x[" << in.a.index << "];\n";
    } else if (in.b.index >= 0) {
      s << "ApplyBinary<T>(ExprOp::" << OpName(in.op) << ", " << first(in.a) << ", " << second(in.b) << ");\n";
    } else {
      s << "ApplyUnary(ExprOp::" << OpName(in.op) << ", " << Operand(in.a) << ");\n";
    }
  }
  for (int i = 0; i < program.num_outputs(); ++i) {
    const auto& o = program.outputs()[i];
    s << "  out[" << i << "] = " << (o.kind == 'r' ? Operand(o) : "T(" + Operand(o) + ")") << ";\n";
  }
  s << "}\n";
}

// One program as a function template `P<id>(x, p, out)`.
void EmitProgram(std::ostringstream& s, const std::string& id, const ExpressionProgram& program) {
  s << "template <class T>\nvoid P" << id << "(const T* x, const double* p, T* out) {\n";
  s << "  (void)x; (void)p;\n";
  for (const auto& in : program.constant_code()) {
    s << "  const double c" << in.dst << " = ";
    if (in.op == ExprOp::kParameter) {
      s << "p[" << in.a.index << "];\n";
    } else if (in.op == ExprOp::kConstant) {
      char buffer[64];
      std::snprintf(buffer, sizeof buffer, "%a", in.value);
      s << buffer << ";\n";
    } else {
      s << "ApplyDouble(ExprOp::" << OpName(in.op) << ", " << Operand(in.a) << ", "
        << (in.b.index >= 0 ? Operand(in.b) : std::string("0.0")) << ");\n";
    }
  }
  EmitRegisters(s, program, Operand, Operand);
}

// The same program with the parameters as jets too, `Q<id>(x, p, out)` over T = ParamJet: the operations of
// ExpressionProgram::EvaluateWithParameterJets, instruction by instruction (a constant register that holds
// no parameter, a literal, stays a double, so that x^2 is the exact product the interpreter forms).
void EmitParamJetProgram(std::ostringstream& s, const std::string& id, const ExpressionProgram& program) {
  s << "template <class T>\nvoid Q" << id << "(const T* x, const T* p, T* out) {\n";
  s << "  (void)x; (void)p;\n";
  std::vector<char> literal(program.constant_code().size() + program.code().size() + 64, 0);
  const auto is_literal = [&](const ExpressionProgram::Operand& o) {
    return o.kind == 'c' && o.index >= 0 && o.index < static_cast<int>(literal.size()) && literal[o.index];
  };
  const auto as_t = [&](const ExpressionProgram::Operand& o) {  // an operand as a T
    return is_literal(o) ? "T(" + Operand(o) + ")" : Operand(o);
  };
  for (const auto& in : program.constant_code()) {
    if (in.dst >= static_cast<int>(literal.size())) literal.resize(in.dst + 1, 0);
    if (in.op == ExprOp::kParameter) {
      literal[in.dst] = 0;
      s << "  const T c" << in.dst << " = p[" << in.a.index << "];\n";
    } else if (in.op == ExprOp::kConstant) {
      literal[in.dst] = 1;
      char buffer[64];
      std::snprintf(buffer, sizeof buffer, "%a", in.value);
      s << "  const double c" << in.dst << " = " << buffer << ";\n";
    } else if (in.b.index >= 0) {
      const bool a = is_literal(in.a), b = is_literal(in.b);
      literal[in.dst] = a && b;
      if (a && b) {
        s << "  const double c" << in.dst << " = ApplyDouble(ExprOp::" << OpName(in.op) << ", " << Operand(in.a) << ", "
          << Operand(in.b) << ");\n";
      } else {
        s << "  const T c" << in.dst << " = ApplyBinary<T>(ExprOp::" << OpName(in.op) << ", " << as_t(in.a) << ", "
          << (b ? Operand(in.b) : as_t(in.b)) << ");\n";
      }
    } else {
      literal[in.dst] = is_literal(in.a);
      if (literal[in.dst]) {
        s << "  const double c" << in.dst << " = ApplyDouble(ExprOp::" << OpName(in.op) << ", " << Operand(in.a)
          << ", 0.0);\n";
      } else {
        s << "  const T c" << in.dst << " = ApplyUnary(ExprOp::" << OpName(in.op) << ", " << Operand(in.a) << ");\n";
      }
    }
  }
  EmitRegisters(s, program, as_t,
                [&](const ExpressionProgram::Operand& o) { return is_literal(o) ? Operand(o) : as_t(o); });
}

// Scalar types per kind for a phase of dimension n (expression_model.h, ScalarKind). Above kMaxPhaseDim
// the jets are emitted as the kValueJacobian and kValueHessian entries instead (EmitValueJacobianEntry,
// EmitValueHessianEntry).
std::vector<std::pair<int, std::string>> ScalarTypes(int n, bool second_order) {
  std::vector<std::pair<int, std::string>> types = {{0, "double"}};
  if (n > kMaxPhaseDim) return types;
  if (n <= kMaxFixedJetDim) {
    types.push_back({1, "JetTypes<" + std::to_string(n) + ">::J"});
    if (second_order) types.push_back({2, "HessianJet<" + std::to_string(n) + ">"});
  } else {
    types.push_back({3, "Jet"});
    if (second_order) types.push_back({4, "Jet2"});
  }
  return types;
}

// The kValueJacobian entry of program P<id> with n inputs and k outputs: one evaluation over forward jets of
// exactly n directions (stack storage), values and the row-major Jacobian written as doubles.
void EmitValueJacobianEntry(std::ostringstream& entries, const std::string& name, const std::string& id, int n, int k) {
  const std::string jet = "Eigen::AutoDiffScalar<Eigen::Matrix<double, " + std::to_string(n) + ", 1>>";
  entries << "void " << name << "(const void* x, const double* p, void* out) {\n"
          << "  using J = " << jet << ";\n"
          << "  const double* xd = static_cast<const double*>(x);\n"
          << "  double* o = static_cast<double*>(out);\n"
          << "  J xs[" << n << "], ys[" << std::max(k, 1) << "];\n"
          << "  for (int i = 0; i < " << n << "; ++i) xs[i] = J(xd[i], J::DerType::Unit(i));\n"
          << "  P" << id << "<J>(xs, p, ys);\n"
          << "  for (int j = 0; j < " << k << "; ++j) {\n"
          << "    o[j] = ys[j].value();\n"
          << "    for (int i = 0; i < " << n << "; ++i) o[" << k << " + j * " << n << " + i] = ys[j].derivatives()(i);\n"
          << "  }\n}\n";
}

// The kValueHessian entry of program P<id> (n inputs, k outputs): values and Jacobian as above, then row i
// of every Hessian from one evaluation over a jet in direction e_i whose value and derivative are n-direction
// jets (forward over forward), n evaluations in all.
void EmitValueHessianEntry(std::ostringstream& entries, const std::string& name, const std::string& id, int n, int k) {
  const std::string jet = "Eigen::AutoDiffScalar<Eigen::Matrix<double, " + std::to_string(n) + ", 1>>";
  const std::string N = std::to_string(n), K = std::to_string(k);
  entries << "void " << name << "(const void* x, const double* p, void* out) {\n"
          << "  using J = " << jet << ";\n"
          << "  using J1 = Eigen::AutoDiffScalar<Eigen::Matrix<J, 1, 1>>;\n"
          << "  const double* xd = static_cast<const double*>(x);\n"
          << "  double* o = static_cast<double*>(out);\n"
          << "  J1 xs[" << N << "], ys[" << std::max(k, 1) << "];\n"
          << "  for (int i = 0; i < " << N << "; ++i) {\n"
          << "    for (int a = 0; a < " << N << "; ++a) {\n"
          << "      Eigen::Matrix<J, 1, 1> d;\n"
          << "      d(0) = J(a == i ? 1.0 : 0.0, J::DerType::Zero());\n"
          << "      xs[a] = J1(J(xd[a], J::DerType::Unit(a)), d);\n"
          << "    }\n"
          << "    P" << id << "<J1>(xs, p, ys);\n"
          << "    for (int j = 0; j < " << K << "; ++j) {\n"
          << "      if (i == 0) {\n"
          << "        o[j] = ys[j].value().value();\n"
          << "        for (int b = 0; b < " << N << "; ++b) o[" << K << " + j * " << N << " + b] = ys[j].value().derivatives()(b);\n"
          << "      }\n"
          << "      const bool constant = ys[j].derivatives().size() == 0;\n"
          << "      for (int b = 0; b < " << N << "; ++b) {\n"
          << "        o[" << K << " * (1 + " << N << ") + (j * " << N << " + i) * " << N << " + b] =\n"
          << "            constant ? 0.0 : ys[j].derivatives()(0).derivatives()(b);\n"
          << "      }\n"
          << "    }\n"
          << "  }\n}\n";
}

std::string EntryName(int slot, int kind) { return "hybridcont_model_" + std::to_string(slot) + "_" + std::to_string(kind); }
std::string ParamJetEntryName(int slot) { return "hybridcont_model_" + std::to_string(slot) + "_param_jet"; }

fs::path CacheDirectory(const ModelFileOptions& options) {
  if (!options.cache_dir.empty()) return options.cache_dir;
  if (const char* d = std::getenv("HYBRIDCONT_CACHE"); d && *d) return d;
  if (const char* d = std::getenv("XDG_CACHE_HOME"); d && *d) return fs::path(d) / "hybridcont";
  if (const char* d = std::getenv("HOME"); d && *d) return fs::path(d) / ".cache" / "hybridcont";
  return fs::temp_directory_path() / ("hybridcont-cache-" + std::to_string(geteuid()));
}

// What identifies the compiler for the cache key: its resolved path, size and modification time (an
// upgraded compiler is another one).
std::string CompilerIdentity(const std::string& compiler) {
  std::error_code ec;
  const fs::path real = fs::canonical(compiler, ec);
  struct stat st;
  if (ec || stat(real.c_str(), &st) != 0) return compiler;
  return real.string() + " " + std::to_string(st.st_size) + " " + std::to_string(st.st_mtime);
}

constexpr const char* kSourceDigestSymbol = "hybridcont_model_source_sha256";
// The text of that symbol: this prefix and the SHA-256 of the generated source.
constexpr const char* kIdentityPrefix = "hybridcont-model-source-sha256:";

// Whether the file's bytes hold `text` (read in blocks; the text may straddle two).
bool FileContains(const fs::path& file, const std::string& text) {
  std::ifstream in(file, std::ios::binary);
  if (!in || text.empty()) return false;
  std::string window;
  std::vector<char> block(1 << 16);
  while (in.read(block.data(), static_cast<std::streamsize>(block.size())) || in.gcount() > 0) {
    window.append(block.data(), static_cast<std::size_t>(in.gcount()));
    if (window.find(text) != std::string::npos) return true;
    window.erase(0, window.size() - std::min(window.size(), text.size() - 1));
  }
  return false;
}

// `command` run by /bin/sh in a child process; its wait status (-1 where it could not start). Unlike
// std::system this process neither ignores SIGINT nor blocks SIGCHLD meanwhile: Ctrl-C during a compile interrupts
// the command line at once (the compiler, in the same process group, gets it too), and a caller's own SIGINT
// handler (Python's) sees it.
int RunShell(const std::string& command) {
  const pid_t pid = fork();
  if (pid < 0) return -1;
  if (pid == 0) {
    execl("/bin/sh", "sh", "-c", command.c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  int status = 0;
  while (waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) return -1;
  }
  return status;
}

// Removes what compiles of processes that no longer run left in the cache folder (a command line interrupted
// while it compiled): files named model-<key>.<pid>-<n>.{cc,so,log} or model-<key>.sha256.<pid>-<n> whose pid is
// gone. Files of running processes and published entries are left alone.
void RemoveLeftovers(const fs::path& cache) {
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(cache, ec)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind("model-", 0) != 0) continue;
    const std::size_t dot = name.find('.', 6);
    if (dot == std::string::npos) continue;
    std::size_t at = dot + 1;
    if (name.compare(at, 7, "sha256.") == 0) at += 7;
    const std::size_t dash = name.find('-', at);
    if (dash == std::string::npos || dash == at || name.find_first_not_of("0123456789", at) != dash) continue;
    const long pid = std::strtol(name.substr(at, dash - at).c_str(), nullptr, 10);
    if (pid > 0 && pid != getpid() && kill(static_cast<pid_t>(pid), 0) != 0 && errno == ESRCH) {
      fs::remove(entry.path(), ec);
    }
  }
}

// The mutex of a cache key in this process.
std::mutex& KeyLock(const std::string& key) {
  static std::mutex guard;
  static std::map<std::string, std::unique_ptr<std::mutex>> locks;
  const std::lock_guard<std::mutex> lock(guard);
  std::unique_ptr<std::mutex>& m = locks[key];
  if (!m) m = std::make_unique<std::mutex>();
  return *m;
}

// The compiler's bounds: $HYBRIDCONT_COMPILE_SECONDS (default 120) and $HYBRIDCONT_COMPILE_MEMORY_MB (its
// address space, default 4096); a value that is not a whole number in range keeps the default.
constexpr const char* kSecondsVariable = "HYBRIDCONT_COMPILE_SECONDS";
constexpr const char* kMegabytesVariable = "HYBRIDCONT_COMPILE_MEMORY_MB";
struct CompileLimits {
  long seconds = 120;
  long megabytes = 4096;
};
CompileLimits Limits() {
  CompileLimits limits;
  const auto read = [](const char* name, long lo, long hi, long* value) {
    const char* text = std::getenv(name);
    if (text == nullptr || *text == '\0') return;
    char* end = nullptr;
    errno = 0;
    const long v = std::strtol(text, &end, 10);
    if (errno == 0 && *end == '\0' && v >= lo && v <= hi) *value = v;
  };
  read(kSecondsVariable, 1, 86400, &limits.seconds);
  read(kMegabytesVariable, 256, 1L << 20, &limits.megabytes);
  return limits;
}

// The entry points of a loaded library, all of them, and its source digest: false (nothing stored) when a
// symbol is missing or the digest is another model's.
bool LoadEntries(void* handle, int slots, const std::string& source_digest, CompiledPrograms* compiled,
                 std::string* why) {
  const auto* digest = static_cast<const char*>(dlsym(handle, kSourceDigestSymbol));
  if (digest == nullptr || source_digest != digest) {
    *why = "it was compiled from another model's code";
    return false;
  }
  compiled->entries.resize(slots);
  compiled->param_jet_entries.resize(slots);
  for (int slot = 0; slot < slots; ++slot) {
    compiled->param_jet_entries[slot] = reinterpret_cast<CompiledParamJetFn>(dlsym(handle, ParamJetEntryName(slot).c_str()));
    for (int kind = 0; kind < kNumScalarKinds; ++kind) {
      compiled->entries[slot][kind] = reinterpret_cast<CompiledProgramFn>(dlsym(handle, EntryName(slot, kind).c_str()));
    }
    // The programs GenerateModelSource emits: four per phase (slot 5 i + 0..3) and the anchor (5 m + 4), each
    // with its parameter-jet entry and at least the double one.
    const bool emitted = (slot < slots - 5 && slot % 5 != 4) || slot == slots - 1;
    if (emitted && (compiled->param_jet_entries[slot] == nullptr || compiled->entries[slot][0] == nullptr)) {
      *why = "it lacks the entry points of program " + std::to_string(slot);
    }
  }
  return why->empty();
}

// The folder holding hybridcont/model.h for the generated code: $HYBRIDCONT_INCLUDE_DIR, the installed
// headers next to the running program (<prefix>/bin/../include: an installed, possibly moved, prefix), the
// source tree this library was built from (a build-tree program), or the configured install location (a
// program of the user's own linked to the installed library).
fs::path HeaderDirectory() {
  std::vector<fs::path> candidates;
  if (const char* d = std::getenv("HYBRIDCONT_INCLUDE_DIR"); d && *d) candidates.push_back(d);
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) candidates.push_back(exe.parent_path().parent_path() / "include");
  candidates.push_back(HYBRIDCONT_SOURCE_INCLUDE_DIR);
  candidates.push_back(HYBRIDCONT_INSTALL_INCLUDE_DIR);
  for (const fs::path& c : candidates) {
    if (fs::exists(c / "hybridcont" / "model.h", ec)) return c;
  }
  return {};
}

std::string Quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

std::string FindCompiler() {
  std::vector<std::string> candidates;
  if (const char* cxx = std::getenv("CXX"); cxx && *cxx) candidates.push_back(cxx);
  candidates.push_back(HYBRIDCONT_CXX_COMPILER);
  candidates.push_back("/usr/bin/c++");
  candidates.push_back("/usr/bin/g++");
  for (const std::string& c : candidates) {
    if (!c.empty() && access(c.c_str(), X_OK) == 0) return c;
  }
  return {};
}

}  // namespace

std::string GenerateModelSource(const ExpressionModelSpec& spec) {
  std::ostringstream s;
  s << "// Generated by hybridcont from the model's parsed expressions; do not edit.\n"
    << "#include \"hybridcont/expression.h\"\n#include \"hybridcont/internal/autodiff_phase.h\"\n"
    << "namespace {\nusing namespace hybridcont;\nusing namespace hybridcont::internal;\n";
  const int m = static_cast<int>(spec.phases.size());
  std::ostringstream entries;
  entries << "extern \"C\" {\n";
  const auto emit = [&](int slot, int n, const ExpressionProgram& program, bool second_order) {
    const std::string id = std::to_string(slot);
    EmitProgram(s, id, program);
    for (const auto& [kind, type] : ScalarTypes(n, second_order)) {
      entries << "void " << EntryName(slot, kind) << "(const void* x, const double* p, void* out) { P" << id << "<"
              << type << ">(static_cast<const " << type << "*>(x), p, static_cast<" << type << "*>(out)); }\n";
    }
    if (n > kMaxPhaseDim) {
      EmitValueJacobianEntry(entries, EntryName(slot, static_cast<int>(ScalarKind::kValueJacobian)), id, n,
                             program.num_outputs());
      if (second_order) {
        EmitValueHessianEntry(entries, EntryName(slot, static_cast<int>(ScalarKind::kValueHessian)), id, n,
                              program.num_outputs());
      }
    }
    EmitParamJetProgram(s, id, program);
    entries << "void " << ParamJetEntryName(slot) << "(const void* x, const void* p, void* out) { Q" << id
            << "<ParamJet>(static_cast<const ParamJet*>(x), static_cast<const ParamJet*>(p), "
            << "static_cast<ParamJet*>(out)); }\n";
  };
  for (int i = 0; i < m; ++i) {
    const ExpressionPhaseSpec& p = spec.phases[i];
    const int n = static_cast<int>(p.state_names.size());
    emit(5 * i + 0, n, p.vector_field, false);
    emit(5 * i + 1, n, p.integrals, true);
    emit(5 * i + 2, n, p.event, false);
    emit(5 * i + 3, n, p.reset, false);
  }
  emit(5 * m + 4, static_cast<int>(spec.phases[0].state_names.size()), spec.anchor, false);
  entries << "}\n";
  s << "}  // namespace\n" << entries.str();
  return s.str();
}

std::shared_ptr<const CompiledPrograms> CompileModel(const ExpressionModelSpec& spec, const ModelFileOptions& options) {
  const auto note = [&](const std::string& why) {
    if (options.log) *options.log << "note: model '" << spec.name << "' runs interpreted (slower): " << why << "\n";
    return nullptr;
  };
  const std::string compiler = FindCompiler();
  if (compiler.empty()) return note("no C++ compiler found (set CXX)");
  const fs::path include = HeaderDirectory();
  if (include.empty()) return note("the hybridcont headers were not found (set HYBRIDCONT_INCLUDE_DIR)");
  const std::string source = GenerateModelSource(spec);
  std::string flags = "-std=c++20 -O3 -DNDEBUG -fPIC -shared -w -I" + Quote(include.string());
  for (const std::string& dir : {std::string(HYBRIDCONT_EIGEN_INCLUDE_DIR)}) {
    if (!dir.empty() && dir != include.string()) flags += " -I" + Quote(dir);
  }
  const std::string source_digest = Sha256Hex(source);
  // The library's identity, in its bytes: the symbol's text, which the library's constant data holds verbatim, is
  // found in the file before it is loaded (a library built from other code is never opened), and read again
  // through the loaded symbol.
  const std::string identity = std::string(kIdentityPrefix) + source_digest;
  const std::string code = source + "extern \"C\" const char " + kSourceDigestSymbol + "[] = \"" + identity + "\";\n";
  const std::string key =
      Sha256Hex(source_digest + "\n" + CompilerIdentity(compiler) + " " + flags + "\n" + HYBRIDCONT_VERSION).substr(0, 32);
  const fs::path cache = CacheDirectory(options);
  if (const std::string why = CheckCacheFolder(cache); !why.empty()) {
    return note("the cache folder is not trusted: " + why);
  }
  const int slots = 5 * static_cast<int>(spec.phases.size()) + 5;
  const CacheEntry entry = EntryFor(cache, key);
  const auto load = [&](const fs::path& library, std::string* why) -> std::shared_ptr<CompiledPrograms> {
    if (!FileContains(library, identity)) {
      *why = "it was compiled from another model's code (its bytes do not name this model's source; not opened)";
      return nullptr;
    }
    void* handle = dlopen(library.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (handle == nullptr) {
      *why = std::string("loading failed: ") + dlerror();
      return nullptr;
    }
    auto compiled = std::make_shared<CompiledPrograms>();
    // Never unloaded: phases of models built from it may outlive this object in a user's program.
    compiled->library = std::shared_ptr<void>(handle, [](void*) {});
    if (!LoadEntries(handle, slots, identity, compiled.get(), why)) return nullptr;
    return compiled;
  };
  // One compile per key in this process: a second thread asking for the same model (two threads of a Dask
  // worker) waits, then finds the entry the first published.
  const std::unique_lock<std::mutex> compiling(KeyLock(key));
  bool absent = false;
  std::string why = VerifyEntry(entry, key, &absent);
  if (why.empty()) {
    if (auto compiled = load(entry.library, &why)) return compiled;
  }
  if (!absent) {
    if (options.log) *options.log << "note: the cached model " << entry.library.string() << " is not used (" << why << "); compiling it again\n";
    RemoveEntry(entry);
  }
  RemoveLeftovers(cache);
  // Compiled under names of this process and this call (two threads of one process, a Dask worker's, may
  // compile the same model at once), loaded from there, then published.
  static std::atomic<long> calls{0};
  const std::string stem = "model-" + key + "." + std::to_string(getpid()) + "-" + std::to_string(calls.fetch_add(1));
  const fs::path src = cache / (stem + ".cc"), tmp = cache / (stem + ".so"), log = cache / (stem + ".log");
  {
    std::ofstream f(src);
    f << code;
    if (!f) return note("cannot write to the cache folder " + cache.string());
  }
  if (options.log) {
    *options.log << "compiling model '" << spec.name << "' (" << (absent ? "first use of this model; " : "")
                 << "cached in " << cache.string() << ")..." << std::flush;
  }
  // The compiler's time and memory are bounded (a huge model could take minutes and gigabytes): past
  // either the model runs interpreted, and the note names the limit and how to raise it.
  const CompileLimits limits = Limits();
  const auto start = std::chrono::steady_clock::now();
  const std::string command = "ulimit -v " + std::to_string(limits.megabytes * 1024) + "; exec timeout -k 5 " +
                              std::to_string(limits.seconds) + " " + Quote(compiler) + " " + flags + " -o " +
                              Quote(tmp.string()) + " " + Quote(src.string()) + " > " + Quote(log.string()) + " 2>&1";
  const int status = RunShell(command);
  const int rc = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::error_code ec;
  fs::remove(src, ec);
  if (rc != 0) {
    if (options.log) *options.log << " failed\n";
    fs::remove(tmp, ec);
    if (rc == 124 || rc == 137) {
      fs::remove(log, ec);
      return note("compiling took more than " + std::to_string(limits.seconds) + " s (the limit; raise it with " +
                  kSecondsVariable + "=SECONDS)");
    }
    std::ifstream in(log);
    const std::string output((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (output.find("memory exhausted") != std::string::npos || output.find("Cannot allocate memory") != std::string::npos ||
        output.find("out of memory") != std::string::npos) {
      return note("compiling needed more than " + std::to_string(limits.megabytes) + " MB (the limit; raise it with " +
                  kMegabytesVariable + "=MB)");
    }
    return note("compiling the generated code failed (compiler output in " + log.string() + ")");
  }
  fs::remove(log, ec);
  if (options.log) {
    char buffer[64];
    std::snprintf(buffer, sizeof buffer, " %.1f s\n", seconds);
    *options.log << buffer;
  }
  why.clear();
  auto compiled = load(tmp, &why);
  if (!compiled) {
    fs::remove(tmp, ec);
    return note("the compiled model cannot be used: " + why);
  }
  if (const std::string published = PublishEntry(tmp, entry, key); !published.empty() && options.log) {
    *options.log << "note: model '" << spec.name << "' is not cached: " << published << "\n";
  }
  return compiled;
}

}  // namespace hybridcont::internal
