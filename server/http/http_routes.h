// The API's routes, each named once as api/openapi.yaml names it: a method and
// an OpenAPI path template (`/v1/renders/{id}/image.exr`).  RouteRegistrar
// adds a route to the httplib server under the pattern made from that
// template and records it, so the routes the server answers and the paths the
// document lists can be compared (tests/server/http/http_routes_test.cpp).
//
// The pattern: literal text matched as is (regex characters escaped), each
// `{name}` one path segment, `([^/]+)`, captured in req.matches in order.
// HEAD is answered by every GET route (httplib) and is not recorded apart.
#pragma once
#include <functional>
#include <string>
#include <string_view>
#include <vector>
#include "server/http/httplib_fwd.h"

namespace skyfarm::server {

struct Route {
  std::string method;  // "GET", "POST", "DELETE"
  std::string path;    // the OpenAPI path template
  bool operator==(const Route&) const = default;
  auto operator<=>(const Route&) const = default;
};

// The httplib pattern of an OpenAPI path template.
std::string route_pattern(std::string_view path);

class RouteRegistrar {
 public:
  using Handler = std::function<void(const httplib::Request&, httplib::Response&)>;
  using HandlerWithReader =
      std::function<void(const httplib::Request&, httplib::Response&, const httplib::ContentReader&)>;

  explicit RouteRegistrar(httplib::Server& server) : server_(server) {}

  void get(std::string_view path, Handler handler);
  // POST and DELETE take the body reader: a handler that does not read the
  // body keeps httplib from reading one of any size first.
  void post(std::string_view path, HandlerWithReader handler);
  void del(std::string_view path, HandlerWithReader handler);

  // Every route added so far, in the order added.
  const std::vector<Route>& added() const { return added_; }

 private:
  httplib::Server& server_;
  std::vector<Route> added_;
};

}  // namespace skyfarm::server
