#include "common/core/wakeup_pipe.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <system_error>

namespace skyfarm {

WakeupPipe::WakeupPipe() {
  if (::pipe2(fds_, O_NONBLOCK | O_CLOEXEC) != 0) throw std::system_error(errno, std::generic_category(), "pipe2");
}

WakeupPipe::~WakeupPipe() {
  ::close(fds_[0]);
  ::close(fds_[1]);
}

void WakeupPipe::notify() const noexcept {
  const char byte = 1;
  const int saved = errno;
  // A full pipe already wakes the reader: EAGAIN is fine.
  [[maybe_unused]] const auto n = ::write(fds_[1], &byte, 1);
  errno = saved;
}

void WakeupPipe::drain() const noexcept {
  char buf[256];
  while (::read(fds_[0], buf, sizeof buf) > 0) {
  }
}

}  // namespace skyfarm
