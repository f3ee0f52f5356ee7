#include "hybridcont/model_file.h"

#include <toml++/toml.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <functional>
#include <map>
#include <optional>
#include <set>
#include <sstream>

#include "model_compiler.h"
#include "model_reader.h"

namespace hybridcont {
namespace {

// A model file is a few kilobytes; a larger one is not a model file (and parsing it would take long).
constexpr std::uintmax_t kMaxModelFileBytes = 4 << 20;

// Longest chain of dotted keys the reader accepts (the format's deepest is 3: `[drawing.flight]` plus a
// key). toml++ builds and destroys dotted keys recursively: `[a.a.a...]` 100000 deep overflows the stack
// before any field is checked, so such a chain is refused before parsing.
constexpr int kMaxKeyDepth = 32;

// Throws ModelInputError at the first chain of more than kMaxKeyDepth dotted keys outside strings and
// comments (a key's parts may be quoted strings: `"a"."b"`).
void CheckKeyDepth(const std::string& text, const std::string& file_name) {
  int line = 1, dots = 0;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (c == '\n') {
      ++line, dots = 0;
    } else if (c == '#') {
      while (i + 1 < text.size() && text[i + 1] != '\n') ++i;
    } else if (c == '"' || c == '\'') {  // a string: skipped, it is one part of a key at most
      const bool multi = text.compare(i, 3, std::string(3, c)) == 0;
      const std::string close = multi ? std::string(3, c) : std::string(1, c);
      std::size_t j = i + close.size();
      while (j < text.size() && text.compare(j, close.size(), close) != 0) {
        if (c == '"' && text[j] == '\\') ++j;  // escapes only in basic strings
        else if (!multi && text[j] == '\n') break;  // unterminated: the TOML parser reports it
        if (j < text.size() && text[j] == '\n') ++line;
        ++j;
      }
      const bool closed = j < text.size() && text.compare(j, close.size(), close) == 0;
      i = closed ? j + close.size() - 1 : j - 1;  // unterminated: resume at the line's end
    } else if (c == '.') {
      if (++dots > kMaxKeyDepth) {
        throw ModelInputError(SourceLocation{file_name, line, ""},
                              "keys nested more than " + std::to_string(kMaxKeyDepth) + " deep (a.b.c...)");
      }
    } else if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == ' ' || c == '\t' ||
                 c == '+')) {
      dots = 0;  // anything else ends a dotted key
    }
  }
}

}  // namespace

ExpressionModelSpec ParseModelText(const std::string& text, const std::string& file_name) {
  CheckKeyDepth(text, file_name);
  toml::table root;
  try {
    root = toml::parse(text, file_name);
  } catch (const toml::parse_error& e) {
    SourceLocation where;
    where.file = file_name;
    where.line = static_cast<int>(e.source().begin.line);
    throw ModelInputError(where, "TOML syntax: " + std::string(e.description()) + " (column " +
                                     std::to_string(e.source().begin.column) + ")");
  }
  return internal::Reader(root, file_name).Read();
}

std::string ReadModelFileText(const std::filesystem::path& path) {
  const auto fail = [&](const std::string& why) { throw ModelInputError(SourceLocation{path.string(), 0, ""}, why); };
  // Checked before opening: a FIFO or a device would block or never end (`z.toml -> /dev/zero`).
  std::error_code ec;
  const std::filesystem::file_status status = std::filesystem::status(path, ec);
  if (ec || !std::filesystem::exists(status)) {
    fail("cannot read the model file (" + (ec ? ec.message() : std::string("no such file")) + ")");
  }
  if (std::filesystem::is_directory(status)) fail("cannot read the model file: it is a folder");
  if (!std::filesystem::is_regular_file(status)) fail("cannot read the model file: not a regular file");
  const std::uintmax_t size = std::filesystem::file_size(path, ec);
  if (!ec && size > kMaxModelFileBytes) {
    fail("the model file has " + std::to_string(size) + " bytes; a model file has at most " +
         std::to_string(kMaxModelFileBytes) + " bytes");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) fail("cannot read the model file (" + std::string(std::strerror(errno)) + ")");
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) fail("cannot read the model file (read error)");
  return text.str();
}

ExpressionModelSpec ReadModelFile(const std::filesystem::path& path) {
  return ParseModelText(ReadModelFileText(path), path.string());
}

namespace {

// The spec built (compiled if asked and possible); errors name `source`.
HybridModel BuildSpec(ExpressionModelSpec spec, const std::string& source, const ModelFileOptions& options) {
  std::shared_ptr<const CompiledPrograms> compiled;
  if (options.compile) compiled = internal::CompileModel(spec.automaton ? ExpressionCatalogueSpec(spec) : spec, options);
  try {
    return BuildExpressionModel(std::move(spec), std::move(compiled));
  } catch (const ModelInputError&) {
    throw;
  } catch (const std::invalid_argument& e) {
    throw ModelInputError(SourceLocation{source, 0, ""}, e.what());
  }
}

}  // namespace

HybridModel LoadModelText(const std::string& text, const std::string& file_name, const ModelFileOptions& options) {
  return BuildSpec(ParseModelText(text, file_name), file_name, options);
}

HybridModel LoadModelFile(const std::filesystem::path& path, const ModelFileOptions& options) {
  return BuildSpec(ReadModelFile(path), path.string(), options);
}

bool IsModelFilePath(const std::string& name_or_path) {
  return name_or_path.size() > 5 && name_or_path.substr(name_or_path.size() - 5) == ".toml";
}

}  // namespace hybridcont
