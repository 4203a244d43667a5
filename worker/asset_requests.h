// The farm worker's asset fetches (api/wire.h ASSET_GET / ASSET): render
// threads ask for a mesh file and wait; the I/O thread, which alone owns the
// socket, sends the questions and hands back the answers.
//
//   render thread   fetch(id, timeout): registers the question (one per id,
//                   however many threads ask), wakes the I/O thread, waits
//                   for the answer up to `timeout`
//   I/O thread      take_unsent() -> ASSET_GET for each; answer(ASSET)
//                   fulfils the waiters; resend_all() at a new session (the
//                   old socket's questions are lost with it); close() when
//                   the worker stops
// Thread-safe.
#pragma once
#include <chrono>
#include <functional>
#include <future>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "api/wire.h"

namespace skyfarm {

class AssetRequests {
 public:
  explicit AssetRequests(std::function<void()> wake) : wake_(std::move(wake)) {}

  // The mesh file of `id`.  Throws std::runtime_error naming the id when
  // the server refused (no such asset), AssetUnavailable (worker/mesh_cache.h)
  // when no answer came within `timeout` or after close().
  std::string fetch(const std::string& id, std::chrono::milliseconds timeout);

  // Ids to send ASSET_GET for; they count as sent.
  std::vector<std::string> take_unsent();
  // A question that could not be sent: send it again later.
  void unsent(const std::string& id);
  // Every open question goes out again (a new connection).
  void resend_all();
  // Fulfils the question for answer.id; false when none is open (a late answer).
  bool answer(const api::AssetMsg& answer);
  // Every waiter, and every later fetch, gets AssetUnavailable(why).
  void close(const std::string& why);

 private:
  struct Request {
    std::promise<std::string> promise;
    std::shared_future<std::string> answer = promise.get_future().share();
    bool sent = false;
  };
  std::function<void()> wake_;
  std::mutex mutex_;
  std::map<std::string, std::shared_ptr<Request>> open_;
  std::optional<std::string> closed_;  // why, once closed
};

}  // namespace skyfarm
