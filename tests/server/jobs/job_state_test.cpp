// A job state's names are the status document's "state" values and what the
// job store and timelapse records hold: they must read back as written.
#include "server/jobs/job_state.h"

#include <gtest/gtest.h>

namespace skyfarm::server {
namespace {

TEST(JobState, NamesReadBackAndOnlyTheLastThreeAreTerminal) {
  const JobState all[] = {JobState::kQueued, JobState::kRunning, JobState::kDone, JobState::kFailed,
                          JobState::kCancelled};
  const char* names[] = {"queued", "running", "done", "failed", "cancelled"};
  for (int i = 0; i < 5; ++i) {
    EXPECT_EQ(to_string(all[i]), names[i]);
    EXPECT_EQ(parse_job_state(names[i]), all[i]);
    EXPECT_EQ(is_terminal(all[i]), i >= 2) << names[i];
  }
  EXPECT_FALSE(parse_job_state("Done").has_value());
  EXPECT_FALSE(parse_job_state("").has_value());
  EXPECT_FALSE(parse_job_state("expired").has_value());
}

}  // namespace
}  // namespace skyfarm::server
