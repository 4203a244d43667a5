// The import's child process: a good file, a refused one, and children that
// crash, hang or are missing (skyfarm-server import-mesh is the real child).
#include "server/assets/mesh_import_process.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>

#include "tests/support/mesh_files.h"

namespace skyfarm::server {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

class MeshImportProcess : public ::testing::Test {
 protected:
  void SetUp() override {
    options_.command = {SKYFARM_SERVER_BINARY, "import-mesh"};
    options_.work_dir = dir_.string();
  }
  void TearDown() override {
    // Every import removes its scratch directory.
    EXPECT_TRUE(fs::is_empty(dir_));
    fs::remove_all(dir_);
  }
  const fs::path dir_ = fs::temp_directory_path() / ("skyfarm_import_" + std::to_string(::getpid()));
  MeshImportOptions options_;
};

TEST_F(MeshImportProcess, ImportsInTheChild) {
  const MeshImportResult r = run_mesh_import(skyfarm::testing::cube_obj(), "obj", options_);
  ASSERT_TRUE(r.ok) << r.error;
  EXPECT_EQ(r.mesh.triangle_count(), 12u);
  EXPECT_EQ(r.mesh.vertex_count(), 8u);
}

TEST_F(MeshImportProcess, TheChildsRefusalIsTheError) {
  options_.limits.max_triangles = 5;
  const MeshImportResult r = run_mesh_import(skyfarm::testing::cube_obj(), "obj", options_);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.error.find("limit of 5"), std::string::npos) << r.error;
}

TEST_F(MeshImportProcess, ACrashingChildIsAnError) {
  options_.command = {"/bin/sh", "-c", "kill -SEGV $$", "sh"};
  const MeshImportResult r = run_mesh_import("v 0 0 0\n", "obj", options_);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.error.find("signal 11"), std::string::npos) << r.error;
}

TEST_F(MeshImportProcess, AHangingChildIsKilled) {
  options_.command = {"/bin/sh", "-c", "sleep 30", "sh"};
  options_.timeout = 200ms;
  const auto start = std::chrono::steady_clock::now();
  const MeshImportResult r = run_mesh_import("v 0 0 0\n", "obj", options_);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.error.find("longer than 200 ms"), std::string::npos) << r.error;
  EXPECT_LT(std::chrono::steady_clock::now() - start, 20s);
}

TEST_F(MeshImportProcess, GarbageOutputIsRefused) {
  // A child that "succeeds" but writes a mesh with an index out of range.
  options_.command = {"/bin/sh", "-c", "printf 'SKYMESH1\\001\\000\\000\\000\\001\\000\\000\\000' > \"$8\"", "sh"};
  const MeshImportResult r = run_mesh_import("v 0 0 0\n", "obj", options_);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.error.find("invalid"), std::string::npos) << r.error;
}

TEST_F(MeshImportProcess, AMissingImporterIsTheServersError) {
  options_.command = {"/nonexistent/skyfarm-importer"};
  EXPECT_THROW(run_mesh_import("v 0 0 0\n", "obj", options_), std::runtime_error);
}

}  // namespace
}  // namespace skyfarm::server
