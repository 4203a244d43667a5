// The farm's jobs, between the HTTP layer (http/http_api.h) and the ZeroMQ
// broker (broker/broker.h): the front of the job service.  It implements both
// backends, takes the one lock of its state (job_book.h) and hands each call
// to the part that owns it:
//   admission.h      POST /v1/renders: idempotency, result cache, capacity, disk
//   scheduler.h      which worker gets which unit; timeouts and requeues
//   result_intake.h  results checked, merged, passes recorded, jobs finished
//   job_images.h     previews and final images (EXR, PNG)
//   job_book.h       cancel, purge, expiry; the status document and metrics
// The way of a render: submit → Admission → JobBook::add_job (plan cut into
// units) → Scheduler::next_unit → broker → worker → ResultIntake::unit_done →
// TileMerger (tiles on disk) → finish → job_images (image.exr, image.png).
//
// Every method is thread-safe; neither the HTTP threads nor the broker thread
// ever touch another's sockets.  A restarted server resumes every job from
// its merged tiles (and hands out again what it merged after the last tile
// write); the final image is bit-identical to `skyfarm-worker render`.
//
// Disk (ServiceLimits::max_disk_bytes, retention_hours; disk_budget.h): a
// job's tiles are deleted once it is done (after its final image is written),
// failed or cancelled; a finished job's directory is removed after the
// retention (its record stays, "expired"); purge removes a job's files and
// record at once.
#pragma once
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "api/render_request.h"
#include "server/broker/broker_backend.h"
#include "server/http/http_backend.h"
#include "server/jobs/job_errors.h"
#include "server/jobs/job_state.h"
#include "server/jobs/service_limits.h"
#include "server/jobs/unit_assignment.h"

namespace skyfarm::server {

// A job's state in brief, cheaper than its status document (a timelapse
// follows many frames).
struct JobSummary {
  JobState state = JobState::kQueued;
  double fraction = 0.0;                          // progress towards the first limit (render_progress.h; 1 when done)
  std::optional<double> estimated_relative_rms;   // after the first complete pass
  std::string failure;                            // when failed
};

class JobService final : public HttpBackend, public BrokerBackend {
 public:
  JobService(std::filesystem::path data_dir, ServiceLimits limits = {});
  ~JobService() override;
  JobService(const JobService&) = delete;
  JobService& operator=(const JobService&) = delete;

  SubmitResult submit(const api::RenderRequest& request, const std::optional<std::string>& idempotency_key) override;
  std::optional<nlohmann::json> status(const std::string& id) const override;
  nlohmann::json list(std::size_t offset, std::size_t limit) const override;
  std::size_t job_count() const override;
  bool cancel(const std::string& id) override;
  PurgeOutcome purge(const std::string& id) override;
  std::optional<ImageFile> image(const std::string& id, ImageFormat format) override;
  std::vector<JobEvent> events_after(const std::string& id, std::uint64_t after,
                                     std::chrono::milliseconds timeout) override;
  nlohmann::json workers() const override;
  bool set_worker_draining(const std::string& worker_id, bool draining) override;
  nlohmann::json metrics() const override;
  std::vector<HistogramSeries> histograms() const override;

  void worker_joined(const std::string& worker_id, const nlohmann::json& info) override;
  void worker_left(const std::string& worker_id) override;
  std::optional<UnitAssignment> next_unit(const std::string& worker_id) override;
  void unit_done(const std::string& worker_id, const UnitKey& key, std::uint64_t attempt,
                 const std::vector<std::uint8_t>& film_tile_bytes, std::uint64_t paths) override;
  void unit_failed(const std::string& worker_id, const UnitKey& key, std::uint64_t attempt,
                   const std::string& message) override;
  std::vector<std::pair<std::string, std::uint64_t>> take_cancelled_attempts() override;
  void check_timeouts(Clock::time_point now) override;

  // Expires the jobs finished more than ServiceLimits::retention_hours
  // before now_unix (check_timeouts does so once a minute); returns how many.
  std::size_t expire_finished(double now_unix);

  // --- For timelapses (server/timelapse/timelapse_service.h) ---------------------------
  // Jobs of one group (a timelapse's frames) share out their passes: they
  // count as one tenant in the fair share (next_unit), and when that tenant
  // is served the unit handed out is the one of the lowest next pass among
  // the group's jobs of the same priority (ties: submission order), so every
  // frame gets pass p before any gets pass p + 1 and the frames fill in
  // together.  Groups are not
  // persisted: their owner sets them again after a restart.  false: unknown id.
  bool set_group(const std::string& id, const std::string& group);
  std::optional<JobSummary> summary(const std::string& id) const;
  // Called with (job id, new state) on every state change, under the
  // service's lock: it must not call into the service (wake a thread instead).
  // An empty function removes the observer.
  void set_state_observer(std::function<void(const std::string&, JobState)> observer);

 private:
  struct Parts;
  std::unique_ptr<Parts> parts_;
};

}  // namespace skyfarm::server
