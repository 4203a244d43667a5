// The web page: server/http/web/index.html, app.js and style.css,
// embedded into the binary at build time (cmake/EmbedData.cmake
// skyfarm_embed_files) and served as
//
//   GET /                 index.html   text/html; charset=utf-8
//   GET /web/<file>       app.js       text/javascript; charset=utf-8
//                         style.css    text/css; charset=utf-8
//
// with a strong ETag (a hash of the file), If-None-Match -> 304, and
// "Cache-Control: no-cache" (a browser revalidates every time, so a rebuilt
// server's page shows at once), X-Content-Type-Options: nosniff and a
// Content-Security-Policy allowing only this origin (the page loads nothing
// from elsewhere; images are fetched as blobs so that a bearer token can be
// sent).  Another name under /web/ is a 404 problem like any unknown path.
// The files are public: with --token they are served without it (the page
// asks for the token and sends it on its API calls).
#pragma once
#include <string>
#include <string_view>

namespace httplib {
struct Request;
struct Response;
}  // namespace httplib

namespace skyfarm::server {

struct WebFile {
  std::string path;               // "/" or "/web/app.js"
  std::string_view content_type;  // with charset for text
  std::string_view body;
  std::string etag;               // quoted
};

// The embedded file served at `path`, or null.
const WebFile* find_web_file(std::string_view path);

// Answers `req.path` (200 or 304); throws a 404 HttpError for a name not embedded.
void serve_web_file(const httplib::Request& req, httplib::Response& res);

}  // namespace skyfarm::server
