#include "hybridcont/study.h"

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

namespace hybridcont {

HybridModel MakeStudyModel(const std::string& name, const std::vector<NamedValue>& parameters,
                           const std::string& models_directory_text, std::ostream* log, bool compile) {
  const std::filesystem::path models_directory = models_directory_text;
  HybridModel model = [&] {
    if (!IsModelFilePath(name)) {
      // A shipped model file by its name alone (`hybridcont run compass-gait`), where no built-in has it: a
      // plain name (letters, digits, '-', '_'), never a path.
      const std::vector<std::string> builtins = BuiltinModelNames();
      const bool plain = !name.empty() && std::all_of(name.begin(), name.end(), [](char ch) {
        return std::isalnum(static_cast<unsigned char>(ch)) || ch == '-' || ch == '_';
      });
      std::error_code ec;
      if (plain && std::find(builtins.begin(), builtins.end(), name) == builtins.end() && !models_directory.empty() &&
          std::filesystem::is_regular_file(models_directory / (name + ".toml"), ec)) {
        ModelFileOptions options;
        options.log = log;
        options.compile = compile;
        return LoadModelFile(models_directory / (name + ".toml"), options);
      }
      return MakeBuiltinModel(name);
    }
    ModelFileOptions options;
    options.log = log;
    options.compile = compile;
    // A relative path that does not exist here names one of the shipped models: `hybridcont run
    // stiffening-slip.toml` finds <models folder>/stiffening-slip.toml of this installation.
    std::filesystem::path path = name;
    std::error_code ec;
    if (path.is_relative() && !std::filesystem::exists(path, ec)) {
      const std::filesystem::path shipped = models_directory / path.filename();
      if (!models_directory.empty() && std::filesystem::exists(shipped, ec)) path = shipped;
    }
    return LoadModelFile(path, options);
  }();
  std::set<std::string> assigned;
  for (std::size_t i = 0; i < parameters.size(); ++i) {
    const NamedValue& p = parameters[i];
    const std::string text = fmt::format("'{}={:g}'", p.name, p.value);
    if (!assigned.insert(p.name).second) {
      throw StudyOptionError("parameters", static_cast<int>(i), text + ": '" + p.name + "' is given twice");
    }
    try {
      model.SetParameter(p.name, p.value);
    } catch (const ModelInputError&) {
      throw;
    } catch (const std::invalid_argument& e) {
      throw StudyOptionError("parameters", static_cast<int>(i), text + ": " + e.what());
    }
  }
  return model;
}

std::unique_ptr<HybridModel> MakeStudyModelIfKnown(const std::string& model, const std::vector<NamedValue>& parameters,
                                                   const std::string& models_directory) {
  try {
    return std::make_unique<HybridModel>(MakeStudyModel(model, parameters, models_directory));
  } catch (const std::exception&) {
    return nullptr;
  }
}

}  // namespace hybridcont
