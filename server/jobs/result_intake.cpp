#include "server/jobs/result_intake.h"

#include "common/film/film_tile.h"
#include "server/jobs/job_files.h"

namespace skyfarm::server {
namespace fs = std::filesystem;

void ResultIntake::unit_done(std::unique_lock<std::mutex>& lock, const std::string& worker_id, const UnitKey& key,
                             std::uint64_t attempt, const std::vector<std::uint8_t>& bytes, std::uint64_t paths) {
  const auto it = book_.in_flight.find(attempt);
  // A superseded attempt (requeued after a timeout or a lost worker) or a
  // cancelled job: the result is dropped.
  if (it == book_.in_flight.end() || it->second.job_id != key.job_id || it->second.unit.tile != key.tile ||
      it->second.unit.batch != key.batch || it->second.unit.pass != key.pass)
    return;
  const InFlight f = it->second;
  book_.in_flight.erase(it);
  auto& workers = book_.workers;
  const auto w = workers.find(worker_id);
  if (w != workers.end()) {
    --w->second.in_flight;
    w->second.last_seen = Clock::now();
  }
  Job& job = *book_.jobs.at(f.job_id);
  --job.in_flight;
  if (!job.active()) return;
  std::optional<FilmTile> film;
  std::string refusal;
  try {
    film = FilmTile::deserialize(bytes);
    // Exactly the unit's tile, batch and sample counts: anything else would
    // be merged into the image (or, of another size, never merge and hang
    // the job).
    WorkUnit asked = f.unit;
    if (asked.pass > 0 && job.allocation) asked.samples = job.allocation->tile(asked.tile);
    refusal = job.result_check->check(asked, *film);
  } catch (const FilmTileDecodeError& e) {
    refusal = e.what();
  }
  if (!refusal.empty()) {
    refuse_result(job, f.unit, worker_id, refusal);
    return;
  }
  try {
    if (job.merger->add(f.unit, std::move(*film))) {
      if (job.waits_for_allocation() && job.merger->merged_units_of(f.unit.tile) == job.plan.batches) {
        job.pilot_statistics.resize(static_cast<std::size_t>(job.plan.tile_count()));
        job.pilot_statistics[static_cast<std::size_t>(f.unit.tile)] = SampleAllocation::pilot_statistics(
            job.plan, f.unit.tile, job.merger->sums_of(f.unit.tile), job.sun_pixels);
      }
      if (w != workers.end()) ++w->second.units_done;
      ++job.worker_units[worker_id];
      job.paths += paths;
      book_.samples_total += paths;
      ++book_.units_completed;
      const Clock::time_point merged_at = Clock::now();
      (job.plan.lut ? book_.unit_seconds_lut : book_.unit_seconds_path)
          .observe(std::chrono::duration<double>(merged_at - f.since).count());
      book_.recent_paths.emplace_back(merged_at, paths);
      while (book_.recent_paths.size() > 10000) book_.recent_paths.pop_front();
    }
  } catch (const FilmTileDecodeError& e) {
    refuse_result(job, f.unit, worker_id, e.what());
    return;
  } catch (const StorageError& e) {
    book_.fail_job(job, e.what());
    return;
  }
  std::optional<PendingFinish> pending = finish_if_complete(job);
  if (!pending) {
    if (job.active()) book_.emit(job, "progress");
    return;
  }
  // The final image is encoded and written without the lock: a large one
  // takes seconds, and dispatch, merging and status requests go on meanwhile
  // (the job, finishing, gets no units).  A finishing job is not purged
  // (and purged ones are kept in memory), so `job` stays valid.
  lock.unlock();
  std::optional<std::string> failure;
  try {
    write_snapshot(pending->final_image);
  } catch (const StorageError& e) {
    failure = e.what();
  }
  lock.lock();
  if (failure) {
    job.finishing = false;
    book_.fail_job(job, *failure);
    return;
  }
  complete_finish(job, pending->stopped_by);
}

void ResultIntake::refuse_result(Job& job, const WorkUnit& unit, const std::string& worker_id,
                                     const std::string& why) {
  ++book_.results_refused;
  ++book_.unit_failures;
  auto& failed = job.failed_workers[static_cast<int>(job.unit_index(unit))];
  failed.insert(worker_id);
  if (static_cast<int>(failed.size()) >= book_.limits.max_unit_failures) {
    book_.fail_job(job, "unit (" + unit_text(unit) + ") got results that do not match it from " +
                      std::to_string(failed.size()) + " workers; the last (" + worker_id + "): " + why);
    return;
  }
  job.requeued.push_front(unit);
  ++book_.requeues;
}

void ResultIntake::unit_failed(const std::string& worker_id, const UnitKey& key, std::uint64_t attempt,
                             const std::string& message) {
  const auto it = book_.in_flight.find(attempt);
  if (it == book_.in_flight.end() || it->second.job_id != key.job_id) return;
  const WorkUnit unit = it->second.unit;
  book_.requeue(attempt, false);
  ++book_.unit_failures;
  Job& job = *book_.jobs.at(key.job_id);
  auto& failed = job.failed_workers[static_cast<int>(job.unit_index(unit))];
  failed.insert(worker_id);
  if (static_cast<int>(failed.size()) >= book_.limits.max_unit_failures && job.active())
    book_.fail_job(job, "unit (" + unit_text(unit) + ") failed on " + std::to_string(failed.size()) +
                             " workers; last error: " + message);
}

bool ResultIntake::allocate(Job& job) {
  const fs::path path = job.dir / kAllocationFile;
  if (std::optional<SampleAllocation> stored = read_allocation(path, job.plan)) {
    job.allocation = std::move(stored);
    return true;
  }
  // Computed from the pilot alone: nothing beyond pass 0 may have been merged.
  if (job.merger->merged_units() != job.plan.tile_count() * job.plan.batches) {
    book_.fail_job(job, "the adaptive sample allocation (" + path.string() + ") is missing or unreadable, and the pilot "
                  "pass can no longer be told apart from later passes");
    return false;
  }
  // The statistics taken as the pilots completed; a tile without them (a
  // restart in between) is read back.
  std::vector<SampleAllocation::BlockStatistics> rms(static_cast<std::size_t>(job.plan.tile_count()));
  job.pilot_statistics.resize(rms.size());
  for (std::size_t t = 0; t < rms.size(); ++t)
    rms[t] = job.pilot_statistics[t] ? std::move(*job.pilot_statistics[t])
                                     : SampleAllocation::pilot_statistics(job.plan, static_cast<int>(t),
                                                                          job.merger->sums_of(static_cast<int>(t)),
                                                                          job.sun_pixels);
  job.pilot_statistics.clear();
  job.pilot_statistics.shrink_to_fit();
  SampleAllocation a = SampleAllocation::from_statistics(job.plan, rms);
  try {
    write_allocation(path, a);
  } catch (const StorageError& e) {
    book_.fail_job(job, e.what());
    return false;
  }
  job.allocation = std::move(a);
  return true;
}

// True when the request can stop before its last sample (a target error or a time limit).
static bool stops_early(const Job& job) {
  return job.request.quality.target_relative_error.has_value() || job.request.quality.time_limit_s.has_value();
}

// After merges: advance the pass gate (early-stopping jobs), record the error
// of every newly completed pass, and finish the job when its samples are all
// merged, its target error is reached, or its time limit has passed (checked
// at pass boundaries: the pass in progress completes, so the image is always
// a whole number of passes and equals a local render of that many passes).
std::optional<ResultIntake::PendingFinish> ResultIntake::finish_if_complete(Job& job) {
  if (!job.active()) return std::nullopt;
  std::string stop;
  if (job.waits_for_allocation() && job.merger->complete_passes() >= 1 && !allocate(job)) return std::nullopt;
  while (stop.empty()) {
    const int passes = job.merger->complete_passes();
    if (passes > job.passes_reported) {
      job.passes_reported = passes;
      const ErrorSums sums = job.merger->error_sums(job.sun_pixels);
      const auto rms = sums.relative_rms();
      const auto rms_rgb = sums.relative_rms_rgb();
      job.history.push_back(
          {{"elapsed_s", job.elapsed_s()},
           {"samples_per_pixel", job.samples_per_pixel(passes)},
           {"estimated_relative_rms", rms ? nlohmann::json(*rms) : nlohmann::json(nullptr)},
           {"estimated_relative_rms_rgb", rms_rgb ? nlohmann::json{{"r", rms_rgb->r}, {"g", rms_rgb->g}, {"b", rms_rgb->b}}
                                                  : nlohmann::json(nullptr)},
           {"pixels_without_estimate", sums.unknown}});
      thin_history(&job.history);
      write_report(job, false);
      const auto& q = job.request.quality;
      if (job.merger->complete()) {
        stop = "samples";
      } else if (q.target_relative_error && rms && *rms <= *q.target_relative_error) {
        stop = "target_error";
      } else if (q.time_limit_s && job.elapsed_s() >= *q.time_limit_s) {
        stop = "time_limit";
      }
    }
    if (!stop.empty()) break;
    // The gate: the next pass may merge only now that this one is complete everywhere.
    if (stops_early(job) && job.merger->pass_limit() < passes + 1) {
      job.merger->set_pass_limit(passes + 1);
      continue;
    }
    break;
  }
  if (stop.empty() && job.merger->complete()) stop = "samples";
  if (stop.empty()) return std::nullopt;
  // Every merged unit on disk before the job can be done (a restart
  // rebuilds a missing final image from the tiles).
  try {
    job.merger->flush();
  } catch (const StorageError& e) {
    book_.fail_job(job, e.what());
    return std::nullopt;
  }
  book_.drop_attempts_of(job);
  job.merger->drop_waiting();
  job.finishing = true;
  return PendingFinish{snapshot_images(job, true), stop};
}

void ResultIntake::complete_finish(Job& job, const std::string& stopped_by) {
  job.finishing = false;
  // A done job serves its final image: the last preview goes.
  if (job.preview_units >= 0) remove_preview(job.dir, job.preview_units);
  job.preview_units = job.merger->merged_units();
  job.stopped_by = stopped_by;
  book_.set_state(job, JobState::kDone);
  book_.release_tiles(job);
  book_.emit(job, "done");
}

void ResultIntake::finish_now_if_complete(Job& job) {
  if (std::optional<PendingFinish> pending = finish_if_complete(job)) {
    write_snapshot(pending->final_image);
    complete_finish(job, pending->stopped_by);
  }
}

}  // namespace skyfarm::server
