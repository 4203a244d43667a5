#include "server/http/http_api.h"

#include <httplib.h>

#include <algorithm>
#include <chrono>
#include <optional>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <thread>

#include "api/json_fields.h"
#include "api/render_request.h"
#include "api/render_spec.h"
#include "common/image/png_thumbnail.h"
#include "server/http/http_checks.h"
#include "server/http/http_files.h"
#include "server/http/http_gate.h"
#include "server/http/http_openapi.h"
#include "server/probes/http_probe.h"
#include "server/http/http_query.h"
#include "server/http/http_problem.h"
#include "server/http/http_routes.h"
#include "server/sky/http_sky.h"
#include "server/http/http_web.h"
#include "server/timelapse/timelapse_http.h"
#include "server/timelapse/timelapse_service.h"
#include "server/assets/asset_admission.h"
#include "server/assets/asset_http.h"
#include "api/probe_answer.h"
#include "api/probe_spec.h"

namespace skyfarm::server {
namespace {

using httplib::ContentReader;
using httplib::Request;
using httplib::Response;
using HandlerResponse = httplib::Server::HandlerResponse;

// --- Server settings -------------------------------------------------------
// cpp-httplib 0.11 serves each connection on one thread of a fixed pool for
// the connection's whole life; GatedHttpServer (server/http/http_gate.h) holds a
// connection without a thread until its request has arrived, under the
// header and body deadlines, and the settings below bound the rest:
// - read timeout 10 s: one recv() of a request line, header or body chunk may
//   wait this long (a slow but live uploader on a bad link still gets
//   through; a stalled one is dropped);
// - write timeout 10 s: a client that stops reading an image or an event
//   stream is dropped after this long without progress;
// - keep-alive: up to 100 requests per connection (0.11's default of 5 makes
//   pollers reconnect all the time), but an idle connection is closed after
//   3 s (it holds a file descriptor meanwhile), and a poller of 1-2 s still
//   reuses its connection;
// - TCP_NODELAY: event frames and small JSON answers leave at once instead
//   of waiting for Nagle + delayed ACK (up to 40 ms);
// - the pool: max_concurrent_streams threads may be pinned by event streams,
//   so the pool has that many plus max(8, cores) for everything else;
// - payload: set_payload_max_length(max_body_bytes) bounds Content-Length
//   bodies (httplib discards the declared bytes, then answers 413, so the
//   connection stays usable); 0.11 does not bound chunked bodies, so the
//   routes with a body read through a ContentReader that stops at the limit,
//   and "Expect: 100-continue" uploads are refused before they start.
constexpr std::time_t kReadTimeoutS = 10;
constexpr std::time_t kWriteTimeoutS = 10;
constexpr std::size_t kKeepAliveMaxCount = 100;
constexpr std::time_t kKeepAliveTimeoutS = 3;
constexpr int kMinSpareThreads = 4;        // beyond the stream slots, whatever http_threads says
constexpr int kStreamRetryAfterS = 5;      // 503 when every stream slot is taken

// When the request on this thread was routed (the pre-routing handler),
// for skyfarm_http_request_duration_seconds; the logger reads and clears it.
// httplib serves a request on one thread from routing to logging.
thread_local std::optional<std::chrono::steady_clock::time_point> request_start;

// Catch-all for methods with a body: the fallback must not read it.
const char* const kAnyPath = R"([\s\S]*)";

std::string render_path(const std::string& id) { return "/v1/renders/" + id; }

nlohmann::json render_links(const std::string& id) {
  const std::string self = render_path(id);
  return {{"self", self}, {"exr", self + "/image.exr"}, {"png", self + "/image.png"}, {"events", self + "/events"}};
}

// "GET, HEAD, POST" for a path the API serves with other methods, else nullopt.
std::optional<std::string_view> allowed_methods(std::string_view path) {
  if (auto timelapse = timelapse_allowed_methods(path)) return timelapse;
  if (auto asset = asset_allowed_methods(path)) return asset;
  if (path == "/v1/renders") return "GET, HEAD, POST";
  if (path == "/v1/sky/radiance") return "POST";
  if (path == "/v1/workers" || path == "/v1/openapi.yaml" || path == "/healthz" || path == "/metrics" ||
      path == "/v1/sky" || path == "/v1/sky/envmap.exr" || find_web_file(path))
    return "GET, HEAD";
  constexpr std::string_view kWorkers = "/v1/workers/";
  if (path.starts_with(kWorkers)) {  // /v1/workers/{id}/drain | resume
    const std::string_view rest = path.substr(kWorkers.size());
    const std::size_t slash = rest.find('/');
    if (slash == 0 || slash == std::string_view::npos) return std::nullopt;
    const std::string_view action = rest.substr(slash + 1);
    return action == "drain" || action == "resume" ? std::optional<std::string_view>("POST") : std::nullopt;
  }
  constexpr std::string_view kPrefix = "/v1/renders/";
  if (!path.starts_with(kPrefix)) return std::nullopt;
  const std::string_view rest = path.substr(kPrefix.size());
  const std::size_t slash = rest.find('/');
  if (rest.empty() || slash == 0) return std::nullopt;
  if (slash == std::string_view::npos) return "GET, HEAD, DELETE";
  const std::string_view tail = rest.substr(slash + 1);
  if (tail == "image.exr" || tail == "image.png" || tail == "events") return "GET, HEAD";
  return std::nullopt;
}

// The request carries a body (which a handler may leave unread).
bool has_body(const Request& req) {
  if (req.has_header("Transfer-Encoding")) return true;
  const std::string length = req.get_header_value("Content-Length");
  return !length.empty() && length != "0";
}

// Content-Length as sent (0 when absent or unreadable).
std::uint64_t declared_length(const Request& req) {
  return parse_decimal(req.get_header_value("Content-Length"), std::numeric_limits<std::uint64_t>::max()).value_or(0);
}

// A body left unread would be taken for the next request on this connection.
void close_if_body_unread(const Request& req, Response& res) {
  if (has_body(req)) res.set_header("Connection", "close");
}

void answer_exception(const Request& req, Response& res, std::exception_ptr error) noexcept {
  try {
    send_problem(res, problem_from_exception(error, req.method + " " + printable_excerpt(req.path)), req.path);
  } catch (...) {
    res.status = 500;
    res.body.clear();
  }
}

template <class F>
void run_guarded(const Request& req, Response& res, F&& f) noexcept {
  try {
    f();
  } catch (...) {
    answer_exception(req, res, std::current_exception());
  }
}

std::string job_id_of(const Request& req) {
  std::string id = req.matches.size() > 1 ? req.matches[1].str() : std::string();
  if (!valid_job_id(id)) throw invalid_parameter("id", std::string(kJobIdRule), quote_text(id));
  return id;
}

HttpError not_found(const std::string& id) {
  return http_error(404, "there is no render with id \"" + id + "\"");
}

void check_media_type(const Request& req) {
  const std::string type = req.get_header_value("Content-Type");
  std::string detail;
  switch (check_json_media_type(type)) {
    case MediaTypeCheck::kOk: return;
    case MediaTypeCheck::kMissing: detail = "the body must be sent with Content-Type: application/json"; break;
    case MediaTypeCheck::kNotJson: detail = "Content-Type " + quote_text(type) + " is not supported: send application/json"; break;
    case MediaTypeCheck::kBadCharset: detail = "Content-Type " + quote_text(type) + ": JSON bodies must be UTF-8"; break;
  }
  Problem p;
  p.status = 415;
  p.detail = std::move(detail);
  p.headers.emplace_back("Accept-Post", "application/json");
  throw HttpError(std::move(p));
}

std::optional<std::string> idempotency_key_of(const Request& req) {
  const std::size_t count = req.get_header_value_count("Idempotency-Key");
  if (count == 0) return std::nullopt;
  if (count > 1) throw invalid_parameter("Idempotency-Key", "must be given once", std::to_string(count) + " values");
  std::string key = req.get_header_value("Idempotency-Key");
  if (!valid_idempotency_key(key))
    throw invalid_parameter("Idempotency-Key", std::string(kIdempotencyKeyRule), quote_text(key));
  return key;
}

std::uint64_t last_event_id_of(const Request& req) {
  const std::string text = req.get_header_value("Last-Event-ID");
  if (text.empty()) return 0;
  const auto value = parse_decimal(text, std::numeric_limits<std::uint64_t>::max());
  if (!value) throw invalid_parameter("Last-Event-ID", "must be an event id (a non-negative integer)", quote_text(text));
  return *value;
}

std::string state_of(const std::optional<nlohmann::json>& status) {
  if (status && status->is_object()) {
    const auto it = status->find("state");
    if (it != status->end() && it->is_string()) return it->get<std::string>();
  }
  return "queued";
}

// The detail of an httplib-made error (no handler ran, or it left no body).
std::string generic_detail(int status, std::size_t max_body_bytes) {
  switch (status) {
    case 400: return "the request is not valid HTTP/1.1 (request line, header or body framing)";
    case 413: return "the request body is larger than " + std::to_string(max_body_bytes) + " bytes";
    case 414: return "the request target is too long";
    default: return std::string(status_phrase(status));
  }
}

// A file served in chunks (images can be tens of MB); the stream stays open on
// the file the backend named, so a newer preview renamed over it meanwhile
// does not mix two images.

}  // namespace

HttpApi::HttpApi(HttpBackend& backend, HttpOptions options)
    : backend_(backend),
      options_(std::move(options)),
      streams_(std::max(0, options_.max_concurrent_streams)),
      sky_(std::make_unique<SkyHttp>(options_.sky ? options_.sky : std::make_shared<SkyService>(),
                                     options_.token.has_value())) {
  if (options_.timelapses)
    timelapses_ = std::make_unique<TimelapseHttp>(*options_.timelapses, options_.token.has_value());
  if (options_.assets) assets_ = std::make_unique<AssetHttp>(*options_.assets);
}

HttpApi::~HttpApi() = default;

void HttpApi::register_routes(httplib::Server& server) {
  gate_ = dynamic_cast<const GatedHttpServer*>(&server);
  configure_server(server);
  add_routes(server);
  add_fallbacks(server);
}

void HttpApi::configure_server(httplib::Server& server) {
  // The largest body any route takes; each route reads its own limit.
  server.set_payload_max_length(std::max(options_.max_body_bytes, body_limit("/v1/assets")));
  server.set_read_timeout(kReadTimeoutS, 0);
  server.set_write_timeout(kWriteTimeoutS, 0);
  server.set_keep_alive_max_count(kKeepAliveMaxCount);
  server.set_keep_alive_timeout(kKeepAliveTimeoutS);
  server.set_tcp_nodelay(true);
  const int streams = std::max(0, options_.max_concurrent_streams);
  const int cores = static_cast<int>(std::thread::hardware_concurrency());
  const int threads = options_.http_threads > 0 ? std::max(options_.http_threads, streams + kMinSpareThreads)
                                                : streams + std::max(8, cores);
  server.new_task_queue = [threads] { return new httplib::ThreadPool(static_cast<std::size_t>(threads)); };

  using WithResponse = httplib::Server::HandlerWithResponse;
  server.set_pre_routing_handler(WithResponse([this](const Request& req, Response& res) {
    request_start = std::chrono::steady_clock::now();
    return admitted(req, res) ? HandlerResponse::Unhandled : HandlerResponse::Handled;
  }));
  server.set_expect_100_continue_handler(
      [this](const Request& req, Response& res) { return expect_continue(req, res); });
  server.set_error_handler(WithResponse([this](const Request& req, Response& res) {
    return answer_library_error(req, res) ? HandlerResponse::Handled : HandlerResponse::Unhandled;
  }));
  server.set_exception_handler([](const Request& req, Response& res, std::exception_ptr error) {
    answer_exception(req, res, error);
  });
  server.set_logger([this](const Request& req, const Response& res) { log_response(req, res); });
}

bool HttpApi::admitted(const Request& req, Response& res) const {
  // The web page's files are public; the page sends the token on its API calls.
  if (!options_.token || req.path == "/healthz" || find_web_file(req.path) || authorized(req)) return true;
  run_guarded(req, res, [&] { answer_unauthorized(req, res); });
  return false;
}

int HttpApi::expect_continue(const Request& req, Response& res) const {
  int status = 100;
  run_guarded(req, res, [&] {
    if (!admitted(req, res)) {
      status = 401;
    } else if (declared_length(req) > body_limit(req.path)) {
      res.set_header("Connection", "close");
      Problem p;
      p.status = 413;
      p.detail = generic_detail(413, body_limit(req.path));
      send_problem(res, p, req.path);
      status = 413;
    }
  });
  // httplib 0.11 writes this answer without Content-Length unless told.
  if (status != 100) res.set_header("Content-Length", std::to_string(res.body.size()));
  return status;
}

bool HttpApi::answer_library_error(const Request& req, Response& res) {
  if (!res.body.empty() || res.content_provider_) return false;  // a handler's problem document already
  run_guarded(req, res, [&] {
    if (res.status == 404) {  // no route matched, or a method httplib keeps no handlers for
      fallback(req, res);
      return;
    }
    Problem p;
    p.status = res.status;
    p.detail = generic_detail(res.status, body_limit(req.path));
    send_problem(res, p, req.path);
  });
  return true;
}

void HttpApi::log_response(const Request& req, const Response& res) noexcept {
  responses_.count(res.status);
  std::optional<double> seconds;
  if (request_start) seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - *request_start).count();
  request_start.reset();
  try {
    requests_.observe(req.method, req.path, res.status, seconds);
  } catch (...) {  // out of memory: the count is lost, the connection goes on
  }
  if (!options_.on_response) return;
  try {
    options_.on_response(req, res);
  } catch (...) {  // a logging failure must not end the connection's thread
  }
}

