#include "study/io/resume_store.h"

#include <cerrno>
#include <cmath>
#include <fstream>
#include <limits>
#include <stdexcept>

#include "hybridcont/version.h"
#include "modelfile/model_cache.h"
#include "study/io/json_fields.h"

namespace hybridcont::study {

namespace fs = std::filesystem;

namespace {

// 2: each stored branch carries the digest of its content with the study's options (a branch changed or
// planted since it was stored is refused, never resumed from).
constexpr int kFormat = 2;

template <typename Enum>
Enum EnumFrom(const nlohmann::json& j, const char* key, const std::string& where, Enum last) {
  const int v = JsonInt(j, key, where);
  if (v < 0 || v > static_cast<int>(last)) throw std::invalid_argument(where + "." + key + ": out of range");
  return static_cast<Enum>(v);
}

nlohmann::json SpecialPointJson(const SpecialPoint& p) {
  return {{"id", p.id},
          {"type", static_cast<int>(p.type)},
          {"status", static_cast<int>(p.status)},
          {"branch_id", p.branch_id},
          {"index", p.index},
          {"arclength", NumberJson(p.arclength)},
          {"component", p.component},
          {"component_index", p.component_index},
          {"u", VectorJson(p.u)},
          {"tangent", VectorJson(p.tangent)},
          {"tangent_before", VectorJson(p.tangent_before)},
          {"tangent_after", VectorJson(p.tangent_after)},
          {"test_value", NumberJson(p.test_value)},
          {"interval_lo", NumberJson(p.interval_lo)},
          {"interval_hi", NumberJson(p.interval_hi)},
          {"interval_width", VectorJson(p.interval_width)},
          {"residual_norm", NumberJson(p.residual_norm)},
          {"iterations", p.iterations},
          {"duplicate_of", p.duplicate_of},
          {"message", p.message}};
}

SpecialPoint SpecialPointFrom(const nlohmann::json& j, const std::string& where) {
  SpecialPoint p;
  p.id = JsonInt(j, "id", where);
  p.type = EnumFrom(j, "type", where, kLastSpecialPointType);
  p.status = EnumFrom(j, "status", where, LocationStatus::kBracketed);
  p.branch_id = JsonInt(j, "branch_id", where);
  p.index = JsonInt(j, "index", where);
  p.arclength = JsonNumber(j, "arclength", where);
  p.component = JsonText(j, "component", where);
  p.component_index = JsonInt(j, "component_index", where);
  p.u = VectorFrom(JsonField(j, "u", where), where + ".u");
  p.tangent = VectorFrom(JsonField(j, "tangent", where), where + ".tangent");
  p.tangent_before = VectorFrom(JsonField(j, "tangent_before", where), where + ".tangent_before");
  p.tangent_after = VectorFrom(JsonField(j, "tangent_after", where), where + ".tangent_after");
  p.test_value = JsonNumber(j, "test_value", where);
  p.interval_lo = JsonNumber(j, "interval_lo", where);
  p.interval_hi = JsonNumber(j, "interval_hi", where);
  p.interval_width = VectorFrom(JsonField(j, "interval_width", where), where + ".interval_width");
  p.residual_norm = JsonNumber(j, "residual_norm", where);
  p.iterations = JsonInt(j, "iterations", where);
  p.duplicate_of = JsonInt(j, "duplicate_of", where);
  p.message = JsonText(j, "message", where);
  return p;
}

// Writes `text` to `file` whole: a temp file renamed over it.
bool WriteWhole(const fs::path& file, const std::string& text) {
  const fs::path tmp = file.string() + ".tmp";
  {
    std::ofstream f(tmp);
    f << text;
    f.close();
    if (f.fail()) return false;
  }
  std::error_code ec;
  fs::rename(tmp, file, ec);
  if (ec) fs::remove(tmp, ec);
  return !ec;
}

// A stored file read as JSON; a name there that is no regular file (a FIFO would block the open) is refused.
nlohmann::json ReadJson(const fs::path& file) {
  std::error_code ec;
  const fs::file_status status = fs::status(file, ec);
  if (fs::exists(status) && !fs::is_regular_file(status)) {
    throw std::invalid_argument(file.string() + ": not a regular file (a resume store holds regular files only)");
  }
  std::ifstream f(file);
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(f, nullptr, /*allow_exceptions=*/false);
  } catch (const nlohmann::json::exception& e) {  // a number out of range is an exception even so
    throw std::invalid_argument(file.string() + ": not a JSON document (" + e.what() + ")");
  }
  if (j.is_discarded()) throw std::invalid_argument(file.string() + ": not a JSON document");
  return j;
}

}  // namespace

