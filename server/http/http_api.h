// The HTTP API of the render farm, on cpp-httplib 0.11.
//
// Routes (JSON in and out unless noted; the OpenAPI document
// api/openapi.yaml, served at /v1/openapi.yaml, is the reference):
//   POST   /v1/renders                  submit a render request (docs/request-schema.md);
//                                       Idempotency-Key honoured -> 202, Location,
//                                       {"id", "state", "links", "from_cache", "created"}
//   GET    /v1/renders?offset=&limit=   newest first, limit 1..100 (default 20)
//                                       -> {"renders", "offset", "limit", "total"}
//   GET    /v1/renders/{id}             the status document
//   DELETE /v1/renders/{id}             cancel -> 202 + the status document
//   GET    /v1/renders/{id}/image.exr   current (progressive) or final image; strong ETag,
//   GET    /v1/renders/{id}/image.png   If-None-Match -> 304; 409 before the first pass
//   GET    /v1/renders/{id}/events      text/event-stream, Last-Event-ID resumes
//   GET    /v1/workers                  {"workers": [...]}
//   GET    /v1/sky?...                  radiance in one direction from a cached LUT sky (JSON);
//   GET    /v1/sky/envmap.exr?...       a cached lat-long environment map; both with strong
//                                       ETags, If-None-Match -> 304 (server/sky/http_sky.h)
//   POST   /v1/sky/radiance             the radiance probe: "lut" from tables in
//                                       this process, "path" traced on the farm and waited for
//                                       (server/probes/http_probe.h: 502, 503, 504)
//   GET    /v1/openapi.yaml             the OpenAPI 3.0 document (application/yaml)
//   GET    /, /web/<file>               the web page (server/http/http_web.h); public even with a token
//   GET    /healthz                     {"status": "ok"}; never needs the token
//   /v1/timelapses...                   timelapses, when HttpOptions::timelapses is set
//                                       (server/timelapse/timelapse_http.h)
//   /v1/assets...                       mesh assets, when HttpOptions::assets is set
//                                       (server/assets/asset_http.h)
//   GET    /metrics                     Prometheus text (text/plain; version=0.0.4)
// Job ids are 1-64 of [A-Za-z0-9_-] (else 400, before the backend sees them).
//
// Errors are RFC 9457 application/problem+json {type, title, status, detail,
// instance} (+ "errors": [{field, rule, value, message}] for 400): 400 invalid
// body, id, query parameter or header; 401 missing/wrong bearer token
// (WWW-Authenticate: Bearer); 404 unknown job or route; 405 wrong method
// (Allow); 409 image before the first pass; 413 body over max_body_bytes; 415
// body not application/json; 422 Idempotency-Key reused with another body; 429
// farm at capacity (Retry-After); 500 anything else (generic detail, logged to
// stderr); 502 a probe unit failed on the workers; 503 too many event
// streams, or no worker for a probe (Retry-After); 504 a probe not answered
// in time; 507 data directory not writable.
//
// Options: `token` (bearer token on every route but /healthz and the web
// page; compared in constant time), `max_body_bytes`, `max_json_depth`
// (stricter than the parser's own 32 when lower), `max_concurrent_streams`, `sse_keepalive`,
// `http_threads` (httplib's pool), `on_response` (access log hook), `sky`
// (the sky look-ups' caches, shared; a default one when null), `probes` and
// `probe_timeout` (path-traced probes on the farm).
//
// register_routes() also configures the server: payload limit, timeouts,
// keep-alive, thread pool, error/exception handlers and the logger (see
// http_api.cpp "Server settings" for the reasons).  The HttpApi and its
// backend must outlive the server's listen().
#pragma once
#include <chrono>
#include <cstddef>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "server/http/http_events.h"
#include "server/http/http_metrics.h"
#include "server/http/http_request_metrics.h"
#include "server/http/http_backend.h"
#include "server/probes/probe_service.h"
#include "server/sky/sky_service.h"
#include "server/http/httplib_fwd.h"

namespace skyfarm::server {

class AssetHttp;
class AssetStore;
class GatedHttpServer;
struct Route;
class SkyHttp;
class TimelapseHttp;
class TimelapseService;

struct HttpOptions {
  std::optional<std::string> token;          // bearer token required on every route but /healthz when set
  std::size_t max_body_bytes = 1 << 20;      // 413 beyond
  int max_json_depth = 32;                   // 400 beyond (the request parser also checks 32)
  int max_concurrent_streams = 16;           // SSE streams; 503 + Retry-After beyond
  std::chrono::milliseconds sse_keepalive = std::chrono::seconds(10);  // ": keepalive" comment interval
  // httplib pool threads; 0 = max_concurrent_streams + max(8, cores).  Behind
  // GatedHttpServer (server/http/http_gate.h) a request holds one while it is
  // served (an event stream for its whole life), not while it arrives.
  int http_threads = 0;
  // Called after every response (access logging); may be empty.
  std::function<void(const httplib::Request&, const httplib::Response&)> on_response;
  // The sky look-ups' caches (/v1/sky, /v1/sky/envmap.exr); null: a default SkyService.
  std::shared_ptr<SkyService> sky;
  // Path-traced probes (POST /v1/sky/radiance) on the farm; null: answered 503.
  std::shared_ptr<ProbeService> probes;
  std::chrono::milliseconds probe_timeout = std::chrono::seconds(120);  // 504 beyond (server/probes/http_probe.h)
  // The timelapses (not owned; must outlive the HttpApi); null: no /v1/timelapses routes.
  TimelapseService* timelapses = nullptr;
  // The mesh assets (not owned; must outlive the HttpApi); null: no /v1/assets routes.
  // Their uploads have their own body limit (AssetStoreOptions::max_upload_bytes).
  AssetStore* assets = nullptr;
  // More figures for /metrics (e.g. the broker's auth_failures, results_refused),
  // added to the backend's (summed where both have one); may be empty.
  std::function<nlohmann::json()> extra_metrics;
};

class HttpApi {
 public:
  HttpApi(HttpBackend& backend, HttpOptions options);
  ~HttpApi();
  HttpApi(const HttpApi&) = delete;
  HttpApi& operator=(const HttpApi&) = delete;

