// Model files: a hybrid model, its default run and its drawing in one TOML file (format in docs/model-files.md).
//
//   ModelFileOptions options;                       // compile = true: generated code, cached
//   HybridModel slip = LoadModelFile("models/slip.toml", options);
//   Explore(...) / `hybridcont run models/slip.toml`
//
// Why TOML: a flat, typed, line-oriented format with an unambiguous specification that researchers read
// without learning it (no significant indentation, no implicit type guessing as in YAML: `no` stays a
// string), parsed by toml++ (MIT, Debian's libtomlplusplus-dev), which reports the line of every value, so
// each message can name file, line and field.
//
// A model file is untrusted input. Every problem (TOML syntax, a missing, duplicated or unknown field, a
// wrong type, a malformed expression, an unknown symbol, a reset that does not give the next phase's states,
// a parameter default outside its range) throws ModelInputError naming the file, the line and the field;
// nothing is evaluated or compiled before the whole file has been checked. Generated code is emitted from
// the parsed instructions (model_codegen.h), never from the file's text.
#ifndef HYBRIDCONT_MODEL_FILE_H_
#define HYBRIDCONT_MODEL_FILE_H_

#include <filesystem>
#include <iosfwd>
#include <string>

#include "hybridcont/expression_model.h"
#include "hybridcont/model.h"

namespace hybridcont {

// The format version this reader writes into its messages and accepts (`hybridcont = 1`). A file of a
// later version is refused with a message naming both versions.
inline constexpr int kModelFileFormatVersion = 1;

struct ModelFileOptions {
  // Generate C++ for the model's functions, compile it with the system compiler and load it: the model then
  // runs at the speed of a built-in one. Off, or when no compiler is found or compiling fails, the
  // expressions are interpreted (same numbers, slower), which `log` is told once.
  bool compile = true;
  // Where compiled models are kept, by the hash of their generated source ($HYBRIDCONT_CACHE, else
  // $XDG_CACHE_HOME/hybridcont, else ~/.cache/hybridcont, else the system's temporary folder).
  std::filesystem::path cache_dir;
  // Progress and fall-back notes ("compiling model 'slip' (first use, about 10 s)..."); null: silent.
  std::ostream* log = nullptr;
};

// The text of a model file: a regular file of at most 4 MB (a folder, a FIFO or a device is refused before it
// is opened). Throws ModelInputError naming the file.
std::string ReadModelFileText(const std::filesystem::path& path);
// Parses and checks the file into a spec (no compilation). Throws ModelInputError.
ExpressionModelSpec ReadModelFile(const std::filesystem::path& path);
// The same from text (for tests and fuzzing); `file_name` appears in messages.
ExpressionModelSpec ParseModelText(const std::string& text, const std::string& file_name);

// ReadModelFile, then build (compiled if possible). Throws ModelInputError.
HybridModel LoadModelFile(const std::filesystem::path& path, const ModelFileOptions& options = {});
// The same from model text (a model written by a program: the Python package's models from SymPy);
// `file_name` appears in messages. Throws ModelInputError.
HybridModel LoadModelText(const std::string& text, const std::string& file_name, const ModelFileOptions& options = {});

// True when `name_or_path` names a model file rather than a built-in model (it ends in ".toml").
bool IsModelFilePath(const std::string& name_or_path);

}  // namespace hybridcont

#endif  // HYBRIDCONT_MODEL_FILE_H_
