// A shipped model file with one piece of text replaced, written to a fresh folder: tests of how the tool
// answers a user's edit (a start that is not an orbit, a reset that breaks conservation, ...).
#ifndef HYBRIDCONT_TESTS_EDITED_MODEL_H_
#define HYBRIDCONT_TESTS_EDITED_MODEL_H_

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

namespace hybridcont {

// Writes models/<name> with its one occurrence of `from` replaced by `to` to `path`, in a fresh folder;
// false when `from` does not occur.
inline bool WriteEditedModel(const std::string& name, const std::string& from, const std::string& to,
                             const std::filesystem::path& path) {
  std::filesystem::remove_all(path.parent_path());
  std::filesystem::create_directories(path.parent_path());
  std::ifstream in(std::string(HYBRIDCONT_SOURCE_DIR) + "/models/" + name);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (text.find(from) == std::string::npos) return false;
  text.replace(text.find(from), from.size(), to);
  std::ofstream(path) << text;
  return true;
}

}  // namespace hybridcont

#endif  // HYBRIDCONT_TESTS_EDITED_MODEL_H_
