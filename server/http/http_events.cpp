#include "server/http/http_events.h"

#include <httplib.h>

#include <algorithm>
#include <thread>

#include "server/http/http_problem.h"

namespace skyfarm::server {
namespace {

// An event name on one line: CR and LF would end the field early.
std::string one_line(std::string_view text) {
  std::string s(text);
  std::replace_if(s.begin(), s.end(), [](char c) { return c == '\r' || c == '\n'; }, ' ');
  return s;
}

}  // namespace

std::string sse_frame(const JobEvent& event) {
  // dump_json escapes control characters, so the data is one line.
  return "id: " + std::to_string(event.sequence) + "\nevent: " + one_line(event.type) +
         "\ndata: " + dump_json(event.data) + "\n\n";
}

bool is_terminal_event(std::string_view type) {
  return type == "done" || type == "failed" || type == "cancelled";
}

bool is_terminal_state(std::string_view state) { return is_terminal_event(state); }

std::shared_ptr<void> StreamSlots::try_acquire() {
  int open = counter_->load();
  do {
    if (open >= max_) return nullptr;
  } while (!counter_->compare_exchange_weak(open, open + 1));
  auto counter = counter_;  // the token may outlive this object
  return std::shared_ptr<void>(counter.get(), [counter](void*) { counter->fetch_sub(1); });
}

EventStream::EventStream(HttpBackend& backend, std::string job_id, std::uint64_t after,
                         std::chrono::milliseconds keepalive)
    : backend_(backend),
      job_id_(std::move(job_id)),
      last_sent_(after),
      keepalive_(std::max(keepalive, std::chrono::milliseconds(1))),
      last_write_(std::chrono::steady_clock::now()) {}

bool EventStream::provide(httplib::DataSink& sink) noexcept {
  try {
    if (finished_) {
      sink.done();
      return true;
    }
    const bool first_call = !polled_once_;
    polled_once_ = true;
    const auto wait = std::min(keepalive_, kPollSlice);
    const auto start = std::chrono::steady_clock::now();
    std::string out = frames_after(wait);
    // A backend that answers "nothing" at once (unknown job) must not make
    // this loop spin: check the job, then wait out the slice.
    const bool early = out.empty() && std::chrono::steady_clock::now() - start < wait / 2;
    const bool keepalive_due = std::chrono::steady_clock::now() - last_write_ >= keepalive_;
    if (out.empty() && (first_call || keepalive_due || early) && job_over()) {
      out = frames_after(std::chrono::milliseconds(0));  // a terminal event may have just arrived
      finished_ = true;
    }
    if (out.empty() && keepalive_due) out = ": keepalive\n\n";
    if (out.empty() && early && !finished_) std::this_thread::sleep_until(start + wait);
    if (!out.empty() && !write(sink, out)) return false;
    if (finished_) sink.done();
    return true;
  } catch (...) {
    return false;  // an exception must not leave the provider: httplib would not catch it
  }
}

std::string EventStream::frames_after(std::chrono::milliseconds wait) {
  std::vector<JobEvent> events = backend_.events_after(job_id_, last_sent_, wait);
  std::sort(events.begin(), events.end(),
            [](const JobEvent& a, const JobEvent& b) { return a.sequence < b.sequence; });
  std::string out;
  for (const JobEvent& e : events) {
    if (e.sequence <= last_sent_) continue;
    out += sse_frame(e);
    last_sent_ = e.sequence;
    if (is_terminal_event(e.type)) {
      finished_ = true;
      break;
    }
  }
  return out;
}

bool EventStream::write(httplib::DataSink& sink, const std::string& text) {
  if (!sink.is_writable() || !sink.write(text.data(), text.size())) return false;
  last_write_ = std::chrono::steady_clock::now();
  return true;
}

bool EventStream::job_over() const {
  const std::optional<nlohmann::json> status = backend_.status(job_id_);
  if (!status) return true;
  const auto state = status->find("state");
  return state != status->end() && state->is_string() && is_terminal_state(state->get<std::string>());
}

}  // namespace skyfarm::server
