// The farm worker's per-job setups (worker/farm_worker.h): an LRU of job id ->
// what renders that job's units (a TileRenderer for a render, the scene and
// plan of a probe), shared by the render threads.  Each entry is built once,
// under its own mutex, so threads working on other jobs do not wait; an
// entry is rebuilt when the job's request text differs from the cached one;
// a request that cannot be set up caches its error, which every unit of the
// job then reports, unless the error is a TransientSetupError (an asset the
// server did not send in time): the next unit builds again.  Entries evicted
// while in use live on in their users.
#pragma once
#include <algorithm>
#include <functional>
#include <list>
#include <memory>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>

namespace skyfarm {

// A setup that failed for now (the next attempt may work): not cached.
class TransientSetupError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

template <class Setup>
class SetupCache {
 public:
  // `build` makes the setup from the request text; it throws (any
  // std::exception) with the message FAILED should carry.
  using Build = std::function<Setup(const std::string& request)>;

  SetupCache(std::size_t capacity, Build build)
      : capacity_(std::max<std::size_t>(1, capacity)), build_(std::move(build)) {}

  // Throws std::runtime_error with the reason when the request cannot be set up.
  std::shared_ptr<const Setup> get(const std::string& job, const std::string& request) {
    const std::shared_ptr<Entry> e = entry(job, request);
    std::lock_guard lock(e->mutex);
    if (!e->built) {
      e->built = true;
      try {
        e->setup.emplace(build_(e->request));
      } catch (const TransientSetupError&) {
        e->built = false;
        throw;
      } catch (const std::exception& ex) {
        e->error = ex.what();
      }
    }
    if (!e->setup) throw std::runtime_error(e->error);
    return {e, &*e->setup};
  }

 private:
  struct Entry {
    std::string request;
    std::mutex mutex;
    bool built = false;
    std::string error;
    std::optional<Setup> setup;
  };

  std::shared_ptr<Entry> entry(const std::string& job, const std::string& request) {
    std::lock_guard lock(mutex_);
    const auto it = std::find_if(lru_.begin(), lru_.end(), [&](const auto& p) { return p.first == job; });
    if (it != lru_.end() && it->second->request == request) {
      lru_.splice(lru_.begin(), lru_, it);
      return lru_.front().second;
    }
    if (it != lru_.end()) lru_.erase(it);
    auto e = std::make_shared<Entry>();
    e->request = request;
    lru_.emplace_front(job, e);
    while (lru_.size() > capacity_) lru_.pop_back();
    return e;
  }

  std::mutex mutex_;
  std::list<std::pair<std::string, std::shared_ptr<Entry>>> lru_;  // most recent first
  std::size_t capacity_;
  Build build_;
};

}  // namespace skyfarm
