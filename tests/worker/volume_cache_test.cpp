// The worker's VolumeCache (worker/volume_cache.h): a volume is fetched once,
// then served from memory and from the disk cache; bytes that do not hash to
// their id are refused.
#include "worker/volume_cache.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <filesystem>

#include "common/assets/asset_id.h"

namespace skyfarm {
namespace {

namespace fs = std::filesystem;

std::string small_volume_file() {
  assets::VolumeGrid g;
  g.size = {2, 2, 1};
  g.voxel_size_m = glm::dvec3(10.0);
  g.values = {0.0f, 1.0f, 2.0f, 3.0f};
  g.max_value = 3.0f;
  return assets::encode_volume_file(g);
}

TEST(VolumeCache, FetchesOnceThenMemoryThenDisk) {
  const fs::path dir = fs::temp_directory_path() / ("skyfarm_volume_cache_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  const std::string file = small_volume_file();
  const std::string id = assets::asset_id_of(file);
  std::atomic<int> fetches{0};
  {
    AssetDiskCache disk(dir.string(), 1 << 20);
    VolumeCache cache(&disk, [&](const std::string& asked) {
      ++fetches;
      EXPECT_EQ(asked, id);
      return file;
    });
    const auto v = cache.volume(id);
    ASSERT_TRUE(v);
    EXPECT_EQ(v->at(1, 1, 0), 3.0f);
    EXPECT_EQ(cache.volume(id), v);
    EXPECT_EQ(fetches.load(), 1);
    EXPECT_EQ(cache.stats().memory_hits, 1u);
  }
  {
    AssetDiskCache disk(dir.string(), 1 << 20);
    VolumeCache offline(&disk, {});
    EXPECT_EQ(offline.volume(id)->max_value, 3.0f);
    EXPECT_EQ(offline.stats().disk_hits, 1u);
  }
  VolumeCache liar(nullptr, [&](const std::string&) { return small_volume_file() + "x"; });
  EXPECT_THROW(liar.volume(id), std::runtime_error);
  VolumeCache none(nullptr, {});
  EXPECT_THROW(none.volume(id), std::runtime_error);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace skyfarm
