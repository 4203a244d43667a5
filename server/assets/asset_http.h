// The mesh and cloud volume asset routes of the HTTP API, registered by
// HttpApi when it has an AssetStore (HttpOptions::assets):
//
//   POST /v1/assets?format=F      body: the mesh file (OBJ, PLY, STL, glTF with
//                                 embedded buffers, GLB; F one of obj, ply, stl,
//                                 gltf, glb, detected from the bytes when absent)
//                                 or an OpenVDB file (F vdb, or the bytes'
//                                 magic " BDV", or Content-Type
//                                 application/x-openvdb; &grid=NAME picks its
//                                 float grid, default "density", else its only one)
//                                 -> 201 + Location, the metadata (200 when
//                                 the same mesh is already stored)
//   GET  /v1/assets/{id}          the metadata {"id": "sha256:...", "triangles",
//                                 "vertices", "bounds": {"min", "max"}, "bytes"}
//   GET  /v1/assets/{id}/mesh     the canonical mesh file (application/octet-stream;
//                                 common/assets/mesh_file.h)
//   GET  /v1/assets/{id}/volume   a volume's SKYVOL1 file (common/assets/volume_file.h)
//
// Errors are problem documents: 400 an unknown format or a malformed id, 404
// an unknown asset, 413 a body over AssetStoreOptions::max_upload_bytes, 422
// (urn:skyfarm:problem:invalid-mesh, urn:skyfarm:problem:invalid-volume) a
// file the importer refused, crashed on, timed out on or found over its limits.
#pragma once
#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <string_view>

#include "server/assets/asset_store.h"
#include "server/http/httplib_fwd.h"

namespace skyfarm::server {

class RouteRegistrar;

inline constexpr std::string_view kProblemInvalidMesh = "urn:skyfarm:problem:invalid-mesh";
inline constexpr std::string_view kProblemInvalidVolume = "urn:skyfarm:problem:invalid-volume";

class AssetHttp {
 public:
  struct Hooks {
    // Runs a handler; its exceptions become problem documents.
    std::function<void(const httplib::Request&, httplib::Response&, const std::function<void()>&)> guard;
    // The body, read up to `limit` bytes (413 beyond, 400 truncated).
    std::function<std::string(const httplib::Request&, httplib::Response&, const httplib::ContentReader&,
                              std::size_t limit)>
        body;
  };

  explicit AssetHttp(AssetStore& store) : store_(store) {}
  void add_routes(RouteRegistrar& routes, Hooks hooks);

 private:
  void upload(const httplib::Request& req, httplib::Response& res, const httplib::ContentReader& reader);
  void upload_volume(const std::string& body, const std::string& grid, httplib::Response& res);
  void meta(const httplib::Request& req, httplib::Response& res) const;
  void file(const httplib::Request& req, httplib::Response& res, bool volume) const;

  AssetStore& store_;
  Hooks hooks_;
};

// "GET, HEAD, POST", ... for an asset path (405 answers), else nullopt.
std::optional<std::string_view> asset_allowed_methods(std::string_view path);

}  // namespace skyfarm::server
