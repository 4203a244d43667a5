// The timelapse routes of the HTTP API, registered by
// HttpApi when it has a TimelapseService (HttpOptions::timelapses):
//
//   POST   /v1/timelapses                     a timelapse request (api/timelapse_request.h)
//                                             -> 202, Location, the status document
//                                             (+ "created", "from_cache"); Idempotency-Key honoured
//   GET    /v1/timelapses?offset=&limit=      newest first, limit 1..100 (default 20)
//                                             -> {"timelapses", "offset", "limit", "total"}
//   GET    /v1/timelapses/{id}                the status document
//   DELETE /v1/timelapses/{id}                cancel every frame -> 202 + the status document
//   GET    /v1/timelapses/{id}/frames         {"frames": [...]} (the status document's list)
//   GET    /v1/timelapses/{id}/frames/{n}.exr the frame's render image (progressive, then final)
//   GET    /v1/timelapses/{id}/frames/{n}.png the frame's render PNG while the timelapse runs;
//                                             once done, the frame exposed as the sequence is
//   GET    /v1/timelapses/{id}/contact_sheet.png  once done (409 before)
//   GET    /v1/timelapses/{id}/video.mp4      once done (409 before; 404 when there is
//                                             no video, e.g. no ffmpeg, with the reason)
//
// Files carry strong ETags (If-None-Match -> 304) and Cache-Control as the
// render images do.  Errors are problem documents: 400 naming the field or
// path parameter (body fields as for renders; "id", "frame"), 404 unknown
// timelapse or frame index, 409 a file not made yet, 422/429/507 as for renders.
#pragma once
#include <functional>
#include <optional>
#include <string>
#include <string_view>

#include "server/timelapse/timelapse_service.h"
#include "server/http/httplib_fwd.h"

namespace skyfarm::server {

class RouteRegistrar;

class TimelapseHttp {
 public:
  // What HttpApi lends to these routes, so that they behave as its own.
  struct Hooks {
    // Runs a handler; its exceptions become problem documents.
    std::function<void(const httplib::Request&, httplib::Response&, const std::function<void()>&)> guard;
    // A JSON body checked as POST /v1/renders checks it (size, media type, depth).
    std::function<std::string(const httplib::Request&, httplib::Response&, const httplib::ContentReader&)> json_body;
    // The Idempotency-Key header, validated.
    std::function<std::optional<std::string>(const httplib::Request&)> idempotency_key;
    // Throws api::ValidationError when the frames' objects name mesh assets
    // the server lacks (as POST /v1/renders refuses them); empty: no check.
    std::function<void(const api::RenderRequest&)> admit_objects;
  };

  // private_cache: final files are "private" (the API needs a token).
  TimelapseHttp(TimelapseService& service, bool private_cache);
  void add_routes(RouteRegistrar& routes, Hooks hooks);

 private:
  void submit(const httplib::Request& req, httplib::Response& res, const httplib::ContentReader& reader);
  void list(const httplib::Request& req, httplib::Response& res) const;
  void status(const httplib::Request& req, httplib::Response& res) const;
  void cancel(const httplib::Request& req, httplib::Response& res);
  void frames(const httplib::Request& req, httplib::Response& res) const;
  void frame_file(const httplib::Request& req, httplib::Response& res) const;
  void contact_sheet(const httplib::Request& req, httplib::Response& res) const;
  void video(const httplib::Request& req, httplib::Response& res) const;
  void send(const httplib::Request& req, httplib::Response& res, const TimelapseFile& file, const char* content_type,
            const std::string& filename) const;

  TimelapseService& service_;
  const char* cache_final_;
  Hooks hooks_;
};

// "GET, HEAD, POST", ... for a timelapse path (405 answers), else nullopt.
std::optional<std::string_view> timelapse_allowed_methods(std::string_view path);

}  // namespace skyfarm::server
