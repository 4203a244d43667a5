// A fake HttpBackend for the HTTP layer's tests: jobs are status documents in
// a map, events and images are what a test puts there, and every call is
// recorded (the ids it was given, the submissions with their keys).
// Idempotency works like JobService's: same key + same canonical request ->
// the same job, another request -> IdempotencyConflict.
#pragma once
#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <exception>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "api/render_request.h"
#include "server/http/http_backend.h"

namespace skyfarm::server::testing {

class FakeBackend final : public HttpBackend {
 public:
  struct Submission {
    std::string canonical;
    std::optional<std::string> key;
  };

  // --- What tests set up and inspect (all thread-safe) ----------------------

  // Adds (or replaces) a job with the given state.
  void add_job(const std::string& id, const std::string& state = "running") {
    std::lock_guard lock(mu_);
    jobs_[id] = status_doc(id, state);
    order_.push_back(id);
  }
  void set_state(const std::string& id, const std::string& state) {
    std::lock_guard lock(mu_);
    jobs_.at(id)["state"] = state;
  }
  void set_field(const std::string& id, const std::string& key, nlohmann::json value) {
    std::lock_guard lock(mu_);
    jobs_.at(id)[key] = std::move(value);
  }
  // Appends an event with the next sequence number and wakes waiting streams.
  void push_event(const std::string& id, const std::string& type) {
    {
      std::lock_guard lock(mu_);
      auto& list = events_[id];
      JobEvent e;
      e.sequence = list.empty() ? 1 : list.back().sequence + 1;
      e.type = type;
      e.data = jobs_.count(id) ? jobs_[id] : nlohmann::json::object();
      e.data["event"] = type;
      list.push_back(std::move(e));
    }
    changed_.notify_all();
  }
  void set_image(const std::string& id, ImageFormat format, ImageFile file) {
    std::lock_guard lock(mu_);
    images_[{id, format}] = std::move(file);
  }
  // The next submit() throws this (once).
  void fail_next_submit(std::exception_ptr error) {
    std::lock_guard lock(mu_);
    submit_error_ = std::move(error);
  }
  // Every later call of any method throws this.
  void fail_everything(std::exception_ptr error) {
    std::lock_guard lock(mu_);
    always_error_ = std::move(error);
  }
  void set_metrics(nlohmann::json metrics) {
    std::lock_guard lock(mu_);
    metrics_ = std::move(metrics);
  }
  std::vector<Submission> submissions() const {
    std::lock_guard lock(mu_);
    return submissions_;
  }
  // Every id a method was called with, in call order.
  std::vector<std::string> ids_seen() const {
    std::lock_guard lock(mu_);
    return ids_seen_;
  }
  std::vector<std::string> cancelled() const {
    std::lock_guard lock(mu_);
    return cancelled_;
  }
  std::pair<std::size_t, std::size_t> last_list_call() const {
    std::lock_guard lock(mu_);
    return last_list_;
  }

  // --- HttpBackend ---------------------------------------------------------------

  SubmitResult submit(const api::RenderRequest& request, const std::optional<std::string>& key) override {
    std::lock_guard lock(mu_);
    rethrow_if_failing();
    if (submit_error_) std::rethrow_exception(std::exchange(submit_error_, nullptr));
    const std::string canonical = api::canonical_text(request);
    submissions_.push_back({canonical, key});
    if (key) {
      if (const auto it = by_key_.find(*key); it != by_key_.end()) {
        if (it->second.second != canonical)
          throw IdempotencyConflict("Idempotency-Key '" + *key + "' was used for a different request");
        return {it->second.first, false, false};
      }
    }
    const std::string id = "job-" + std::to_string(++next_id_);
    jobs_[id] = status_doc(id, "queued");
    order_.push_back(id);
    if (key) by_key_[*key] = {id, canonical};
    return {id, true, false};
  }

  std::optional<nlohmann::json> status(const std::string& id) const override {
    std::lock_guard lock(mu_);
    rethrow_if_failing();
    ids_seen_.push_back(id);
    const auto it = jobs_.find(id);
    if (it == jobs_.end()) return std::nullopt;
    return it->second;
  }

  nlohmann::json list(std::size_t offset, std::size_t limit) const override {
    std::lock_guard lock(mu_);
    rethrow_if_failing();
    last_list_ = {offset, limit};
    nlohmann::json out = nlohmann::json::array();
    for (std::size_t i = offset; i < order_.size() && out.size() < limit; ++i)
      out.push_back(jobs_.at(order_[order_.size() - 1 - i]));
    return out;
  }

