// A non-blocking self-pipe that wakes a poll loop from other threads.
//
// The farm's I/O threads (the server's broker, the worker's socket thread)
// sleep in zmq_poll on their sockets and on read_fd(); another thread that
// has something for them (a rendered unit, a stop, a drain) calls
// notify() instead of touching their sockets, which ZeroMQ forbids across
// threads.  notify() is thread-safe and async-signal-safe (one write(2), errno
// kept), so a signal handler may call it (the worker drains on SIGTERM); a full pipe already wakes the
// reader, so notify() never blocks.  drain() (owner thread) empties it.
#pragma once

namespace skyfarm {

class WakeupPipe {
 public:
  WakeupPipe();  // throws std::system_error if pipe2 fails
  ~WakeupPipe();
  WakeupPipe(const WakeupPipe&) = delete;
  WakeupPipe& operator=(const WakeupPipe&) = delete;

  int read_fd() const { return fds_[0]; }
  void notify() const noexcept;
  void drain() const noexcept;

 private:
  int fds_[2] = {-1, -1};
};

}  // namespace skyfarm
