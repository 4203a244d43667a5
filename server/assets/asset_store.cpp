#include "server/assets/asset_store.h"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "api/wire.h"
#include "common/assets/asset_id.h"
#include "common/assets/mesh_file.h"
#include "common/assets/triangle_mesh.h"
#include "common/assets/volume_file.h"

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
  options_.volume_import.work_dir = options_.import.work_dir;
  // Workers fetch a volume in one ASSET frame: its file must fit the wire's bound (~42 M voxels).
  options_.volume_import.limits.max_bytes = std::min<std::uint64_t>(
      options_.volume_import.limits.max_bytes, api::kMaxAssetBytes - assets::kVolumeFileHeaderBytes);
  fs::remove_all(options_.import.work_dir);
  fs::create_directories(options_.import.work_dir);
}

class AssetStore::ImportTurn {
 public:
  explicit ImportTurn(AssetStore* store) : store_(store) {
    std::unique_lock lock(store_->mutex_);
    store_->turn_.wait(lock, [&] { return store_->importing_ < std::max(1, store_->options_.max_concurrent_imports); });
    ++store_->importing_;
  }
  ~ImportTurn() {
    std::lock_guard lock(store_->mutex_);
    --store_->importing_;
    store_->turn_.notify_one();
  }
  ImportTurn(const ImportTurn&) = delete;
  ImportTurn& operator=(const ImportTurn&) = delete;

 private:
  AssetStore* store_;
};

void AssetStore::store(const std::string& hex, std::string_view extension, std::string_view file, AssetPut* put) {
  const fs::path data = fs::path(dir_) / (hex + std::string(extension));
  const fs::path meta = fs::path(dir_) / (hex + ".json");
  put->ok = true;
  if (fs::exists(meta) && fs::exists(data)) return;
  write_atomically(data, file);
  write_atomically(meta, put->meta.dump());
  put->created = true;
}

AssetPut AssetStore::put(std::string_view bytes, std::string_view format) {
  AssetPut put;
  MeshImportResult imported;
  {
    ImportTurn turn(this);
    imported = run_mesh_import(bytes, format, options_.import);
  }
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
  store(hex, ".mesh", file, &put);
  return put;
}

AssetPut AssetStore::put_volume(std::string_view bytes, std::string_view grid_name) {
  AssetPut put;
  VolumeImportResult imported;
  {
    ImportTurn turn(this);
    imported = run_volume_import(bytes, grid_name, options_.volume_import);
  }
  if (!imported.ok) {
    put.error = std::move(imported.error);
    return put;
  }
  const assets::VolumeGrid& g = imported.grid;
  const std::string hex = sha256_hex(imported.file);
  const glm::dvec3 far = g.origin_m + g.voxel_size_m * glm::dvec3(g.size - 1);
  put.meta = {{"id", std::string(assets::kAssetIdPrefix) + hex},
              {"kind", "volume"},
              {"voxels", {g.size.x, g.size.y, g.size.z}},
              {"voxel_size_m", {g.voxel_size_m.x, g.voxel_size_m.y, g.voxel_size_m.z}},
              {"bounds", {{"min", {g.origin_m.x, g.origin_m.y, g.origin_m.z}}, {"max", {far.x, far.y, far.z}}}},
              {"max_value", g.max_value},
              {"bytes", imported.file.size()}};
  store(hex, ".vol", imported.file, &put);
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
  const fs::path path = fs::path(dir_) / (std::string(assets::asset_hex(id)) + ".mesh");
  if (!fs::exists(path)) return std::nullopt;
  return path.string();
}

std::optional<std::string> AssetStore::volume_path(std::string_view id) const {
  if (!meta(id)) return std::nullopt;
  const fs::path path = fs::path(dir_) / (std::string(assets::asset_hex(id)) + ".vol");
  if (!fs::exists(path)) return std::nullopt;
  return path.string();
}

bool AssetStore::is_volume(std::string_view id) const {
  const std::optional<nlohmann::json> m = meta(id);
  return m && m->value("kind", "") == "volume";
}

std::optional<std::string> AssetStore::read_file(std::string_view id, std::string_view extension) const {
  const std::optional<std::string> path = extension == ".vol" ? volume_path(id) : mesh_path(id);
  if (!path) return std::nullopt;
  std::ifstream in(*path, std::ios::binary);
  if (!in) return std::nullopt;
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw std::runtime_error("cannot read " + *path);
  return bytes;
}

std::optional<std::string> AssetStore::mesh_file(std::string_view id) const { return read_file(id, ".mesh"); }

std::optional<std::string> AssetStore::volume_file(std::string_view id) const { return read_file(id, ".vol"); }

std::optional<std::string> AssetStore::asset_file(std::string_view id) const {
  return is_volume(id) ? volume_file(id) : mesh_file(id);
}

}  // namespace skyfarm::server
