// Query parameters of the list routes (GET /v1/renders, GET /v1/timelapses),
// read the same way on each:
//
//   page_of(req)  offset in [0, 1e9] (default 0), limit in [1, 100] (default 20);
//                 each optional, given at most once, a decimal integer; else a
//                 400 naming the parameter ("must be given once", "must be an
//                 integer in [lo, hi]")
#pragma once
#include <cstdint>

namespace httplib {
struct Request;
}  // namespace httplib

namespace skyfarm::server {

inline constexpr std::uint64_t kMaxListOffset = 1000000000;
inline constexpr std::uint64_t kDefaultListLimit = 20;
inline constexpr std::uint64_t kMaxListLimit = 100;

struct Page {
  std::uint64_t offset = 0;
  std::uint64_t limit = kDefaultListLimit;
};

Page page_of(const httplib::Request& req);

}  // namespace skyfarm::server