std::function<void(const Request&, Response&)> HttpApi::guarded(Handler handler) {
  return [this, handler](const Request& req, Response& res) {
    run_guarded(req, res, [&] { (this->*handler)(req, res); });
  };
}

void HttpApi::add_routes(httplib::Server& server) {
  RouteRegistrar routes(server);
  routes.post("/v1/renders", [this](const Request& req, Response& res, const ContentReader& reader) {
    run_guarded(req, res, [&] { submit(req, res, reader); });
  });
  routes.get("/v1/renders", guarded(&HttpApi::list));
  routes.get("/v1/renders/{id}", guarded(&HttpApi::status));
  routes.del("/v1/renders/{id}", [this](const Request& req, Response& res, const ContentReader&) {
    close_if_body_unread(req, res);  // a DELETE body means nothing here
    run_guarded(req, res, [&] { cancel(req, res); });
  });
  routes.get("/v1/renders/{id}/image.exr", guarded(&HttpApi::image_exr));
  routes.get("/v1/renders/{id}/image.png", guarded(&HttpApi::image_png));
  routes.get("/v1/renders/{id}/events", guarded(&HttpApi::events));
  routes.get("/v1/workers", guarded(&HttpApi::workers));
  for (const bool drain : {true, false})
    routes.post(drain ? "/v1/workers/{id}/drain" : "/v1/workers/{id}/resume",
                [this, drain](const Request& req, Response& res, const ContentReader&) {
                  close_if_body_unread(req, res);  // the route takes no body
                  run_guarded(req, res, [&] { drain_worker(req, res, drain); });
                });
  routes.get("/v1/sky", guarded(&HttpApi::sky));
  routes.post("/v1/sky/radiance", [this](const Request& req, Response& res, const ContentReader& reader) {
    run_guarded(req, res, [&] { sky_radiance(req, res, reader); });
  });
  routes.get("/v1/sky/envmap.exr", guarded(&HttpApi::sky_envmap));
  routes.get("/v1/openapi.yaml", guarded(&HttpApi::openapi));
  routes.get("/healthz", guarded(&HttpApi::healthz));
  routes.get("/metrics", guarded(&HttpApi::metrics));
  routes.get("/", guarded(&HttpApi::web_file));
  routes.get("/web/{file}", guarded(&HttpApi::web_file));
  if (timelapses_)
    timelapses_->add_routes(
        routes, {[](const Request& req, Response& res, const std::function<void()>& handler) {
                   run_guarded(req, res, handler);
                 },
                 [this](const Request& req, Response& res, const ContentReader& reader) {
                   std::string body = read_body(req, res, reader);
                   check_media_type(req);
                   if (options_.max_json_depth < api::kMaxJsonDepth && json_deeper_than(body, options_.max_json_depth))
                     throw api::ValidationError({api::FieldError{
                         "", "JSON nested deeper than " + std::to_string(options_.max_json_depth) + " levels", ""}});
                   return body;
                 },
                 [](const Request& req) { return idempotency_key_of(req); },
                 [this](const api::RenderRequest& request) { admit_objects(request); }});
  if (assets_)
    assets_->add_routes(routes, {[](const Request& req, Response& res, const std::function<void()>& handler) {
                                   run_guarded(req, res, handler);
                                 },
                                 [this](const Request& req, Response& res, const ContentReader& reader,
                                        std::size_t limit) { return read_body(req, res, reader, limit); }});
  routes_ = routes.added();
  requests_.set_routes(routes_);
}