  // Adds every route and configures `server` (call before listen).
  void register_routes(httplib::Server& server);

  // Event streams open now (for tests and /metrics).
  int open_streams() const { return streams_.open(); }

  // The routes register_routes added, as api/openapi.yaml names them.
  const std::vector<Route>& routes() const { return routes_; }

 private:
  using Handler = void (HttpApi::*)(const httplib::Request&, httplib::Response&);

  void configure_server(httplib::Server& server);
  // Server-wide hooks: the token check before routing (false: a 401 was
  // answered), "Expect: 100-continue", problem documents for httplib's own
  // errors (400, 404, 413, 414, ...; false: a handler answered already), and
  // the response counter.
  bool admitted(const httplib::Request& req, httplib::Response& res) const;
  int expect_continue(const httplib::Request& req, httplib::Response& res) const;
  bool answer_library_error(const httplib::Request& req, httplib::Response& res);
  void log_response(const httplib::Request& req, const httplib::Response& res) noexcept;
  void add_routes(httplib::Server& server);
  void add_fallbacks(httplib::Server& server);
  // A route handler that turns every exception into its problem document.
  std::function<void(const httplib::Request&, httplib::Response&)> guarded(Handler handler);

  // Route handlers.
  void submit(const httplib::Request& req, httplib::Response& res, const httplib::ContentReader& reader);
  void admit_objects(const api::RenderRequest& request) const;
  void list(const httplib::Request& req, httplib::Response& res);
  void status(const httplib::Request& req, httplib::Response& res);
  void cancel(const httplib::Request& req, httplib::Response& res);
  void image_exr(const httplib::Request& req, httplib::Response& res);
  void image_png(const httplib::Request& req, httplib::Response& res);
  void events(const httplib::Request& req, httplib::Response& res);
  void workers(const httplib::Request& req, httplib::Response& res);
  void drain_worker(const httplib::Request& req, httplib::Response& res, bool drain);
  void thumbnail(const httplib::Request& req, httplib::Response& res);
  ImageFile image_file(const std::string& id, ImageFormat format);
  void sky(const httplib::Request& req, httplib::Response& res);
  void sky_radiance(const httplib::Request& req, httplib::Response& res, const httplib::ContentReader& reader);
  void sky_envmap(const httplib::Request& req, httplib::Response& res);
  void openapi(const httplib::Request& req, httplib::Response& res);
  void web_file(const httplib::Request& req, httplib::Response& res);
  void healthz(const httplib::Request& req, httplib::Response& res);
  void metrics(const httplib::Request& req, httplib::Response& res);
  // Unmatched paths and methods: 404, or 405 with Allow (204 for OPTIONS).
  void fallback(const httplib::Request& req, httplib::Response& res);

  // Helpers.
  std::string read_body(const httplib::Request& req, httplib::Response& res,
                        const httplib::ContentReader& reader) const;
  std::string read_body(const httplib::Request& req, httplib::Response& res, const httplib::ContentReader& reader,
                        std::size_t limit) const;
  // The body limit of a path: max_body_bytes, or the asset uploads' own.
  std::size_t body_limit(std::string_view path) const;
  void image(const httplib::Request& req, httplib::Response& res, ImageFormat format);
  bool authorized(const httplib::Request& req) const;
  void answer_unauthorized(const httplib::Request& req, httplib::Response& res) const;

  HttpBackend& backend_;
  const HttpOptions options_;
  StreamSlots streams_;
  ResponseCounter responses_;
  HttpRequestMetrics requests_;  // by route template, method, code; durations
  std::unique_ptr<SkyHttp> sky_;
  std::unique_ptr<TimelapseHttp> timelapses_;
  std::unique_ptr<AssetHttp> assets_;
  const GatedHttpServer* gate_ = nullptr;  // its metrics, when the server is one
  std::vector<Route> routes_;
  std::mutex thumbnail_writer_;  // thumbnail files (AtomicFile: one writer of a path at a time)
};

}  // namespace skyfarm::server
