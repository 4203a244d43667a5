#include "server/jobs/job_service.h"

#include <algorithm>
#include <mutex>

#include "server/jobs/admission.h"
#include "server/jobs/disk_budget.h"
#include "server/jobs/job_book.h"
#include "server/jobs/job_ids.h"
#include "server/jobs/job_images.h"
#include "server/jobs/result_intake.h"
#include "server/jobs/scheduler.h"

namespace skyfarm::server {
namespace fs = std::filesystem;

struct JobService::Parts {
  JobBook book;
  Admission admission{book};
  Scheduler scheduler{book};
  ResultIntake results{book};
};

// --- Construction and restart -------------------------------------------------

JobService::JobService(fs::path data_dir, ServiceLimits limits) : parts_(std::make_unique<Parts>()) {
  JobBook& book = parts_->book;
  book.data_dir = std::move(data_dir);
  book.limits = limits;
  std::error_code ec;
  fs::create_directories(book.data_dir / "jobs", ec);
  if (ec) throw StorageError("cannot create the data directory " + book.data_dir.string() + ": " + ec.message());
  book.store = std::make_unique<JobStore>(book.data_dir / "skyfarm.db");
  // Attempt ids stay unique across restarts (a late result from before a
  // restart can never match a new dispatch): start from the clock.
  book.next_attempt = static_cast<std::uint64_t>(unix_now() * 1000.0) << 16;
  // Resume: every job comes back; unfinished ones continue after their merged units.
  for (JobRecord& r : book.store->load_all()) {
    api::RenderRequest request = api::parse_render_request(r.request);
    book.next_sequence = std::max(book.next_sequence, r.sequence + 1);
    Job& job = book.add_job(std::move(r), std::move(request));
    if (job.record.state == JobState::kRunning) book.set_state(job, JobState::kQueued);
    if (job.expired) continue;
    if (job.record.state == JobState::kDone && !fs::exists(job.dir / "image.exr") && job.merger->merged_units() > 0)
      write_images(job, true);
    if (job.record.state == JobState::kDone) job.preview_units = job.merger->merged_units();
    parts_->results.finish_now_if_complete(job);
    // Finished before tiles were deleted at the end (or stopped by a crash in between).
    if (is_terminal(job.record.state) && !job.merger->files_removed() &&
        (job.record.state != JobState::kDone || fs::exists(job.dir / "image.exr")))
      book.release_tiles(job);
    book.measure(job);
  }
  // The budget counts the data directory's other files as they are now.
  std::int64_t jobs_bytes = 0;
  for (const auto& [id, job] : book.jobs) jobs_bytes += job->disk_used();
  const std::int64_t all = directory_bytes(book.data_dir);
  book.base_bytes = std::max<std::int64_t>(0, all - jobs_bytes);
  book.disk_budget = limits.max_disk_bytes < 0 ? default_disk_budget(book.data_dir) : limits.max_disk_bytes;
  book.expire(unix_now());
}

JobService::~JobService() = default;

// --- HTTP side ------------------------------------------------------------

SubmitResult JobService::submit(const api::RenderRequest& request, const std::optional<std::string>& key) {
  const std::lock_guard<std::mutex> lock(parts_->book.mu);
  return parts_->admission.submit(request, key);
}

std::optional<nlohmann::json> JobService::status(const std::string& id) const {
  const std::lock_guard<std::mutex> lock(parts_->book.mu);
  const auto it = parts_->book.jobs.find(id);
  if (it == parts_->book.jobs.end()) return std::nullopt;
  return parts_->book.status_of(*it->second);
}

nlohmann::json JobService::list(std::size_t offset, std::size_t limit) const {
  const JobBook& book = parts_->book;
  const std::lock_guard<std::mutex> lock(book.mu);
  nlohmann::json out = nlohmann::json::array();
  const auto& order = book.order;
  for (std::size_t i = offset; i < order.size() && out.size() < limit; ++i)
    out.push_back(book.status_of(*book.jobs.at(order[order.size() - 1 - i])));
  return out;
}

std::size_t JobService::job_count() const {
  const std::lock_guard<std::mutex> lock(parts_->book.mu);
  return parts_->book.jobs.size();
}

bool JobService::cancel(const std::string& id) {
  const std::lock_guard<std::mutex> lock(parts_->book.mu);
  const auto it = parts_->book.jobs.find(id);
  if (it == parts_->book.jobs.end()) return false;
  if (it->second->active()) parts_->book.cancel(*it->second);
  return true;
}

PurgeOutcome JobService::purge(const std::string& id) {
  const std::lock_guard<std::mutex> lock(parts_->book.mu);
  return parts_->book.purge(id);
}

std::size_t JobService::expire_finished(double now_unix) {
  const std::lock_guard<std::mutex> lock(parts_->book.mu);
  return parts_->book.expire(now_unix);
}

// A preview is resolved under the lock but encoded and written without it,
// so a client fetching previews of a large image never holds up dispatch
// and merging.  Concurrent fetches of the same version write the same bytes
// once (one writer per job); a version overtaken by a newer one while it was
// written is removed and the newer one served.
std::optional<ImageFile> JobService::image(const std::string& id, ImageFormat format) {
  JobBook& book = parts_->book;
  const char* ext = format == ImageFormat::kExr ? ".exr" : ".png";
  auto preview_file = [&](const Job& job) {
    return ImageFile{job.dir / ("preview-" + std::to_string(job.preview_units) + ext),
                     "\"" + job.record.id + "-" + std::to_string(job.preview_units) + "\"", false};
  };
  auto final_file = [&](const Job& job) {
    return ImageFile{job.dir / (std::string("image") + ext), "\"" + job.record.request_hash + "\"", true};
  };
  std::optional<ImageSnapshot> snap;
  int units = 0;
  Job* job = nullptr;
  {
    const std::lock_guard<std::mutex> lock(book.mu);
    const auto it = book.jobs.find(id);
    if (it == book.jobs.end()) return std::nullopt;
    job = it->second.get();  // purged jobs are kept (JobBook::purged): the pointer outlives the lock
    if (job->expired) return std::nullopt;
    if (job->record.state == JobState::kDone) return final_file(*job);
    if (!job->active() && !job->finishing) return std::nullopt;  // cancelled or failed: its sums are deleted
    if (!job->merger->first_pass_complete()) return std::nullopt;
    units = job->merger->merged_units();
    if (job->preview_units == units) return preview_file(*job);
    snap = snapshot_images(*job, false);
  }
  {
    // One writer per job at a time: two fetches of one version would share
    // its temporary file name (AtomicFile); the second finds it written.
    const std::lock_guard<std::mutex> writing(job->preview_writer);
    if (job->preview_written != units) {
      write_snapshot(*snap);
      job->preview_written = units;
    }
  }
  const std::lock_guard<std::mutex> lock(book.mu);
  if (job->record.state == JobState::kDone) {  // finished meanwhile: the final image it is
    remove_preview(job->dir, units);
    return final_file(*job);
  }
  if (!job->active() && !job->finishing) {  // cancelled or failed meanwhile
    remove_preview(job->dir, units);
    return std::nullopt;
  }
  if (units > job->preview_units) {
    if (job->preview_units >= 0) remove_preview(job->dir, job->preview_units);
    job->preview_units = units;
  } else if (units != job->preview_units) {
    remove_preview(job->dir, units);  // overtaken by a newer preview
  }
  book.measure(*job);
  return preview_file(*job);
}

std::vector<JobEvent> JobService::events_after(const std::string& id, std::uint64_t after,
                                               std::chrono::milliseconds timeout) {
  std::unique_lock<std::mutex> lock(parts_->book.mu);
  auto ready = [&] {
    const auto it = parts_->book.jobs.find(id);
    return it == parts_->book.jobs.end() || (!it->second->events.empty() && it->second->events.back().sequence > after);
  };
  parts_->book.changed.wait_for(lock, timeout, ready);
  std::vector<JobEvent> out;
  const auto it = parts_->book.jobs.find(id);
  if (it == parts_->book.jobs.end()) return out;
  for (const auto& e : it->second->events)
    if (e.sequence > after) out.push_back(e);
  return out;
}

nlohmann::json JobService::workers() const {
  const std::lock_guard<std::mutex> lock(parts_->book.mu);
  return parts_->scheduler.workers();
}

bool JobService::set_worker_draining(const std::string& worker_id, bool draining) {
  const std::lock_guard<std::mutex> lock(parts_->book.mu);
  return parts_->scheduler.set_draining(worker_id, draining);
}

nlohmann::json JobService::metrics() const {
  const std::lock_guard<std::mutex> lock(parts_->book.mu);
  return parts_->book.metrics();
}

std::vector<HistogramSeries> JobService::histograms() const {
  const std::lock_guard<std::mutex> lock(parts_->book.mu);
  return parts_->book.histograms();
}

// --- Broker side ----------------------------------------------------------

void JobService::worker_joined(const std::string& worker_id, const nlohmann::json& info) {
  const std::lock_guard<std::mutex> lock(parts_->book.mu);
  parts_->scheduler.worker_joined(worker_id, info);
}

void JobService::worker_left(const std::string& worker_id) {
  const std::lock_guard<std::mutex> lock(parts_->book.mu);
  parts_->scheduler.worker_left(worker_id);
}

std::optional<UnitAssignment> JobService::next_unit(const std::string& worker_id) {
  const std::lock_guard<std::mutex> lock(parts_->book.mu);
  return parts_->scheduler.next_unit(worker_id);
}

void JobService::unit_done(const std::string& worker_id, const UnitKey& key, std::uint64_t attempt,
                           const std::vector<std::uint8_t>& bytes, std::uint64_t paths) {
  std::unique_lock<std::mutex> lock(parts_->book.mu);
  parts_->results.unit_done(lock, worker_id, key, attempt, bytes, paths);
}

void JobService::unit_failed(const std::string& worker_id, const UnitKey& key, std::uint64_t attempt,
                             const std::string& message) {
  const std::lock_guard<std::mutex> lock(parts_->book.mu);
  parts_->results.unit_failed(worker_id, key, attempt, message);
}

std::vector<std::pair<std::string, std::uint64_t>> JobService::take_cancelled_attempts() {
  const std::lock_guard<std::mutex> lock(parts_->book.mu);
  return parts_->scheduler.take_cancelled_attempts();
}

// Every 250 ms from the broker: late units requeued, finished jobs expired
// (once a minute), held progress events taken, due tiles written.
void JobService::check_timeouts(Clock::time_point now) {
  JobBook& book = parts_->book;
  const std::lock_guard<std::mutex> lock(book.mu);
  parts_->scheduler.requeue_late(now);
  if (now - book.last_expiry >= std::chrono::minutes(1)) {
    book.last_expiry = now;
    book.expire(unix_now());
  }
  book.flush_held_progress(Clock::now());
  book.flush_due_tiles(Clock::now());
}

// --- Timelapse support ------------------------------------------------------

bool JobService::set_group(const std::string& id, const std::string& group) {
  const std::lock_guard<std::mutex> lock(parts_->book.mu);
  const auto it = parts_->book.jobs.find(id);
  if (it == parts_->book.jobs.end()) return false;
  it->second->group = group;
  return true;
}

std::optional<JobSummary> JobService::summary(const std::string& id) const {
  const std::lock_guard<std::mutex> lock(parts_->book.mu);
  const auto it = parts_->book.jobs.find(id);
  if (it == parts_->book.jobs.end()) return std::nullopt;
  const Job& job = *it->second;
  JobSummary s;
  s.state = job.record.state;
  s.fraction = job.progress();
  if (!job.history.empty() && job.history.back()["estimated_relative_rms"].is_number())
    s.estimated_relative_rms = job.history.back()["estimated_relative_rms"].get<double>();
  s.failure = job.record.failure;
  return s;
}

void JobService::set_state_observer(std::function<void(const std::string&, JobState)> observer) {
  const std::lock_guard<std::mutex> lock(parts_->book.mu);
  parts_->book.state_observer = std::move(observer);
}

}  // namespace skyfarm::server