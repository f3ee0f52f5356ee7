// Standalone fuzz driver for model files: the libFuzzer target (model_file_fuzzer.cc) without clang.
//
//   model_file_fuzz_driver --inputs 100000 --seed 1 --work /tmp/fuzz     # generate, run, count
//   model_file_fuzz_driver --replay /tmp/fuzz/crash-s1-1234.toml         # run saved inputs again
//
// Inputs are random bytes (a few percent) or mutations of the seed corpus (models/*.toml and
// tests/fuzz/corpus/*.toml): byte flips, line deletions, duplications and swaps, splices, replacements
// by tokens of TOML and of the expression language, generated and hostile expressions, huge arrays, deep
// nesting, unicode and NUL bytes, out-of-range numbers. Input i is a function of (seed, i) only, so
// `--seed S --start i --inputs 1` regenerates it, and a run can resume after a crash at i + 1.
//
// Findings, each saved under --work with its input:
//   crash       the process dies (signal); the input being run is always in <work>/current-input.toml,
//               and the signal handler copies it to crash-s<seed>-<i>.toml and names i on stderr;
//   hang        an input that takes longer than --time-limit (1 s); a watchdog saves it while it runs and
//               ends the process after --hard-limit (20 s);
//   exception   anything but std::invalid_argument escaping the target;
//   contract    a refusal without file:line, a plain invalid_argument, a file the reader accepts and the
//               model refuses, outputs of the wrong size (FuzzOutcome::kContractBroken).
// Files the reader accepts and the run set-up refuses (with file:line, before anything is written) are
// counted and their first distinct messages printed as notes, not findings (FuzzOutcome::kRefusedAtSetup).
// Exit code: 0 without findings, 1 with findings, 2 for bad arguments.
#include <fcntl.h>
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "model_file_fuzzer.h"

namespace hybridcont::fuzz {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

// ---------------------------------------------------------------------------------------------------
// Input generation.

// Tokens of TOML and of the expression language, and values that have broken parsers before.
const std::vector<std::string>& Dictionary() {
  static const std::vector<std::string> kTokens = {
      "=", " = ", "[[phases]]", "[phases]", "[[phases]]\nname = \"p\"\n", "ode.", "reset.", "let.", "ode = {}",
      "\"(0, inf)\"", "\"[0, 1]\"", "\"(1, 0)\"", "\"(-inf, inf]\"", "\"(0,\"", "^", "**", "((((", "))))", "(", ")",
      "1e999", "-1e999", "1e-400", "nan", "-nan", "+nan", "inf", "+inf", "-inf", "0x7fffffffffffffff",
      "9223372036854775807", "-9223372036854775808", "99999999999999999999", "1_000", "0o17", "0b101",
      "1979-05-27T07:32:00Z", "07:32:00", "true", "false", "\"\"", "''", "'''", "\"\"\"", "{", "}", "[", "]", "[]",
      "{}", ",", ".", "#", "\\", "\\u0000", "\\uD800", "\\U0010FFFF", "\n", "\r\n", "\r", "\t", "hybridcont = 1",
      "hybridcont = 2", "hybridcont = 0", "hybridcont = -1", "hybridcont = \"1\"", "[start]", "[run]",
      "[run.bounds]", "[run.keyframes]", "[run.scales]", "[[families]]", "[[figures]]", "[drawing]",
      "[drawing.stance]", "[drawing.flight]", "[definitions]", "[parameters]", "[quantities]", "[[symmetries]]",
      "[[start.conditions]]", "integrals = [\"1\", \"2\"]", "energy", "integrals", "anchor", "event", "typical",
      "states", "name", "kind = \"guess\"", "values", "conditions", "terms", "bounds", "scales", "keyframes",
      "component = \"T\"", "max_points = 0", "max_depth = 101", "initial_step = -1", "zoom = true", "points",
      "lines", "masses", "x_velocity", "ground = 1", "mass_radius = 0", "flip", "reverses_time", "description",
      "title", "range", "value", "sin(", "cos(", "atan2(", "atan2(1)", "pow(", "min(", "max(", "sqrt(-1)",
      "log(0)", "exp(1000)", "1/0", "0/0", "0^-1", "(-8)^(1/3)", "x^64", "x^65", "x^-64", "2^1e9", "pi", "X", "T",
      "H", "xi", "xi1", "xi2", "t1", "t2", "t3", "t9999", "x1_l", "x2_y", "x3_l", "x2_dx", "period", "<", "<=", ">",
      ">=", "==", "!=", "&&", "||", "!", "-", "+", "*", "/", "--", "!!", ",,", "()", "(,)", "f()", "_", "__", "a.b",
      "\"a b\"", "α", "ü", "\xE2\x80\xAE", "\xEF\xBB\xBF", "\xC3\x28", "\xF0\x9F\x98\x80", "\xFF\xFE",
      std::string("\0", 1), std::string("a\0b", 3), "\x7f", "\x01", "0.", ".0", ".", "1e", "1e+", "1.2.3", "1ee5",
      "-0", "0", "1", "17", "64", "65", "1e308", "2.2250738585072014e-308", "4.9e-324",
  };
  return kTokens;
}

class Generator {
 public:
  explicit Generator(std::vector<std::string> seeds) : seeds_(std::move(seeds)) {}

