#include "worker/signals.h"

#include <signal.h>
#include <unistd.h>

namespace skyfarm {
namespace {

std::atomic<bool> g_terminate{false};
static_assert(std::atomic<bool>::is_always_lock_free, "the signal handler needs a lock-free flag");

void on_termination_signal(int signal_number) {
  if (g_terminate.exchange(true)) ::_exit(128 + signal_number);
}

}  // namespace

void install_termination_handlers() {
  struct sigaction action {};
  action.sa_handler = on_termination_signal;
  sigemptyset(&action.sa_mask);
  action.sa_flags = SA_RESTART;
  ::sigaction(SIGTERM, &action, nullptr);
  ::sigaction(SIGINT, &action, nullptr);
}

const std::atomic<bool>& termination_requested() { return g_terminate; }

}  // namespace skyfarm
