#include "worker/asset_requests.h"

#include "worker/mesh_cache.h"

namespace skyfarm {

std::string AssetRequests::fetch(const std::string& id, std::chrono::milliseconds timeout) {
  std::shared_ptr<Request> request;
  {
    std::lock_guard lock(mutex_);
    if (closed_) throw AssetUnavailable("asset " + id + ": " + *closed_);
    auto& slot = open_[id];
    if (!slot) slot = std::make_shared<Request>();
    request = slot;
  }
  wake_();
  if (request->answer.wait_for(timeout) != std::future_status::ready) {
    {
      std::lock_guard lock(mutex_);
      if (const auto it = open_.find(id); it != open_.end() && it->second == request) open_.erase(it);
    }
    throw AssetUnavailable("asset " + id + ": no answer from the server within " + std::to_string(timeout.count()) +
                           " ms");
  }
  return request->answer.get();
}

std::vector<std::string> AssetRequests::take_unsent() {
  std::vector<std::string> ids;
  std::lock_guard lock(mutex_);
  for (auto& [id, request] : open_)
    if (!request->sent) {
      request->sent = true;
      ids.push_back(id);
    }
  return ids;
}

void AssetRequests::unsent(const std::string& id) {
  std::lock_guard lock(mutex_);
  if (const auto it = open_.find(id); it != open_.end()) it->second->sent = false;
}

void AssetRequests::resend_all() {
  std::lock_guard lock(mutex_);
  for (auto& [id, request] : open_) request->sent = false;
}

bool AssetRequests::answer(const api::AssetMsg& answer) {
  std::shared_ptr<Request> request;
  {
    std::lock_guard lock(mutex_);
    const auto it = open_.find(answer.id);
    if (it == open_.end()) return false;
    request = it->second;
    open_.erase(it);
  }
  if (answer.ok) request->promise.set_value(answer.file);
  else request->promise.set_exception(std::make_exception_ptr(std::runtime_error("asset " + answer.id + ": " + answer.error)));
  return true;
}

void AssetRequests::close(const std::string& why) {
  std::map<std::string, std::shared_ptr<Request>> open;
  {
    std::lock_guard lock(mutex_);
    closed_ = why;
    open.swap(open_);
  }
  for (auto& [id, request] : open) request->promise.set_exception(std::make_exception_ptr(AssetUnavailable("asset " + id + ": " + why)));
}

}  // namespace skyfarm