  std::string Input(std::uint64_t seed, std::uint64_t index, std::size_t max_len) {
    // SplitMix64 of (seed, index): independent streams per input.
    std::uint64_t z = seed * 0x9E3779B97F4A7C15ull + index + 0x632BE59BD9B4E019ull;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    rng_.seed(z ^ (z >> 31));
    std::string s;
    if (seeds_.empty() || Below(100) < 6) {
      s = RandomBytes();
    } else {
      s = seeds_[Below(seeds_.size())];
      const int n = 1 + static_cast<int>(std::min<std::size_t>(Below(4) == 0 ? Below(12) : Below(3), 12));
      for (int k = 0; k < n; ++k) Mutate(&s);
    }
    if (s.size() > max_len) s.resize(max_len);
    return s;
  }

 private:
  std::size_t Below(std::size_t n) { return n == 0 ? 0 : static_cast<std::size_t>(rng_() % n); }
  bool Chance(int percent) { return static_cast<int>(Below(100)) < percent; }
  const std::string& Token() { return Dictionary()[Below(Dictionary().size())]; }

  std::string RandomBytes() {
    std::string s(Below(Chance(20) ? 4096 : 300), '\0');
    const bool printable = Chance(60);
    for (char& c : s) c = static_cast<char>(printable ? " \n=[]{}\",.#abcxyz_019-+*/^()e"[Below(30)] : Below(256));
    if (Chance(50)) s.insert(0, "hybridcont = 1\n");
    return s;
  }

  // Lines of s (each without its '\n'), and back.
  static std::vector<std::string> Lines(const std::string& s) {
    std::vector<std::string> lines;
    std::size_t start = 0;
    for (;;) {
      const std::size_t end = s.find('\n', start);
      lines.push_back(s.substr(start, end == std::string::npos ? std::string::npos : end - start));
      if (end == std::string::npos) return lines;
      start = end + 1;
    }
  }
  static std::string Join(const std::vector<std::string>& lines) {
    std::string s;
    for (std::size_t i = 0; i < lines.size(); ++i) s += (i ? "\n" : "") + lines[i];
    return s;
  }
  static bool IsWordChar(char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '.'; }

  // Names that appear in s (states, parameters, phases, functions): the operands of generated expressions.
  std::vector<std::string> Names(const std::string& s) {
    std::set<std::string> names;
    for (std::size_t i = 0; i < s.size();) {
      if (std::isalpha(static_cast<unsigned char>(s[i])) || s[i] == '_') {
        std::size_t j = i;
        while (j < s.size() && (std::isalnum(static_cast<unsigned char>(s[j])) || s[j] == '_')) ++j;
        if (j - i <= 12) names.insert(s.substr(i, j - i));
        i = j;
      } else {
        ++i;
      }
    }
    std::vector<std::string> v(names.begin(), names.end());
    if (v.empty()) v.push_back("x");
    return v;
  }

