// The worker's disk cache of mesh assets (worker/asset_cache.h): files named
// by the id's hex, atomic writes, least recently used out when over the bound.
#include "worker/asset_cache.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>

#include "common/assets/asset_id.h"

namespace skyfarm {
namespace {

namespace fs = std::filesystem;

struct TempDir {
  explicit TempDir(const std::string& name)
      : path(fs::temp_directory_path() / ("skyfarm_assetcache_" + name + "_" + std::to_string(::getpid()))) {
    fs::remove_all(path);
  }
  ~TempDir() { fs::remove_all(path); }
  fs::path path;
};

std::string id_of(const std::string& bytes) { return assets::asset_id_of(bytes); }

TEST(AssetDiskCache, WritesAndReadsFilesNamedByTheHex) {
  TempDir dir("rw");
  AssetDiskCache cache(dir.path.string(), 1 << 20);
  const std::string bytes = "mesh bytes";
  const std::string id = id_of(bytes);
  EXPECT_FALSE(cache.read(id)) << "empty cache";
  cache.write(id, bytes);
  EXPECT_EQ(cache.path(id), (dir.path / (assets::sha256_hex(bytes) + ".mesh")).string());
  EXPECT_TRUE(fs::exists(cache.path(id)));
  EXPECT_EQ(cache.read(id), bytes);
  EXPECT_FALSE(cache.read("cube.obj")) << "not an id";
  cache.remove(id);
  EXPECT_FALSE(cache.read(id));
  for (const auto& entry : fs::directory_iterator(dir.path))
    ADD_FAILURE() << "left behind: " << entry.path();
}

// Use order is the files' modification times, set here rather than waited for.
TEST(AssetDiskCache, EvictsTheLeastRecentlyUsedWhenOverTheBound) {
  TempDir dir("lru");
  AssetDiskCache cache(dir.path.string(), 250);
  const std::string a(100, 'a'), b(100, 'b'), c(100, 'c');
  const auto now = fs::file_time_type::clock::now();
  cache.write(id_of(a), a);
  cache.write(id_of(b), b);
  fs::last_write_time(cache.path(id_of(a)), now - std::chrono::hours(2));
  fs::last_write_time(cache.path(id_of(b)), now - std::chrono::hours(1));
  ASSERT_TRUE(cache.read(id_of(a))) << "a read marks a used now";
  cache.write(id_of(c), c);
  EXPECT_TRUE(cache.read(id_of(a)));
  EXPECT_FALSE(cache.read(id_of(b))) << "b was the least recently used";
  EXPECT_TRUE(cache.read(id_of(c)));
}

TEST(AssetDiskCache, KeepsTheFileJustWrittenEvenAloneOverTheBound) {
  TempDir dir("big");
  AssetDiskCache cache(dir.path.string(), 10);
  const std::string small(5, 's'), big(100, 'b');
  cache.write(id_of(small), small);
  cache.write(id_of(big), big);
  EXPECT_FALSE(cache.read(id_of(small)));
  EXPECT_EQ(cache.read(id_of(big)), big);
}

TEST(AssetDiskCache, DefaultDirFollowsSystemdsCacheDirectory) {
  const char* saved = std::getenv("CACHE_DIRECTORY");
  const std::string before = saved ? saved : "";
  ::setenv("CACHE_DIRECTORY", "/var/cache/skyfarm-worker", 1);
  EXPECT_EQ(default_asset_cache_dir(), "/var/cache/skyfarm-worker/assets");
  if (saved) ::setenv("CACHE_DIRECTORY", before.c_str(), 1);
  else ::unsetenv("CACHE_DIRECTORY");
  EXPECT_FALSE(default_asset_cache_dir().empty());
}

}  // namespace
}  // namespace skyfarm
