#include "server/broker/worker_auth.h"

#include <sys/stat.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "api/curve_keys.h"

namespace skyfarm::server {
namespace {

namespace fs = std::filesystem;

constexpr std::size_t kMaxTrackedAddresses = 4096;  // a bound on memory under a flood of addresses

std::string stat_signature(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) return "-";
  return std::to_string(st.st_ino) + ":" + std::to_string(st.st_size) + ":" + std::to_string(st.st_mtim.tv_sec) + "." +
         std::to_string(st.st_mtim.tv_nsec);
}

std::vector<std::string> pub_files(const std::string& dir) {
  std::vector<std::string> out;
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec))
    if (it->path().extension() == ".pub") out.push_back(it->path().string());
  std::sort(out.begin(), out.end());
  return out;
}

void read_list(const std::string& path, std::set<std::string>* keys, std::vector<std::string>* errors) {
  std::ifstream in(path);
  if (!in) {
    errors->push_back(path + ": cannot read");
    return;
  }
  int n = 0;
  for (std::string line; std::getline(in, line);) {
    ++n;
    std::istringstream words(line);
    std::string key;
    if (!(words >> key) || key[0] == '#') continue;
    if (api::is_z85_key(key)) keys->insert(key);
    else errors->push_back(path + ":" + std::to_string(n) + ": not a public key (40 Z85 characters)");
  }
}

}  // namespace

std::set<std::string> read_worker_keys(const std::string& path, std::vector<std::string>* errors) {
  std::set<std::string> keys;
  std::error_code ec;
  if (fs::is_directory(path, ec)) {
    for (const std::string& f : pub_files(path)) read_list(f, &keys, errors);
  } else if (fs::exists(path, ec)) {
    read_list(path, &keys, errors);
  } else {
    errors->push_back(path + ": no such file or folder");
  }
  return keys;
}

WorkerAuth::WorkerAuth(WorkerAuthOptions options, std::function<void(const std::string&)> log)
    : options_(std::move(options)), log_(std::move(log)), fixed_(options_.allowed_keys.begin(), options_.allowed_keys.end()) {
  reload_if_changed();
}

void WorkerAuth::reload_if_changed() {
  if (options_.keys_path.empty()) return;
  std::string signature = stat_signature(options_.keys_path);
  std::error_code ec;
  if (fs::is_directory(options_.keys_path, ec))
    for (const std::string& f : pub_files(options_.keys_path)) signature += "|" + f + "=" + stat_signature(f);
  if (signature == signature_) return;
  signature_ = signature;
  std::vector<std::string> errors;
  listed_ = read_worker_keys(options_.keys_path, &errors);
  for (const std::string& e : errors) log_("broker: worker keys: " + e);
  log_("broker: " + std::to_string(listed_.size()) + " worker key(s) allowed by " + options_.keys_path);
}

void WorkerAuth::prune(Clock::time_point now) {
  if (addresses_.size() < kMaxTrackedAddresses) return;
  for (auto it = addresses_.begin(); it != addresses_.end();) {
    auto& f = it->second.failures;
    while (!f.empty() && now - f.front() > options_.failure_window) f.pop_front();
    it = f.empty() && it->second.blocked_until <= now ? addresses_.erase(it) : std::next(it);
  }
}

void WorkerAuth::charge(const std::string& address, Clock::time_point now) {
  prune(now);
  Address& a = addresses_[address];
  if (a.blocked_until > now) return;  // a blocked address's attempts do not extend its cool-down
  a.failures.push_back(now);
  while (!a.failures.empty() && now - a.failures.front() > options_.failure_window) a.failures.pop_front();
  if (options_.max_failures > 0 && static_cast<int>(a.failures.size()) >= options_.max_failures) {
    a.blocked_until = now + options_.cooldown;
    a.failures.clear();
    log_("broker: " + std::to_string(options_.max_failures) + " failed worker authentications from " + address +
         ": refusing it for " + std::to_string(options_.cooldown.count() / 1000) + " s");
  }
}

WorkerAuth::Decision WorkerAuth::check(const std::string& address, const std::string& public_key,
                                       Clock::time_point now) {
  if (const auto it = addresses_.find(address); it != addresses_.end() && it->second.blocked_until > now)
    return {false, "too many failed authentications from " + address};
  reload_if_changed();
  if (fixed_.count(public_key) || listed_.count(public_key)) return {true, ""};
  charge(address, now);
  return {false, "unknown worker key " + public_key};
}

}  // namespace skyfarm::server
