// GET /v1/renders/{id}/events: a job's progress as Server-Sent Events.
//
// Each JobEvent becomes one frame "id: <sequence>\nevent: <type>\ndata:
// <json>\n\n"; a client that reconnects with Last-Event-ID gets the events
// after it.  A stream sends ": keepalive" comments when nothing happened for
// the keep-alive interval (so a dead peer makes a write fail and frees the
// thread) and ends after a terminal event (done, failed, cancelled), or when
// the job is terminal or unknown and no event is left.  Every stream pins one
// of httplib's pool threads for its lifetime, so StreamSlots caps how many run.
#pragma once
#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "server/http/http_backend.h"

namespace httplib {
class DataSink;
}

namespace skyfarm::server {

// "id: 3\nevent: progress\ndata: {...}\n\n" (type and data on one line each).
std::string sse_frame(const JobEvent& event);
bool is_terminal_event(std::string_view type);
bool is_terminal_state(std::string_view state);

// A counting limit on open streams.
class StreamSlots {
 public:
  explicit StreamSlots(int max) : max_(max) {}
  // A slot held until the returned token is destroyed, or nullptr when all are taken.
  std::shared_ptr<void> try_acquire();
  int open() const { return open_.load(); }

 private:
  const int max_;
  std::shared_ptr<std::atomic<int>> counter_ = std::make_shared<std::atomic<int>>(0);
  std::atomic<int>& open_ = *counter_;
};

// The state of one stream; provide() is httplib's chunked content provider.
class EventStream {
 public:
  EventStream(HttpBackend& backend, std::string job_id, std::uint64_t after,
              std::chrono::milliseconds keepalive);
  // Writes what is new (or a keep-alive comment) after waiting at most
  // kPollSlice; false ends the connection (peer gone, backend failure).
  bool provide(httplib::DataSink& sink) noexcept;

  // How long one provide() waits for events: bounds how late a stopping
  // server notices the stream.
  static constexpr std::chrono::milliseconds kPollSlice{500};

 private:
  // Frames of the events after the last one sent, waiting up to `wait` for
  // one; marks the stream finished at a terminal event.
  std::string frames_after(std::chrono::milliseconds wait);
  bool write(httplib::DataSink& sink, const std::string& text);
  // The job is terminal or unknown: what is left gets flushed, then the end.
  bool job_over() const;

  HttpBackend& backend_;
  const std::string job_id_;
  std::uint64_t last_sent_;
  const std::chrono::milliseconds keepalive_;
  std::chrono::steady_clock::time_point last_write_;
  bool finished_ = false;
  bool polled_once_ = false;
};

}  // namespace skyfarm::server
