// The name of a mesh asset: "sha256:" and the 64 lowercase hex digits of the
// SHA-256 of its canonical mesh file (mesh_file.h).  The server's store names
// its files by it, and whoever receives the bytes (a farm worker fetching an
// asset, `skyfarm-worker render` importing a file) checks them against it.
#pragma once
#include <string>
#include <string_view>

namespace skyfarm::assets {

inline constexpr std::string_view kAssetIdPrefix = "sha256:";

// "sha256:" and 64 lowercase hex digits.
bool is_asset_id(std::string_view id);

// Lowercase hex SHA-256 of `bytes`.
std::string sha256_hex(std::string_view bytes);

// "sha256:" + sha256_hex(file): the id of a canonical mesh file's bytes.
std::string asset_id_of(std::string_view file);

// The hex digits of an id (is_asset_id), the name of its files.
inline std::string_view asset_hex(std::string_view id) { return id.substr(kAssetIdPrefix.size()); }

}  // namespace skyfarm::assets