nlohmann::json BranchToJson(const Branch& b) {
  nlohmann::json points = nlohmann::json::array();
  for (const ContinuationPoint& p : b.points) {
    points.push_back({{"u", VectorJson(p.u)},
                      {"tangent", VectorJson(p.tangent)},
                      {"arclength", NumberJson(p.arclength)},
                      {"step", NumberJson(p.step)},
                      {"newton_iterations", p.newton_iterations},
                      {"contraction", NumberJson(p.contraction)},
                      {"sb_test", NumberJson(p.sb_test)},
                      {"test_values", VectorJson(p.test_values)},
                      {"evaluated_at", VectorJson(p.evaluated_at)}});
  }
  nlohmann::json special = nlohmann::json::array();
  for (const SpecialPoint& p : b.special_points) special.push_back(SpecialPointJson(p));
  return {{"id", b.id},
          {"direction", b.direction},
          {"parent_special_point", b.parent_special_point},
          {"depth", b.depth},
          {"points", points},
          {"special_points", special},
          {"termination", static_cast<int>(b.termination)},
          {"message", b.message},
          {"newton_iterations", b.newton_iterations},
          {"rejected_steps", b.rejected_steps},
          {"located_iterations", b.located_iterations},
          {"image_of", b.image_of},
          {"symmetry", b.symmetry},
          {"reflected_from", b.reflected_from}};
}

Branch BranchFromJson(const nlohmann::json& j, const std::string& where) {
  Branch b;
  b.id = JsonInt(j, "id", where);
  b.direction = JsonInt(j, "direction", where);
  b.parent_special_point = JsonInt(j, "parent_special_point", where);
  b.depth = JsonInt(j, "depth", where);
  const nlohmann::json& points = JsonField(j, "points", where);
  if (!points.is_array()) throw std::invalid_argument(where + ".points: expected a list");
  for (std::size_t i = 0; i < points.size(); ++i) {
    const std::string at = where + ".points[" + std::to_string(i) + "]";
    const nlohmann::json& q = points[i];
    ContinuationPoint p;
    p.u = VectorFrom(JsonField(q, "u", at), at + ".u");
    p.tangent = VectorFrom(JsonField(q, "tangent", at), at + ".tangent");
    p.arclength = JsonNumber(q, "arclength", at);
    p.step = JsonNumber(q, "step", at);
    p.newton_iterations = JsonInt(q, "newton_iterations", at);
    p.contraction = JsonNumber(q, "contraction", at);
    p.sb_test = JsonNumber(q, "sb_test", at);
    p.test_values = VectorFrom(JsonField(q, "test_values", at), at + ".test_values");
    if (q.contains("evaluated_at")) p.evaluated_at = VectorFrom(q["evaluated_at"], at + ".evaluated_at");
    if (p.evaluated_at.size() != 0 && p.evaluated_at.size() != p.u.size()) {
      throw std::invalid_argument(at + ".evaluated_at: must be empty or of u's size");
    }
    if (p.u.size() == 0 || p.tangent.size() != p.u.size() ||
        (!b.points.empty() && p.u.size() != b.points.front().u.size())) {
      throw std::invalid_argument(at + ": u and tangent must have the branch's one size");
    }
    b.points.push_back(std::move(p));
  }
  const nlohmann::json& special = JsonField(j, "special_points", where);
  if (!special.is_array()) throw std::invalid_argument(where + ".special_points: expected a list");
  const Eigen::Index n = b.points.empty() ? 0 : b.points.front().u.size();
  for (std::size_t i = 0; i < special.size(); ++i) {
    const std::string at = where + ".special_points[" + std::to_string(i) + "]";
    SpecialPoint p = SpecialPointFrom(special[i], at);
    for (const Vector* v : {&p.u, &p.tangent, &p.tangent_before, &p.tangent_after, &p.interval_width}) {
      if (v->size() != 0 && v->size() != n) throw std::invalid_argument(at + ": a vector of another size than u");
    }
    if (p.index < -1 || p.index >= static_cast<int>(b.points.size())) {
      throw std::invalid_argument(at + ".index: beyond the branch's points");
    }
    b.special_points.push_back(std::move(p));
  }
  b.termination = EnumFrom(j, "termination", where, kLastTerminationReason);
  b.message = JsonText(j, "message", where);
  b.newton_iterations = JsonInt(j, "newton_iterations", where);
  b.rejected_steps = JsonInt(j, "rejected_steps", where);
  b.located_iterations = JsonInt(j, "located_iterations", where);
  b.image_of = JsonInt(j, "image_of", where);
  b.symmetry = JsonText(j, "symmetry", where);
  b.reflected_from = JsonInt(j, "reflected_from", where);
  if (b.reflected_from < -1 || b.reflected_from >= static_cast<int>(b.points.size())) {
    throw std::invalid_argument(where + ".reflected_from: beyond the branch's points");
  }
  if (b.points.empty()) throw std::invalid_argument(where + ".points: empty (a stored branch has its points)");
  if (b.direction != 1 && b.direction != -1) throw std::invalid_argument(where + ".direction: must be 1 or -1");
  return b;
}