  std::string Number() {
    static const char* kNumbers[] = {"0", "1", "2", "0.5", "-1", "1e-9", "1e300", "1e999", "64", "65", "-64", "0.1",
                                     "3", "1e-320", "1.", ".5", "2e", "1..2"};
    return kNumbers[Below(std::size(kNumbers))];
  }

  // A random expression over the names of the file; mostly well-formed, so that it reaches the model.
  std::string Expression(const std::vector<std::string>& names, int depth) {
    if (depth <= 0 || Chance(30)) return Chance(60) ? names[Below(names.size())] : Number();
    static const char* kBinary[] = {"+", "-", "*", "/", "^", "**", "<", "<=", "==", "!=", "&&", "||", ">", ">="};
    static const char* kFunctions[] = {"sin", "cos", "tan", "asin", "acos", "atan", "sinh", "cosh", "tanh", "exp",
                                       "log", "sqrt", "abs", "atan2", "pow", "min", "max", "foo"};
    switch (Below(6)) {
      case 0: return "(" + Expression(names, depth - 1) + ")";
      case 1: return std::string(Chance(80) ? "-" : "!") + Expression(names, depth - 1);
      case 2: {
        const std::string f = kFunctions[Below(std::size(kFunctions))];
        std::string e = f + "(" + Expression(names, depth - 1);
        const bool two = f == "atan2" || f == "pow" || f == "min" || f == "max";
        if (two != Chance(10)) e += ", " + Expression(names, depth - 1);
        return e + ")";
      }
      default:
        return Expression(names, depth - 1) + " " + kBinary[Below(Chance(80) ? 6 : std::size(kBinary))] + " " +
               Expression(names, depth - 1);
    }
  }

  // Expressions built to stress the parser and the compiler: long chains, deep nesting.
  std::string HostileExpression(const std::vector<std::string>& names) {
    // Now and then beyond any sensible size (50000 terms of a sum overflowed the stack once), with the
    // shortest operand, so that the input stays below --max-len.
    const bool huge = Chance(5);
    const std::size_t n = huge ? 20000 + Below(40000) : 1 + Below(Chance(20) ? 6000 : 400);
    const std::string x = huge ? std::string("1") : names[Below(names.size())];
    std::string e;
    if (huge) {
      for (std::size_t i = 0; i < n; ++i) e += (i ? "+" : "") + x;
      return e;
    }
    switch (Below(7)) {
      case 0: return std::string(n, '(') + x + std::string(n, ')');
      case 1: return std::string(n, '-') + x;
      case 2:
        for (std::size_t i = 0; i < n; ++i) e += (i ? "+" : "") + x;
        return e;
      case 3:
        for (std::size_t i = 0; i < n; ++i) e += (i ? "^" : "") + x;
        return e;
      case 4:
        for (std::size_t i = 0; i < n; ++i) e += "sin(";
        return e + x + std::string(n, ')');
      case 5: return std::string(n, '(') + x;
      default:
        for (std::size_t i = 0; i < n; ++i) e += (i ? "*" : "") + std::string("(") + x + "-1)";
        return e;
    }
  }

  // [begin, end) of the contents of a random "..." string in s, or {npos, npos}.
  std::pair<std::size_t, std::size_t> RandomString(const std::string& s) {
    std::vector<std::size_t> quotes;
    for (std::size_t i = 0; i < s.size(); ++i) {
      if (s[i] == '"') quotes.push_back(i);
    }
    for (int attempt = 0; attempt < 8 && quotes.size() >= 2; ++attempt) {
      const std::size_t q = Below(quotes.size() - 1);
      const std::size_t b = quotes[q] + 1, e = quotes[q + 1];
      if (s.find('\n', b) >= e) return {b, e};
    }
    return {std::string::npos, std::string::npos};
  }

