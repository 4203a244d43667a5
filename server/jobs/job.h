// One render job in memory, as the job service's parts share it: its record
// and request, its plan cut into units (tile, batch, pass), the merger of its
// results, the units waiting to be handed out again, its error history and
// events, and what it holds on disk.  Guarded by the job book's mutex
// (job_book.h), except preview_writer.
//
// Units are numbered pass-major (every tile and batch of pass 0, then pass 1,
// ...): unit_at(plan, i) is the i-th, and a job hands them out from a cursor,
// so a far pass waits nowhere.
#pragma once
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "api/render_request.h"
#include "common/render/render_plan.h"
#include "common/render/render_progress.h"
#include "common/render/sample_allocation.h"
#include "server/http/http_backend.h"
#include "server/jobs/job_state.h"
#include "server/jobs/job_store.h"
#include "server/jobs/tile_merger.h"
#include "server/jobs/unit_assignment.h"
#include "server/jobs/unit_result_check.h"

namespace skyfarm::server {

// Unit index i of a job, pass-major: every tile and batch of pass 0 first.
WorkUnit unit_at(const RenderPlan& plan, std::size_t i);

// The queue's measure of a job (ServiceLimits::max_queue_units): its units
// not yet merged, at most kQueueHorizonPasses passes' worth.  Units are made
// on demand from a cursor, so a far pass waits nowhere; and a request that
// stops by a target error or a time limit alone has no sample cap (1048576
// samples per pixel: 65536 passes), which counted whole made "1 % in at most
// 2 minutes" of a 512x256 frame 4.2 million units, over the limit.
constexpr std::int64_t kQueueHorizonPasses = 16;
std::int64_t waiting_units(const RenderPlan& plan, std::int64_t merged);

// "tile T, batch B, pass P", for messages.
std::string unit_text(const WorkUnit& u);

// The status document's "plan": what the render includes and leaves out
// (constituents, skipped ones), and how it is cut into units.
nlohmann::json plan_report(const api::RenderRequest& request, const RenderPlan& plan);

struct Job {
  JobRecord record;
  api::RenderRequest request;
  RenderPlan plan;
  nlohmann::json plan_json;
  std::unique_ptr<TileMerger> merger;
  std::unique_ptr<UnitResultCheck> result_check;  // what a unit's result must be, exactly
  std::size_t cursor = 0;               // next never-dispatched unit index (pass-major)
  std::deque<WorkUnit> requeued;        // units to dispatch again
  std::map<int, std::set<std::string>> failed_workers;  // by pass-major index
  int in_flight = 0;
  std::uint64_t dispatched = 0;  // units handed out so far (fair share: next_unit)
  std::map<std::string, int> worker_units;
  std::uint64_t paths = 0;
  bool started = false;
  Clock::time_point start_time{}, end_time{};
  int passes_reported = 0;
  nlohmann::json history = nlohmann::json::array();
  std::vector<JobEvent> events;
  Clock::time_point last_event{};  // when events.back() was made
  bool progress_held = false;      // a "progress" event was held back (emit)
  std::string stopped_by;
  int preview_units = -1;
  // Disk (disk_budget.h): what the job may write at most (reserved while it
  // runs), and the bytes of its files other than tiles, measured.
  std::int64_t disk_estimate = 0;
  std::int64_t other_bytes = 0;
  bool expired = false;  // finished longer than the retention ago: its directory is gone
  // Once its tile files are deleted (it finished, failed or was cancelled):
  // the merged units and whole passes they held, for the status.
  std::optional<std::pair<std::int64_t, int>> released;
  std::int64_t units_done() const { return released ? released->first : merger->merged_units(); }
  int complete_passes() const { return released ? released->second : merger->complete_passes(); }
  std::int64_t disk_used() const { return expired ? 0 : merger->bytes_on_disk() + other_bytes; }
  // What the budget counts: a running job its estimate (it may write that much).
  std::int64_t disk_reserved() const {
    return is_terminal(record.state) ? disk_used() : std::max(disk_estimate, disk_used());
  }
  // Held while a preview is written outside the service's lock; guards preview_written.
  std::mutex preview_writer;
  int preview_written = -1;
  std::filesystem::path dir;
  std::vector<std::uint32_t> sun_pixels;  // left out of the error estimate
  std::string group;                      // shares out passes with its group (set_group)
  // Adaptive plans: the samples per pass of every tile after the pilot
  // (sample_allocation.h), set once pass 0 is merged everywhere and kept in
  // dir/allocation.json; until then no unit of a later pass is handed out.
  std::optional<SampleAllocation> allocation;
  bool waits_for_allocation() const { return plan.adaptive && !allocation; }
  // Each tile's pilot statistics, taken as its pilot completes (while the
  // tile is in memory), so that the allocation does not read every tile back
  // from disk under the service's lock; empty entries are read at allocation.
  std::vector<std::optional<SampleAllocation::BlockStatistics>> pilot_statistics;
  // Mean samples per pixel after `passes` whole passes (the EXR's metadata,
  // as a local render writes it), and as the status shows it.
  double mean_samples_per_pixel(int passes) const {
    return allocation ? allocation->mean_samples_per_pixel(plan, passes) : plan.samples_after(passes);
  }
  nlohmann::json samples_per_pixel(int passes) const {
    if (allocation) return std::round(mean_samples_per_pixel(passes) * 10.0) / 10.0;
    return plan.samples_after(passes);
  }

  std::size_t unit_index(const WorkUnit& u) const {
    return (static_cast<std::size_t>(u.pass) * static_cast<std::size_t>(plan.tile_count()) +
            static_cast<std::size_t>(u.tile)) *
               static_cast<std::size_t>(plan.batches) +
           static_cast<std::size_t>(u.batch);
  }
  // Stopped, its final image being written outside the service's lock
  // (finish_if_complete, then complete_finish): no more units, not yet done.
  bool finishing = false;
  bool active() const { return !finishing && !is_terminal(record.state); }
  bool has_work() const {
    if (!active()) return false;
    if (!requeued.empty()) return true;
    return cursor < static_cast<std::size_t>(plan.unit_count()) &&
           !(waits_for_allocation() && unit_at(plan, cursor).pass > 0);
  }
  // Towards the first of the request's limits (render_progress.h): 1 when done.
  double progress() const {
    if (record.state == JobState::kDone) return 1.0;
    const std::int64_t total = merger->total_units();
    const double samples_share = total > 0 ? static_cast<double>(merger->merged_units()) / total : 1.0;
    std::optional<double> estimate;
    if (!history.empty() && history.back()["estimated_relative_rms"].is_number())
      estimate = history.back()["estimated_relative_rms"].get<double>();
    return render_progress(samples_share, elapsed_s(), request.quality.time_limit_s,
                           request.quality.target_relative_error, estimate);
  }
  Clock::time_point report_written{};  // write_report's last write
  // Run time, including what the job ran before a restart (report.json).
  double elapsed_before_s = 0.0;
  double elapsed_s() const {
    if (!started) return elapsed_before_s;
    const auto end = is_terminal(record.state) ? end_time : Clock::now();
    return elapsed_before_s + std::chrono::duration<double>(end - start_time).count();
  }
};

}  // namespace skyfarm::server
