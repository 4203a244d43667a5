// Declarations of the cpp-httplib types that headers only name, so that a
// header which registers routes need not include all of <httplib.h>.
#pragma once

namespace httplib {
class Server;
class ContentReader;
struct Request;
struct Response;
}  // namespace httplib