  void Mutate(std::string* s) {
    if (s->empty()) {
      *s = Token();
      return;
    }
    std::vector<std::string> lines;
    switch (Below(17)) {
      case 0:  // flip bits
        for (std::size_t k = 0, n = 1 + Below(4); k < n; ++k) (*s)[Below(s->size())] ^= static_cast<char>(1u << Below(8));
        break;
      case 1: {  // set a byte to a structural one
        static const char kBytes[] = "\0\n\"'[]{}=,.#\\ \t\r-+()^*/<>!&|ex0";
        (*s)[Below(s->size())] = kBytes[Below(sizeof kBytes - 1)];
        break;
      }
      case 2:  // delete a range
        s->erase(Below(s->size()), 1 + Below(Chance(80) ? 8 : 200));
        break;
      case 3:  // delete lines
        lines = Lines(*s);
        lines.erase(lines.begin() + static_cast<long>(Below(lines.size())));
        if (Chance(30) && !lines.empty()) lines.erase(lines.begin() + static_cast<long>(Below(lines.size())));
        *s = Join(lines);
        break;
      case 4: {  // duplicate a line (a duplicate key, a second table header, ...)
        lines = Lines(*s);
        const std::size_t i = Below(lines.size());
        lines.insert(lines.begin() + static_cast<long>(Below(lines.size() + 1)), lines[i]);
        *s = Join(lines);
        break;
      }
      case 5: {  // swap two lines
        lines = Lines(*s);
        std::swap(lines[Below(lines.size())], lines[Below(lines.size())]);
        *s = Join(lines);
        break;
      }
      case 6: {  // replace a word or a punctuation mark by a token
        const std::size_t i = Below(s->size());
        std::size_t b = i, e = i + 1;
        if (IsWordChar((*s)[i])) {
          while (b > 0 && IsWordChar((*s)[b - 1])) --b;
          while (e < s->size() && IsWordChar((*s)[e])) ++e;
        }
        s->replace(b, e - b, Token());
        break;
      }
      case 7:  // insert a token
        s->insert(Below(s->size() + 1), Token());
        break;
      case 8:
      case 9: {  // replace a string's contents by a generated expression
        const auto [b, e] = RandomString(*s);
        if (b == std::string::npos) break;
        s->replace(b, e - b, Expression(Names(*s), 1 + static_cast<int>(Below(5))));
        break;
      }
      case 10: {  // ... or by a hostile one
        const auto [b, e] = RandomString(*s);
        if (b == std::string::npos) break;
        s->replace(b, e - b, HostileExpression(Names(*s)));
        break;
      }
      case 11: {  // a huge array after some '= ['
        const std::size_t at = s->find("= [", Below(s->size()));
        if (at == std::string::npos) break;
        std::string items;
        const std::size_t n = Below(Chance(50) ? 40 : 5000);
        const bool strings = Chance(50);
        for (std::size_t k = 0; k < n; ++k) items += strings ? "\"a" + std::to_string(k) + "\", " : "0.5, ";
        s->insert(at + 3, items);
        break;
      }
      case 12: {  // deep TOML nesting
        const std::size_t n = 1 + Below(Chance(50) ? 50 : 3000);
        std::string v;
        if (Chance(50)) v = std::string(n, '[') + "1" + std::string(n, ']');
        else for (std::size_t k = 0; k < n; ++k) v += "{a=";
        if (v[0] == '{') v += "1" + std::string(n, '}');
        s->insert(LineStart(*s), "deep = " + v + "\n");
        break;
      }
      case 13: {  // unicode, NUL and control bytes inside a string or a name
        static const char* kUnicode[] = {"α", "ü", "\xE2\x80\xAE", "\xEF\xBB\xBF", "\xC3\x28", "\xF0\x9F\x98\x80",
                                         "\xFF", "\x01", "\x7F", "\xE2\x88\x92" /* minus sign */};
        const std::string u = Chance(20) ? std::string("\0", 1) : std::string(kUnicode[Below(std::size(kUnicode))]);
        const auto [b, e] = RandomString(*s);
        s->insert(b == std::string::npos ? Below(s->size() + 1) : b + Below(e - b + 1), u);
        break;
      }
      case 14: {  // replace a number by an extreme one
        std::vector<std::size_t> starts;
        for (std::size_t i = 0; i < s->size(); ++i) {
          if (std::isdigit(static_cast<unsigned char>((*s)[i])) && (i == 0 || !IsWordChar((*s)[i - 1]))) starts.push_back(i);
        }
        if (starts.empty()) break;
        const std::size_t b = starts[Below(starts.size())];
        std::size_t e = b;
        while (e < s->size() && (IsWordChar((*s)[e]) || (*s)[e] == '-' || (*s)[e] == '+')) ++e;
        static const char* kExtreme[] = {"1e999", "nan", "inf", "-inf", "1e-320", "0", "-0.0", "1e308", "17",
                                         "9223372036854775807", "99999999999999999999", "1_0", "0x10", "-1", "2"};
        s->replace(b, e - b, kExtreme[Below(std::size(kExtreme))]);
        break;
      }
      case 15: {  // duplicate or drop a whole table (a third phase, a phase fewer, a duplicated header)
        std::vector<std::size_t> headers;
        for (std::size_t i = 0; i < s->size(); ++i) {
          if ((*s)[i] == '[' && (i == 0 || (*s)[i - 1] == '\n')) headers.push_back(i);
        }
        if (headers.empty()) break;
        const std::size_t k = Below(headers.size());
        const std::size_t b = headers[k], e = k + 1 < headers.size() ? headers[k + 1] : s->size();
        const std::string block = s->substr(b, e - b);
        if (Chance(50)) s->erase(b, e - b);
        else s->insert(Chance(50) ? e : s->size(), (s->back() == '\n' ? "" : "\n") + block);
        break;
      }
      default: {  // splice lines of another seed
        const std::vector<std::string> other = Lines(seeds_[Below(seeds_.size())]);
        lines = Lines(*s);
        const std::size_t from = Below(other.size()), count = 1 + Below(6);
        const std::size_t at = Below(lines.size() + 1);
        lines.insert(lines.begin() + static_cast<long>(at), other.begin() + static_cast<long>(from),
                     other.begin() + static_cast<long>(std::min(other.size(), from + count)));
        *s = Join(lines);
        break;
      }
    }
  }

