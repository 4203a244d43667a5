#include "server/jobs/job_ids.h"

#include <chrono>
#include <cstdint>
#include <mutex>
#include <random>
#include <sstream>

namespace skyfarm::server {

double unix_now() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

std::string random_id() {
  static std::mutex mu;
  static std::mt19937_64 rng(std::random_device{}() ^ static_cast<std::uint64_t>(unix_now() * 1e6));
  const std::lock_guard<std::mutex> lock(mu);
  std::ostringstream o;
  o << std::hex;
  o.width(16);
  o.fill('0');
  o << rng();
  return o.str();
}

}  // namespace skyfarm::server
