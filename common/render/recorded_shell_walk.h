// A shell walk kept to be walked again.  The path tracer walks the first
// segments of a path twice: once for their majorant optical depth (the
// camera ray's majorant inflation and the forced collision need it before
// the flight) and once for the free flight itself.  Each step of a
// ShellTraversal costs a square root and a division; the replay yields the
// very same segments (bit for bit: they are the recorded values) from memory.
//
// Up to kCapacity segments are kept (an Earth atmosphere has 51 shells, so a
// ray crosses at most about 2 x 51); a longer walk (a custom atmosphere
// reaching far up) keeps the traversal where the record stopped and every
// replay walks on from there, so a replay always yields the whole walk.
//
// The storage is left uninitialised: only recorded entries are read.
#pragma once
#include <array>
#include <cstddef>

#include "common/render/shell_traversal.h"

namespace skyfarm {

class RecordedShellWalk {
 public:
  static constexpr std::size_t kCapacity = 160;

  // Nothing recorded (recorded() is false).  Cheaper than an empty
  // std::optional<RecordedShellWalk>, whose constructor (GCC 12) zero-fills
  // the ~4 kB of storage.
  RecordedShellWalk() {}  // NOLINT: user-provided, so the storage stays uninitialised
  // Walks `walk` as far as the record holds.
  explicit RecordedShellWalk(const ShellTraversal& walk) { record(walk); }

  // Records `walk` (in place of any earlier record).
  void record(const ShellTraversal& walk) {
    rest_ = walk;
    count_ = 0;
    recorded_ = true;
    ShellSegment s;
    while (count_ < kCapacity && rest_.next(&s)) {
      t0_[count_] = s.t0;
      t1_[count_] = s.t1;
      shell_[count_] = s.shell;
      ++count_;
    }
  }
  bool recorded() const { return recorded_; }

  // The recorded segments in order, then those of the walk past the record.
  class Replay {
   public:
    explicit Replay(const RecordedShellWalk& record) : record_(record), rest_(record.rest_) {}
    bool next(ShellSegment* segment) {
      if (i_ < record_.count_) {
        segment->t0 = record_.t0_[i_];
        segment->t1 = record_.t1_[i_];
        segment->shell = record_.shell_[i_];
        ++i_;
        return true;
      }
      return record_.count_ == kCapacity && rest_.next(segment);
    }

   private:
    const RecordedShellWalk& record_;
    std::size_t i_ = 0;
    ShellTraversal rest_;
  };

  Replay replay() const { return Replay(*this); }

 private:
  std::array<double, kCapacity> t0_, t1_;
  std::array<std::size_t, kCapacity> shell_;
  std::size_t count_ = 0;
  bool recorded_ = false;
  ShellTraversal rest_;  // the walk after the last recorded segment
};

}  // namespace skyfarm