  std::size_t LineStart(const std::string& s) {
    const std::size_t i = Below(s.size() + 1);
    const std::size_t nl = i == 0 ? std::string::npos : s.rfind('\n', i - 1);
    return nl == std::string::npos ? 0 : nl + 1;
  }

  std::vector<std::string> seeds_;
  std::mt19937_64 rng_;
};

// ---------------------------------------------------------------------------------------------------
// Running inputs: crash attribution, watchdog, counts.

// What the signal handler needs, set before each input (async-signal-safe access only).
char g_current_path[4096];
char g_crash_path[4096];
char g_crash_message[3 * 4096 + 64];
const char* volatile g_input_data = nullptr;
volatile std::size_t g_input_size = 0;

extern "C" void OnFatalSignal(int sig) {
  const char* name = sig == SIGSEGV ? "SIGSEGV" : sig == SIGABRT ? "SIGABRT" : sig == SIGBUS ? "SIGBUS"
                     : sig == SIGFPE ? "SIGFPE" : sig == SIGILL ? "SIGILL" : "signal";
  const int fd = open(g_crash_path, O_WRONLY | O_CREAT | O_TRUNC, 0644);
  if (fd >= 0) {
    std::size_t done = 0;
    while (done < g_input_size) {
      const ssize_t w = write(fd, g_input_data + done, g_input_size - done);
      if (w <= 0) break;
      done += static_cast<std::size_t>(w);
    }
    close(fd);
  }
  const char* prefix = "\nmodel_file_fuzz_driver: CRASH (";
  ssize_t ignored = write(2, prefix, std::strlen(prefix));
  ignored = write(2, name, std::strlen(name));
  ignored = write(2, g_crash_message, std::strlen(g_crash_message));
  (void)ignored;
  signal(sig, SIG_DFL);
  raise(sig);
}

void InstallCrashHandlers() {
  // The handler runs on its own stack, so that a stack overflow is reported too.
  static std::vector<char> stack(1 << 16);
  stack_t ss{};
  ss.ss_sp = stack.data();
  ss.ss_size = stack.size();
  sigaltstack(&ss, nullptr);
  struct sigaction sa {};
  sa.sa_handler = OnFatalSignal;
  sa.sa_flags = SA_ONSTACK;
  sigemptyset(&sa.sa_mask);
  for (int sig : {SIGSEGV, SIGABRT, SIGBUS, SIGFPE, SIGILL}) sigaction(sig, &sa, nullptr);
}

bool WriteFile(const fs::path& path, const std::string& data) {
  std::ofstream f(path, std::ios::binary | std::ios::trunc);
  f.write(data.data(), static_cast<std::streamsize>(data.size()));
  return static_cast<bool>(f);
}

struct Options {
  std::uint64_t inputs = 3000;
  std::uint64_t seed = 1;
  std::uint64_t start = 0;
  std::vector<fs::path> corpus;
  fs::path work = "model-file-fuzz";
  double time_limit = 1.0;
  double hard_limit = 20.0;
  std::size_t max_len = 1 << 18;
  std::vector<fs::path> replay;
  bool verbose = false;
};

class Runner {
 public:
  explicit Runner(const Options& options) : options_(options) {
    std::snprintf(g_current_path, sizeof g_current_path, "%s", (options.work / "current-input.toml").c_str());
    watchdog_ = std::thread([this] { Watch(); });
  }
  ~Runner() {
    stop_ = true;
    watchdog_.join();
  }

