#include "server/timelapse/timelapse_http.h"

#include <httplib.h>

#include <cstdio>

#include "api/timelapse_request.h"
#include "server/http/http_checks.h"
#include "server/http/http_files.h"
#include "server/http/http_problem.h"
#include "server/http/http_query.h"
#include "server/http/http_routes.h"

namespace skyfarm::server {
namespace {

using httplib::ContentReader;
using httplib::Request;
using httplib::Response;

inline constexpr std::string_view kProblemNotReady = "urn:skyfarm:problem:timelapse-file-not-ready";
inline constexpr std::string_view kProblemVideoUnavailable = "urn:skyfarm:problem:video-unavailable";
constexpr std::uint64_t kMaxFrameIndex = 999999;

std::string id_of(const Request& req) {
  std::string id = req.matches.size() > 1 ? req.matches[1].str() : std::string();
  if (!valid_job_id(id)) throw invalid_parameter("id", std::string(kJobIdRule), quote_text(id));
  return id;
}

HttpError not_found(const std::string& id) { return http_error(404, "there is no timelapse with id \"" + id + "\""); }

}  // namespace

std::optional<std::string_view> timelapse_allowed_methods(std::string_view path) {
  if (path == "/v1/timelapses") return "GET, HEAD, POST";
  constexpr std::string_view kPrefix = "/v1/timelapses/";
  if (!path.starts_with(kPrefix)) return std::nullopt;
  const std::string_view rest = path.substr(kPrefix.size());
  const std::size_t slash = rest.find('/');
  if (rest.empty() || slash == 0) return std::nullopt;
  if (slash == std::string_view::npos) return "GET, HEAD, DELETE";
  const std::string_view tail = rest.substr(slash + 1);
  if (tail == "frames" || tail == "contact_sheet.png" || tail == "video.mp4") return "GET, HEAD";
  if (tail.starts_with("frames/") && (tail.ends_with(".exr") || tail.ends_with(".png"))) return "GET, HEAD";
  return std::nullopt;
}

TimelapseHttp::TimelapseHttp(TimelapseService& service, bool private_cache)
    : service_(service),
      cache_final_(final_cache_control(private_cache)) {}

void TimelapseHttp::add_routes(RouteRegistrar& routes, Hooks hooks) {
  hooks_ = std::move(hooks);
  using Handler = void (TimelapseHttp::*)(const Request&, Response&) const;
  auto guarded = [this](Handler h) {
    return [this, h](const Request& req, Response& res) { hooks_.guard(req, res, [&] { (this->*h)(req, res); }); };
  };
  routes.post("/v1/timelapses", [this](const Request& req, Response& res, const ContentReader& reader) {
    hooks_.guard(req, res, [&] { submit(req, res, reader); });
  });
  routes.get("/v1/timelapses", guarded(&TimelapseHttp::list));
  routes.get("/v1/timelapses/{id}", guarded(&TimelapseHttp::status));
  routes.del("/v1/timelapses/{id}", [this](const Request& req, Response& res, const ContentReader&) {
    if (req.has_header("Content-Length") || req.has_header("Transfer-Encoding"))
      res.set_header("Connection", "close");  // a DELETE body means nothing here and stays unread
    hooks_.guard(req, res, [&] { cancel(req, res); });
  });
  routes.get("/v1/timelapses/{id}/frames", guarded(&TimelapseHttp::frames));
  routes.get("/v1/timelapses/{id}/frames/{n}.exr", guarded(&TimelapseHttp::frame_file));
  routes.get("/v1/timelapses/{id}/frames/{n}.png", guarded(&TimelapseHttp::frame_file));
  routes.get("/v1/timelapses/{id}/contact_sheet.png", guarded(&TimelapseHttp::contact_sheet));
  routes.get("/v1/timelapses/{id}/video.mp4", guarded(&TimelapseHttp::video));
}

void TimelapseHttp::submit(const Request& req, Response& res, const ContentReader& reader) {
  const std::string body = hooks_.json_body(req, res, reader);
  const std::optional<std::string> key = hooks_.idempotency_key(req);
  const api::TimelapseRequest request = api::parse_timelapse_request(body, service_.options().max_frames);
  if (hooks_.admit_objects) hooks_.admit_objects(request.base);
  const SubmitResult result = service_.submit(request, key);
  std::optional<nlohmann::json> doc = service_.status(result.id);
  if (!doc) throw http_error(500, "the timelapse vanished after its submission");
  (*doc)["created"] = result.created;
  (*doc)["from_cache"] = result.from_cache;
  res.set_header("Location", "/v1/timelapses/" + result.id);
  send_json(res, 202, *doc);
}

void TimelapseHttp::list(const Request& req, Response& res) const {
  const Page page = page_of(req);
  nlohmann::json timelapses = service_.list(page.offset, page.limit);
  send_json(res, 200, {{"timelapses", std::move(timelapses)},
                       {"offset", page.offset},
                       {"limit", page.limit},
                       {"total", service_.count()}});
}

void TimelapseHttp::status(const Request& req, Response& res) const {
  const std::string id = id_of(req);
  send_json_or_throw(res, 200, service_.status(id), not_found(id));
}

void TimelapseHttp::cancel(const Request& req, Response& res) {
  const std::string id = id_of(req);
  if (!service_.cancel(id)) throw not_found(id);
  send_json_or_throw(res, 202, service_.status(id), not_found(id));
}

void TimelapseHttp::frames(const Request& req, Response& res) const {
  const std::string id = id_of(req);
  const std::optional<nlohmann::json> doc = service_.status(id);
  if (!doc) throw not_found(id);
  send_json(res, 200, {{"id", id}, {"frames", (*doc)["frames"]}});
}

void TimelapseHttp::frame_file(const Request& req, Response& res) const {
  const std::string id = id_of(req);
  const std::string index_text = req.matches.size() > 2 ? req.matches[2].str() : std::string();
  const auto index = parse_decimal(index_text, kMaxFrameIndex);
  if (!index) throw invalid_parameter("frame", "must be a frame index (0, 1, 2, ...)", quote_text(index_text));
  const bool exr = req.path.ends_with(".exr");  // the routes are {n}.exr and {n}.png
  const TimelapseFile file = service_.frame_image(id, static_cast<int>(*index), exr ? ImageFormat::kExr : ImageFormat::kPng);
  char name[64];
  std::snprintf(name, sizeof name, "%s-frame-%05d.%s", id.c_str(), static_cast<int>(*index), exr ? "exr" : "png");
  send(req, res, file, exr ? "image/x-exr" : "image/png", name);
}

void TimelapseHttp::contact_sheet(const Request& req, Response& res) const {
  const std::string id = id_of(req);
  send(req, res, service_.contact_sheet(id), "image/png", id + "-contact-sheet.png");
}

void TimelapseHttp::video(const Request& req, Response& res) const {
  const std::string id = id_of(req);
  send(req, res, service_.video(id), "video/mp4", id + ".mp4");
}

void TimelapseHttp::send(const Request& req, Response& res, const TimelapseFile& file, const char* content_type,
                         const std::string& filename) const {
  const std::string id = req.matches.size() > 1 ? req.matches[1].str() : std::string();
  switch (file.status) {
    case TimelapseFile::Status::kOk: break;
    case TimelapseFile::Status::kUnknownTimelapse: throw not_found(id);
    case TimelapseFile::Status::kUnknownFrame: throw http_error(404, file.detail);
    case TimelapseFile::Status::kNotReady: {
      Problem p;
      p.status = 409;
      p.type = std::string(kProblemNotReady);
      p.title = "The file is not available yet";
      p.detail = file.detail;
      throw HttpError(std::move(p));
    }
    case TimelapseFile::Status::kUnavailable: {
      Problem p;
      p.status = 404;
      p.type = std::string(kProblemVideoUnavailable);
      p.title = "There is no video";
      p.detail = file.detail;
      throw HttpError(std::move(p));
    }
  }
  send_file(req, res, *file.file,
            {content_type, filename, cache_final_, "a file of timelapse \"" + id + "\" could not be read"});
}

}  // namespace skyfarm::server
