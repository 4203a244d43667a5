// Timelapses: many frames of one camera over a time
// range, rendered as ordinary render jobs of the JobService (each frame has
// its render id and shows under /v1/renders too), then a contact sheet and a
// video made once, when the last frame is done.
//
// Behaviour
//   frames     frame i is the request's render fields at the frame's time
//              (api/timelapse_request.h).  Its job joins the timelapse's
//              group (JobService::set_group), so the frames share out passes:
//              every frame gets pass p before any gets pass p + 1, and the
//              frames fill in together on every worker.  At most
//              `frames_in_flight` frames of one timelapse are submitted at a
//              time (the farm's max-active-jobs limit is shared with plain
//              renders); the next ones follow, in frame order, as frames
//              finish.  A full farm (429) only delays a frame.
//   outputs    when every frame is done: timelapse_outputs.h, on this
//              service's thread, never on an HTTP request; then "done".
//   failure    a failed frame fails the timelapse ("frame 2 (2013-05-27T...,
//              render abc) failed: ..."), a frame cancelled from
//              /v1/renders too; the other frames are cancelled.
//   cancel     cancels every frame not also used by another active timelapse
//              (identical frames are shared through the render result cache).
//   restart    the record (timelapse_record.h) is reloaded, the frames'
//              groups are set again and the timelapse goes on where its
//              frames are; outputs interrupted by the restart are rebuilt.
//   idempotency  an Idempotency-Key replays its timelapse (422 with another
//              body); an identical request that is active or done is
//              answered with the existing timelapse (result cache).
//
// Parameters (TimelapseOptions)
//   ffmpeg                 the server's --ffmpeg / SKYFARM_FFMPEG ("" = ffmpeg on PATH)
//   max_frames             --max-timelapse-frames: frames per timelapse (400 beyond)
//   frames_in_flight       frames of one timelapse submitted at once (16)
//   max_active_timelapses  queued + running timelapses (429 beyond; 64)
//   ffmpeg_timeout         one video encoding at most (600 s)
//   poll_interval          how often active timelapses are looked at without
//                          a job changing state (1 s; a job state change wakes
//                          the service at once)
// Thread-safe; one internal thread advances the timelapses and builds their
// outputs.  The JobService must outlive this service.
#pragma once
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "api/timelapse_request.h"
#include "server/jobs/job_service.h"
#include "server/timelapse/timelapse_record.h"

namespace skyfarm::server {

struct TimelapseOptions {
  std::string ffmpeg;
  int max_frames = api::kMaxTimelapseFrames;
  int frames_in_flight = 16;
  int max_active_timelapses = 64;
  std::chrono::seconds ffmpeg_timeout{600};
  std::chrono::milliseconds poll_interval{1000};
};

// A file of a timelapse for GET, or why there is none.
struct TimelapseFile {
  enum class Status {
    kOk,
    kUnknownTimelapse,  // 404
    kUnknownFrame,      // 404: no frame of that index
    kNotReady,          // 409: not yet (or never, for a failed or cancelled timelapse)
    kUnavailable,       // 404: done, but this file will not exist (no ffmpeg)
  };
  Status status = Status::kOk;
  std::optional<ImageFile> file;  // kOk
  std::string detail;             // otherwise: why
};

class TimelapseService {
 public:
  TimelapseService(JobService& jobs, std::filesystem::path data_dir, TimelapseOptions options = {});
  ~TimelapseService();
  TimelapseService(const TimelapseService&) = delete;
  TimelapseService& operator=(const TimelapseService&) = delete;

  const TimelapseOptions& options() const { return options_; }

  // May throw IdempotencyConflict, CapacityExceeded, StorageError.
  SubmitResult submit(const api::TimelapseRequest& request, const std::optional<std::string>& idempotency_key);
  // The status document (docs in api/openapi.yaml), or nullopt for an unknown id.
  std::optional<nlohmann::json> status(const std::string& id) const;
  // Newest first.
  nlohmann::json list(std::size_t offset, std::size_t limit) const;
  std::size_t count() const;
  // false for an unknown id; cancelling a finished timelapse is a no-op.
  bool cancel(const std::string& id);

  TimelapseFile frame_image(const std::string& id, int index, ImageFormat format) const;
  TimelapseFile contact_sheet(const std::string& id) const;
  TimelapseFile video(const std::string& id) const;

  // /metrics: skyfarm_job_duration_seconds{kind="timelapse",state}, submission
  // to end of the timelapses that ended since the server started.
  std::vector<HistogramSeries> histograms() const;

  // Wakes the service's thread (a job changed state); also called by tests.
  void poke();

 private:
  struct Entry;

  void run();
  void advance(const std::string& id);
  // Updates frames and state under the lock; true when every frame is done
  // and the outputs are to be built.
  bool refresh(Entry& t);
  // Submits the next frames while fewer than frames_in_flight are active.
  void feed(Entry& t, int* active, int* done);
  void fail(Entry& t, const std::string& message);
  // Counts a timelapse that just ended in skyfarm_job_duration_seconds.
  void observe_end(const Entry& t);
  void cancel_frames(const Entry& t);
  void build_outputs(const std::string& id);
  void persist(const Entry& t) const;
  nlohmann::json status_of(const Entry& t) const;
  nlohmann::json video_json(const Entry& t, int frames_done) const;
  bool shared_with_other_active(const Entry& t, const std::string& render_id) const;
  std::filesystem::path dir_of(const std::string& id) const;

  JobService& jobs_;
  const std::filesystem::path root_;
  const TimelapseOptions options_;
  mutable std::mutex mu_;
  std::map<std::string, std::unique_ptr<Entry>> timelapses_;
  std::vector<std::string> order_;  // creation order
  std::map<std::string, std::string> idempotency_;
  std::int64_t next_sequence_ = 1;
  MetricsHistogram durations_done_{kJobDurationBucketsS}, durations_failed_{kJobDurationBucketsS},
      durations_cancelled_{kJobDurationBucketsS};

  std::mutex wake_mu_;
  std::condition_variable wake_;
  bool woken_ = false;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace skyfarm::server
