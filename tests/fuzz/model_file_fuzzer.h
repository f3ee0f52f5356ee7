// The model-file fuzz target, shared by the libFuzzer build and the standalone driver (fuzz_driver.cc).
//
//   FuzzOutcome o = FuzzModelText(text);   // never throws ModelInputError; anything else escaping is a bug
//
// A model file is untrusted input: every bad file must be refused by ParseModelText with a ModelInputError
// that names the file and a line, and every file it accepts must build and evaluate. The outcome says which
// of the two happened (a third: refused only when a run is set up), and names the softer failures that are not crashes but break that contract (a
// refusal without a line, a plain std::invalid_argument, a file accepted by the reader and refused by
// BuildExpressionModel, function outputs of the wrong size). Crashes, hangs, sanitizer reports and other
// exceptions are not outcomes: they escape, so that libFuzzer (or the driver) reports them with the input.
#ifndef HYBRIDCONT_TESTS_FUZZ_MODEL_FILE_FUZZER_H_
#define HYBRIDCONT_TESTS_FUZZ_MODEL_FILE_FUZZER_H_

#include <cstddef>
#include <cstdint>
#include <string>

namespace hybridcont::fuzz {

// The file name ParseModelText is given; a message must start with it.
inline constexpr const char* kFuzzFileName = "fuzz.toml";

struct FuzzOutcome {
  enum class Kind {
    kParsed,        // accepted, built (interpreted) and every phase function evaluated at its typical state
    kRejected,      // ModelInputError naming kFuzzFileName and a line > 0: the contract
    // Accepted and built, refused when a run is set up (setup_evaluation.h: StartPoint, the set-up values,
    // OrbitPresentation) with file:line: the CLI still exits 2 before it writes anything, but the reader
    // should have said so (or the value is not finite at the defaults, which only evaluating can tell).
    kRefusedAtSetup,
    kContractBroken,  // refused or built, but not as the contract says; `message` says how
  };
  Kind kind = Kind::kParsed;
  std::string message;  // the error's text (kRejected) or what broke the contract
};

FuzzOutcome FuzzModelText(const std::string& text);

}  // namespace hybridcont::fuzz

// The libFuzzer entry point (model_file_fuzzer.cc). With HYBRIDCONT_FUZZ_STRICT=1 in the environment a
// broken contract aborts (a libFuzzer finding); otherwise only crashes, hangs and sanitizer reports do.
extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

#endif  // HYBRIDCONT_TESTS_FUZZ_MODEL_FILE_FUZZER_H_
