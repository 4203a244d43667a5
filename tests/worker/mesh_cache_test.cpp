// The worker's MeshSource (worker/mesh_cache.h): memory, disk, then fetch;
// bytes checked against the id; one fetch however many threads ask.
#include "worker/mesh_cache.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <filesystem>
#include <thread>
#include <vector>

#include "common/assets/asset_id.h"
#include "common/assets/mesh_file.h"

namespace skyfarm {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

assets::TriangleMesh tetra(double scale = 1.0) {
  assets::TriangleMesh m;
  m.positions = {0, 0, 0, scale, 0, 0, 0, scale, 0, 0, 0, scale};
  m.indices = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};
  return m;
}

struct TempDir {
  explicit TempDir(const std::string& name)
      : path(fs::temp_directory_path() / ("skyfarm_meshcache_" + name + "_" + std::to_string(::getpid()))) {
    fs::remove_all(path);
  }
  ~TempDir() { fs::remove_all(path); }
  fs::path path;
};

TEST(MeshCache, FetchesOnceForManyThreadsAndKeepsTheMesh) {
  const std::string file = assets::encode_mesh_file(tetra());
  const std::string id = assets::asset_id_of(file);
  std::atomic<int> fetches{0};
  MeshCache cache(nullptr, [&](const std::string& asked) {
    EXPECT_EQ(asked, id);
    ++fetches;
    std::this_thread::sleep_for(50ms);  // the others arrive while it is on its way
    return file;
  });
  std::vector<std::thread> threads;
  std::vector<std::shared_ptr<const assets::TriangleMesh>> got(8);
  for (int i = 0; i < 8; ++i) threads.emplace_back([&, i] { got[i] = cache.mesh(id); });
  for (auto& t : threads) t.join();
  EXPECT_EQ(fetches.load(), 1);
  for (const auto& m : got) {
    ASSERT_TRUE(m);
    EXPECT_EQ(m->triangle_count(), 4u);
  }
  EXPECT_EQ(cache.mesh(id), got[0]) << "the same decoded mesh, from memory";
  EXPECT_EQ(fetches.load(), 1);
  EXPECT_EQ(cache.stats().fetches, 1u);
}

TEST(MeshCache, RefusesBytesThatDoNotHashToTheId) {
  const std::string file = assets::encode_mesh_file(tetra());
  const std::string other_id = assets::asset_id_of(assets::encode_mesh_file(tetra(2.0)));
  TempDir dir("forged");
  AssetDiskCache disk(dir.path.string(), 1 << 20);
  MeshCache cache(&disk, [&](const std::string&) { return file; });
  try {
    cache.mesh(other_id);
    ADD_FAILURE() << "a forged mesh was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(other_id), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("hash"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(disk.read(other_id)) << "nothing cached under a wrong name";
  EXPECT_EQ(cache.stats().rejected, 1u);
}

TEST(MeshCache, FetchedFilesGoToDiskAndADamagedOneIsFetchedAgain) {
  const std::string file = assets::encode_mesh_file(tetra());
  const std::string id = assets::asset_id_of(file);
  TempDir dir("disk");
  AssetDiskCache disk(dir.path.string(), 1 << 20);
  int fetches = 0;
  const auto fetch = [&](const std::string&) {
    ++fetches;
    return file;
  };
  EXPECT_EQ(MeshCache(&disk, fetch).mesh(id)->vertex_count(), 4u);
  EXPECT_EQ(fetches, 1);
  EXPECT_EQ(disk.read(id), file);
  MeshCache restarted(&disk, {});  // no server: the disk serves
  EXPECT_EQ(restarted.mesh(id)->vertex_count(), 4u);
  EXPECT_EQ(restarted.stats().disk_hits, 1u);
  disk.write(id, file.substr(0, file.size() - 1));  // damaged
  EXPECT_EQ(MeshCache(&disk, fetch).mesh(id)->vertex_count(), 4u);
  EXPECT_EQ(fetches, 2);
  EXPECT_EQ(disk.read(id), file) << "the good copy replaced it";
}

TEST(MeshCache, WithoutAServerAMissingAssetSaysWhatToDo) {
  TempDir dir("missing");
  AssetDiskCache disk(dir.path.string(), 1 << 20);
  MeshCache cache(&disk, {});
  const std::string id = "sha256:" + std::string(64, 'e');
  try {
    cache.mesh(id);
    ADD_FAILURE() << "no error";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(id), std::string::npos) << what;
    EXPECT_NE(what.find("upload it"), std::string::npos) << what;
  }
  EXPECT_THROW(cache.mesh("cube.obj"), std::runtime_error);
}

TEST(MeshCache, AFailedFetchIsNotRememberedAndTheMemoryIsBounded) {
  const std::string a = assets::encode_mesh_file(tetra(1.0)), b = assets::encode_mesh_file(tetra(2.0));
  int calls = 0;
  bool fail = true;
  MeshCache cache(
      nullptr,
      [&](const std::string& id) {
        ++calls;
        if (fail) throw AssetUnavailable("asset " + id + ": no answer");
        return id == assets::asset_id_of(a) ? a : b;
      },
      /*memory_bytes=*/mesh_bytes(tetra()));  // room for one
  EXPECT_THROW(cache.mesh(assets::asset_id_of(a)), AssetUnavailable);
  fail = false;
  EXPECT_TRUE(cache.mesh(assets::asset_id_of(a))) << "asked again";
  EXPECT_EQ(calls, 2);
  cache.mesh(assets::asset_id_of(b));
  cache.mesh(assets::asset_id_of(a));
  EXPECT_EQ(calls, 4) << "b pushed a out of memory";
}

}  // namespace
}  // namespace skyfarm