  // Runs one input; `label` names it in messages and saved files ("s1-1234", or a replayed file's name).
  // Returns what happened, in one line.
  std::string Run(const std::string& input, const std::string& label) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      current_ = input;
      label_ = label;
      slow_saved_ = false;
    }
    WriteFile(g_current_path, input);
    std::snprintf(g_crash_path, sizeof g_crash_path, "%s", (options_.work / ("crash-" + label + ".toml")).c_str());
    std::snprintf(g_crash_message, sizeof g_crash_message, ") at input %s; input saved to %s and %s\n", label.c_str(),
                  g_crash_path, g_current_path);
    g_input_size = 0;
    g_input_data = current_.data();
    g_input_size = current_.size();
    ++tried_;
    const Clock::time_point t0 = Clock::now();
    started_ns_ = Nanoseconds(t0);
    FuzzOutcome outcome;
    std::string escaped;
    try {
      outcome = FuzzModelText(input);
    } catch (const std::exception& e) {
      escaped = std::string("escaped: ") + e.what();
    } catch (...) {
      escaped = "escaped: an exception not derived from std::exception";
    }
    started_ns_ = 0;
    const double seconds = std::chrono::duration<double>(Clock::now() - t0).count();
    slowest_ = std::max(slowest_, seconds);
    if (seconds > options_.time_limit) {
      Finding("hang", label, input, "took " + std::to_string(seconds) + " s (limit " +
                                        std::to_string(options_.time_limit) + " s)");
    }
    if (!escaped.empty()) {
      Finding("exception", label, input, escaped);
      return escaped;
    }
    switch (outcome.kind) {
      case FuzzOutcome::Kind::kParsed: ++parsed_; break;
      case FuzzOutcome::Kind::kRejected: {
        ++rejected_;
        // "fuzz.toml:12: phases.stance.ode.l: ..." -> the field's first two parts, for the coverage table.
        const std::string& m = outcome.message;
        const std::size_t a = m.find(": ");
        std::string field = a == std::string::npos ? m : m.substr(a + 2, m.find(": ", a + 2) - a - 2);
        if (field.rfind("TOML syntax", 0) == 0) field = "(TOML syntax)";
        field = field.substr(0, field.find_first_of("[(", 1));
        if (std::count(field.begin(), field.end(), '.') > 1) field = field.substr(0, field.find('.', field.find('.') + 1));
        ++rejected_by_field_[field];
        break;
      }
      case FuzzOutcome::Kind::kRefusedAtSetup:
        ++refused_at_setup_;
        if (setup_messages_.insert(outcome.message.substr(outcome.message.find(": ") + 2, 60)).second &&
            setup_messages_.size() <= 20) {
          std::fprintf(stderr, "NOTE refused only at run set-up, input %s: %s\n", label.c_str(),
                       outcome.message.substr(0, 300).c_str());
        }
        break;
      case FuzzOutcome::Kind::kContractBroken: Finding("contract", label, input, outcome.message); break;
    }
    return outcome.kind == FuzzOutcome::Kind::kParsed ? "parsed OK" : outcome.message;
  }

  int Report(double seconds) const {
    std::printf("model-file fuzzing: %llu inputs tried in %.1f s (slowest %.3f s)\n",
                static_cast<unsigned long long>(tried_), seconds, slowest_);
    std::printf("  parsed OK (built, every function evaluated): %llu\n", static_cast<unsigned long long>(parsed_));
    std::printf("  rejected with ModelInputError (file:line):   %llu\n", static_cast<unsigned long long>(rejected_));
    std::printf("  accepted, refused at run set-up (file:line): %llu\n",
                static_cast<unsigned long long>(refused_at_setup_));
    std::size_t total = 0;
    for (const auto& [kind, n] : findings_) total += n;
    std::printf("  findings: %zu", total);
    for (const auto& [kind, n] : findings_) std::printf(" (%s: %zu)", kind.c_str(), n);
    std::printf("%s\n", total ? "" : " (no crash, hang > time limit, escaped exception or broken contract)");
    std::vector<std::pair<std::uint64_t, std::string>> fields;
    for (const auto& [f, n] : rejected_by_field_) fields.push_back({n, f});
    std::sort(fields.rbegin(), fields.rend());
    std::printf("  rejections by field (top 25):");
    for (std::size_t i = 0; i < std::min<std::size_t>(25, fields.size()); ++i) {
      std::printf("%s %s %llu", i ? "," : "", fields[i].second.c_str(), static_cast<unsigned long long>(fields[i].first));
    }
    std::printf("\n");
    return total == 0 ? 0 : 1;
  }

 private:
  void Finding(const std::string& kind, const std::string& label, const std::string& input, const std::string& what) {
    const std::size_t n = ++findings_[kind];
    // Distinct messages (numbers, quoted text and columns vary with the input) are reported; the first
    // 20 inputs of each kind are saved.
    const fs::path path = options_.work / (kind + "-" + label + ".toml");
    if (n <= 20) WriteFile(path, input);
    std::string key = kind + ": " + what.substr(0, what.find(" at column"));
    if (messages_.insert(key.substr(0, 120)).second && messages_.size() <= 60) {
      std::fprintf(stderr, "FINDING %s at input %s%s: %s\n", kind.c_str(), label.c_str(),
                   n <= 20 ? (" (saved " + path.string() + ")").c_str() : "", what.substr(0, 400).c_str());
    }
  }

  static long long Nanoseconds(Clock::time_point t) {
    return std::chrono::duration_cast<std::chrono::nanoseconds>(t.time_since_epoch()).count();
  }

  // Saves an input that runs longer than the time limit, and ends the process after the hard limit.
  void Watch() {
    while (!stop_) {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
      const long long t0 = started_ns_;
      if (t0 == 0) continue;
      const double seconds = (Nanoseconds(Clock::now()) - t0) * 1e-9;
      if (seconds <= options_.time_limit) continue;
      std::lock_guard<std::mutex> lock(mutex_);
      if (started_ns_ != t0) continue;  // finished meanwhile
      if (!slow_saved_) {
        slow_saved_ = true;
        const fs::path path = options_.work / ("hang-" + label_ + ".toml");
        WriteFile(path, current_);
        std::fprintf(stderr, "model_file_fuzz_driver: input %s still running after %.1f s; saved to %s\n",
                     label_.c_str(), seconds, path.c_str());
      }
      if (seconds > options_.hard_limit) {
        std::fprintf(stderr, "model_file_fuzz_driver: HANG at input %s: ended after %.0f s (input in hang-%s.toml)\n",
                     label_.c_str(), seconds, label_.c_str());
        std::fflush(stderr);
        std::fflush(stdout);
        _exit(3);
      }
    }
  }

  const Options& options_;
  std::thread watchdog_;
  std::atomic<bool> stop_{false};
  std::atomic<long long> started_ns_{0};
  std::mutex mutex_;
  std::string current_, label_;
  bool slow_saved_ = false;
  std::uint64_t tried_ = 0, parsed_ = 0, rejected_ = 0, refused_at_setup_ = 0;
  double slowest_ = 0.0;
  std::map<std::string, std::size_t> findings_;
  std::map<std::string, std::uint64_t> rejected_by_field_;
  std::set<std::string> messages_, setup_messages_;
};