void HttpApi::add_fallbacks(httplib::Server& server) {
  // GET/HEAD paths that match no route reach the error handler as 404 (no
  // body to read).  Methods with a body get a handler that leaves it unread:
  // httplib 0.11 would otherwise read a chunked body of any size first.
  auto unread = httplib::Server::HandlerWithContentReader(
      [this](const Request& req, Response& res, const ContentReader&) {
        close_if_body_unread(req, res);
        run_guarded(req, res, [&] { fallback(req, res); });
      });
  server.Post(kAnyPath, unread);
  server.Put(kAnyPath, unread);
  server.Patch(kAnyPath, unread);
  server.Delete(kAnyPath, unread);
  server.Options(kAnyPath, guarded(&HttpApi::fallback));
}

// --- Routes ------------------------------------------------------------------

void HttpApi::submit(const Request& req, Response& res, const ContentReader& reader) {
  const std::string body = read_body(req, res, reader);
  check_media_type(req);
  const std::optional<std::string> key = idempotency_key_of(req);
  if (options_.max_json_depth < api::kMaxJsonDepth && json_deeper_than(body, options_.max_json_depth))
    throw api::ValidationError(
        {api::FieldError{"", "JSON nested deeper than " + std::to_string(options_.max_json_depth) + " levels", ""}});
  const api::RenderRequest request = api::parse_render_request(std::string_view(body));
  admit_objects(request);
  const SubmitResult result = backend_.submit(request, key);
  const nlohmann::json answer = {{"id", result.id},
                                 {"state", state_of(backend_.status(result.id))},
                                 {"created", result.created},
                                 {"from_cache", result.from_cache},
                                 {"links", render_links(result.id)}};
  res.set_header("Location", render_path(result.id));
  send_json(res, 202, answer);
}

