#include "server/http/http_files.h"

#include <httplib.h>

#include <algorithm>
#include <fstream>
#include <memory>
#include <vector>

#include "server/http/http_checks.h"
#include "server/http/http_problem.h"

namespace skyfarm::server {
namespace {

// A file streamed in chunks from the stream opened when the answer began.
struct FileBody {
  std::ifstream in;
  std::vector<char> buffer = std::vector<char>(64 * 1024);

  bool provide(std::size_t offset, std::size_t length, httplib::DataSink& sink) {
    const std::size_t n = std::min(length, buffer.size());
    in.seekg(static_cast<std::streamoff>(offset));
    in.read(buffer.data(), static_cast<std::streamsize>(n));
    if (static_cast<std::size_t>(in.gcount()) != n) return false;
    return sink.write(buffer.data(), n);
  }
};

}  // namespace

const char* final_cache_control(bool private_cache) {
  return private_cache ? "private, max-age=31536000, immutable" : "public, max-age=31536000, immutable";
}

void send_file(const httplib::Request& req, httplib::Response& res, const ImageFile& file, const FileAnswer& answer) {
  res.set_header("ETag", file.etag);
  res.set_header("Cache-Control", file.final ? answer.cache_final : "no-cache");
  if (if_none_match_matches(req.get_header_value("If-None-Match"), file.etag)) {
    res.status = 304;
    return;
  }
  auto body = std::make_shared<FileBody>();
  body->in.open(file.path, std::ios::binary);
  body->in.seekg(0, std::ios::end);
  const std::streamoff size = body->in ? static_cast<std::streamoff>(body->in.tellg()) : -1;
  if (!body->in || size < 0) {
    log_server_error("GET " + req.path, "cannot read " + file.path.string());
    throw http_error(500, answer.unreadable_detail);
  }
  res.set_header("Content-Disposition", "inline; filename=\"" + answer.filename + "\"");
  res.status = 200;
  res.set_content_provider(static_cast<std::size_t>(size), answer.content_type,
                           [body](std::size_t offset, std::size_t length, httplib::DataSink& sink) {
                             return body->provide(offset, length, sink);
                           });
}

}  // namespace skyfarm::server
