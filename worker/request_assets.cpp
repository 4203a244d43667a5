#include "worker/request_assets.h"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <vector>

#include "api/field_error.h"
#include "common/assets/asset_id.h"
#include "common/assets/mesh_file.h"
#include "common/assets/mesh_import.h"
#include "common/assets/vdb_import.h"
#include "common/assets/volume_file.h"

namespace skyfarm {

namespace fs = std::filesystem;

namespace {

// The file's bytes, or an error sentence naming it as `shown`.
std::string read_file(const fs::path& path, const std::string& shown, std::string* bytes) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    std::error_code ec;
    const bool exists = fs::exists(path, ec);
    return "cannot read " + shown + ": " + (exists ? "permission denied or not a file" : "no such file");
  }
  bytes->assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  if (in.bad()) return "cannot read " + shown + ": read error";
  return "";
}

// The format named by the file's extension, else guessed from its bytes.
std::optional<std::string> mesh_format(const fs::path& path, std::string_view bytes) {
  std::string ext = path.extension().string();
  if (!ext.empty()) ext.erase(0, 1);
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  if (assets::is_mesh_format(ext)) return ext;
  return assets::detect_mesh_format(bytes);
}

// The imported file's id and mesh, or an error sentence.
std::string import_file(const fs::path& path, const std::string& shown, std::string* id,
                        std::shared_ptr<const assets::TriangleMesh>* out) {
  std::string bytes;
  if (std::string error = read_file(path, shown, &bytes); !error.empty()) return error;
  const std::optional<std::string> format = mesh_format(path, bytes);
  if (!format) return "cannot import " + shown + ": not a mesh file this importer knows (obj, ply, stl, gltf, glb)";
  auto mesh = std::make_shared<assets::TriangleMesh>();
  std::string error;
  if (!assets::import_mesh(bytes, *format, assets::MeshLimits{}, mesh.get(), &error))
    return "cannot import " + shown + ": " + error;
  *id = assets::asset_id_of(assets::encode_mesh_file(*mesh));
  *out = std::move(mesh);
  return "";
}

// The imported volume file's id and grid, or an error sentence.
std::string import_volume_file(const fs::path& path, const std::string& shown, const std::string& grid_name,
                               std::string* id, std::shared_ptr<const assets::VolumeGrid>* out) {
  std::string bytes;
  if (std::string error = read_file(path, shown, &bytes); !error.empty()) return error;
  auto grid = std::make_shared<assets::VolumeGrid>();
  std::string error;
  if (assets::is_volume_file(bytes)) {
    if (!assets::decode_volume_file(bytes, assets::VolumeLimits{}, grid.get(), &error))
      return "cannot read " + shown + ": " + error;
  } else if (assets::looks_like_vdb(bytes)) {
    if (!assets::import_vdb(bytes, grid_name, assets::VolumeLimits{}, grid.get(), &error))
      return "cannot import " + shown + ": " + error;
  } else {
    return "cannot import " + shown + ": not an OpenVDB (.vdb) or SKYVOL1 file";
  }
  *id = assets::asset_id_of(assets::encode_volume_file(*grid));
  *out = std::move(grid);
  return "";
}

// The entries of `entries` (the request's array `name`) that name an asset
// by a non-empty string.  An asset id is loaded now by `load(id)`, so that a
// missing one is named by its field; a path is replaced by the id that
// `import(entry, path, &error)` returns, or its error is the field's.  What
// is not a string is left to the request's parser.
template <class Load, class Import>
void resolve_asset_entries(nlohmann::json& entries, const std::string& name, Load load, Import import,
                           std::vector<api::FieldError>* errors) {
  for (std::size_t i = 0; i < entries.size(); ++i) {
    nlohmann::json& entry = entries[i];
    if (!entry.is_object()) continue;
    const auto asset = entry.find("asset");
    if (asset == entry.end() || !asset->is_string()) continue;
    const std::string field = name + "[" + std::to_string(i) + "].asset";
    const std::string value = asset->get<std::string>();
    if (assets::is_asset_id(value)) {
      try {
        load(value);
      } catch (const std::exception& e) {
        errors->push_back({field, e.what(), ""});
      }
      continue;
    }
    if (value.empty()) continue;  // the parser says what an asset must be
    std::string error;
    const std::string id = import(entry, value, &error);
    if (!error.empty()) {
      errors->push_back({field, error, ""});
      continue;
    }
    *asset = id;
  }
}

}  // namespace

