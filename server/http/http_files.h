// Files on disk answered over HTTP (render images, timelapse frames, the
// contact sheet, the video): one place for how every such route answers.
//
//   final_cache_control(private_cache)  Cache-Control of a file that will not
//                                       change: "public, max-age=31536000,
//                                       immutable", or "private, ..." when the
//                                       API needs a token (never in shared caches)
//   send_file(req, res, file, answer)   ETag and Cache-Control (`answer.cache_final`
//                                       when file.final, else "no-cache"); 304 when
//                                       If-None-Match matches; else 200 with
//                                       Content-Disposition: inline; filename=...,
//                                       the body streamed in 64 KiB chunks from a
//                                       stream opened now (a newer file renamed over
//                                       it meanwhile does not mix two versions).
//                                       An unreadable file is logged and thrown as a
//                                       500 whose detail is `answer.unreadable_detail`.
#pragma once
#include <string>

#include "server/http/http_backend.h"

namespace httplib {
struct Request;
struct Response;
}  // namespace httplib

namespace skyfarm::server {

const char* final_cache_control(bool private_cache);

struct FileAnswer {
  const char* content_type;        // "image/png", "video/mp4", ...
  std::string filename;            // for Content-Disposition
  const char* cache_final;         // final_cache_control(...)
  std::string unreadable_detail;   // the 500's detail when the file cannot be read
};

void send_file(const httplib::Request& req, httplib::Response& res, const ImageFile& file, const FileAnswer& answer);

}  // namespace skyfarm::server
