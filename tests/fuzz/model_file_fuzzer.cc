// Fuzz target: a model file's text through the reader, and what the reader accepts through the model.
//
// libFuzzer (scripts/fuzz-model-files.sh):  clang++ -fsanitize=fuzzer,address,undefined ... this file
// standalone (no clang needed):             fuzz_driver.cc, compiled with this file (ctest fuzz.*)
//
// Per input: ParseModelText (TOML, every field, every expression); if it accepts the file, the generated
// source of the compiled form (text only, nothing is compiled), BuildExpressionModel interpreted, and every
// phase's vector field, first integrals, event, reset and unfolded vector field with their derivatives at
// the phase's typical state, and the anchor at the first phase's; then what `hybridcont run` evaluates
// before it writes anything: the start point, every set-up value, the family rules and quantities at the
// start, and the drawing of every segment at its phase's typical state. Values may be NaN (a model may be
// singular at its typical state); sizes must be right.
#include "model_file_fuzzer.h"

#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "hybridcont/expression_model.h"
#include "hybridcont/model_file.h"
#include "hybridcont/setup_evaluation.h"
#include "modelfile/model_compiler.h"

namespace hybridcont::fuzz {
namespace {

// Empty if every function of the model gives outputs of the sizes its phase declares.
std::string EvaluateEveryFunction(const HybridModel& model) {
  const int k = model.num_first_integrals();
  for (int i = 0; i < model.num_phases(); ++i) {
    const Phase& p = model.phase(i);
    const int n = p.dim();
    const Vector& x = p.typical_state();
    const std::string at = "phase '" + p.name() + "': ";
    if (x.size() != n) return at + "typical state of size " + std::to_string(x.size());
    Vector f, H, x_next, f_tilde;
    Matrix df, dH, D, A, B;
    std::vector<Matrix> d2H;
    RowVector de;
    p.VectorField(x, &f, &df);
    if (f.size() != n || df.rows() != n || df.cols() != n) return at + "vector field of the wrong size";
    p.FirstIntegrals(x, &H, &dH, &d2H);
    if (H.size() != k || dH.rows() != k || dH.cols() != n || static_cast<int>(d2H.size()) != k) {
      return at + "first integrals of the wrong size";
    }
    for (const Matrix& h : d2H) {
      if (h.rows() != n || h.cols() != n) return at + "Hessian of a first integral of the wrong size";
    }
    p.Event(x, &de);
    if (de.size() != n) return at + "event gradient of the wrong size";
    p.Reset(x, &x_next, &D);
    if (x_next.size() != p.next_dim() || x_next.size() != model.phase(i + 1).dim() || D.rows() != p.next_dim() ||
        D.cols() != n) {
      return at + "reset of the wrong size";
    }
    p.UnfoldedVectorField(x, Vector::Constant(k, 0.1), &f_tilde, &A, &B);
    if (f_tilde.size() != n || A.rows() != n || A.cols() != n || B.rows() != n || B.cols() != k) {
      return at + "unfolded vector field of the wrong size";
    }
  }
  RowVector da;
  model.anchor().Evaluate(model.phase(0).typical_state(), &da);
  if (da.size() != model.phase(0).dim()) return "anchor gradient of the wrong size";
  return {};
}

// What a run evaluates of the set-up before it writes anything (src/study/engine/scenario.cc: DefaultScenario).
void EvaluateSetup(const HybridModel& model) {
  const Vector u = StartPoint(model);
  const RunSpec& run = model.setup().run;
  for (const BoundSpec& b : run.bounds) {
    EvaluateSetupValue(model, b.lower);
    EvaluateSetupValue(model, b.upper);
  }
  for (const auto& [name, value] : run.scales) EvaluateSetupValue(model, value);
  EvaluateSetupValue(model, run.keyframe_value);
  const OrbitPresentation presentation(model);
  presentation.Quantities(u);
  presentation.Family(u);
  for (int segment = 0; segment <= model.num_phases(); ++segment) {
    const Vector& x = model.phase(segment).typical_state();
    presentation.XVelocity(segment, x);
    presentation.DrawingPoints(segment, x, 0.0);
  }
}

// Empty if e names the fuzzed file and a line, as every refusal must.
std::string WithoutFileLine(const ModelInputError& e) {
  const std::string prefix = std::string(kFuzzFileName) + ":" + std::to_string(e.where().line);
  if (e.where().file == kFuzzFileName && e.where().line > 0 && std::string(e.what()).rfind(prefix, 0) == 0) return {};
  return std::string("without file:line: ") + e.what();
}

}  // namespace

FuzzOutcome FuzzModelText(const std::string& text) {
  ExpressionModelSpec spec;
  try {
    spec = ParseModelText(text, kFuzzFileName);
  } catch (const ModelInputError& e) {
    // The contract: the message names the file and a line (`where` is what the CLI prints first).
    if (std::string why = WithoutFileLine(e); !why.empty()) return {FuzzOutcome::Kind::kContractBroken, "refused " + why};
    return {FuzzOutcome::Kind::kRejected, e.what()};
  } catch (const std::invalid_argument& e) {
    return {FuzzOutcome::Kind::kContractBroken, std::string("refused by a plain invalid_argument: ") + e.what()};
  }
  // The compiled form's source: generated from the instructions, whatever the file says.
  if (internal::GenerateModelSource(spec).empty()) return {FuzzOutcome::Kind::kContractBroken, "empty source"};
  try {
    const HybridModel model = BuildExpressionModel(std::move(spec));
    if (std::string why = EvaluateEveryFunction(model); !why.empty()) {
      return {FuzzOutcome::Kind::kContractBroken, "accepted, then " + why};
    }
    try {
      EvaluateSetup(model);
    } catch (const ModelInputError& e) {
      if (std::string why = WithoutFileLine(e); !why.empty()) {
        return {FuzzOutcome::Kind::kContractBroken, "refused at run set-up " + why};
      }
      return {FuzzOutcome::Kind::kRefusedAtSetup, e.what()};
    }
  } catch (const std::invalid_argument& e) {
    return {FuzzOutcome::Kind::kContractBroken, std::string("accepted by the reader, refused by the model: ") + e.what()};
  }
  return {FuzzOutcome::Kind::kParsed, {}};
}

}  // namespace hybridcont::fuzz

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const bool strict = [] {
    const char* s = std::getenv("HYBRIDCONT_FUZZ_STRICT");
    return s != nullptr && std::string(s) == "1";
  }();
  const hybridcont::fuzz::FuzzOutcome o =
      hybridcont::fuzz::FuzzModelText(std::string(reinterpret_cast<const char*>(data), size));
  if (strict && o.kind == hybridcont::fuzz::FuzzOutcome::Kind::kContractBroken) {
    std::fprintf(stderr, "model-file contract broken: %s\n", o.message.c_str());
    std::abort();
  }
  return 0;
}