std::shared_ptr<const assets::VolumeGrid> LocalVolumeSource::volume(std::string_view id) const {
  if (const auto it = imported_.find(id); it != imported_.end()) return it->second;
  return cache_.volume(id);
}

std::unique_ptr<LocalVolumeSource> resolve_request_volumes(nlohmann::json* request, const std::string& base_dir,
                                                           AssetDiskCache* disk) {
  auto source = std::make_unique<LocalVolumeSource>(disk);
  if (!request->is_object()) return source;
  const auto clouds = request->find("clouds");
  if (clouds == request->end() || !clouds->is_object()) return source;
  const auto volumes = clouds->find("volumes");
  if (volumes == clouds->end() || !volumes->is_array()) return source;
  std::vector<api::FieldError> errors;
  std::map<std::string, std::string> imported;  // path and grid -> id: a file named twice is read once
  resolve_asset_entries(
      *volumes, "clouds.volumes",
      [&](const std::string& id) {
        (void)source->volume(id);  // loads it now, so a missing one is named by its field
      },
      [&](const nlohmann::json& volume, const std::string& value, std::string* error) {
        const auto grid_field = volume.find("grid");
        const std::string grid =
            grid_field != volume.end() && grid_field->is_string() ? grid_field->get<std::string>() : std::string();
        const fs::path path = fs::path(value).is_absolute() ? fs::path(value) : fs::path(base_dir) / value;
        const std::string key = path.string() + '\n' + grid;
        if (const auto seen = imported.find(key); seen != imported.end()) return seen->second;
        std::string id;
        std::shared_ptr<const assets::VolumeGrid> loaded;
        *error = import_volume_file(path, value, grid, &id, &loaded);
        if (!error->empty()) return std::string();
        source->add(id, std::move(loaded));
        imported.emplace(key, id);
        return id;
      },
      &errors);
  if (!errors.empty()) throw api::ValidationError(std::move(errors));
  return source;
}

std::shared_ptr<const assets::TriangleMesh> LocalMeshSource::mesh(std::string_view id) const {
  if (const auto it = imported_.find(id); it != imported_.end()) return it->second;
  return cache_.mesh(id);
}

std::unique_ptr<LocalMeshSource> resolve_request_assets(nlohmann::json* request, const std::string& base_dir,
                                                        AssetDiskCache* disk) {
  auto source = std::make_unique<LocalMeshSource>(disk);
  if (!request->is_object()) return source;
  const auto objects = request->find("objects");
  if (objects == request->end() || !objects->is_array()) return source;
  std::vector<api::FieldError> errors;
  std::map<std::string, std::string> imported;  // path -> id: a file named twice is read once
  resolve_asset_entries(
      *objects, "objects",
      [&](const std::string& id) {
        (void)source->mesh(id);  // loads it now, so a missing one is named by its field
      },
      [&](const nlohmann::json&, const std::string& value, std::string* error) {
        const fs::path path = fs::path(value).is_absolute() ? fs::path(value) : fs::path(base_dir) / value;
        if (const auto seen = imported.find(path.string()); seen != imported.end()) return seen->second;
        std::string id;
        std::shared_ptr<const assets::TriangleMesh> mesh;
        *error = import_file(path, value, &id, &mesh);
        if (!error->empty()) return std::string();
        source->add(id, std::move(mesh));
        imported.emplace(path.string(), id);
        return id;
      },
      &errors);
  if (!errors.empty()) throw api::ValidationError(std::move(errors));
  return source;
}

}  // namespace skyfarm
