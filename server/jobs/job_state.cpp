#include "server/jobs/job_state.h"

#include <array>
#include <utility>

namespace skyfarm::server {
namespace {

constexpr std::array<std::pair<JobState, std::string_view>, 5> kNames{{{JobState::kQueued, "queued"},
                                                                       {JobState::kRunning, "running"},
                                                                       {JobState::kDone, "done"},
                                                                       {JobState::kFailed, "failed"},
                                                                       {JobState::kCancelled, "cancelled"}}};

}  // namespace

std::string to_string(JobState state) {
  for (const auto& [s, name] : kNames)
    if (s == state) return std::string(name);
  return "unknown";
}

std::optional<JobState> parse_job_state(std::string_view text) {
  for (const auto& [s, name] : kNames)
    if (name == text) return s;
  return std::nullopt;
}

}  // namespace skyfarm::server