// The mesh assets a request's objects name, and the volumes its clouds name,
// must be in the store before a job is made, or every worker would fail its
// units (400 naming objects[i].asset or clouds.volumes[i].asset).
void HttpApi::admit_objects(const api::RenderRequest& request) const {
  std::vector<api::FieldError> errors = missing_assets(api::render_spec(request).objects, options_.assets);
  for (api::FieldError& e : missing_volume_assets(request.clouds, options_.assets)) errors.push_back(std::move(e));
  if (!errors.empty()) throw api::ValidationError(std::move(errors));
}

void HttpApi::list(const Request& req, Response& res) {
  const Page page = page_of(req);
  nlohmann::json renders = backend_.list(page.offset, page.limit);
  const std::size_t total = backend_.job_count();
  send_json(res, 200,
            {{"renders", std::move(renders)}, {"offset", page.offset}, {"limit", page.limit}, {"total", total}});
}

void HttpApi::status(const Request& req, Response& res) {
  const std::string id = job_id_of(req);
  send_json_or_throw(res, 200, backend_.status(id), not_found(id));
}

// DELETE /v1/renders/{id}: cancels (202 with the status; a finished job's
// status as it is).  ?purge=true also removes the job's files and record:
// 204, and the id is unknown afterwards.
void HttpApi::cancel(const Request& req, Response& res) {
  const std::string id = job_id_of(req);
  const std::size_t given = req.get_param_value_count("purge");
  const std::string purge = given ? req.get_param_value("purge") : "false";
  if (given > 1 || (purge != "true" && purge != "false"))
    throw invalid_parameter("purge", given > 1 ? "must be given once" : "must be true or false", quote_text(purge));
  if (purge == "true") {
    const PurgeOutcome outcome = backend_.purge(id);
    if (outcome.kind == PurgeOutcome::kUnknown) throw not_found(id);
    if (outcome.kind == PurgeOutcome::kConflict) throw http_error(409, outcome.detail);
    res.status = 204;
    return;
  }
  if (!backend_.cancel(id)) throw not_found(id);
  send_json_or_throw(res, 202, backend_.status(id), not_found(id));
}

