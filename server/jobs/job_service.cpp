#include "server/jobs/job_service.h"

#include <algorithm>
#include <condition_variable>
#include <cmath>
#include <deque>
#include <fstream>
#include <map>
#include <mutex>
#include <random>
#include <set>
#include <sstream>

#include "api/render_spec.h"
#include "common/atmosphere/atmosphere_builder.h"
#include "common/film/film_tile.h"
#include "common/image/atomic_file.h"
#include "common/image/exr_writer.h"
#include "common/image/png_writer.h"
#include "common/render/render_plan.h"
#include "common/render/render_progress.h"
#include "common/render/sample_allocation.h"
#include "common/render/sun_pixels.h"
#include "common/sampling/sampler.h"
#include "server/jobs/disk_budget.h"
#include "server/jobs/job_store.h"
#include "server/jobs/tile_merger.h"
#include "server/jobs/unit_result_check.h"

#include "server/jobs/job_ids.h"

namespace skyfarm::server {
namespace {

namespace fs = std::filesystem;

// The result-cache key: the canonical request without its priority (which
// changes when a job runs, not what it renders), hashed.
std::string request_hash(const api::RenderRequest& request) {
  nlohmann::json j = api::to_canonical_json(request);
  j.erase("priority");
  const std::string text = j.dump();
  std::uint64_t h1 = 0x9e3779b97f4a7c15ULL, h2 = 0xc2b2ae3d27d4eb4fULL;
  for (unsigned char c : text) {
    h1 = fmix64(h1 ^ c);
    h2 = fmix64(h2 + c * 0x100000001b3ULL);
  }
  std::ostringstream o;
  o << std::hex << h1 << h2;
  return o.str();
}

bool is_terminal(const std::string& state) { return state == "done" || state == "failed" || state == "cancelled"; }

// Unit index i of a job, pass-major: every tile and batch of pass 0 first.
WorkUnit unit_at(const RenderPlan& plan, std::size_t i) {
  const std::size_t per_pass = static_cast<std::size_t>(plan.tile_count()) * static_cast<std::size_t>(plan.batches);
  const std::size_t rem = i % per_pass;
  return WorkUnit{static_cast<int>(rem / static_cast<std::size_t>(plan.batches)),
                  static_cast<int>(rem % static_cast<std::size_t>(plan.batches)), static_cast<int>(i / per_pass)};
}

// The queue's measure of a job (ServiceLimits::max_queue_units): its units
// not yet merged, at most kQueueHorizonPasses passes' worth.  Units are made
// on demand from a cursor, so a far pass waits nowhere; and a request that
// stops by a target error or a time limit alone has no sample cap (1048576
// samples per pixel: 65536 passes), which counted whole made "1 % in at most
// 2 minutes" of a 512x256 frame 4.2 million units, over the limit.
constexpr std::int64_t kQueueHorizonPasses = 16;
std::int64_t waiting_units(const RenderPlan& plan, std::int64_t merged) {
  const std::int64_t per_pass = static_cast<std::int64_t>(plan.tile_count()) * plan.batches;
  return std::max<std::int64_t>(0, std::min(plan.unit_count() - merged, per_pass * kQueueHorizonPasses));
}

std::string unit_text(const WorkUnit& u) {
  return "tile " + std::to_string(u.tile) + ", batch " + std::to_string(u.batch) + ", pass " + std::to_string(u.pass);
}

// What the render includes and leaves out (DESIGN §3.5 "scene plan").
nlohmann::json plan_report(const api::RenderRequest& request, const RenderPlan& plan) {
  nlohmann::json constituents = nlohmann::json::array(), skipped = nlohmann::json::array();
  const Atmosphere atmosphere = build_atmosphere(request.atmosphere);
  for (const auto& c : atmosphere.constituents()) constituents.push_back(c.name);
  if (request.atmosphere.preset != AtmospherePreset::kCustom) {
    if (request.atmosphere.ozone_du <= 0.0) skipped.push_back("ozone");
    if (!request.atmosphere.aerosol || request.atmosphere.aerosol->optical_depth_550 <= 0.0)
      skipped.push_back("aerosol");
  }
  return {{"constituents", constituents}, {"skipped", skipped},       {"tiles", plan.tile_count()},
          {"batches", plan.batches},      {"passes", plan.passes},    {"samples_per_pass", plan.samples_per_pass},
          {"tile_size", plan.tile_size},  {"units", plan.unit_count()},  {"mirrored", plan.mirrored},
          {"method", plan.lut ? "lut" : "path"}, {"roulette_control", plan.roulette_control},
          {"shadow_guide", plan.shadow_guide},     {"adaptive", plan.adaptive},
          {"pooled_ground_row", plan.pooled_ground_row >= 0 ? nlohmann::json(plan.pooled_ground_row) : nlohmann::json()}};
}

// A job's image at one moment, ready to be encoded and stored: dir/stem.exr|png.
struct ImageSnapshot {
  Image image;
  fs::path dir;
  std::string stem;
  ExrWriteOptions exr;
  PngWriteOptions png;
};

void write_snapshot(const ImageSnapshot& snap) {
  try {
    write_exr(snap.image, snap.dir / (snap.stem + ".exr"), snap.exr);
    write_png(snap.image, snap.dir / (snap.stem + ".png"), snap.png);
  } catch (const FileWriteError& e) {
    throw StorageError(e.what());
  }
}

void remove_preview(const fs::path& dir, int units) {
  std::error_code ec;
  for (const char* ext : {".exr", ".png"}) fs::remove(dir / ("preview-" + std::to_string(units) + ext), ec);
}

}  // namespace

// --- One job in memory ------------------------------------------------------
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
  fs::path dir;
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
    if (record.state == "done") return 1.0;
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

namespace {

const char* kAllocationFile = "allocation.json";
// A tile is written at most this often while it merges (tile_merger.h): tiny
// units merge thousands of times a second.  A crash loses at most this much
// merging (those units are handed out again), never a merged image: a job's
// tiles are all written before it is done.
constexpr std::chrono::milliseconds kTilePersistInterval{1000};
const char* kReportFile = "report.json";

// Writes `text` to `path` atomically (image/atomic_file.h): readers see the
// old or the new file, never half of one; kSynced survives a power failure.
bool write_atomically(const fs::path& path, const std::string& text, AtomicFile::Durability durability) {
  try {
    AtomicFile file(path);
    file.write(text.data(), text.size());
    file.commit(durability);
    return true;
  } catch (const FileWriteError&) {
    return false;
  }
}

// What the status reports beyond the merged tiles, kept in the job's
// directory so that a restart does not lose it: the error history, what
// stopped the job, and its run time so far.  Written at every state change
// and every recorded pass, but beyond the first 64 passes at most once a
// second (a small frame's passes can take milliseconds).  Best effort: a job
// whose report cannot be written still renders (its tiles are the data).
void write_report(Job& job, bool state_change) {
  const Clock::time_point now = Clock::now();
  if (!state_change && job.history.size() > 64 && now - job.report_written < std::chrono::seconds(1)) return;
  job.report_written = now;
  if (!fs::exists(job.dir)) return;
  nlohmann::json report = {{"history", job.history},
                           {"stopped_by", job.stopped_by},
                           {"elapsed_s", job.elapsed_s()}};
  if (job.released) report["released"] = {{"units_done", job.released->first}, {"passes", job.released->second}};
  // Not synced: after a power failure the last second of history may be gone
  // (an unreadable report is ignored), the tiles are still the data.
  write_atomically(job.dir / kReportFile, report.dump(), AtomicFile::Durability::kRenamed);
}

// At most kMaxHistory entries: beyond that every second entry but the last
// goes, so a long job's history keeps its whole span at a coarser step (a
// 1x1 frame to a tight target error can run a pass per millisecond).
constexpr std::size_t kMaxHistory = 512;
void thin_history(nlohmann::json* history) {
  if (history->size() <= kMaxHistory) return;
  nlohmann::json kept = nlohmann::json::array();
  for (std::size_t i = 0; i + 1 < history->size(); i += 2) kept.push_back(std::move((*history)[i]));
  kept.push_back(std::move(history->back()));
  *history = std::move(kept);
}

void read_report(Job& job) {
  std::ifstream in(job.dir / kReportFile);
  if (!in) return;
  try {
    const nlohmann::json r = nlohmann::json::parse(in);
    if (r.at("history").is_array()) job.history = r.at("history");
    job.stopped_by = r.at("stopped_by").get<std::string>();
    job.elapsed_before_s = std::max(0.0, r.at("elapsed_s").get<double>());
    if (r.contains("released"))
      job.released.emplace(r["released"].at("units_done").get<std::int64_t>(), r["released"].at("passes").get<int>());
  } catch (const std::exception&) {
    // An unreadable report: the status starts again from the tiles.
  }
}

nlohmann::json allocation_json(const SampleAllocation& a) {
  nlohmann::json tiles = nlohmann::json::array();
  for (int t = 0; t < a.tile_count(); ++t) {
    nlohmann::json blocks = nlohmann::json::array();
    for (const PassSamples& n : a.tile(t)) blocks.push_back({n.even, n.odd});
    tiles.push_back(std::move(blocks));
  }
  return {{"samples_per_pass", tiles}};
}

// The stored allocation, or nullopt when there is none or it does not fit the plan.
std::optional<SampleAllocation> read_allocation(const fs::path& path, const RenderPlan& plan) {
  std::ifstream in(path);
  if (!in) return std::nullopt;
  try {
    const nlohmann::json j = nlohmann::json::parse(in);
    std::vector<std::vector<PassSamples>> tiles;
    for (const auto& blocks : j.at("samples_per_pass")) {
      tiles.emplace_back();
      for (const auto& n : blocks) tiles.back().push_back({n.at(0).get<int>(), n.at(1).get<int>()});
    }
    return SampleAllocation::from_counts(plan, std::move(tiles));
  } catch (const std::exception&) {
    return std::nullopt;
  }
}

void write_allocation(const fs::path& path, const SampleAllocation& a) {
  // Synced: the passes after the pilot are rendered with these counts, so
  // losing the file would lose the job (JobService::Impl::allocate).
  if (!write_atomically(path, allocation_json(a).dump(), AtomicFile::Durability::kSynced))
    throw StorageError("cannot write " + path.string());
}

}  // namespace

struct InFlight {
  std::string job_id;
  WorkUnit unit;
  std::string worker;
  Clock::time_point since;
};

struct WorkerInfo {
  nlohmann::json info;
  int units_done = 0;
  int in_flight = 0;
  Clock::time_point last_seen;
};

struct JobService::Impl {
  fs::path data_dir;
  ServiceLimits limits;
  std::unique_ptr<JobStore> store;
  mutable std::mutex mu;
  std::condition_variable changed;
  std::map<std::string, std::unique_ptr<Job>> jobs;
  std::vector<std::string> order;  // submission order
  // The jobs that may still get units, in submission order (next_unit prunes
  // the finished), so that dispatch scans neither finished jobs nor units.
  std::vector<Job*> runnable;
  std::map<std::string, std::string> idempotency;
  std::map<std::uint64_t, InFlight> in_flight;
  std::uint64_t next_attempt = 1;
  std::vector<std::pair<std::string, std::uint64_t>> cancelled;
  std::map<std::string, WorkerInfo> workers;
  std::int64_t next_sequence = 1;
  std::uint64_t unit_failures = 0, requeues = 0, results_refused = 0;
  std::deque<std::pair<Clock::time_point, std::uint64_t>> recent_paths;  // for samples/s
  std::function<void(const std::string&, const std::string&)> state_observer;
  // Disk: the budget (0: none), the data directory's bytes outside the jobs'
  // directories (measured at start: the database, timelapses), purged jobs
  // kept for threads that still hold them (image()), and the last expiry.
  std::int64_t disk_budget = 0;
  std::int64_t base_bytes = 0;
  std::vector<std::unique_ptr<Job>> purged;
  Clock::time_point last_expiry{};
  std::int64_t disk_used() const {
    std::int64_t total = base_bytes;
    for (const auto& [id, job] : jobs) total += job->disk_used();
    return total;
  }
  std::int64_t disk_reserved() const {
    std::int64_t total = base_bytes;
    for (const auto& [id, job] : jobs) total += job->disk_reserved();
    return total;
  }
  // The bytes of the job's files other than its tiles, measured again.
  void measure(Job& job) {
    job.other_bytes = job.expired ? 0 : std::max<std::int64_t>(0, directory_bytes(job.dir) - job.merger->bytes_on_disk());
  }
  // A finished, failed or cancelled job's tiles are deleted: only a resume
  // reads them, and its status keeps their counts (report.json).  Nothing
  // else reads a finished job's tiles: the final image, its error history
  // and the timelapses' frames (their final EXRs) are files of their own.
  void release_tiles(Job& job);
  std::size_t expire(double now_unix);

