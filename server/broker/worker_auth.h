// Who may join the farm as a worker: the policy the broker's ZAP handler
// (server/broker/broker.cpp) applies to each CURVE handshake.
//
//   allowed_keys   worker public keys (Z85) always let in: the one derived
//                  from the shared worker secret (api/curve_keys.h).
//   keys_path      an allow-list: a file of Z85 public keys, one per line
//                  (blank lines and `#` comments ignored; a line's first word
//                  is the key), or a directory whose *.pub files each hold one
//                  such list.  Re-read when it changes (the mtime, size or
//                  inode of the file, the folder, or any of its *.pub files),
//                  checked at each handshake; a missing path lets nobody in
//                  through it.  Lines that are not keys are logged and skipped.
//   rate limit     max_failures denials from one address within
//                  failure_window deny that address outright for cooldown,
//                  even with a valid key (these denials count as failures but
//                  do not extend the cool-down).
// Not thread-safe: the broker thread alone uses it.
#pragma once
#include <chrono>
#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <set>
#include <string>
#include <string_view>
#include <vector>

namespace skyfarm::server {

struct WorkerAuthOptions {
  std::vector<std::string> allowed_keys;
  std::string keys_path;
  int max_failures = 10;
  std::chrono::milliseconds failure_window{60000};
  std::chrono::milliseconds cooldown{60000};
};

class WorkerAuth {
 public:
  using Clock = std::chrono::steady_clock;
  struct Decision {
    bool allowed = false;
    std::string reason;  // why not (for the log and the ZAP status text)
  };

  WorkerAuth(WorkerAuthOptions options, std::function<void(const std::string&)> log);
  // `address`: the peer's IP address; `public_key`: its key in Z85.
  Decision check(const std::string& address, const std::string& public_key, Clock::time_point now);
  // A failure not seen by check() (e.g. a wrong mechanism) charged to `address`.
  void charge(const std::string& address, Clock::time_point now);

 private:
  struct Address {
    std::deque<Clock::time_point> failures;  // within failure_window
    Clock::time_point blocked_until{};
  };
  void reload_if_changed();
  void prune(Clock::time_point now);

  WorkerAuthOptions options_;
  std::function<void(const std::string&)> log_;
  std::set<std::string> fixed_;   // allowed_keys
  std::set<std::string> listed_;  // from keys_path
  std::string signature_;         // of keys_path when last read
  std::map<std::string, Address> addresses_;
};

// The keys of an allow-list file or folder (see above); each line that is not
// a key adds "PATH:LINE: ..." to *errors.
std::set<std::string> read_worker_keys(const std::string& path, std::vector<std::string>* errors);

}  // namespace skyfarm::server
