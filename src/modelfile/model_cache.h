// The cache of compiled model files, which cannot lie: an entry is used only when it is the user's own and
// is what this program compiled for this model.
//
// Layout: <folder>/model-<key>.so, the compiled code, and model-<key>.sha256, its record:
//     hybridcont-model-cache 1
//     key <key>
//     library-sha256 <SHA-256 of the .so's bytes>
// <key> is the SHA-256 of the generated source, the compiler's identity (its resolved path, size and
// modification time) and flags, and the library's version; the generated source itself ends with its own
// digest as a symbol (hybridcont_model_source_sha256 = "hybridcont-model-source-sha256:<digest>"), whose text is
// found in the library's bytes before it is opened (a library built from another model's code is never loaded,
// so its constructors never run) and read through the symbol after.
//
// Trust: the folder must be a real folder (not a symbolic link) owned by the effective user and writable by
// no one else; otherwise nothing in it is loaded (the model runs interpreted, and the reason is said). An
// entry is loaded only when its two files are regular files owned by the user and writable by no one else,
// the record names this key, and the .so's bytes hash to the recorded digest: a truncated, foreign, planted
// or half-written entry is never opened, so none of its code runs. Such an entry is deleted and compiled
// again. The default folder without HOME is <tmp>/hybridcont-cache-<uid>, made with mode 0700.
//
// Concurrency: a compiling process writes under names of its own (its pid and a per-call count), loads its own
// fresh file, then publishes it by renaming the .so and then the record; a reader that finds the .so without its
// record treats the entry as absent. Within one process one thread compiles a key at a time (a lock per key):
// the others wait and load what it published.
#ifndef HYBRIDCONT_SRC_MODELFILE_MODEL_CACHE_H_
#define HYBRIDCONT_SRC_MODELFILE_MODEL_CACHE_H_

#include <filesystem>
#include <string>

namespace hybridcont::internal {

// Hexadecimal SHA-256 of `bytes` (OpenSSL's libcrypto).
std::string Sha256Hex(const std::string& bytes);
// Hexadecimal SHA-256 of a regular file's bytes, streamed; "" for anything else or a file that cannot be read.
std::string Sha256OfFile(const std::filesystem::path& path);

// The folder's trust: "" when it is (or was just made, mode 0700) a folder of the effective user that no one
// else can write; else why not ("... is writable by others (mode 0777)").
std::string CheckCacheFolder(const std::filesystem::path& folder);

// The two files of an entry.
struct CacheEntry {
  std::filesystem::path library;  // model-<key>.so
  std::filesystem::path record;   // model-<key>.sha256
};
CacheEntry EntryFor(const std::filesystem::path& folder, const std::string& key);

// "" when the entry's files exist, are trusted (see above), its record names `key` and the library's bytes
// hash to the recorded digest; else why not. `absent` is set when neither file exists.
std::string VerifyEntry(const CacheEntry& entry, const std::string& key, bool* absent);

// Removes the entry's files (what exists of them).
void RemoveEntry(const CacheEntry& entry);

// Publishes `compiled` (a library this process just wrote in the folder) as the entry of `key`: restricts
// its mode to the user, writes the record under a name of its own and renames both into place. "" on
// success, else why not.
std::string PublishEntry(const std::filesystem::path& compiled, const CacheEntry& entry, const std::string& key);

}  // namespace hybridcont::internal

#endif  // HYBRIDCONT_SRC_MODELFILE_MODEL_CACHE_H_