  Job& add_job(JobRecord record, api::RenderRequest request);
  void set_state(Job& job, const std::string& state, const std::string& failure = "");
  void emit(Job& job, const std::string& type);
  // The "progress" events emit held back, once their interval has passed.
  void flush_held_progress(Clock::time_point now);
  // Writes the merged tiles whose persistence interval has passed.
  void flush_due_tiles(Clock::time_point now);
  nlohmann::json status_of(const Job& job) const;
  // A stopped job's final image, to be written outside the lock, then
  // complete_finish (under it) makes the job done.
  struct PendingFinish {
    ImageSnapshot final_image;
    std::string stopped_by;
  };
  std::optional<PendingFinish> finish_if_complete(Job& job);
  void complete_finish(Job& job, const std::string& stopped_by);
  // Under the lock (start-up): finish_if_complete, the write, complete_finish.
  void finish_now_if_complete(Job& job);
  void write_images(Job& job, bool final);
  // The images of a job's merged sums, resolved under the lock, and written
  // (encoded and stored) by write_snapshot without it.
  ImageSnapshot snapshot_images(Job& job, bool final);
  void requeue(std::uint64_t attempt, bool tell_worker);
  void fail_job(Job& job, const std::string& message);
  // A result that is not exactly what its unit asked for: counted, held
  // against its worker as a failure of the unit (max_unit_failures distinct
  // workers fail the job), and the unit dispatched again first.
  void refuse_result(Job& job, const WorkUnit& unit, const std::string& worker_id, const std::string& why);
  // An adaptive job's allocation from its merged pilot, stored before use;
  // false when the job failed instead.
  bool allocate(Job& job);
  void drop_attempts_of(Job& job);
  Job& lowest_pass_in_group(Job& chosen);
  // The job whose tenant is served next (next_unit), or nullptr when no job has work.
  Job* fair_choice();
};

// --- Construction and restart -------------------------------------------------

JobService::JobService(fs::path data_dir, ServiceLimits limits) : impl_(std::make_unique<Impl>()) {
  impl_->data_dir = std::move(data_dir);
  impl_->limits = limits;
  std::error_code ec;
  fs::create_directories(impl_->data_dir / "jobs", ec);
  if (ec) throw StorageError("cannot create the data directory " + impl_->data_dir.string() + ": " + ec.message());
  impl_->store = std::make_unique<JobStore>(impl_->data_dir / "skyfarm.db");
  // Attempt ids stay unique across restarts (a late result from before a
  // restart can never match a new dispatch): start from the clock.
  impl_->next_attempt = static_cast<std::uint64_t>(unix_now() * 1000.0) << 16;
  // Resume: every job comes back; unfinished ones continue after their merged units.
  for (JobRecord& r : impl_->store->load_all()) {
    api::RenderRequest request = api::parse_render_request(r.request);
    impl_->next_sequence = std::max(impl_->next_sequence, r.sequence + 1);
    Job& job = impl_->add_job(std::move(r), std::move(request));
    if (job.record.state == "running") impl_->set_state(job, "queued");
    if (job.expired) continue;
    if (job.record.state == "done" && !fs::exists(job.dir / "image.exr") && job.merger->merged_units() > 0)
      impl_->write_images(job, true);
    if (job.record.state == "done") job.preview_units = job.merger->merged_units();
    impl_->finish_now_if_complete(job);
    // Finished before tiles were deleted at the end (or stopped by a crash in between).
    if (is_terminal(job.record.state) && !job.merger->files_removed() &&
        (job.record.state != "done" || fs::exists(job.dir / "image.exr")))
      impl_->release_tiles(job);
    impl_->measure(job);
  }
  // The budget counts the data directory's other files as they are now.
  std::int64_t jobs_bytes = 0;
  for (const auto& [id, job] : impl_->jobs) jobs_bytes += job->disk_used();
  const std::int64_t all = directory_bytes(impl_->data_dir);
  impl_->base_bytes = std::max<std::int64_t>(0, all - jobs_bytes);
  impl_->disk_budget = limits.max_disk_bytes < 0 ? default_disk_budget(impl_->data_dir) : limits.max_disk_bytes;
  impl_->expire(unix_now());
}

JobService::~JobService() = default;

Job& JobService::Impl::add_job(JobRecord record, api::RenderRequest request) {
  auto job = std::make_unique<Job>();
  const Sun sun = Sun::from_spec(request.sun, request.location, request.time);
  job->plan = api::render_plan_for(request, sun);
  job->plan_json = plan_report(request, job->plan);
  {
    const Camera camera(request.camera,
                        {0.0, 0.0, request.atmosphere.planet_radius_m + request.location.altitude_m});
    job->sun_pixels = sun_pixels(camera, sun);
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

void JobService::Impl::set_state(Job& job, const std::string& state, const std::string& failure) {
  store->set_state(job.record.id, state, failure);
  if (is_terminal(state) && !is_terminal(job.record.state)) {
    job.record.finished_unix = unix_now();
    store->set_finished(job.record.id, job.record.finished_unix);
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

void JobService::Impl::emit(Job& job, const std::string& type) {
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

void JobService::Impl::flush_due_tiles(Clock::time_point now) {
  for (const auto& [id, job] : jobs) {
    if (!job->active() || job->merger->dirty_tiles() == 0) continue;
    try {
      job->merger->flush_due(now);
    } catch (const StorageError& e) {
      fail_job(*job, e.what());
    }
  }
}

void JobService::Impl::flush_held_progress(Clock::time_point now) {
  for (const auto& [id, job] : jobs)
    if (job->progress_held && job->active() && now - job->last_event >= kProgressEventInterval) emit(*job, "progress");
}

// --- HTTP side ------------------------------------------------------------

SubmitResult JobService::submit(const api::RenderRequest& request, const std::optional<std::string>& key) {
  const std::lock_guard<std::mutex> lock(impl_->mu);
  const std::string canonical = api::canonical_text(request);
  const std::string hash = request_hash(request);
  if (key) {
    const auto it = impl_->idempotency.find(*key);
    if (it != impl_->idempotency.end()) {
      const Job& job = *impl_->jobs.at(it->second);
      if (job.record.request != canonical)
        throw IdempotencyConflict("Idempotency-Key '" + *key + "' was used for a different request (job " +
                                  job.record.id + ")");
      return {job.record.id, false, false};
    }
  }
  // Result cache: an identical request that is done, or still on its way.
  for (const auto& id : impl_->order) {
    const Job& job = *impl_->jobs.at(id);
    if (job.record.request_hash == hash && ((job.record.state == "done" && !job.expired) || job.active() || job.finishing)) {
      if (key) impl_->idempotency[*key] = job.record.id;
      return {job.record.id, false, job.record.state == "done"};
    }
  }
  int active = 0;
  std::int64_t queued_units = 0;
  for (const auto& [id, job] : impl_->jobs) {
    if (!job->active()) continue;
    ++active;
    queued_units += waiting_units(job->plan, job->merger->merged_units());
  }
  if (active >= impl_->limits.max_active_jobs)
    throw CapacityExceeded("too many active jobs (" + std::to_string(active) + "); try again later");
  const RenderPlan plan = api::render_plan_for(request, Sun::from_spec(request.sun, request.location, request.time));
  const std::int64_t units = waiting_units(plan, 0);
  if (units > impl_->limits.max_queue_units)
    throw CapacityExceeded("this render alone is " + std::to_string(units) + " units of work (" +
                           std::to_string(plan.tile_count()) + " tiles x " + std::to_string(plan.batches) +
                           " batches x " + std::to_string(std::min<std::int64_t>(plan.passes, kQueueHorizonPasses)) +
                           " passes), more than the queue's " + std::to_string(impl_->limits.max_queue_units) +
                           "; fewer pixels, batches or samples_per_pixel");
  if (queued_units + units > impl_->limits.max_queue_units)
    throw CapacityExceeded("the queue is full (" + std::to_string(queued_units) + " units waiting); try again later");
  if (impl_->disk_budget > 0) {
    const std::int64_t needs = estimated_job_bytes(request, plan);
    const std::int64_t committed = impl_->disk_reserved();
    if (committed + needs > impl_->disk_budget) {
      constexpr std::int64_t kMiB = 1 << 20;
      const std::int64_t free_mib = std::max<std::int64_t>(0, impl_->disk_budget - committed) / kMiB;
      throw InsufficientStorage(
          "this render needs about " + std::to_string((needs + kMiB - 1) / kMiB) + " MiB of disk (" +
          std::to_string(plan.tile_count()) + " tiles x " + std::to_string(plan.batches) +
          (plan.batches == 1 ? " batch" : " batches") + ", and its images); the disk budget (--max-disk-mb " + std::to_string(impl_->disk_budget / kMiB) +
          ") has " + std::to_string(free_mib) + " MiB free. Render fewer pixels or batches, wait for running "
          "renders to finish, or free space by deleting a finished render (DELETE /v1/renders/{id}?purge=true)");
    }
  }

  JobRecord r;
  r.id = random_id();
  r.request = canonical;
  r.request_hash = hash;
  r.priority = request.priority;
  r.state = "queued";
  r.created_unix = unix_now();
  r.idempotency_key = key.value_or("");
  r.sequence = impl_->next_sequence++;
  impl_->store->insert(r);
  Job& job = impl_->add_job(std::move(r), request);
  impl_->emit(job, "queued");
  return {job.record.id, true, false};
}

nlohmann::json JobService::Impl::status_of(const Job& job) const {
  const std::int64_t merged = job.units_done(), total = job.merger->total_units();
  const double fraction = job.progress();
  const double elapsed = job.elapsed_s();
  const int passes = job.complete_passes();
  const nlohmann::json spp = job.samples_per_pixel(passes);
  nlohmann::json plan = job.plan_json;
  if (job.allocation)
    plan["samples_per_pass_after_pilot"] = {{"min", job.allocation->min_samples_per_pass()},
                                            {"max", job.allocation->max_samples_per_pass()}};
  nlohmann::json eta = nullptr;
  if (job.active())
    if (const auto left = remaining_seconds(fraction, elapsed)) eta = *left;
  nlohmann::json workers_json = nlohmann::json::array();
  for (const auto& [id, n] : job.worker_units) workers_json.push_back({{"id", id}, {"units", n}});
  const std::string self = "/v1/renders/" + job.record.id;
  nlohmann::json estimate = nullptr, estimate_rgb = nullptr, unknown = nullptr;
  if (!job.history.empty()) {
    estimate = job.history.back()["estimated_relative_rms"];
    estimate_rgb = job.history.back().value("estimated_relative_rms_rgb", nlohmann::json(nullptr));
    unknown = job.history.back()["pixels_without_estimate"];
  }
  return {{"id", job.record.id},
          {"state", job.record.state},
          {"method", job.plan.lut ? "lut" : "path"},
          // The LUT renderer's error is its bias against the path tracer
          // (README "LUT accuracy"); it has no Monte Carlo estimate.
          {"approximate", job.plan.lut},
          {"priority", job.record.priority},
          {"progress",
           {{"fraction", fraction}, {"samples_per_pixel", spp}, {"units_done", merged}, {"units_total", total}}},
          {"elapsed_s", elapsed},
          {"eta_s", eta},
          {"error",
           {{"estimated_relative_rms", estimate},
            {"estimated_relative_rms_rgb", estimate_rgb},
            {"pixels_without_estimate", unknown},
            {"sun_pixels_excluded", job.sun_pixels.size()},
            {"history", job.history}}},
          {"stopped_by", job.stopped_by.empty() ? nlohmann::json(nullptr) : nlohmann::json(job.stopped_by)},
          {"plan", plan},
          {"workers", workers_json},
          {"failure", job.record.failure.empty() ? nlohmann::json(nullptr) : nlohmann::json(job.record.failure)},
          {"created_unix", job.record.created_unix},
          {"finished_unix", is_terminal(job.record.state) ? nlohmann::json(job.record.finished_unix) : nlohmann::json()},
          // Finished longer than the retention ago: its files (images) are gone.
          {"expired", job.expired},
          {"links",
           {{"self", self}, {"exr", self + "/image.exr"}, {"png", self + "/image.png"}, {"events", self + "/events"}}}};
}

std::optional<nlohmann::json> JobService::status(const std::string& id) const {
  const std::lock_guard<std::mutex> lock(impl_->mu);
  const auto it = impl_->jobs.find(id);
  if (it == impl_->jobs.end()) return std::nullopt;
  return impl_->status_of(*it->second);
}

nlohmann::json JobService::list(std::size_t offset, std::size_t limit) const {
  const std::lock_guard<std::mutex> lock(impl_->mu);
  nlohmann::json out = nlohmann::json::array();
  const auto& order = impl_->order;
  for (std::size_t i = offset; i < order.size() && out.size() < limit; ++i)
    out.push_back(impl_->status_of(*impl_->jobs.at(order[order.size() - 1 - i])));
  return out;
}

std::size_t JobService::job_count() const {
  const std::lock_guard<std::mutex> lock(impl_->mu);
  return impl_->jobs.size();
}

void JobService::Impl::drop_attempts_of(Job& job) {
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

bool JobService::cancel(const std::string& id) {
  const std::lock_guard<std::mutex> lock(impl_->mu);
  const auto it = impl_->jobs.find(id);
  if (it == impl_->jobs.end()) return false;
  Job& job = *it->second;
  if (!job.active()) return true;
  impl_->drop_attempts_of(job);
  job.stopped_by = "cancelled";
  impl_->set_state(job, "cancelled");
  impl_->release_tiles(job);
  impl_->emit(job, "cancelled");
  return true;
}

PurgeOutcome JobService::purge(const std::string& id) {
  const std::lock_guard<std::mutex> lock(impl_->mu);
  const auto it = impl_->jobs.find(id);
  if (it == impl_->jobs.end()) return {PurgeOutcome::kUnknown, ""};
  Job& job = *it->second;
  if (!job.group.empty())
    return {PurgeOutcome::kConflict, "render \"" + id + "\" is a frame of timelapse \"" + job.group +
                                         "\"; delete the timelapse instead"};
  if (job.finishing)
    return {PurgeOutcome::kConflict, "render \"" + id + "\" is writing its final image; try again in a moment"};
  if (job.active()) {
    impl_->drop_attempts_of(job);
    job.stopped_by = "cancelled";
    impl_->set_state(job, "cancelled");
    impl_->release_tiles(job);
    impl_->emit(job, "cancelled");
  }
  impl_->store->remove(id);
  std::error_code ec;
  fs::remove_all(job.dir, ec);
  // Its own key and those the result cache pointed at it.
  std::erase_if(impl_->idempotency, [&](const auto& entry) { return entry.second == id; });
  impl_->order.erase(std::find(impl_->order.begin(), impl_->order.end(), id));
  // The object outlives its record: a preview fetch may still hold it (image()).
  job.expired = true;
  job.events.clear();
  job.history = nlohmann::json::array();
  impl_->purged.push_back(std::move(it->second));
  impl_->jobs.erase(it);
  impl_->changed.notify_all();
  return {PurgeOutcome::kPurged, ""};
}

std::size_t JobService::expire_finished(double now_unix) {
  const std::lock_guard<std::mutex> lock(impl_->mu);
  return impl_->expire(now_unix);
}

// Resolves the merged tiles into an image and writes EXR and PNG next to the
// job's tiles: image.* when final, preview.* while running (atomic renames,
// so readers of an older preview keep a complete file).
ImageSnapshot JobService::Impl::snapshot_images(Job& job, bool final) {
  const auto& out = job.request.output;
  ImageLayers layers;
  if (out.spectral_channels)
    layers.spectral = SpectralLayout{job.plan.lambda_min_nm, job.plan.lambda_max_nm, job.plan.batches};
  layers.relative_error = out.error_layer;
  ImageSnapshot snap{Image(job.plan.width, job.plan.height, layers), job.dir,
                     final ? "image" : "preview-" + std::to_string(job.merger->merged_units()), {}, {}};
  job.merger->resolve(&snap.image);
  const Sun sun = Sun::from_spec(job.request.sun, job.request.location, job.request.time);
  api::set_render_metadata(&snap.image, job.request, job.plan, sun,
                           job.mean_samples_per_pixel(job.merger->complete_passes()),
                           job.merger->error_sums(job.sun_pixels));
  snap.exr.half = out.half;
  snap.exr.spectral_channels = out.spectral_channels;
  snap.exr.error_layer = out.error_layer;
  snap.exr.latlong_envmap = job.request.camera.projection == Projection::kEquirectangular;
  snap.png.exposure_ev = out.exposure_ev;
  return snap;
}

// The final image (at finish and on resume), under the lock.
void JobService::Impl::write_images(Job& job, bool final) {
  write_snapshot(snapshot_images(job, final));
  // Previews are versioned by the units they hold, so a file and its ETag
  // always agree; the previous one is removed (open readers keep its inode).
  if (job.preview_units >= 0 && job.preview_units != job.merger->merged_units())
    remove_preview(job.dir, job.preview_units);
}

// A preview is resolved under the lock but encoded and written without it,
// so a client fetching previews of a large image never holds up dispatch
// and merging.  Concurrent fetches of the same version write the same bytes
// once (one writer per job); a version overtaken by a newer one while it was
// written is removed and the newer one served.
std::optional<ImageFile> JobService::image(const std::string& id, ImageFormat format) {
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
    const std::lock_guard<std::mutex> lock(impl_->mu);
    const auto it = impl_->jobs.find(id);
    if (it == impl_->jobs.end()) return std::nullopt;
    job = it->second.get();  // purged jobs are kept (Impl::purged): the pointer outlives the lock
    if (job->expired) return std::nullopt;
    if (job->record.state == "done") return final_file(*job);
    if (!job->active() && !job->finishing) return std::nullopt;  // cancelled or failed: its sums are deleted
    if (!job->merger->first_pass_complete()) return std::nullopt;
    units = job->merger->merged_units();
    if (job->preview_units == units) return preview_file(*job);
    snap = impl_->snapshot_images(*job, false);
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
  const std::lock_guard<std::mutex> lock(impl_->mu);
  if (job->record.state == "done") {  // finished meanwhile: the final image it is
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
  impl_->measure(*job);
  return preview_file(*job);
}

std::vector<JobEvent> JobService::events_after(const std::string& id, std::uint64_t after,
                                               std::chrono::milliseconds timeout) {
  std::unique_lock<std::mutex> lock(impl_->mu);
  auto ready = [&] {
    const auto it = impl_->jobs.find(id);
    return it == impl_->jobs.end() || (!it->second->events.empty() && it->second->events.back().sequence > after);
  };
  impl_->changed.wait_for(lock, timeout, ready);
  std::vector<JobEvent> out;
  const auto it = impl_->jobs.find(id);
  if (it == impl_->jobs.end()) return out;
  for (const auto& e : it->second->events)
    if (e.sequence > after) out.push_back(e);
  return out;
}

nlohmann::json JobService::workers() const {
  const std::lock_guard<std::mutex> lock(impl_->mu);
  nlohmann::json out = nlohmann::json::array();
  const auto now = Clock::now();
  for (const auto& [id, w] : impl_->workers) {
    auto field = [&info = w.info](const char* name) {
      return info.contains(name) ? info[name] : nlohmann::json(nullptr);
    };
    out.push_back({{"id", id},
                   {"cores", field("cores")},
                   {"slots", field("slots")},
                   {"version", field("version")},
                   {"units_done", w.units_done},
                   {"units_in_flight", w.in_flight},
                   {"last_seen_s", std::chrono::duration<double>(now - w.last_seen).count()}});
  }
  return out;
}

nlohmann::json JobService::metrics() const {
  const std::lock_guard<std::mutex> lock(impl_->mu);
  std::int64_t queue_units = 0;
  int queued = 0, running = 0, done = 0, failed = 0;
  for (const auto& [id, job] : impl_->jobs) {
    const std::string& s = job->record.state;
    if (job->active()) queue_units += waiting_units(job->plan, job->merger->merged_units()) - job->in_flight;
    queued += s == "queued";
    running += s == "running";
    done += s == "done";
    failed += s == "failed";
  }
  // Samples per second: paths merged over the last 10 s.
  const auto now = Clock::now();
  std::uint64_t paths = 0;
  for (const auto& [t, n] : impl_->recent_paths)
    if (now - t < std::chrono::seconds(10)) paths += n;
  return {{"queue_units", queue_units},
          {"units_in_flight", impl_->in_flight.size()},
          {"jobs_queued", queued},
          {"jobs_running", running},
          {"jobs_done", done},
          {"jobs_failed", failed},
          {"workers", impl_->workers.size()},
          {"samples_per_second", static_cast<double>(paths) / 10.0},
          {"unit_failures", impl_->unit_failures},
          {"requeues", impl_->requeues},
          {"results_refused", impl_->results_refused},
          {"disk_used_bytes", impl_->disk_used()},
          {"disk_budget_bytes", impl_->disk_budget}};
}

// --- Broker side ----------------------------------------------------------

void JobService::worker_joined(const std::string& worker_id, const nlohmann::json& info) {
  const std::lock_guard<std::mutex> lock(impl_->mu);
  WorkerInfo& w = impl_->workers[worker_id];
  w.info = info;
  w.last_seen = Clock::now();
}

void JobService::Impl::requeue(std::uint64_t attempt, bool tell_worker) {
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

void JobService::worker_left(const std::string& worker_id) {
  const std::lock_guard<std::mutex> lock(impl_->mu);
  std::vector<std::uint64_t> attempts;
  for (const auto& [a, f] : impl_->in_flight)
    if (f.worker == worker_id) attempts.push_back(a);
  for (auto a : attempts) impl_->requeue(a, false);
  impl_->workers.erase(worker_id);
}

std::optional<UnitAssignment> JobService::next_unit(const std::string& worker_id) {
  const std::lock_guard<std::mutex> lock(impl_->mu);
  auto& workers = impl_->workers;
  if (auto w = workers.find(worker_id); w != workers.end()) w->second.last_seen = Clock::now();
  Job* picked = nullptr;
  std::optional<WorkUnit> unit;
  // A job whose units left turn out to be received already has no work after
  // this look (its queue drained, its cursor at the end or at the allocation
  // gate), so the next choice is another: the loop ends.
  while (!unit) {
    Job* chosen = impl_->fair_choice();
    if (!chosen) return std::nullopt;
    picked = chosen->group.empty() ? chosen : &impl_->lowest_pass_in_group(*chosen);
    Job& job = *picked;
    while (!job.requeued.empty() && !unit) {
      const WorkUnit u = job.requeued.front();
      job.requeued.pop_front();
      if (!job.merger->received(u)) unit = u;
    }
    while (!unit && job.cursor < static_cast<std::size_t>(job.plan.unit_count())) {
      if (job.waits_for_allocation() && unit_at(job.plan, job.cursor).pass > 0) break;
      const WorkUnit u = unit_at(job.plan, job.cursor++);
      if (!job.merger->received(u)) unit = u;
    }
  }
  Job& job = *picked;
  if (!job.started) {
    job.started = true;
    job.start_time = Clock::now();
  }
  if (job.record.state == "queued") {
    impl_->set_state(job, "running");
    impl_->emit(job, "progress");
  }
  const std::uint64_t attempt = impl_->next_attempt++;
  impl_->in_flight[attempt] = InFlight{job.record.id, *unit, worker_id, Clock::now()};
  ++job.in_flight;
  ++job.dispatched;
  if (auto w = workers.find(worker_id); w != workers.end()) ++w->second.in_flight;
  UnitAssignment a{{job.record.id, unit->tile, unit->batch, unit->pass}, attempt, job.record.request};
  if (unit->pass > 0 && job.allocation)
    for (const PassSamples& n : job.allocation->tile(unit->tile)) a.samples_per_pass.emplace_back(n.even, n.odd);
  return a;
}

// The pass of the unit a job would hand out next (requeued units first).
static int next_pass(const Job& job) {
  if (!job.requeued.empty()) return job.requeued.front().pass;
  return unit_at(job.plan, job.cursor).pass;
}

// Among `chosen`'s group at its priority, the job whose next unit has the
// lowest pass; the earliest submitted on a tie (set_group).
Job& JobService::Impl::lowest_pass_in_group(Job& chosen) {
  Job* pick = &chosen;
  int pick_pass = next_pass(chosen);
  for (Job* job : runnable) {
    if (job->group != chosen.group || job->record.priority != chosen.record.priority || !job->has_work()) continue;
    const int pass = next_pass(*job);
    if (pass < pick_pass) {
      pick = job;
      pick_pass = pass;
    }
  }
  return *pick;
}

// Fair share among the tenants of the highest priority that has work.  A
// tenant is a job, or a group's jobs of one priority (a timelapse's frames
// share out as one: lowest_pass_in_group).  The tenant with the fewest units
// in flight is served, so N tenants each get about 1/N of the workers
// whatever their sizes, and a small job submitted behind a huge one finishes
// in about the time it would take alone on its share; ties go to the tenant
// handed the fewest units so far, then to the earliest submitted.  One scan
// of the runnable jobs, which also drops the finished ones from it.
Job* JobService::Impl::fair_choice() {
  struct Tenant {
    const std::string* group;  // nullptr: a job alone
    int priority;
    int in_flight = 0;
    std::uint64_t dispatched = 0;
    Job* first_with_work = nullptr;  // earliest submitted (groups: lowest_pass_in_group picks among them)
  };
  auto better = [](const Tenant& a, const Tenant& b) {
    if (a.priority != b.priority) return a.priority > b.priority;
    if (a.in_flight != b.in_flight) return a.in_flight < b.in_flight;
    if (a.dispatched != b.dispatched) return a.dispatched < b.dispatched;
    return a.first_with_work->record.sequence < b.first_with_work->record.sequence;
  };
  std::optional<Tenant> best;
  std::vector<Tenant> groups;  // few: timelapses in progress
  std::size_t kept = 0;
  for (std::size_t i = 0; i < runnable.size(); ++i) {
    Job* job = runnable[i];
    if (is_terminal(job->record.state)) continue;  // finished: dropped
    runnable[kept++] = job;
    const bool work = job->has_work();
    if (job->group.empty()) {
      if (!work) continue;
      Tenant t{nullptr, job->record.priority, job->in_flight, job->dispatched, job};
      if (!best || better(t, *best)) best = t;
      continue;
    }
    // A group's units in flight count whether or not the frame has work left.
    auto g = std::find_if(groups.begin(), groups.end(), [&](const Tenant& t) {
      return *t.group == job->group && t.priority == job->record.priority;
    });
    if (g == groups.end()) {
      groups.push_back(Tenant{&job->group, job->record.priority});
      g = groups.end() - 1;
    }
    g->in_flight += job->in_flight;
    g->dispatched += job->dispatched;
    if (work && !g->first_with_work) g->first_with_work = job;
  }
  runnable.resize(kept);
  for (const Tenant& g : groups)
    if (g.first_with_work && (!best || better(g, *best))) best = g;
  return best ? best->first_with_work : nullptr;
}

bool JobService::Impl::allocate(Job& job) {
  const fs::path path = job.dir / kAllocationFile;
  if (std::optional<SampleAllocation> stored = read_allocation(path, job.plan)) {
    job.allocation = std::move(stored);
    return true;
  }
  // Computed from the pilot alone: nothing beyond pass 0 may have been merged.
  if (job.merger->merged_units() != job.plan.tile_count() * job.plan.batches) {
    fail_job(job, "the adaptive sample allocation (" + path.string() + ") is missing or unreadable, and the pilot "
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
    fail_job(job, e.what());
    return false;
  }
  job.allocation = std::move(a);
  return true;
}

void JobService::Impl::fail_job(Job& job, const std::string& message) {
  drop_attempts_of(job);
  job.stopped_by = "failed";
  set_state(job, "failed", message);
  release_tiles(job);
  emit(job, "failed");
}

// When every unit is merged: the final image files, then "done".
// True when the request can stop before its last sample (DESIGN §6 quality modes).
bool stops_early(const Job& job) {
  return job.request.quality.target_relative_error.has_value() || job.request.quality.time_limit_s.has_value();
}

// After merges: advance the pass gate (early-stopping jobs), record the error
// of every newly completed pass, and finish the job when its samples are all
// merged, its target error is reached, or its time limit has passed (checked
// at pass boundaries: the pass in progress completes, so the image is always
// a whole number of passes and equals a local render of that many passes).
std::optional<JobService::Impl::PendingFinish> JobService::Impl::finish_if_complete(Job& job) {
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
    fail_job(job, e.what());
    return std::nullopt;
  }
  drop_attempts_of(job);
  job.merger->drop_waiting();
  job.finishing = true;
  return PendingFinish{snapshot_images(job, true), stop};
}

void JobService::Impl::complete_finish(Job& job, const std::string& stopped_by) {
  job.finishing = false;
  // A done job serves its final image: the last preview goes.
  if (job.preview_units >= 0) remove_preview(job.dir, job.preview_units);
  job.preview_units = job.merger->merged_units();
  job.stopped_by = stopped_by;
  set_state(job, "done");
  release_tiles(job);
  emit(job, "done");
}

void JobService::Impl::release_tiles(Job& job) {
  if (!job.released) job.released.emplace(job.merger->merged_units(), job.merger->complete_passes());
  job.merger->remove_files();
  job.pilot_statistics.clear();
  // A cancelled or failed job shows no partial image: its sums are gone.
  if (job.record.state != "done" && job.preview_units >= 0) {
    remove_preview(job.dir, job.preview_units);
    job.preview_units = -1;
  }
  write_report(job, true);
  measure(job);
}

std::size_t JobService::Impl::expire(double now_unix) {
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

void JobService::Impl::finish_now_if_complete(Job& job) {
  if (std::optional<PendingFinish> pending = finish_if_complete(job)) {
    write_snapshot(pending->final_image);
    complete_finish(job, pending->stopped_by);
  }
}

void JobService::unit_done(const std::string& worker_id, const UnitKey& key, std::uint64_t attempt,
                           const std::vector<std::uint8_t>& bytes, std::uint64_t paths) {
  std::unique_lock<std::mutex> lock(impl_->mu);
  const auto it = impl_->in_flight.find(attempt);
  // A superseded attempt (requeued after a timeout or a lost worker) or a
  // cancelled job: the result is dropped.
  if (it == impl_->in_flight.end() || it->second.job_id != key.job_id || it->second.unit.tile != key.tile ||
      it->second.unit.batch != key.batch || it->second.unit.pass != key.pass)
    return;
  const InFlight f = it->second;
  impl_->in_flight.erase(it);
  auto& workers = impl_->workers;
  const auto w = workers.find(worker_id);
  if (w != workers.end()) {
    --w->second.in_flight;
    w->second.last_seen = Clock::now();
  }
  Job& job = *impl_->jobs.at(f.job_id);
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
    impl_->refuse_result(job, f.unit, worker_id, refusal);
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
      impl_->recent_paths.emplace_back(Clock::now(), paths);
      while (impl_->recent_paths.size() > 10000) impl_->recent_paths.pop_front();
    }
  } catch (const FilmTileDecodeError& e) {
    impl_->refuse_result(job, f.unit, worker_id, e.what());
    return;
  } catch (const StorageError& e) {
    impl_->fail_job(job, e.what());
    return;
  }
  std::optional<Impl::PendingFinish> pending = impl_->finish_if_complete(job);
  if (!pending) {
    if (job.active()) impl_->emit(job, "progress");
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
    impl_->fail_job(job, *failure);
    return;
  }
  impl_->complete_finish(job, pending->stopped_by);
}

void JobService::Impl::refuse_result(Job& job, const WorkUnit& unit, const std::string& worker_id,
                                     const std::string& why) {
  ++results_refused;
  ++unit_failures;
  auto& failed = job.failed_workers[static_cast<int>(job.unit_index(unit))];
  failed.insert(worker_id);
  if (static_cast<int>(failed.size()) >= limits.max_unit_failures) {
    fail_job(job, "unit (" + unit_text(unit) + ") got results that do not match it from " +
                      std::to_string(failed.size()) + " workers; the last (" + worker_id + "): " + why);
    return;
  }
  job.requeued.push_front(unit);
  ++requeues;
}

void JobService::unit_failed(const std::string& worker_id, const UnitKey& key, std::uint64_t attempt,
                             const std::string& message) {
  const std::lock_guard<std::mutex> lock(impl_->mu);
  const auto it = impl_->in_flight.find(attempt);
  if (it == impl_->in_flight.end() || it->second.job_id != key.job_id) return;
  const WorkUnit unit = it->second.unit;
  impl_->requeue(attempt, false);
  ++impl_->unit_failures;
  Job& job = *impl_->jobs.at(key.job_id);
  auto& failed = job.failed_workers[static_cast<int>(job.unit_index(unit))];
  failed.insert(worker_id);
  if (static_cast<int>(failed.size()) >= impl_->limits.max_unit_failures && job.active())
    impl_->fail_job(job, "unit (" + unit_text(unit) + ") failed on " + std::to_string(failed.size()) +
                             " workers; last error: " + message);
}

std::vector<std::pair<std::string, std::uint64_t>> JobService::take_cancelled_attempts() {
  const std::lock_guard<std::mutex> lock(impl_->mu);
  std::vector<std::pair<std::string, std::uint64_t>> out;
  out.swap(impl_->cancelled);
  return out;
}

void JobService::check_timeouts(Clock::time_point now) {
  const std::lock_guard<std::mutex> lock(impl_->mu);
  const auto limit = std::chrono::duration<double>(impl_->limits.unit_timeout_s);
  std::vector<std::uint64_t> late;
  for (const auto& [a, f] : impl_->in_flight)
    if (now - f.since > limit) late.push_back(a);
  for (auto a : late) impl_->requeue(a, true);
  if (now - impl_->last_expiry >= std::chrono::minutes(1)) {
    impl_->last_expiry = now;
    impl_->expire(unix_now());
  }
  impl_->flush_held_progress(Clock::now());
  impl_->flush_due_tiles(Clock::now());
}

// --- Timelapse support ------------------------------------------------------

bool JobService::set_group(const std::string& id, const std::string& group) {
  const std::lock_guard<std::mutex> lock(impl_->mu);
  const auto it = impl_->jobs.find(id);
  if (it == impl_->jobs.end()) return false;
  it->second->group = group;
  return true;
}

std::optional<JobSummary> JobService::summary(const std::string& id) const {
  const std::lock_guard<std::mutex> lock(impl_->mu);
  const auto it = impl_->jobs.find(id);
  if (it == impl_->jobs.end()) return std::nullopt;
  const Job& job = *it->second;
  JobSummary s;
  s.state = job.record.state;
  s.fraction = job.progress();
  if (!job.history.empty() && job.history.back()["estimated_relative_rms"].is_number())
    s.estimated_relative_rms = job.history.back()["estimated_relative_rms"].get<double>();
  s.failure = job.record.failure;
  return s;
}

void JobService::set_state_observer(std::function<void(const std::string&, const std::string&)> observer) {
  const std::lock_guard<std::mutex> lock(impl_->mu);
  impl_->state_observer = std::move(observer);
}

}  // namespace skyfarm::server
