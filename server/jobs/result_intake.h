// Results: a worker's result for a unit is merged only if it answers a unit
// dispatched to that worker under that attempt and is exactly what the unit
// asked for (unit_result_check.h) — anything else is refused and held against
// its worker — and into its tile only in canonical (pass, batch) order
// (tile_merger.h).  After merges each newly complete pass is recorded (its
// estimated error), an adaptive job's allocation is made from its pilot, and
// the job finishes when its samples are all merged, its target error is
// reached or its time limit has passed (at pass boundaries, so the image is
// a whole number of passes and equals a local render of that many).  A
// finishing job's final image is written outside the lock.
#pragma once
#include <cstdint>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "server/jobs/job_book.h"
#include "server/jobs/job_images.h"
#include "server/jobs/unit_assignment.h"

namespace skyfarm::server {

// Every method is called under the book's lock.
class ResultIntake {
 public:
  explicit ResultIntake(JobBook& book) : book_(book) {}

  // `lock` holds the book's mutex; it is released while a final image is
  // written, and held again on return.
  void unit_done(std::unique_lock<std::mutex>& lock, const std::string& worker_id, const UnitKey& key,
                 std::uint64_t attempt, const std::vector<std::uint8_t>& film_tile_bytes, std::uint64_t paths);
  void unit_failed(const std::string& worker_id, const UnitKey& key, std::uint64_t attempt,
                   const std::string& message);
  // At start-up: a job whose merged units complete it is finished at once
  // (its final image written under the lock).
  void finish_now_if_complete(Job& job);

 private:
  // A stopped job's final image, to be written outside the lock, then
  // complete_finish (under it) makes the job done.
  struct PendingFinish {
    ImageSnapshot final_image;
    std::string stopped_by;
  };
  std::optional<PendingFinish> finish_if_complete(Job& job);
  void complete_finish(Job& job, const std::string& stopped_by);
  // A result that is not exactly what its unit asked for: counted, held
  // against its worker as a failure of the unit (max_unit_failures distinct
  // workers fail the job), and the unit dispatched again first.
  void refuse_result(Job& job, const WorkUnit& unit, const std::string& worker_id, const std::string& why);
  // An adaptive job's allocation from its merged pilot, stored before use;
  // false when the job failed instead.
  bool allocate(Job& job);

  JobBook& book_;
};

}  // namespace skyfarm::server