  std::size_t job_count() const override {
    std::lock_guard lock(mu_);
    rethrow_if_failing();
    return jobs_.size();
  }

  bool cancel(const std::string& id) override {
    std::lock_guard lock(mu_);
    rethrow_if_failing();
    ids_seen_.push_back(id);
    const auto it = jobs_.find(id);
    if (it == jobs_.end()) return false;
    cancelled_.push_back(id);
    it->second["state"] = "cancelled";
    return true;
  }

  // Removes the job; "frame-" ids belong to a timelapse and are refused.
  PurgeOutcome purge(const std::string& id) override {
    std::lock_guard lock(mu_);
    rethrow_if_failing();
    ids_seen_.push_back(id);
    const auto it = jobs_.find(id);
    if (it == jobs_.end()) return {PurgeOutcome::kUnknown, ""};
    if (id.rfind("frame-", 0) == 0) return {PurgeOutcome::kConflict, "render \"" + id + "\" is a timelapse's frame"};
    jobs_.erase(it);
    order_.erase(std::find(order_.begin(), order_.end(), id));
    return {PurgeOutcome::kPurged, ""};
  }

  std::optional<ImageFile> image(const std::string& id, ImageFormat format) override {
    std::lock_guard lock(mu_);
    rethrow_if_failing();
    ids_seen_.push_back(id);
    const auto it = images_.find({id, format});
    if (it == images_.end()) return std::nullopt;
    return it->second;
  }

  std::vector<JobEvent> events_after(const std::string& id, std::uint64_t after,
                                     std::chrono::milliseconds timeout) override {
    std::unique_lock lock(mu_);
    rethrow_if_failing();
    ids_seen_.push_back(id);
    auto newer = [&] {
      std::vector<JobEvent> out;
      if (const auto it = events_.find(id); it != events_.end())
        for (const auto& e : it->second)
          if (e.sequence > after) out.push_back(e);
      return out;
    };
    changed_.wait_for(lock, timeout, [&] { return !newer().empty(); });
    return newer();
  }

  nlohmann::json workers() const override {
    std::lock_guard lock(mu_);
    rethrow_if_failing();
    return nlohmann::json::array({{{"id", "w1"}, {"cores", 8}, {"version", "test"}, {"units_done", 3},
                                   {"units_in_flight", 1}, {"last_seen_s", 0.5}}});
  }

  nlohmann::json metrics() const override {
    std::lock_guard lock(mu_);
    rethrow_if_failing();
    return metrics_;
  }

 private:
  static nlohmann::json status_doc(const std::string& id, const std::string& state) {
    const std::string self = "/v1/renders/" + id;
    return {{"id", id},
            {"state", state},
            {"progress", {{"fraction", 0.0}, {"samples_per_pixel", 0}, {"units_done", 0}, {"units_total", 8}}},
            {"links",
             {{"self", self}, {"exr", self + "/image.exr"}, {"png", self + "/image.png"}, {"events", self + "/events"}}}};
  }
  void rethrow_if_failing() const {
    if (always_error_) std::rethrow_exception(always_error_);
  }

  mutable std::mutex mu_;
  std::condition_variable changed_;
  std::map<std::string, nlohmann::json> jobs_;
  std::vector<std::string> order_;
  std::map<std::string, std::vector<JobEvent>> events_;
  std::map<std::pair<std::string, ImageFormat>, ImageFile> images_;
  std::map<std::string, std::pair<std::string, std::string>> by_key_;  // key -> (id, canonical)
  std::vector<Submission> submissions_;
  mutable std::vector<std::string> ids_seen_;
  std::vector<std::string> cancelled_;
  mutable std::pair<std::size_t, std::size_t> last_list_{0, 0};
  std::exception_ptr submit_error_;
  std::exception_ptr always_error_;
  nlohmann::json metrics_ = {{"queue_units", 12},        {"units_in_flight", 3}, {"jobs_queued", 1},
                             {"jobs_running", 2},        {"jobs_done", 5},       {"jobs_failed", 0},
                             {"workers", 2},             {"samples_per_second", 1.5e6},
                             {"unit_failures", 1},       {"requeues", 4},
                             {"results_refused", 2},     {"disk_used_bytes", 123456789},
                             {"disk_budget_bytes", 1000000000}};
  int next_id_ = 0;
};

}  // namespace skyfarm::server::testing