namespace {
// The digest a stored branch carries: of the study's options and its content (JSON numbers round-trip, so the
// content read back serializes to the same text). A whole branch under another id is no damage: the exploration
// takes a stored branch only where it is the one it is about to trace.
std::string BranchDigest(const nlohmann::json& options, const nlohmann::json& branch) {
  return internal::Sha256Hex(options.dump() + "\n" + branch.dump());
}
}  // namespace

ResumeStore::ResumeStore(const fs::path& dir, const nlohmann::json& options, bool resume)
    : dir_(dir / ".resume"), options_(options) {
  std::error_code ec;
  const fs::path study = dir_ / "study.json";
  if (resume && fs::exists(study, ec)) {
    const nlohmann::json saved = ReadJson(study);
    const auto field = [&](const char* key) { return saved.is_object() && saved.contains(key) ? saved[key] : nlohmann::json(); };
    const bool same_format = field("format") == nlohmann::json(kFormat) && field("version") == nlohmann::json(HYBRIDCONT_VERSION);
    if (same_format) {
      const nlohmann::json& old = saved.contains("options") ? saved["options"] : nlohmann::json();
      if (old != options) {
        std::string differs = "its options";
        if (old.is_object()) {
          for (const auto& [key, value] : options.items()) {
            if (!old.contains(key) || old[key] != value) {
              differs = "'" + key + "' (" + (old.contains(key) ? old[key].dump() : "unset") + " there, " +
                        value.dump() + " now)";
              break;
            }
          }
        }
        throw std::invalid_argument("'" + dir.string() + "' holds a study with other options: " + differs +
                                    "; resume it with the options it was run with, or run afresh without resume");
      }
      for (const auto& entry : fs::directory_iterator(dir_, ec)) {
        const std::string name = entry.path().filename().string();
        if (name.rfind("branch-", 0) != 0 || entry.path().extension() != ".json") continue;
        const nlohmann::json j = ReadJson(entry.path());
        if (!j.is_object() || !j.contains("format") || j["format"] != nlohmann::json(kFormat) || !j.contains("branch")) {
          throw std::invalid_argument(entry.path().string() + ": not a stored branch of format " + std::to_string(kFormat));
        }
        int id = -1;
        try {
          id = std::stoi(name.substr(7));
        } catch (const std::exception&) {
          throw std::invalid_argument(entry.path().string() + ": the file name gives no branch id");
        }
        if (id < 0) throw std::invalid_argument(entry.path().string() + ": the file name gives no branch id");
        // Its form first (a damaged file is named with its field), then its content against its digest.
        Branch b = BranchFromJson(j["branch"], entry.path().string() + ": branch");
        if (!j.contains("sha256") || !j["sha256"].is_string() ||
            j["sha256"].get<std::string>() != BranchDigest(options, j["branch"])) {
          throw std::invalid_argument(entry.path().string() + ": the stored branch does not match its digest (it was "
                                      "changed after it was stored, or belongs to another study); remove " +
                                      dir_.string() + " to run the study afresh");
        }
        loaded_.emplace(id, std::move(b));
      }
    }
  }
  if (!resume || loaded_.empty()) {
    fs::remove_all(dir_, ec);
    loaded_.clear();
  }
  fs::create_directories(dir_, ec);
  WriteWhole(study, nlohmann::json{{"format", kFormat}, {"version", HYBRIDCONT_VERSION}, {"options", options}}.dump());
}

std::optional<Branch> ResumeStore::Lookup(int id) const {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto it = loaded_.find(id);
  if (it == loaded_.end()) return std::nullopt;
  ++used_;
  return it->second;
}

void ResumeStore::Save(int id, const Branch& branch) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (loaded_.count(id)) return;  // stored already
  const nlohmann::json stored = BranchToJson(branch);
  WriteWhole(dir_ / ("branch-" + std::to_string(id) + ".json"),
             nlohmann::json{{"format", kFormat}, {"sha256", BranchDigest(options_, stored)}, {"branch", stored}}.dump());
}

void ResumeStore::Complete() {
  std::error_code ec;
  fs::remove_all(dir_, ec);
}

}  // namespace hybridcont::study
