// A render job's state.  Its names are the status document's "state" values
// and the job store's column (docs/request-schema.md): queued → running →
// done | failed | cancelled; the last three are terminal.
#pragma once
#include <optional>
#include <string>
#include <string_view>

namespace skyfarm::server {

enum class JobState { kQueued, kRunning, kDone, kFailed, kCancelled };

std::string to_string(JobState state);
// nullopt for any other text.
std::optional<JobState> parse_job_state(std::string_view text);
constexpr bool is_terminal(JobState state) {
  return state == JobState::kDone || state == JobState::kFailed || state == JobState::kCancelled;
}

}  // namespace skyfarm::server
