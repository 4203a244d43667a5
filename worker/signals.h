// SIGTERM / SIGINT for long-running worker modes: the handler only sets an
// atomic flag (async-signal-safe); the farm worker's loop checks it
// (FarmWorkerOptions::drain_flag) and drains.  A second signal while the
// first is being handled ends the process at once (_exit(128 + signal)), so
// an impatient Ctrl-C still works.
#pragma once
#include <atomic>

namespace skyfarm {

// Installs the handlers (idempotent).
void install_termination_handlers();
// Set by the first SIGTERM or SIGINT.
const std::atomic<bool>& termination_requested();

}  // namespace skyfarm
