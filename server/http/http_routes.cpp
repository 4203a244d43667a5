#include "server/http/http_routes.h"

#include <httplib.h>

#include <stdexcept>

namespace skyfarm::server {

std::string route_pattern(std::string_view path) {
  std::string pattern;
  for (std::size_t i = 0; i < path.size(); ++i) {
    const char c = path[i];
    if (c == '{') {
      const std::size_t close = path.find('}', i);
      if (close == std::string_view::npos || close == i + 1)
        throw std::invalid_argument("route " + std::string(path) + ": a '{' without a name and '}'");
      pattern += "([^/]+)";
      i = close;
    } else if (std::string_view(R"(\^$.|?*+()[]})").find(c) != std::string_view::npos) {
      pattern += '\\';
      pattern += c;
    } else {
      pattern += c;
    }
  }
  return pattern;
}

void RouteRegistrar::get(std::string_view path, Handler handler) {
  server_.Get(route_pattern(path), std::move(handler));
  added_.push_back({"GET", std::string(path)});
}

void RouteRegistrar::post(std::string_view path, HandlerWithReader handler) {
  server_.Post(route_pattern(path), httplib::Server::HandlerWithContentReader(std::move(handler)));
  added_.push_back({"POST", std::string(path)});
}

void RouteRegistrar::del(std::string_view path, HandlerWithReader handler) {
  server_.Delete(route_pattern(path), httplib::Server::HandlerWithContentReader(std::move(handler)));
  added_.push_back({"DELETE", std::string(path)});
}

}  // namespace skyfarm::server
