// The self-pipe that wakes the farm's poll loops (common/core/wakeup_pipe.h):
// a notify makes read_fd() readable, drain empties it, and notifying a full
// pipe neither blocks nor fails.
#include "common/core/wakeup_pipe.h"

#include <gtest/gtest.h>

#include <poll.h>
#include <unistd.h>

namespace skyfarm {
namespace {

bool readable(const WakeupPipe& pipe) {
  pollfd fd{pipe.read_fd(), POLLIN, 0};
  return ::poll(&fd, 1, 0) == 1 && (fd.revents & POLLIN) != 0;
}

TEST(WakeupPipeTest, WakesAPoller) {
  WakeupPipe pipe;
  EXPECT_FALSE(readable(pipe));
  pipe.notify();
  EXPECT_TRUE(readable(pipe));
  pipe.drain();
  EXPECT_FALSE(readable(pipe));
}

TEST(WakeupPipeTest, AFullPipeIsFine) {
  WakeupPipe pipe;
  for (int i = 0; i < 100000; ++i) pipe.notify();  // a full pipe is fine
  EXPECT_TRUE(readable(pipe));
  pipe.drain();
  char c = 0;
  EXPECT_LT(::read(pipe.read_fd(), &c, 1), 0);  // empty after drain
  EXPECT_FALSE(readable(pipe));
}

}  // namespace
}  // namespace skyfarm
