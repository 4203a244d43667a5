#include "server/assets/asset_http.h"

#include <fstream>
#include <sstream>

#include <httplib.h>

#include "common/assets/mesh_import.h"
#include "common/assets/vdb_import.h"
#include "server/http/http_problem.h"
#include "server/http/http_routes.h"

namespace skyfarm::server {

namespace {

using httplib::ContentReader;
using httplib::Request;
using httplib::Response;

std::string asset_path(const std::string& id) { return "/v1/assets/" + id; }

// The {id} segment, checked before the store sees it.
std::string id_of(const Request& req) {
  const std::string id = req.matches.size() > 1 ? std::string(req.matches[1]) : std::string();
  if (!is_asset_id(id)) throw invalid_parameter("id", "must be sha256: and 64 lowercase hex digits", id);
  return id;
}

}  // namespace

std::optional<std::string_view> asset_allowed_methods(std::string_view path) {
  if (path == "/v1/assets") return "POST";
  constexpr std::string_view kPrefix = "/v1/assets/";
  if (!path.starts_with(kPrefix)) return std::nullopt;
  const std::string_view rest = path.substr(kPrefix.size());
  const std::size_t slash = rest.find('/');
  if (rest.empty() || slash == 0) return std::nullopt;
  if (slash == std::string_view::npos || rest.substr(slash) == "/mesh" || rest.substr(slash) == "/volume")
    return "GET, HEAD";
  return std::nullopt;
}

void AssetHttp::add_routes(RouteRegistrar& routes, Hooks hooks) {
  hooks_ = std::move(hooks);
  routes.post("/v1/assets", [this](const Request& req, Response& res, const ContentReader& reader) {
    hooks_.guard(req, res, [&] { upload(req, res, reader); });
  });
  routes.get("/v1/assets/{id}", [this](const Request& req, Response& res) {
    hooks_.guard(req, res, [&] { meta(req, res); });
  });
  routes.get("/v1/assets/{id}/mesh", [this](const Request& req, Response& res) {
    hooks_.guard(req, res, [&] { file(req, res, false); });
  });
  routes.get("/v1/assets/{id}/volume", [this](const Request& req, Response& res) {
    hooks_.guard(req, res, [&] { file(req, res, true); });
  });
}

void AssetHttp::upload(const Request& req, Response& res, const ContentReader& reader) {
  std::string format = req.get_param_value("format");
  if (req.get_param_value_count("format") > 1) throw invalid_parameter("format", "given once", format);
  if (!format.empty() && format != "vdb" && !assets::is_mesh_format(format))
    throw invalid_parameter("format", "one of obj, ply, stl, gltf, glb, vdb", format);
  const std::string grid = req.get_param_value("grid");
  if (req.get_param_value_count("grid") > 1) throw invalid_parameter("grid", "given once", grid);
  const std::string body = hooks_.body(req, res, reader, store_.options().max_upload_bytes);
  const std::string content_type = req.get_header_value("Content-Type");
  if (format == "vdb" || (format.empty() && (assets::looks_like_vdb(body) ||
                                             content_type.starts_with("application/x-openvdb")))) {
    upload_volume(body, grid, res);
    return;
  }
  if (!grid.empty()) throw invalid_parameter("grid", "only for an OpenVDB file (format=vdb)", grid);
  auto fail = [&](std::string detail) {
    Problem p;
    p.status = 422;
    p.type = std::string(kProblemInvalidMesh);
    p.title = "The file is not a usable mesh";
    p.detail = std::move(detail);
    throw HttpError(std::move(p));
  };
  if (body.empty()) fail("the body is empty: send the mesh file as the body");
  if (format.empty()) {
    const auto detected = assets::detect_mesh_format(body);
    if (!detected) fail("the file's format could not be told from its bytes; give ?format=obj|ply|stl|gltf|glb");
    format = *detected;
  }
  AssetPut put = store_.put(body, format);
  if (!put.ok) fail(std::move(put.error));
  const std::string id = put.meta.at("id");
  res.set_header("Location", asset_path(id));
  send_json(res, put.created ? 201 : 200, put.meta);
}

void AssetHttp::upload_volume(const std::string& body, const std::string& grid, Response& res) {
  auto fail = [&](std::string detail) {
    Problem p;
    p.status = 422;
    p.type = std::string(kProblemInvalidVolume);
    p.title = "The file is not a usable cloud volume";
    p.detail = std::move(detail);
    throw HttpError(std::move(p));
  };
  if (body.empty()) fail("the body is empty: send the OpenVDB file as the body");
  AssetPut put = store_.put_volume(body, grid);
  if (!put.ok) fail(std::move(put.error));
  const std::string id = put.meta.at("id");
  res.set_header("Location", asset_path(id));
  send_json(res, put.created ? 201 : 200, put.meta);
}

void AssetHttp::meta(const Request& req, Response& res) const {
  const std::string id = id_of(req);
  send_json_or_throw(res, 200, store_.meta(id), http_error(404, "no asset " + id));
}

void AssetHttp::file(const Request& req, Response& res, bool volume) const {
  const std::string id = id_of(req);
  const auto path = volume ? store_.volume_path(id) : store_.mesh_path(id);
  if (!path) throw http_error(404, std::string(volume ? "no volume asset " : "no mesh asset ") + id);
  std::ifstream in(*path, std::ios::binary);
  std::ostringstream bytes;
  bytes << in.rdbuf();
  if (!in) throw std::runtime_error("cannot read " + *path);
  // The bytes never change under one id.
  res.set_header("Cache-Control", "max-age=31536000, immutable");
  res.set_header("ETag", "\"" + id + "\"");
  res.set_content(std::move(bytes).str(), "application/octet-stream");
}

}  // namespace skyfarm::server