void HttpApi::image_exr(const Request& req, Response& res) { image(req, res, ImageFormat::kExr); }
void HttpApi::image_png(const Request& req, Response& res) {
  if (req.has_param("width")) thumbnail(req, res);
  else image(req, res, ImageFormat::kPng);
}

// GET .../image.png?width=N: the PNG scaled down to N pixels wide (aspect
// kept; common/image/png_thumbnail.h), for lists.  A final image's thumbnail
// is written once beside it (image-wN.png, removed with the job's files) and
// served with the image's ETag and a "-wN" suffix; a preview's is made for
// each request and not kept (the preview changes as units merge).
void HttpApi::thumbnail(const Request& req, Response& res) {
  constexpr int kMaxThumbnailWidth = 1024;
  const std::string text = req.get_param_value("width");
  const auto width = parse_decimal(text, kMaxThumbnailWidth);
  if (req.get_param_value_count("width") > 1 || !width || *width < 1)
    throw invalid_parameter("width", "must be an integer in [1, 1024], given once", quote_text(text));
  const std::string id = job_id_of(req);
  const ImageFile file = image_file(id, ImageFormat::kPng);
  const std::string suffix = "-w" + std::to_string(*width);
  std::string etag = file.etag;
  etag.insert(etag.empty() ? 0 : etag.size() - 1, suffix);  // inside the quotes
  const std::lock_guard<std::mutex> lock(thumbnail_writer_);  // one writer of a thumbnail file at a time
  try {
    if (file.final) {
      const std::filesystem::path thumb = file.path.parent_path() / ("image" + suffix + ".png");
      if (!std::filesystem::exists(thumb)) write_png_thumbnail(file.path, thumb, static_cast<int>(*width));
      send_file(req, res, ImageFile{thumb, etag, true},
                {"image/png", id + suffix + ".png", final_cache_control(options_.token.has_value()),
                 "the thumbnail of render \"" + id + "\" could not be read"});
      return;
    }
    const std::filesystem::path thumb = file.path.parent_path() / "preview-thumbnail.png";
    write_png_thumbnail(file.path, thumb, static_cast<int>(*width));
    std::ifstream in(thumb, std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::error_code ec;
    std::filesystem::remove(thumb, ec);
    res.status = 200;
    res.set_header("ETag", etag);
    res.set_header("Cache-Control", "no-cache");
    res.set_content(std::move(bytes), "image/png");
  } catch (const HttpError&) {
    throw;
  } catch (const std::exception& e) {
    throw http_error(500, "the thumbnail of render \"" + id + "\" could not be made: " + std::string(e.what()));
  }
}

void HttpApi::image(const Request& req, Response& res, ImageFormat format) {
  const std::string id = job_id_of(req);
  const ImageFile file = image_file(id, format);
  const bool exr = format == ImageFormat::kExr;
  send_file(req, res, file,
            {exr ? "image/x-exr" : "image/png", id + (exr ? ".exr" : ".png"), final_cache_control(options_.token.has_value()),
             "the image file of render \"" + id + "\" could not be read"});
}

// The image file of a render, or the problem that says why there is none.
ImageFile HttpApi::image_file(const std::string& id, ImageFormat format) {
  const std::optional<ImageFile> file = backend_.image(id, format);
  if (!file) {
    const std::optional<nlohmann::json> doc = backend_.status(id);
    if (!doc) throw not_found(id);
    if (doc->value("expired", false))
      throw http_error(410, "render \"" + id + "\" finished longer ago than this server keeps files "
                            "(--retention-hours): its images were deleted; submit the request again to render it anew");
    const std::string state = state_of(doc);
    if (state == "cancelled" || state == "failed")
      throw http_error(409, "render \"" + id + "\" is " + state + ": it has no image (its partial results were deleted)");
    Problem p;
    p.status = 409;
    p.type = std::string(kProblemImageNotReady);
    p.title = "The image is not available yet";
    p.detail = "render \"" + id + "\" (state " + state +
               ") has no image: its first pass has not covered the whole frame yet";
    throw HttpError(std::move(p));
  }
  return *file;
}

void HttpApi::events(const Request& req, Response& res) {
  const std::string id = job_id_of(req);
  const std::uint64_t after = last_event_id_of(req);
  if (!backend_.status(id)) throw not_found(id);
  std::shared_ptr<void> slot = streams_.try_acquire();
  if (!slot) {
    Problem p;
    p.status = 503;
    p.type = std::string(kProblemTooManyStreams);
    p.title = "Too many event streams";
    p.detail = "this server allows " + std::to_string(options_.max_concurrent_streams) +
               " event streams at once; retry later, or poll " + render_path(id);
    p.headers.emplace_back("Retry-After", std::to_string(kStreamRetryAfterS));
    throw HttpError(std::move(p));
  }
  auto stream = std::make_shared<EventStream>(backend_, id, after, options_.sse_keepalive);
  res.status = 200;
  res.set_header("Cache-Control", "no-cache");
  res.set_header("X-Accel-Buffering", "no");  // proxies must not buffer the stream
  // The slot is released when httplib destroys the provider (stream over, peer gone, HEAD).
  res.set_chunked_content_provider("text/event-stream",
                                   [stream, slot](std::size_t, httplib::DataSink& sink) { return stream->provide(sink); });
}

void HttpApi::workers(const Request&, Response& res) { send_json(res, 200, {{"workers", backend_.workers()}}); }

// POST /v1/workers/{id}/drain | resume: 200 with the worker's entry of GET
// /v1/workers ("draining" as set); 404 for a worker not connected.
void HttpApi::drain_worker(const Request& req, Response& res, bool drain) {
  const std::string id = req.matches.size() > 1 ? req.matches[1].str() : std::string();
  if (!backend_.set_worker_draining(id, drain))
    throw http_error(404, "there is no connected worker with id " + quote_text(id) + " (GET /v1/workers lists them)");
  for (const nlohmann::json& w : backend_.workers())
    if (w.value("id", "") == id) {
      send_json(res, 200, w);
      return;
    }
  throw http_error(404, "worker " + quote_text(id) + " left");
}

void HttpApi::sky(const Request& req, Response& res) { sky_->lookup(req, res); }

// POST /v1/sky/radiance: the radiance probe.  "lut" is answered here
// from one-bin tables per wavelength (bounded: one table build each); "path"
// is traced on the farm and waited for (server/probes/http_probe.h).
void HttpApi::sky_radiance(const Request& req, Response& res, const ContentReader& reader) {
  constexpr std::size_t kMaxLutWavelengths = 64;  // one table build each
  const std::string body = read_body(req, res, reader);
  check_media_type(req);
  if (options_.max_json_depth < api::kMaxJsonDepth && json_deeper_than(body, options_.max_json_depth))
    throw api::ValidationError(
        {api::FieldError{"", "JSON nested deeper than " + std::to_string(options_.max_json_depth) + " levels", ""}});
  const api::ProbeRequest request = api::parse_probe_request(std::string_view(body));
  if (request.method == api::Method::kPath) {
    answer_farm_probe(options_.probes.get(), request, options_.probe_timeout, res);
    return;
  }
  if (request.wavelengths_nm.size() > kMaxLutWavelengths)
    throw api::ValidationError({api::FieldError{"wavelengths_nm", "at most 64 wavelengths with method lut on the server",
                                                std::to_string(request.wavelengths_nm.size())}});
  send_json(res, 200, api::probe_answer_json(request, answer_probe(api::probe_spec(request), 1)));
}
void HttpApi::sky_envmap(const Request& req, Response& res) { sky_->envmap(req, res); }

void HttpApi::openapi(const Request&, Response& res) {
  const std::string_view text = openapi_yaml();
  if (text.empty()) throw http_error(500, "the OpenAPI document was not built into this server");
  res.status = 200;
  res.set_content(text.data(), text.size(), kOpenApiContentType);
}

void HttpApi::web_file(const Request& req, Response& res) { serve_web_file(req, res); }

void HttpApi::healthz(const Request&, Response& res) { send_json(res, 200, {{"status", "ok"}}); }

void HttpApi::metrics(const Request&, Response& res) {
  res.status = 200;
  nlohmann::json figures = backend_.metrics();
  const nlohmann::json extra = options_.extra_metrics ? options_.extra_metrics() : nlohmann::json::object();
  if (figures.is_object() && extra.is_object())  // the broker's counters; a shared name is summed
    for (const auto& [key, value] : extra.items()) {
      if (!value.is_number()) continue;
      const auto it = figures.find(key);
      if (it == figures.end() || !it->is_number()) figures[key] = value;
      else if (it->is_number_unsigned() && value.is_number_unsigned()) *it = it->get<std::uint64_t>() + value.get<std::uint64_t>();
      else *it = it->get<double>() + value.get<double>();
    }
  std::vector<HistogramSeries> histograms = backend_.histograms();
  if (options_.timelapses)  // kind="timelapse" series of skyfarm_job_duration_seconds
    for (HistogramSeries& h : options_.timelapses->histograms()) histograms.push_back(std::move(h));
  std::string text = prometheus_text(figures, responses_, open_streams(), &requests_, histograms);
  append_sky_cache_metrics(text, sky_->service().stats());
  if (options_.probes) append_probe_metrics(text, options_.probes->stats());
  if (gate_) append_gate_metrics(text, gate_->stats());
  res.set_content(std::move(text), kPrometheusContentType);
}

void HttpApi::fallback(const Request& req, Response& res) {
  const std::optional<std::string_view> allow = allowed_methods(req.path);
  if (!allow) throw http_error(404, "no route " + quote_text(req.path) + "; the routes are listed in /v1/openapi.yaml");
  if (req.method == "OPTIONS") {
    res.status = 204;
    res.set_header("Allow", std::string(*allow));
    return;
  }
  Problem p;
  p.status = 405;
  p.detail = req.method + " is not allowed on " + quote_text(req.path) + "; allowed: " + std::string(*allow);
  p.headers.emplace_back("Allow", std::string(*allow));
  throw HttpError(std::move(p));
}

// --- Helpers -----------------------------------------------------------------

std::size_t HttpApi::body_limit(std::string_view path) const {
  if (options_.assets && path == "/v1/assets") return options_.assets->options().max_upload_bytes;
  return options_.max_body_bytes;
}

std::string HttpApi::read_body(const Request& req, Response& res, const ContentReader& reader) const {
  return read_body(req, res, reader, options_.max_body_bytes);
}

std::string HttpApi::read_body(const Request& req, Response& res, const ContentReader& reader,
                               std::size_t limit) const {
  if (!has_body(req)) return {};  // no Content-Length nor Transfer-Encoding: an empty body (RFC 9112 §6.3)
  std::string body;
  bool too_large = false;
  const bool complete = reader([&](const char* data, std::size_t n) {
    if (n > limit - body.size()) {
      too_large = true;  // chunked bodies: httplib 0.11 does not bound them itself
      return false;
    }
    body.append(data, n);
    return true;
  });
  if (too_large || res.status == 413) {
    if (too_large) res.set_header("Connection", "close");  // the rest of the body is still on the wire
    throw http_error(413, generic_detail(413, limit));
  }
  if (!complete) {
    res.set_header("Connection", "close");
    throw http_error(400, "the request body could not be read (truncated, or malformed chunked encoding)");
  }
  return body;
}

bool HttpApi::authorized(const Request& req) const {
  if (req.get_header_value_count("Authorization") != 1) return false;
  const std::string header = req.get_header_value("Authorization");
  const std::optional<std::string_view> token = bearer_token(header);
  return token && constant_time_equal(*token, *options_.token);
}

void HttpApi::answer_unauthorized(const Request& req, Response& res) const {
  const bool presented = req.has_header("Authorization");
  Problem p;
  p.status = 401;
  p.detail = presented ? "the bearer token is not valid" : "this server requires Authorization: Bearer <token>";
  p.headers.emplace_back("WWW-Authenticate",
                         presented ? R"(Bearer realm="skyfarm", error="invalid_token")" : R"(Bearer realm="skyfarm")");
  close_if_body_unread(req, res);
  send_problem(res, p, req.path);
}

}  // namespace skyfarm::server
