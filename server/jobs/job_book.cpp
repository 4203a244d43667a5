#include "server/jobs/job_book.h"

#include <algorithm>

#include "api/render_spec.h"
#include "common/camera/camera.h"
#include "common/render/sun_pixels.h"
#include "common/sun/sun.h"
#include "server/jobs/disk_budget.h"
#include "server/jobs/job_files.h"
#include "server/jobs/job_ids.h"
#include "server/jobs/job_images.h"

namespace skyfarm::server {
namespace fs = std::filesystem;

std::int64_t JobBook::disk_used() const {
  std::int64_t total = base_bytes;
  for (const auto& [id, job] : jobs) total += job->disk_used();
  return total;
}

std::int64_t JobBook::disk_reserved() const {
  std::int64_t total = base_bytes;
  for (const auto& [id, job] : jobs) total += job->disk_reserved();
  return total;
}

void JobBook::measure(Job& job) {
  job.other_bytes = job.expired ? 0 : std::max<std::int64_t>(0, directory_bytes(job.dir) - job.merger->bytes_on_disk());
}

Job& JobBook::add_job(JobRecord record, api::RenderRequest request) {
  auto job = std::make_unique<Job>();
  const Sun sun = Sun::from_spec(request.sun, request.location, request.time);
  job->plan = api::render_plan_for(request, sun);
  job->plan_json = plan_report(request, job->plan);
  {
    const Camera camera(request.camera,
                        {0.0, 0.0, request.atmosphere.planet_radius_m + request.location.altitude_m});
    const double observer_r = request.atmosphere.planet_radius_m + request.location.altitude_m;
    const auto refraction = request.atmosphere.refraction
                                ? AtmosphereRefraction::shared(request.atmosphere.planet_radius_m,
                                                               request.atmosphere.top_altitude_m)
                                : nullptr;
    job->sun_pixels = sun_pixels(camera, sun, refraction.get(), {0.0, 0.0, observer_r});
    job->result_check = std::make_unique<UnitResultCheck>(job->plan, camera, job->sun_pixels);
  }
  job->dir = data_dir / "jobs" / record.id;
  job->disk_estimate = estimated_job_bytes(request, job->plan);
  // A finished job without its directory has expired (or lost it): it is not made again.
  job->expired = record.expired || (is_terminal(record.state) && !fs::exists(job->dir));
  job->merger = std::make_unique<TileMerger>(job->plan, job->dir, std::size_t{64} << 20, !job->expired,
                                            kTilePersistInterval);
  job->passes_reported = job->merger->complete_passes();
  read_report(*job);
  if (job->plan.adaptive) job->allocation = read_allocation(job->dir / kAllocationFile, job->plan);
  if (request.quality.target_relative_error || request.quality.time_limit_s)
    job->merger->set_pass_limit(job->merger->complete_passes() + 1);
  if (job->expired) job->history = nlohmann::json::array();
  job->record = std::move(record);
  job->request = std::move(request);
  // Finished before finish times were kept: about when it stopped.
  if (is_terminal(job->record.state) && job->record.finished_unix <= 0.0)
    job->record.finished_unix = job->record.created_unix + job->elapsed_before_s;
  if (!job->record.idempotency_key.empty()) idempotency[job->record.idempotency_key] = job->record.id;
  order.push_back(job->record.id);
  if (!is_terminal(job->record.state)) runnable.push_back(job.get());
  Job& ref = *job;
  jobs[ref.record.id] = std::move(job);
  return ref;
}

void JobBook::set_state(Job& job, JobState state, const std::string& failure) {
  store->set_state(job.record.id, state, failure);
  if (is_terminal(state) && !is_terminal(job.record.state)) {
    job.record.finished_unix = unix_now();
    store->set_finished(job.record.id, job.record.finished_unix);
    // Submission to end, wall clock (a restart's downtime included).
    const double seconds = std::max(0.0, job.record.finished_unix - job.record.created_unix);
    if (state == JobState::kDone) job_seconds_done.observe(seconds);
    else if (state == JobState::kFailed) job_seconds_failed.observe(seconds);
    else if (state == JobState::kCancelled) job_seconds_cancelled.observe(seconds);
  }
  job.record.state = state;
  job.record.failure = failure;
  if (is_terminal(state)) job.end_time = Clock::now();
  write_report(job, true);
  if (state_observer) state_observer(job.record.id, state);
}

// A status document is the size of the job's history and of its list of
// workers (a thousand on a big farm), and merged units can come in thousands
// a second: "progress" events are taken at most every kProgressEventInterval
// per job.  One held back meanwhile is taken by the next event of the job, or
// by flush_held_progress (the broker's timeout checks, every 250 ms), so a
// stream never lags the job by much more than that.  Other events are never
// held.  The events kept per job are bounded too (kMaxEvents), as a client
// that reconnects needs only the recent ones.
constexpr auto kProgressEventInterval = std::chrono::milliseconds(100);
constexpr std::size_t kMaxEvents = 256;

void JobBook::emit(Job& job, const std::string& type) {
  const Clock::time_point now = Clock::now();
  if (type == "progress" && !job.events.empty() && job.events.back().type == "progress" &&
      now - job.last_event < kProgressEventInterval) {
    job.progress_held = true;
    return;
  }
  job.progress_held = false;
  job.last_event = now;
  JobEvent e;
  e.sequence = job.events.empty() ? 1 : job.events.back().sequence + 1;
  e.type = type;
  e.data = status_of(job);
  job.events.push_back(std::move(e));
  if (job.events.size() > kMaxEvents) job.events.erase(job.events.begin(), job.events.begin() + kMaxEvents / 2);
  changed.notify_all();
}

void JobBook::flush_due_tiles(Clock::time_point now) {
  for (const auto& [id, job] : jobs) {
    if (!job->active() || job->merger->dirty_tiles() == 0) continue;
    try {
      job->merger->flush_due(now);
    } catch (const StorageError& e) {
      fail_job(*job, e.what());
    }
  }
}

void JobBook::flush_held_progress(Clock::time_point now) {
  for (const auto& [id, job] : jobs)
    if (job->progress_held && job->active() && now - job->last_event >= kProgressEventInterval) emit(*job, "progress");
}

void JobBook::drop_attempts_of(Job& job) {
  for (auto it = in_flight.begin(); it != in_flight.end();) {
    if (it->second.job_id == job.record.id) {
      cancelled.emplace_back(it->second.worker, it->first);
      if (auto w = workers.find(it->second.worker); w != workers.end()) --w->second.in_flight;
      it = in_flight.erase(it);
    } else {
      ++it;
    }
  }
  job.in_flight = 0;
  job.requeued.clear();
}

void JobBook::requeue(std::uint64_t attempt, bool tell_worker) {
  const auto it = in_flight.find(attempt);
  if (it == in_flight.end()) return;
  const InFlight f = it->second;
  in_flight.erase(it);
  if (tell_worker) cancelled.emplace_back(f.worker, attempt);
  if (auto w = workers.find(f.worker); w != workers.end()) --w->second.in_flight;
  const auto j = jobs.find(f.job_id);
  if (j == jobs.end()) return;
  Job& job = *j->second;
  --job.in_flight;
  if (job.active() && !job.merger->received(f.unit)) {
    job.requeued.push_back(f.unit);
    ++requeues;
  }
}

void JobBook::fail_job(Job& job, const std::string& message) {
  drop_attempts_of(job);
  job.stopped_by = "failed";
  set_state(job, JobState::kFailed, message);
  release_tiles(job);
  emit(job, "failed");
}

void JobBook::cancel(Job& job) {
  drop_attempts_of(job);
  job.stopped_by = "cancelled";
  set_state(job, JobState::kCancelled);
  release_tiles(job);
  emit(job, "cancelled");
}

PurgeOutcome JobBook::purge(const std::string& id) {
  const auto it = jobs.find(id);
  if (it == jobs.end()) return {PurgeOutcome::kUnknown, ""};
  Job& job = *it->second;
  if (!job.group.empty())
    return {PurgeOutcome::kConflict, "render \"" + id + "\" is a frame of timelapse \"" + job.group +
                                         "\"; delete the timelapse instead"};
  if (job.finishing)
    return {PurgeOutcome::kConflict, "render \"" + id + "\" is writing its final image; try again in a moment"};
  if (job.active()) cancel(job);
  store->remove(id);
  std::error_code ec;
  fs::remove_all(job.dir, ec);
  // Its own key and those the result cache pointed at it.
  std::erase_if(idempotency, [&](const auto& entry) { return entry.second == id; });
  order.erase(std::find(order.begin(), order.end(), id));
  // The object outlives its record: a preview fetch may still hold it (image()).
  job.expired = true;
  job.events.clear();
  job.history = nlohmann::json::array();
  purged.push_back(std::move(it->second));
  jobs.erase(it);
  changed.notify_all();
  return {PurgeOutcome::kPurged, ""};
}

void JobBook::release_tiles(Job& job) {
  if (!job.released) job.released.emplace(job.merger->merged_units(), job.merger->complete_passes());
  job.merger->remove_files();
  job.pilot_statistics.clear();
  // A cancelled or failed job shows no partial image: its sums are gone.
  if (job.record.state != JobState::kDone && job.preview_units >= 0) {
    remove_preview(job.dir, job.preview_units);
    job.preview_units = -1;
  }
  write_report(job, true);
  measure(job);
}

std::size_t JobBook::expire(double now_unix) {
  if (limits.retention_hours <= 0.0) return 0;
  const double horizon = now_unix - limits.retention_hours * 3600.0;
  std::size_t n = 0;
  for (const auto& id : order) {
    Job& job = *jobs.at(id);
    if (job.expired || !is_terminal(job.record.state) || job.record.finished_unix > horizon) continue;
    std::error_code ec;
    fs::remove_all(job.dir, ec);
    if (ec) continue;  // tried again at the next check
    if (!job.merger->files_removed()) release_tiles(job);
    job.expired = true;
    job.other_bytes = 0;
    job.history = nlohmann::json::array();
    job.preview_units = -1;
    store->set_expired(job.record.id);
    ++n;
  }
  return n;
}

}  // namespace skyfarm::server
