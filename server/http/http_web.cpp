#include "server/http/http_web.h"

#include <httplib.h>

#include <cstddef>
#include <vector>

#include "server/http/http_checks.h"
#include "server/http/http_problem.h"
#include "server/sky/sky_service.h"

// Generated as embedded_web.cpp (cmake/embed_files.cmake) from server/http/web/.
namespace skyfarm::embedded_web {
struct Entry { const char* name; const char* data; std::size_t size; };
extern const Entry kEntries[];
extern const std::size_t kEntryCount;
}  // namespace skyfarm::embedded_web

namespace skyfarm::server {
namespace {

constexpr std::string_view kIndexName = "index.html";
constexpr std::string_view kAssetPrefix = "/web/";

// The page loads its script, style and (blob) images from this origin only.
constexpr const char* kContentSecurityPolicy =
    "default-src 'self'; img-src 'self' blob: data:; media-src 'self' blob:; "
    "object-src 'none'; base-uri 'none'; frame-ancestors 'none'; form-action 'self'";

std::string_view content_type_of(std::string_view name) {
  if (name.ends_with(".html")) return "text/html; charset=utf-8";
  if (name.ends_with(".js")) return "text/javascript; charset=utf-8";
  if (name.ends_with(".css")) return "text/css; charset=utf-8";
  if (name.ends_with(".svg")) return "image/svg+xml";
  return "application/octet-stream";
}

// Every embedded file under its URL path (index.html also at "/"), built once.
const std::vector<WebFile>& web_files() {
  static const std::vector<WebFile> files = [] {
    std::vector<WebFile> out;
    for (std::size_t i = 0; i < embedded_web::kEntryCount; ++i) {
      const auto& e = embedded_web::kEntries[i];
      const std::string_view name(e.name);
      const std::string_view body(e.data, e.size);
      std::string etag = "\"";  // appended, not "a" + b: GCC 12's false -Wrestrict
      etag += text_hash(body);
      etag += '"';
      if (name == kIndexName) out.push_back({"/", content_type_of(name), body, etag});
      out.push_back({std::string(kAssetPrefix) + std::string(name), content_type_of(name), body, etag});
    }
    return out;
  }();
  return files;
}

}  // namespace

const WebFile* find_web_file(std::string_view path) {
  for (const WebFile& f : web_files())
    if (f.path == path) return &f;
  return nullptr;
}

void serve_web_file(const httplib::Request& req, httplib::Response& res) {
  const WebFile* file = find_web_file(req.path);
  if (!file)
    throw http_error(404, "no route \"" + printable_excerpt(req.path) + "\"; the page is at / and its files are " +
                              "/web/app.js and /web/style.css");
  res.set_header("ETag", file->etag);
  res.set_header("Cache-Control", "no-cache");
  res.set_header("X-Content-Type-Options", "nosniff");
  if (file->path == "/") res.set_header("Content-Security-Policy", kContentSecurityPolicy);
  if (if_none_match_matches(req.get_header_value("If-None-Match"), file->etag)) {
    res.status = 304;
    return;
  }
  res.status = 200;
  res.set_content(file->body.data(), file->body.size(), std::string(file->content_type).c_str());
}

}  // namespace skyfarm::server
