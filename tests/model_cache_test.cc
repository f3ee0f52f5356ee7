// The compiled-model cache (src/modelfile/model_cache.h) attacked as a careless or hostile user would: a
// truncated library, another model's library (alone, and with a record forged to match it), a planted one
// whose constructor would run, a folder or file others may write, a folder of another user. Each case
// recompiles or runs interpreted with a note; none crashes, runs planted code or gives another model's
// numbers: the vector field of the loaded model is the interpreter's at a test state.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "hybridcont/model_file.h"
#include "modelfile/model_cache.h"

namespace hybridcont {
namespace {

namespace fs = std::filesystem;

const fs::path kBall = fs::path(HYBRIDCONT_SOURCE_DIR) / "models" / "bouncing-ball.toml";
const fs::path kPendulum = fs::path(HYBRIDCONT_SOURCE_DIR) / "models" / "impacting-pendulum.toml";

struct Loaded {
  HybridModel model;
  std::string log;
};

Loaded Load(const fs::path& file, const fs::path& cache) {
  std::ostringstream log;
  ModelFileOptions options;
  options.cache_dir = cache;
  options.log = &log;
  HybridModel model = LoadModelFile(file, options);
  return {std::move(model), log.str()};
}

// f(x) of phase 0 against the interpreter's at the phase's typical state (the same operations: equal to
// rounding).
void ExpectThePhysicsOf(const fs::path& file, const HybridModel& model) {
  ModelFileOptions interpreted;
  interpreted.compile = false;
  const HybridModel reference = LoadModelFile(file, interpreted);
  const Vector x = reference.phase(0).typical_state();
  Vector f, g;
  model.phase(0).VectorField(x, &f, nullptr);
  reference.phase(0).VectorField(x, &g, nullptr);
  ASSERT_EQ(f.size(), g.size());
  EXPECT_LT((f - g).cwiseAbs().maxCoeff(), 1e-14 * (1 + g.cwiseAbs().maxCoeff())) << f.transpose() << " vs " << g.transpose();
}

// Replaces `path` by a new file (a new inode, as an interrupted copy or another program would leave it): the
// library this process loaded from the old one stays mapped intact.
void ReplaceFile(const fs::path& path, const std::string& bytes) {
  const fs::path tmp = path.string() + ".new";
  std::ofstream(tmp, std::ios::binary) << bytes;
  fs::permissions(tmp, fs::perms::owner_all, fs::perm_options::replace);
  fs::rename(tmp, path);
}

std::string Bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// A library whose constructor creates `marker` when it is loaded (what planted code would do first).
fs::path PlantedLibrary(const fs::path& folder, const fs::path& marker) {
  const fs::path source = folder / "planted.cc", planted = folder / "planted.so";
  std::ofstream(source) << "#include <cstdio>\n__attribute__((constructor)) static void Run() { std::FILE* f = "
                           "std::fopen(\""
                        << marker.string() << "\", \"w\"); if (f) std::fclose(f); }\n";
  EXPECT_EQ(std::system(("c++ -shared -fPIC -o " + planted.string() + " " + source.string()).c_str()), 0);
  return planted;
}

class ModelCache : public ::testing::Test {
 protected:
  void SetUp() override {
    cache_ = fs::temp_directory_path() / ("hybridcont_cache_test_" + std::to_string(getpid()) + "_" +
                                          ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(cache_);
  }
  void TearDown() override {
    std::error_code ec;
    fs::permissions(cache_, fs::perms::owner_all, fs::perm_options::replace, ec);
    fs::remove_all(cache_, ec);
  }
  // The entry's files after a first load of `file` (which compiles it).
  std::pair<fs::path, fs::path> Entry(const fs::path& file) {
    const Loaded first = Load(file, cache_);
    EXPECT_NE(first.log.find("compiling model"), std::string::npos) << first.log;
    fs::path library, record;
    for (const auto& e : fs::directory_iterator(cache_)) {
      if (e.path().extension() == ".so") library = e.path();
      if (e.path().extension() == ".sha256") record = e.path();
    }
    return {library, record};
  }
  fs::path cache_;
};

TEST_F(ModelCache, AnEntryIsTheUsersOwnAndIsLoadedWithoutCompiling) {
  const auto [library, record] = Entry(kBall);
  ASSERT_FALSE(library.empty());
  ASSERT_FALSE(record.empty());
  EXPECT_EQ(fs::status(cache_).permissions() & fs::perms::all, fs::perms::owner_all);
  EXPECT_EQ(fs::status(library).permissions() & (fs::perms::group_all | fs::perms::others_all), fs::perms::none);
  EXPECT_EQ(fs::status(record).permissions() & (fs::perms::group_all | fs::perms::others_all), fs::perms::none);
  const Loaded again = Load(kBall, cache_);
  EXPECT_EQ(again.log, "");
  ExpectThePhysicsOf(kBall, again.model);
}

TEST_F(ModelCache, ATruncatedLibraryIsNeverOpenedAndIsCompiledAgain) {
  const auto [library, record] = Entry(kBall);
  for (const std::size_t size : {1024u, 4096u, 12288u}) {
    ReplaceFile(library, Bytes(library).substr(0, size));
    const Loaded again = Load(kBall, cache_);
    EXPECT_NE(again.log.find("is not used (its library's bytes are not those recorded"), std::string::npos) << again.log;
    EXPECT_NE(again.log.find("compiling model 'bouncing-ball' (cached in"), std::string::npos) << again.log;
    EXPECT_EQ(again.log.find("runs interpreted"), std::string::npos) << again.log;
    ExpectThePhysicsOf(kBall, again.model);
    EXPECT_EQ(Load(kBall, cache_).log, "");  // replaced: the next load trusts it
  }
}

TEST_F(ModelCache, AnotherModelsLibraryGivesNoForeignAnswerEvenWithAForgedRecord) {
  const auto [ball_library, ball_record] = Entry(kBall);
  const fs::path other = cache_ / "other";
  fs::create_directory(other);
  fs::permissions(other, fs::perms::owner_all, fs::perm_options::replace);
  const Loaded pendulum = Load(kPendulum, other);
  fs::path pendulum_library, pendulum_record;
  for (const auto& e : fs::directory_iterator(other)) {
    if (e.path().extension() == ".so") pendulum_library = e.path();
    if (e.path().extension() == ".sha256") pendulum_record = e.path();
  }
  ASSERT_FALSE(pendulum_library.empty());
  // The library alone replaced: its bytes are not the recorded ones.
  ReplaceFile(ball_library, Bytes(pendulum_library));
  Loaded swapped = Load(kBall, cache_);
  EXPECT_NE(swapped.log.find("its library's bytes are not those recorded"), std::string::npos) << swapped.log;
  ExpectThePhysicsOf(kBall, swapped.model);
  // The library and a record forged for it (this model's key, the foreign bytes' digest): the library's
  // own source digest tells it apart once loaded.
  std::string key, digest, word, header;
  {
    std::ifstream in(ball_record);
    std::getline(in, header);
    in >> word >> key;
  }
  {
    std::ifstream in(pendulum_record);
    std::getline(in, header);
    std::string k;
    in >> word >> k >> word >> digest;
  }
  ReplaceFile(ball_library, Bytes(pendulum_library));
  std::ofstream(ball_record) << header << "\nkey " << key << "\nlibrary-sha256 " << digest << "\n";
  fs::permissions(ball_record, fs::perms::owner_read | fs::perms::owner_write, fs::perm_options::replace);
  Loaded forged = Load(kBall, cache_);
  EXPECT_NE(forged.log.find("it was compiled from another model's code"), std::string::npos) << forged.log;
  ExpectThePhysicsOf(kBall, forged.model);
}

TEST_F(ModelCache, APlantedLibraryWithoutItsRecordIsNeverOpened) {
  const auto [library, record] = Entry(kBall);
  const fs::path marker = cache_ / "constructor-ran";
  const fs::path planted = PlantedLibrary(cache_, marker);
  ReplaceFile(library, Bytes(planted));
  fs::remove(record);
  const Loaded again = Load(kBall, cache_);
  EXPECT_NE(again.log.find("its record model-"), std::string::npos) << again.log;
  EXPECT_FALSE(fs::exists(marker)) << "the planted constructor ran";
  ExpectThePhysicsOf(kBall, again.model);
}

// A library planted with a record forged to match it (this model's key, the planted bytes' digest): its bytes do
// not name this model's source, so it is never opened and its constructor never runs.
TEST_F(ModelCache, APlantedLibraryWithAForgedRecordIsNeverOpened) {
  const auto [library, record] = Entry(kBall);
  const fs::path marker = cache_ / "constructor-ran";
  const fs::path planted = PlantedLibrary(cache_, marker);
  std::string header, word, key;
  {
    std::ifstream in(record);
    std::getline(in, header);
    in >> word >> key;
  }
  ReplaceFile(library, Bytes(planted));
  std::ofstream(record) << header << "\nkey " << key << "\nlibrary-sha256 " << internal::Sha256OfFile(library) << "\n";
  fs::permissions(record, fs::perms::owner_read | fs::perms::owner_write, fs::perm_options::replace);
  const Loaded again = Load(kBall, cache_);
  EXPECT_NE(again.log.find("its bytes do not name this model's source; not opened"), std::string::npos) << again.log;
  EXPECT_FALSE(fs::exists(marker)) << "the planted constructor ran";
  ExpectThePhysicsOf(kBall, again.model);
}

// Two threads of one process compiling the same model (a Dask worker's): one compiles, the other waits and loads
// what it published; the folder holds one entry and no temporary file.
TEST_F(ModelCache, TwoThreadsCompilingOneModelMakeOneLibrary) {
  std::ostringstream logs[2];
  std::optional<HybridModel> models[2];
  std::vector<std::thread> threads;
  for (int i = 0; i < 2; ++i) {
    threads.emplace_back([&, i] {
      ModelFileOptions options;
      options.cache_dir = cache_;
      options.log = &logs[i];
      models[i] = LoadModelFile(kBall, options);
    });
  }
  for (std::thread& t : threads) t.join();
  const std::string both = logs[0].str() + logs[1].str();
  EXPECT_EQ(both.find("compiling model"), both.rfind("compiling model")) << both;  // once
  EXPECT_EQ(both.find("interpreted"), std::string::npos) << both;
  std::vector<std::string> files;
  for (const auto& e : fs::directory_iterator(cache_)) files.push_back(e.path().extension().string());
  std::sort(files.begin(), files.end());
  EXPECT_EQ(files, (std::vector<std::string>{".sha256", ".so"}));
  for (const auto& m : models) ExpectThePhysicsOf(kBall, *m);
}

TEST_F(ModelCache, AFolderOrFileOthersMayWriteIsNotTrusted) {
  const auto [library, record] = Entry(kBall);
  // A file of the entry writable by others: the entry is compiled again.
  fs::permissions(library, fs::perms::all, fs::perm_options::replace);
  Loaded file = Load(kBall, cache_);
  EXPECT_NE(file.log.find("is writable by others (mode 0777)"), std::string::npos) << file.log;
  ExpectThePhysicsOf(kBall, file.model);
  // The folder writable by others: nothing in it is loaded or written; the model runs interpreted.
  fs::permissions(cache_, fs::perms::all, fs::perm_options::replace);
  Loaded folder = Load(kBall, cache_);
  EXPECT_NE(folder.log.find("runs interpreted (slower): the cache folder is not trusted: " + cache_.string() +
                            " is writable by others (mode 0777)"),
            std::string::npos)
      << folder.log;
  ExpectThePhysicsOf(kBall, folder.model);
}

// The compiler's memory is bounded ($HYBRIDCONT_COMPILE_MEMORY_MB): past it the model runs interpreted, and
// the note names the limit and how to raise it. (256 MB of address space is below what compiling any model
// with Eigen's headers takes.)
TEST_F(ModelCache, ACompilerPastItsMemoryLimitLeavesTheModelInterpreted) {
  setenv("HYBRIDCONT_COMPILE_MEMORY_MB", "256", 1);
  const Loaded loaded = Load(kBall, cache_);
  unsetenv("HYBRIDCONT_COMPILE_MEMORY_MB");
  EXPECT_NE(loaded.log.find("runs interpreted (slower): compiling needed more than 256 MB (the limit; raise it with "
                            "HYBRIDCONT_COMPILE_MEMORY_MB=MB)"),
            std::string::npos)
      << loaded.log;
  ExpectThePhysicsOf(kBall, loaded.model);
  for (const auto& e : fs::directory_iterator(cache_)) EXPECT_NE(e.path().extension(), ".so") << e.path();
}

TEST_F(ModelCache, AFolderOfAnotherUserIsNotTrusted) {
  if (geteuid() != 0) GTEST_SKIP() << "giving a folder to another user needs root";
  fs::create_directories(cache_);
  fs::permissions(cache_, fs::perms::owner_all, fs::perm_options::replace);
  ASSERT_EQ(chown(cache_.c_str(), 65534, 65534), 0);
  const Loaded loaded = Load(kBall, cache_);
  EXPECT_NE(loaded.log.find(" belongs to user 65534, not to this user (0)"), std::string::npos) << loaded.log;
  ExpectThePhysicsOf(kBall, loaded.model);
}

}  // namespace
}  // namespace hybridcont
