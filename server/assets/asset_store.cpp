#include "server/assets/asset_store.h"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "common/assets/asset_id.h"
#include "common/assets/mesh_file.h"
#include "common/assets/triangle_mesh.h"

namespace skyfarm::server {

namespace fs = std::filesystem;

namespace {

void write_atomically(const fs::path& path, std::string_view bytes) {
  static std::atomic<unsigned> counter{0};
  const fs::path tmp = path.string() + ".tmp-" + std::to_string(getpid()) + "-" + std::to_string(counter++);
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    if (!out.flush()) {
      std::error_code ec;
      fs::remove(tmp, ec);
      throw std::runtime_error("cannot write " + tmp.string());
    }
  }
  fs::rename(tmp, path);
}

}  // namespace

AssetStore::AssetStore(const std::string& data_dir, AssetStoreOptions options)
    : dir_((fs::path(data_dir) / "assets").string()), options_(std::move(options)) {
  fs::create_directories(dir_);
  options_.import.work_dir = (fs::path(dir_) / "tmp").string();
  fs::remove_all(options_.import.work_dir);
  fs::create_directories(options_.import.work_dir);
}

AssetPut AssetStore::put(std::string_view bytes, std::string_view format) {
  AssetPut put;
  MeshImportResult imported;
  {
    std::unique_lock lock(mutex_);
    turn_.wait(lock, [&] { return importing_ < std::max(1, options_.max_concurrent_imports); });
    ++importing_;
  }
  struct Release {
    AssetStore* store;
    ~Release() {
      std::lock_guard lock(store->mutex_);
      --store->importing_;
      store->turn_.notify_one();
    }
  } release{this};
  imported = run_mesh_import(bytes, format, options_.import);
  if (!imported.ok) {
    put.error = std::move(imported.error);
    return put;
  }
  const std::string file = assets::encode_mesh_file(imported.mesh);
  const std::string hex = sha256_hex(file);
  const assets::MeshBounds b = assets::mesh_bounds(imported.mesh);
  put.meta = {{"id", std::string(assets::kAssetIdPrefix) + hex},
              {"triangles", imported.mesh.triangle_count()},
              {"vertices", imported.mesh.vertex_count()},
              {"bounds", {{"min", b.min}, {"max", b.max}}},
              {"bytes", file.size()}};
  const fs::path mesh = fs::path(dir_) / (hex + ".mesh");
  const fs::path meta = fs::path(dir_) / (hex + ".json");
  put.ok = true;
  if (fs::exists(meta) && fs::exists(mesh)) return put;
  write_atomically(mesh, file);
  write_atomically(meta, put.meta.dump());
  put.created = true;
  return put;
}

std::optional<nlohmann::json> AssetStore::meta(std::string_view id) const {
  if (!is_asset_id(id)) return std::nullopt;
  const fs::path path = fs::path(dir_) / (std::string(assets::asset_hex(id)) + ".json");
  std::ifstream in(path);
  if (!in) return std::nullopt;
  try {
    return nlohmann::json::parse(in);
  } catch (const std::exception&) {
    return std::nullopt;
  }
}

std::optional<std::string> AssetStore::mesh_path(std::string_view id) const {
  if (!meta(id)) return std::nullopt;
  return (fs::path(dir_) / (std::string(assets::asset_hex(id)) + ".mesh")).string();
}

std::optional<std::string> AssetStore::mesh_file(std::string_view id) const {
  const std::optional<std::string> path = mesh_path(id);
  if (!path) return std::nullopt;
  std::ifstream in(*path, std::ios::binary);
  if (!in) return std::nullopt;
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw std::runtime_error("cannot read " + *path);
  return bytes;
}

}  // namespace skyfarm::server
