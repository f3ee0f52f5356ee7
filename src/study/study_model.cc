#include "study/study_model.h"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <limits>
#include <set>
#include <stdexcept>

#include "hybridcont/model_file.h"
#include "hybridcont/models.h"
#include "modelfile/model_cache.h"

namespace hybridcont {

void SetStudyParameters(const std::vector<NamedValue>& parameters, HybridModel* model) {
  std::set<std::string> assigned;
  for (std::size_t i = 0; i < parameters.size(); ++i) {
    const NamedValue& p = parameters[i];
    const std::string text = fmt::format("'{}={:g}'", p.name, p.value);
    if (!assigned.insert(p.name).second) {
      throw StudyOptionError("parameters", static_cast<int>(i), text + ": '" + p.name + "' is given twice");
    }
    try {
      model->SetParameter(p.name, p.value);
    } catch (const ModelInputError&) {
      throw;
    } catch (const std::invalid_argument& e) {
      throw StudyOptionError("parameters", static_cast<int>(i), text + ": " + e.what());
    }
  }
}

std::string ToString(StudyModelSource::Kind kind) {
  switch (kind) {
    case StudyModelSource::Kind::kBuiltin: return "builtin";
    case StudyModelSource::Kind::kFile: return "file";
    case StudyModelSource::Kind::kText: return "text";
    case StudyModelSource::Kind::kCaller: return "caller";
    case StudyModelSource::Kind::kName: return "name";
  }
  return "?";
}

bool FromString(const std::string& text, StudyModelSource::Kind* kind) {
  for (const auto k : {StudyModelSource::Kind::kBuiltin, StudyModelSource::Kind::kFile, StudyModelSource::Kind::kText,
                       StudyModelSource::Kind::kCaller, StudyModelSource::Kind::kName}) {
    if (ToString(k) == text) return *kind = k, true;
  }
  return false;
}

namespace {

// Where a study's model is: a built-in model, or the model file to read (`read`: as the name resolves, relative
// where it was given so; `source.path`: absolute).
struct FoundModel {
  StudyModelSource source;
  std::filesystem::path read;
};

FoundModel Find(const std::string& name, const std::string& models_directory_text) {
  const std::filesystem::path models_directory = models_directory_text;
  std::error_code ec;
  std::filesystem::path path;
  if (!IsModelFilePath(name)) {
    // A shipped model file by its name alone (`hybridcont run compass-gait`), where no built-in has it: a
    // plain name (letters, digits, '-', '_'), never a path.
    const std::vector<std::string> builtins = BuiltinModelNames();
    const bool plain = !name.empty() && std::all_of(name.begin(), name.end(), [](char ch) {
      return std::isalnum(static_cast<unsigned char>(ch)) || ch == '-' || ch == '_';
    });
    if (!plain || std::find(builtins.begin(), builtins.end(), name) != builtins.end() || models_directory.empty() ||
        !std::filesystem::is_regular_file(models_directory / (name + ".toml"), ec)) {
      return {{StudyModelSource::Kind::kBuiltin, name, "", "", ""}, {}};
    }
    path = models_directory / (name + ".toml");
  } else {
    // A relative path that does not exist here names one of the shipped models: `hybridcont run
    // stiffening-slip.toml` finds <models folder>/stiffening-slip.toml of this installation.
    path = name;
    if (path.is_relative() && !std::filesystem::exists(path, ec)) {
      const std::filesystem::path shipped = models_directory / path.filename();
      if (!models_directory.empty() && std::filesystem::exists(shipped, ec)) path = shipped;
    }
  }
  const std::filesystem::path absolute = std::filesystem::absolute(path, ec).lexically_normal();
  return {{StudyModelSource::Kind::kFile, name, ec ? path.string() : absolute.string(), "", ""}, path};
}

}  // namespace

StudyModelSource FindStudyModel(const std::string& name, const std::string& models_directory) {
  return Find(name, models_directory).source;
}

HybridModel MakeStudyModel(const std::string& name, const std::vector<NamedValue>& parameters,
                           const std::string& models_directory, std::ostream* log, bool compile) {
  return MakeStudyModel(name, parameters, models_directory, log, compile, nullptr);
}

HybridModel MakeStudyModel(const std::string& name, const std::vector<NamedValue>& parameters,
                           const std::string& models_directory, std::ostream* log, bool compile,
                           StudyModelSource* source) {
  FoundModel found = Find(name, models_directory);
  ModelFileOptions options;
  options.log = log;
  options.compile = compile;
  HybridModel model = [&] {
    if (found.source.kind == StudyModelSource::Kind::kBuiltin) return MakeBuiltinModel(name);
    // The file read once: its digest is that of the very bytes the model is made of.
    const std::string text = ReadModelFileText(found.read);
    found.source.sha256 = internal::Sha256Hex(text);
    return LoadModelText(text, found.read.string(), options);
  }();
  SetStudyParameters(parameters, &model);
  found.source.name = model.name();
  if (source != nullptr) *source = found.source;
  return model;
}

HybridModel ModelOfStudy(const StudyResult& study, const std::string& models_directory, std::ostream* log) {
  const StudyModelSource& source = study.model_source;
  const std::string what = "the model of the study ('" + study.model + "')";
  ModelFileOptions options;
  options.log = log;
  HybridModel model = [&] {
    switch (source.kind) {
      case StudyModelSource::Kind::kBuiltin:
        return MakeBuiltinModel(source.name);
      case StudyModelSource::Kind::kFile: {
        std::error_code ec;
        if (!std::filesystem::is_regular_file(source.path, ec)) {
          throw std::invalid_argument(what + ": its model file " + source.path + " is gone");
        }
        // Read once: the bytes compared with the record are those the model is made of.
        const std::string text = ReadModelFileText(source.path);
        const std::string now = internal::Sha256Hex(text);
        if (now != source.sha256) {
          throw std::invalid_argument(what + ": its model file " + source.path + " has changed since the study (SHA-256 " +
                                      source.sha256.substr(0, 12) + "... then, " + now.substr(0, 12) +
                                      "... now): run the study again, or restore the file");
        }
        return LoadModelText(text, source.path, options);
      }
      case StudyModelSource::Kind::kText:
        if (internal::Sha256Hex(source.text) != source.sha256) {
          throw std::invalid_argument(what + ": its recorded model text does not match its SHA-256 (a damaged folder)");
        }
        return LoadModelText(source.text, "<" + source.name + ">", options);
      case StudyModelSource::Kind::kCaller:
        throw std::invalid_argument(what + " was built by its caller, not from a name, a file or text: pass that "
                                    "model (Python: hc.load(folder, model=...))");
      case StudyModelSource::Kind::kName:
        break;
    }
    return MakeStudyModel(source.name.empty() ? study.model : source.name, {}, models_directory, log);
  }();
  if (model.name() != study.model) {
    throw std::invalid_argument(what + ": rebuilt, it is model '" + model.name() + "'");
  }
  for (const NamedValue& p : study.parameters) {
    try {
      model.SetParameter(p.name, p.value);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(what + ": parameter '" + p.name + "': " + e.what());
    }
  }
  return model;
}

}  // namespace hybridcont
