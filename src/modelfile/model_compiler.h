// Compiled model files: C++ generated from a model's ExpressionPrograms, compiled once, cached, loaded.
//
// The generated source holds, for every program, one straight-line function template over the scalar type
// whose statements are the program's instructions in order (the same ApplyUnary/ApplyBinary calls the
// interpreter makes, so both compute the same operations and give the same numbers), instantiated as
// extern "C" entry points for the scalar kinds the phase's dimension needs (expression_model.h). Only
// instruction codes, register numbers and numbers (as hexadecimal floating-point literals, exact) are
// written; no text of the model file reaches the compiler.
//
// Cache: model_cache.h (an entry is loaded only when it is the user's own and is what this program compiled
// for this model: a SHA-256 record beside it, checked before the library is opened; anything else is
// deleted and compiled again).
//
// Where no compiler is found, or compiling or loading fails, CompileModel returns null and the model runs
// interpreted; the reason is written to options.log once, with the path of the compiler's output, never
// the compiler's messages themselves.
#ifndef HYBRIDCONT_SRC_MODELFILE_MODEL_COMPILER_H_
#define HYBRIDCONT_SRC_MODELFILE_MODEL_COMPILER_H_

#include <memory>
#include <string>

#include "hybridcont/expression_model.h"
#include "hybridcont/model_file.h"

namespace hybridcont::internal {

// The generated C++ source of a model (deterministic: the same spec gives the same text).
std::string GenerateModelSource(const ExpressionModelSpec& spec);

// Compiled entry points for spec's programs, or null (interpreted; the reason is logged).
std::shared_ptr<const CompiledPrograms> CompileModel(const ExpressionModelSpec& spec, const ModelFileOptions& options);

}  // namespace hybridcont::internal

#endif  // HYBRIDCONT_SRC_MODELFILE_MODEL_COMPILER_H_