int Usage(const char* why) {
  std::fprintf(stderr,
               "error: %s\nusage: model_file_fuzz_driver [--inputs N] [--seed S] [--start I] [--corpus DIR|FILE]...\n"
               "         [--work DIR] [--time-limit SEC] [--hard-limit SEC] [--max-len BYTES] [--verbose]\n"
               "       model_file_fuzz_driver --replay FILE... [--work DIR]\n",
               why);
  return 2;
}

int Main(int argc, char** argv) {
  Options o;
  bool replay = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const auto value = [&]() -> std::string {
      if (i + 1 >= argc) throw std::invalid_argument(a + " needs a value");
      return argv[++i];
    };
    try {
      if (a == "--inputs") o.inputs = std::stoull(value());
      else if (a == "--seed") o.seed = std::stoull(value());
      else if (a == "--start") o.start = std::stoull(value());
      else if (a == "--corpus") o.corpus.push_back(value());
      else if (a == "--work") o.work = value();
      else if (a == "--time-limit") o.time_limit = std::stod(value());
      else if (a == "--hard-limit") o.hard_limit = std::stod(value());
      else if (a == "--max-len") o.max_len = std::stoull(value());
      else if (a == "--verbose") o.verbose = true;
      else if (a == "--replay") replay = true;
      else if (replay && a.rfind("--", 0) != 0) o.replay.push_back(a);
      else return Usage(("unknown argument '" + a + "'").c_str());
    } catch (const std::exception& e) {
      return Usage(e.what());
    }
  }
  if (replay && o.replay.empty()) return Usage("--replay needs files");
  std::error_code ec;
  fs::create_directories(o.work, ec);
  if (!fs::is_directory(o.work)) return Usage(("cannot create --work " + o.work.string()).c_str());
  InstallCrashHandlers();

  std::vector<std::string> seeds;
  if (!replay) {
    if (o.corpus.empty()) {
      o.corpus = {fs::path(HYBRIDCONT_SOURCE_DIR) / "models", fs::path(HYBRIDCONT_SOURCE_DIR) / "tests/fuzz/corpus"};
    }
    std::vector<fs::path> files;
    for (const fs::path& c : o.corpus) {
      if (fs::is_directory(c)) {
        for (const auto& entry : fs::directory_iterator(c)) {
          if (entry.path().extension() == ".toml") files.push_back(entry.path());
        }
      } else if (fs::exists(c)) {
        files.push_back(c);
      }
    }
    std::sort(files.begin(), files.end());  // the same inputs on every file system
    for (const fs::path& f : files) {
      std::ifstream in(f, std::ios::binary);
      std::ostringstream text;
      text << in.rdbuf();
      seeds.push_back(text.str());
    }
    std::printf("model-file fuzzing: seed %llu, inputs %llu..%llu, %zu corpus files, per-input limit %.1f s\n",
                static_cast<unsigned long long>(o.seed), static_cast<unsigned long long>(o.start),
                static_cast<unsigned long long>(o.start + o.inputs - 1), seeds.size(), o.time_limit);
  }
  std::fflush(stdout);

  const Clock::time_point t0 = Clock::now();
  Runner runner(o);
  if (replay) {
    for (const fs::path& f : o.replay) {
      std::ifstream in(f, std::ios::binary);
      std::ostringstream text;
      text << in.rdbuf();
      const std::string input = text.str();
      std::printf("%s: %s\n", f.c_str(), runner.Run(input, f.stem().string()).c_str());
    }
  } else {
    Generator generator(seeds);
    for (std::uint64_t i = o.start; i < o.start + o.inputs; ++i) {
      const std::string label = "s" + std::to_string(o.seed) + "-" + std::to_string(i);
      const std::string what = runner.Run(generator.Input(o.seed, i, o.max_len), label);
      if (o.verbose) std::printf("%s: %s\n", label.c_str(), what.substr(0, 300).c_str());
    }
  }
  return runner.Report(std::chrono::duration<double>(Clock::now() - t0).count());
}

}  // namespace
}  // namespace hybridcont::fuzz

int main(int argc, char** argv) { return hybridcont::fuzz::Main(argc, argv); }
