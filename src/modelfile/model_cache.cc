#include "model_cache.h"

#include <openssl/evp.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <vector>

namespace hybridcont::internal {
namespace fs = std::filesystem;

namespace {

constexpr const char* kRecordHeader = "hybridcont-model-cache 1";

std::string Hex(const unsigned char* bytes, unsigned length) {
  std::string hex;
  char buffer[3];
  for (unsigned i = 0; i < length; ++i) {
    std::snprintf(buffer, sizeof buffer, "%02x", bytes[i]);
    hex += buffer;
  }
  return hex;
}

std::string Octal(mode_t mode) {
  char buffer[8];
  std::snprintf(buffer, sizeof buffer, "%04o", static_cast<unsigned>(mode & 07777));
  return buffer;
}

// "" when `path` is a regular file (or, with `folder`, a folder) that is no symbolic link, owned by the
// effective user and not writable by group or others; else why not.
std::string CheckOwned(const fs::path& path, bool folder) {
  struct stat st;
  if (lstat(path.c_str(), &st) != 0) return path.string() + " cannot be examined";
  if (S_ISLNK(st.st_mode)) return path.string() + " is a symbolic link";
  if (folder ? !S_ISDIR(st.st_mode) : !S_ISREG(st.st_mode)) {
    return path.string() + (folder ? " is not a folder" : " is not a regular file");
  }
  if (st.st_uid != geteuid()) {
    return path.string() + " belongs to user " + std::to_string(st.st_uid) + ", not to this user (" +
           std::to_string(geteuid()) + ")";
  }
  if ((st.st_mode & (S_IWGRP | S_IWOTH)) != 0) {
    return path.string() + " is writable by others (mode " + Octal(st.st_mode) + ")";
  }
  return "";
}


}  // namespace

std::string Sha256OfFile(const fs::path& path) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) return "";  // a folder, a FIFO, a device: never read
  std::ifstream in(path, std::ios::binary);
  if (!in) return "";
  EVP_MD_CTX* context = EVP_MD_CTX_new();
  if (context == nullptr || EVP_DigestInit_ex(context, EVP_sha256(), nullptr) != 1) {
    EVP_MD_CTX_free(context);
    return "";
  }
  std::vector<char> buffer(1 << 16);
  bool ok = true;
  while (in) {
    in.read(buffer.data(), static_cast<std::streamsize>(buffer.size()));
    if (in.gcount() > 0) ok = ok && EVP_DigestUpdate(context, buffer.data(), static_cast<std::size_t>(in.gcount())) == 1;
  }
  unsigned char digest[EVP_MAX_MD_SIZE];
  unsigned length = 0;
  ok = ok && !in.bad() && EVP_DigestFinal_ex(context, digest, &length) == 1;
  EVP_MD_CTX_free(context);
  return ok ? Hex(digest, length) : "";
}

std::string Sha256Hex(const std::string& bytes) {
  unsigned char digest[EVP_MAX_MD_SIZE];
  unsigned length = 0;
  if (EVP_Digest(bytes.data(), bytes.size(), digest, &length, EVP_sha256(), nullptr) != 1) return "";
  return Hex(digest, length);
}

std::string CheckCacheFolder(const fs::path& folder) {
  std::error_code ec;
  if (!fs::exists(fs::symlink_status(folder, ec))) {
    fs::create_directories(folder.parent_path(), ec);
    if (mkdir(folder.c_str(), 0700) != 0 && !fs::exists(fs::symlink_status(folder, ec))) {
      return "cannot create the cache folder " + folder.string();
    }
  }
  return CheckOwned(folder, true);
}

CacheEntry EntryFor(const fs::path& folder, const std::string& key) {
  return {folder / ("model-" + key + ".so"), folder / ("model-" + key + ".sha256")};
}

std::string VerifyEntry(const CacheEntry& entry, const std::string& key, bool* absent) {
  std::error_code ec;
  const bool library = fs::exists(fs::symlink_status(entry.library, ec));
  const bool record = fs::exists(fs::symlink_status(entry.record, ec));
  *absent = !library && !record;
  if (*absent) return "absent";
  if (!record) return "its record " + entry.record.filename().string() + " is missing";
  if (!library) return "its library " + entry.library.filename().string() + " is missing";
  for (const fs::path& p : {entry.record, entry.library}) {
    if (const std::string why = CheckOwned(p, false); !why.empty()) return why;
  }
  std::ifstream in(entry.record);
  std::string header, key_word, recorded_key, digest_word, recorded_digest;
  std::getline(in, header);
  in >> key_word >> recorded_key >> digest_word >> recorded_digest;
  if (header != kRecordHeader || key_word != "key" || digest_word != "library-sha256") {
    return "its record " + entry.record.filename().string() + " is not a record of this version";
  }
  if (recorded_key != key) return "its record names another model (key " + recorded_key + ")";
  const std::string digest = Sha256OfFile(entry.library);
  if (digest.empty()) return entry.library.string() + " cannot be read";
  if (digest != recorded_digest) return "its library's bytes are not those recorded (truncated or replaced)";
  return "";
}

void RemoveEntry(const CacheEntry& entry) {
  std::error_code ec;
  fs::remove(entry.library, ec);
  fs::remove(entry.record, ec);
}

std::string PublishEntry(const fs::path& compiled, const CacheEntry& entry, const std::string& key) {
  std::error_code ec;
  fs::permissions(compiled, fs::perms::owner_read | fs::perms::owner_write | fs::perms::owner_exec,
                  fs::perm_options::replace, ec);
  if (ec) return "cannot restrict the mode of " + compiled.string();
  const std::string digest = Sha256OfFile(compiled);
  if (digest.empty()) return "cannot read " + compiled.string();
  static std::atomic<long> calls{0};  // one name per call: two threads may publish the same model at once
  const fs::path record = entry.record.string() + "." + std::to_string(getpid()) + "-" + std::to_string(calls.fetch_add(1));
  {
    std::ofstream out(record);
    out << kRecordHeader << "\nkey " << key << "\nlibrary-sha256 " << digest << "\n";
    if (!out) return "cannot write " + record.string();
  }
  fs::permissions(record, fs::perms::owner_read | fs::perms::owner_write, fs::perm_options::replace, ec);
  fs::rename(compiled, entry.library, ec);
  if (!ec) fs::rename(record, entry.record, ec);
  if (ec) {
    fs::remove(record, ec);
    fs::remove(compiled, ec);
    return "cannot move the compiled model into " + entry.library.string();
  }
  return "";
}

}  // namespace hybridcont::internal
