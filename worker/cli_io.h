// Small helpers shared by the skyfarm-worker commands: reading a request file
// (or '-' for standard input) and a progress display (a bar on a terminal,
// plain lines otherwise).
#pragma once
#include <chrono>
#include <string>

namespace skyfarm {

// Reads `path` ('-' = standard input) into *text; on failure fills *error.
bool read_input(const std::string& path, std::string* text, std::string* error);

class ProgressDisplay {
 public:
  explicit ProgressDisplay(std::string label);
  // Progress in [0, 1] (render_progress.h); redraws at most every 100 ms on
  // a terminal, every 10 % otherwise.
  void update(double fraction);
  void finish();

 private:
  std::string label_;
  bool tty_;
  int last_decile_ = -1;
  std::chrono::steady_clock::time_point start_, last_draw_;
};

}  // namespace skyfarm
