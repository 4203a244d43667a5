#include "server/timelapse/timelapse_service.h"

#include <algorithm>
#include <climits>
#include <iostream>
#include <random>
#include <sstream>

#include "server/timelapse/timelapse_outputs.h"
#include "server/timelapse/timelapse_video.h"

#include "server/jobs/job_ids.h"

namespace skyfarm::server {
namespace {

namespace fs = std::filesystem;

void log_line(const std::string& text) { std::cerr << "skyfarm-server: " << text << std::endl; }

std::string frame_name(const api::TimelapseRequest& request, int i, const std::string& render_id) {
  return "frame " + std::to_string(i) + " (" + request.frame_time_text(i) + ", render " + render_id + ")";
}

nlohmann::json optional_json(const std::optional<double>& x) { return x ? nlohmann::json(*x) : nlohmann::json(nullptr); }

}  // namespace

struct TimelapseService::Entry {
  TimelapseRecord record;
  api::TimelapseRequest request;
  std::string canonical;  // record.request as text (result cache, idempotency)
  bool building = false;  // the outputs are being made (outside the lock)

  bool active() const { return !is_terminal(record.state); }
  int frame_count() const { return request.frame_count; }
};

// --- Construction and restart -------------------------------------------------

TimelapseService::TimelapseService(JobService& jobs, fs::path data_dir, TimelapseOptions options)
    : jobs_(jobs), root_(std::move(data_dir) / "timelapses"), options_(std::move(options)) {
  std::error_code ec;
  fs::create_directories(root_, ec);
  if (ec) throw StorageError("cannot create " + root_.string() + ": " + ec.message());
  std::vector<std::string> problems;
  for (TimelapseRecord& r : load_records(root_, &problems)) {
    auto t = std::make_unique<Entry>();
    try {
      // A record is re-read without the frame cap: it was accepted under the cap of its day.
      t->request = api::parse_timelapse_request(r.request.dump(), INT_MAX);
      if (!r.name.empty()) t->request.base.name = r.name;  // not in the canonical request: its frames' names
    } catch (const std::exception& e) {
      problems.push_back(r.id + ": its request no longer reads: " + e.what());
      continue;
    }
    if (static_cast<int>(r.render_ids.size()) != t->request.frame_count) {
      problems.push_back(r.id + ": " + std::to_string(r.render_ids.size()) + " render ids for " +
                         std::to_string(t->request.frame_count) + " frames");
      continue;
    }
    t->canonical = r.request.dump();
    t->record = std::move(r);
    // Groups live in memory only: set them again; a frame whose job is gone is submitted again.
    for (std::string& render_id : t->record.render_ids)
      if (!render_id.empty() && !jobs_.set_group(render_id, t->record.id) && t->active()) render_id.clear();
    if (!t->record.idempotency_key.empty()) idempotency_[t->record.idempotency_key] = t->record.id;
    next_sequence_ = std::max(next_sequence_, t->record.sequence + 1);
    order_.push_back(t->record.id);
    timelapses_[t->record.id] = std::move(t);
  }
  for (const std::string& p : problems) log_line("timelapse record skipped: " + p);
  jobs_.set_state_observer([this](const std::string&, JobState) { poke(); });
  thread_ = std::thread([this] { run(); });
}

TimelapseService::~TimelapseService() {
  jobs_.set_state_observer({});
  stop_ = true;
  poke();
  if (thread_.joinable()) thread_.join();
}

void TimelapseService::poke() {
  {
    const std::lock_guard<std::mutex> lock(wake_mu_);
    woken_ = true;
  }
  wake_.notify_all();
}

fs::path TimelapseService::dir_of(const std::string& id) const { return root_ / id; }

void TimelapseService::persist(const Entry& t) const {
  try {
    save_record(root_, t.record);
  } catch (const StorageError& e) {
    // The timelapse goes on; only a restart would lose its latest changes.
    log_line(std::string("cannot save timelapse ") + t.record.id + ": " + e.what());
  }
}

// --- The service's thread -------------------------------------------------------

void TimelapseService::run() {
  while (!stop_) {
    {
      std::unique_lock<std::mutex> lock(wake_mu_);
      wake_.wait_for(lock, options_.poll_interval, [this] { return woken_ || stop_; });
      woken_ = false;
    }
    if (stop_) break;
    std::vector<std::string> ids;
    {
      const std::lock_guard<std::mutex> lock(mu_);
      for (const auto& id : order_)
        if (const Entry& t = *timelapses_.at(id); t.active() && !t.building) ids.push_back(id);
    }
    for (const auto& id : ids) {
      if (stop_) break;
      try {
        advance(id);
      } catch (const std::exception& e) {
        log_line("timelapse " + id + ": " + e.what());
      }
    }
  }
}

void TimelapseService::advance(const std::string& id) {
  {
    const std::lock_guard<std::mutex> lock(mu_);
    Entry& t = *timelapses_.at(id);
    if (!t.active() || t.building || !refresh(t)) return;
    t.building = true;
  }
  build_outputs(id);
}

bool TimelapseService::refresh(Entry& t) {
  const int n = t.frame_count();
  bool changed = false, started = false;
  int done = 0, active = 0;
  for (int i = 0; i < n; ++i) {
    std::string& render_id = t.record.render_ids[static_cast<std::size_t>(i)];
    if (render_id.empty()) continue;
    const std::optional<JobSummary> s = jobs_.summary(render_id);
    if (!s) {  // cannot happen while jobs persist; submit the frame again
      render_id.clear();
      changed = true;
      continue;
    }
    if (s->state == JobState::kFailed) {
      fail(t, frame_name(t.request, i, render_id) + " failed: " + s->failure);
      return false;
    }
    if (s->state == JobState::kCancelled) {
      fail(t, frame_name(t.request, i, render_id) + " was cancelled");
      return false;
    }
    if (s->state == JobState::kDone) {
      ++done;
    } else {
      ++active;
      started = started || s->state == JobState::kRunning;
    }
  }
  const int submitted_before = active + done;
  feed(t, &active, &done);
  if (!t.active()) return false;  // a submission failed the timelapse
  changed = changed || active + done != submitted_before;
  const JobState state = done == n || done > 0 || started ? JobState::kRunning : JobState::kQueued;
  if (state != t.record.state) {
    t.record.state = state;
    changed = true;
  }
  if (changed) persist(t);
  return done == n;
}

void TimelapseService::feed(Entry& t, int* active, int* done) {
  for (int i = 0; i < t.frame_count() && *active < options_.frames_in_flight; ++i) {
    std::string& render_id = t.record.render_ids[static_cast<std::size_t>(i)];
    if (!render_id.empty()) continue;
    SubmitResult submitted;
    try {
      submitted = jobs_.submit(t.request.frame_request(i), std::nullopt);
    } catch (const CapacityExceeded&) {
      return;  // the farm is full: the next frames wait for a free slot
    } catch (const std::exception& e) {
      fail(t, "frame " + std::to_string(i) + " (" + t.request.frame_time_text(i) + ") could not be submitted: " +
                  e.what());
      return;
    }
    render_id = submitted.id;
    jobs_.set_group(render_id, t.record.id);
    const std::optional<JobSummary> s = jobs_.summary(render_id);
    if (s && s->state == JobState::kDone) ++*done;
    else ++*active;
  }
}

void TimelapseService::observe_end(const Entry& t) {
  // Submission to end, wall clock, as the renders' (job_book.cpp).
  const double seconds = std::max(0.0, t.record.finished_unix - t.record.created_unix);
  if (t.record.state == JobState::kDone) durations_done_.observe(seconds);
  else if (t.record.state == JobState::kFailed) durations_failed_.observe(seconds);
  else if (t.record.state == JobState::kCancelled) durations_cancelled_.observe(seconds);
}

std::vector<HistogramSeries> TimelapseService::histograms() const {
  constexpr const char* kName = "skyfarm_job_duration_seconds";
  constexpr const char* kHelp = "Renders and timelapses from submission to their end, by kind and final state.";
  return {{kName, kHelp, "kind=\"timelapse\",state=\"done\"", durations_done_.snapshot()},
          {kName, kHelp, "kind=\"timelapse\",state=\"failed\"", durations_failed_.snapshot()},
          {kName, kHelp, "kind=\"timelapse\",state=\"cancelled\"", durations_cancelled_.snapshot()}};
}

void TimelapseService::fail(Entry& t, const std::string& message) {
  cancel_frames(t);
  t.record.state = JobState::kFailed;
  t.record.failure = message;
  t.record.finished_unix = unix_now();
  observe_end(t);
  persist(t);
}

bool TimelapseService::shared_with_other_active(const Entry& t, const std::string& render_id) const {
  for (const auto& [id, other] : timelapses_) {
    if (other.get() == &t || !other->active()) continue;
    const auto& ids = other->record.render_ids;
    if (std::find(ids.begin(), ids.end(), render_id) != ids.end()) return true;
  }
  return false;
}

void TimelapseService::cancel_frames(const Entry& t) {
  for (const std::string& render_id : t.record.render_ids)
    if (!render_id.empty() && !shared_with_other_active(t, render_id)) jobs_.cancel(render_id);
}

// Every frame is done: the frame PNGs, the contact sheet and the video, made
// outside the lock (status requests go on meanwhile), then "done".
void TimelapseService::build_outputs(const std::string& id) {
  std::vector<FrameInput> inputs;
  OutputSettings settings;
  std::string missing;
  {
    const std::lock_guard<std::mutex> lock(mu_);
    const Entry& t = *timelapses_.at(id);
    settings.fixed_ev100 = t.request.base.output.exposure_ev;
    settings.smoothing_frames = t.request.exposure_smoothing_frames;
    settings.view = t.request.base.output.view;
    settings.fps = t.request.video_fps;
    settings.ffmpeg = options_.ffmpeg;
    settings.ffmpeg_timeout = options_.ffmpeg_timeout;
    for (int i = 0; i < t.frame_count() && missing.empty(); ++i) {
      const std::string& render_id = t.record.render_ids[static_cast<std::size_t>(i)];
      const std::optional<ImageFile> exr = jobs_.image(render_id, ImageFormat::kExr);
      if (!exr || !exr->final) missing = frame_name(t.request, i, render_id) + " has no final image";
      else inputs.push_back({exr->path, t.request.frame_time_text(i)});
    }
  }
  OutputsReport report;
  std::string error = missing;
  if (error.empty()) {
    try {
      report = build_timelapse_outputs(inputs, settings, dir_of(id), stop_);
    } catch (const std::exception& e) {
      error = e.what();
    }
  }
  const std::lock_guard<std::mutex> lock(mu_);
  Entry& t = *timelapses_.at(id);
  t.building = false;
  if (report.stopped || !t.active()) return;  // shutting down (rebuilt after a restart), or cancelled meanwhile
  if (!error.empty()) {
    fail(t, "making the contact sheet and video failed: " + error);
    return;
  }
  t.record.exposure_ev100 = report.ev100;
  t.record.contact_sheet = true;
  t.record.video = report.video;
  t.record.video_reason = report.video_reason;
  t.record.state = JobState::kDone;
  t.record.finished_unix = unix_now();
  observe_end(t);
  persist(t);
}

// --- Requests -----------------------------------------------------------------

SubmitResult TimelapseService::submit(const api::TimelapseRequest& request, const std::optional<std::string>& key) {
  const nlohmann::json canonical_json = api::to_canonical_json(request);
  const std::string canonical = canonical_json.dump();
  const std::lock_guard<std::mutex> lock(mu_);
  if (key) {
    if (const auto it = idempotency_.find(*key); it != idempotency_.end()) {
      const Entry& t = *timelapses_.at(it->second);
      if (t.canonical != canonical)
        throw IdempotencyConflict("Idempotency-Key '" + *key + "' was used for a different request (timelapse " +
                                  t.record.id + ")");
      return {t.record.id, false, false};
    }
  }
  int active = 0;
  for (const auto& id : order_) {
    const Entry& t = *timelapses_.at(id);
    if (t.canonical == canonical && (t.active() || t.record.state == JobState::kDone)) {
      if (key) idempotency_[*key] = t.record.id;
      return {t.record.id, false, t.record.state == JobState::kDone};
    }
    active += t.active();
  }
  if (active >= options_.max_active_timelapses)
    throw CapacityExceeded("too many active timelapses (" + std::to_string(active) + "); try again later");
  if (request.frame_count < 2 || request.frame_count > options_.max_frames)
    throw api::ValidationError({api::FieldError{request.frames ? "frames" : "step_s",
                                                "must give 2 to " + std::to_string(options_.max_frames) + " frames",
                                                std::to_string(request.frame_count)}});
  auto t = std::make_unique<Entry>();
  t->request = request;
  t->canonical = canonical;
  t->record.id = random_id();
  t->record.request = canonical_json;
  t->record.sequence = next_sequence_++;
  t->record.created_unix = unix_now();
  t->record.idempotency_key = key.value_or("");
  t->record.name = request.base.name.value_or("");
  t->record.render_ids.assign(static_cast<std::size_t>(request.frame_count), "");
  save_record(root_, t->record);  // StorageError: 507, nothing kept
  const std::string id = t->record.id;
  if (key) idempotency_[*key] = id;
  order_.push_back(id);
  Entry& entry = *(timelapses_[id] = std::move(t));
  refresh(entry);  // the first frames are submitted before the answer
  poke();
  return {id, true, false};
}

bool TimelapseService::cancel(const std::string& id) {
  const std::lock_guard<std::mutex> lock(mu_);
  const auto it = timelapses_.find(id);
  if (it == timelapses_.end()) return false;
  Entry& t = *it->second;
  if (!t.active()) return true;
  cancel_frames(t);
  t.record.state = JobState::kCancelled;
  t.record.finished_unix = unix_now();
  observe_end(t);
  persist(t);
  return true;
}

// --- Status ---------------------------------------------------------------------

nlohmann::json TimelapseService::video_json(const Entry& t, int frames_done) const {
  const JobState state = t.record.state;
  nlohmann::json reason = nullptr;
  if (state == JobState::kDone) {
    if (!t.record.video) reason = t.record.video_reason;
  } else if (state == JobState::kFailed || state == JobState::kCancelled) {
    reason = "the timelapse " + std::string(state == JobState::kFailed ? "failed" : "was cancelled") + ": no video";
  } else if (const FfmpegLookup ffmpeg = find_ffmpeg(options_.ffmpeg); !ffmpeg.path) {
    reason = ffmpeg.reason + "; the frames and the contact sheet are made without it";
  } else if (t.building) {
    reason = "being made";
  } else {
    reason = "made when every frame is done (" + std::to_string(frames_done) + " of " +
             std::to_string(t.frame_count()) + " done)";
  }
  return {{"available", state == JobState::kDone && t.record.video}, {"reason", reason}, {"fps", t.request.video_fps}};
}

nlohmann::json TimelapseService::status_of(const Entry& t) const {
  const std::string self = "/v1/timelapses/" + t.record.id;
  const int n = t.frame_count();
  nlohmann::json frames = nlohmann::json::array();
  int done = 0;
  double fraction_sum = 0.0;
  for (int i = 0; i < n; ++i) {
    const std::string& render_id = t.record.render_ids[static_cast<std::size_t>(i)];
    const std::optional<JobSummary> s = render_id.empty() ? std::nullopt : jobs_.summary(render_id);
    // A frame never submitted is "queued" while its timelapse is active.
    const JobState state = s ? s->state : t.active() ? JobState::kQueued : JobState::kCancelled;
    const double fraction = s ? s->fraction : 0.0;
    done += state == JobState::kDone;
    fraction_sum += fraction;
    const std::string frame = self + "/frames/" + std::to_string(i);
    const bool has_ev = t.record.exposure_ev100.size() == static_cast<std::size_t>(n);
    frames.push_back({{"index", i},
                      {"time", t.request.frame_time_text(i)},
                      {"render_id", render_id.empty() ? nlohmann::json(nullptr) : nlohmann::json(render_id)},
                      {"state", to_string(state)},
                      {"progress", fraction},
                      {"estimated_relative_rms", s ? optional_json(s->estimated_relative_rms) : nlohmann::json(nullptr)},
                      {"exposure_ev100", has_ev ? nlohmann::json(t.record.exposure_ev100[static_cast<std::size_t>(i)])
                                                : nlohmann::json(nullptr)},
                      {"links",
                       {{"render", render_id.empty() ? nlohmann::json(nullptr) : nlohmann::json("/v1/renders/" + render_id)},
                        {"exr", frame + ".exr"},
                        {"png", frame + ".png"}}}});
  }
  const JobState state = t.record.state;
  nlohmann::json stage = nullptr;
  if (t.active()) stage = t.building || done == n ? "making_outputs" : "rendering";
  const auto& exposure = t.request.base.output.exposure_ev;
  return {{"id", t.record.id},
          {"name", t.record.name.empty() ? nlohmann::json(nullptr) : nlohmann::json(t.record.name)},
          {"state", to_string(state)},
          {"stage", stage},
          {"failure", t.record.failure.empty() ? nlohmann::json(nullptr) : nlohmann::json(t.record.failure)},
          {"created_unix", t.record.created_unix},
          {"finished_unix", t.active() ? nlohmann::json(nullptr) : nlohmann::json(t.record.finished_unix)},
          {"progress",
           {{"fraction", state == JobState::kDone ? 1.0 : fraction_sum / n}, {"frames_done", done}, {"frames_total", n}}},
          {"method", t.request.base.method == api::Method::kLut ? "lut" : "path"},
          {"same_seed", t.request.same_seed},
          {"exposure",
           {{"mode", exposure ? "fixed" : "auto_smoothed"},
            {"ev100", optional_json(exposure)},
            {"smoothing_frames", exposure ? nlohmann::json(nullptr) : nlohmann::json(t.request.exposure_smoothing_frames)}}},
          {"frames", frames},
          {"contact_sheet", {{"available", state == JobState::kDone && t.record.contact_sheet}}},
          {"video", video_json(t, done)},
          {"request", t.record.request},
          {"links",
           {{"self", self},
            {"contact_sheet", self + "/contact_sheet.png"},
            {"video", self + "/video.mp4"},
            {"frames", self + "/frames"}}}};
}

std::optional<nlohmann::json> TimelapseService::status(const std::string& id) const {
  const std::lock_guard<std::mutex> lock(mu_);
  const auto it = timelapses_.find(id);
  if (it == timelapses_.end()) return std::nullopt;
  return status_of(*it->second);
}

nlohmann::json TimelapseService::list(std::size_t offset, std::size_t limit) const {
  const std::lock_guard<std::mutex> lock(mu_);
  nlohmann::json out = nlohmann::json::array();
  for (std::size_t i = offset; i < order_.size() && out.size() < limit; ++i)
    out.push_back(status_of(*timelapses_.at(order_[order_.size() - 1 - i])));
  return out;
}

std::size_t TimelapseService::count() const {
  const std::lock_guard<std::mutex> lock(mu_);
  return timelapses_.size();
}

// --- Files ----------------------------------------------------------------------

TimelapseFile TimelapseService::frame_image(const std::string& id, int index, ImageFormat format) const {
  std::string render_id;
  {
    const std::lock_guard<std::mutex> lock(mu_);
    const auto it = timelapses_.find(id);
    if (it == timelapses_.end()) return {TimelapseFile::Status::kUnknownTimelapse, std::nullopt, ""};
    const Entry& t = *it->second;
    if (index < 0 || index >= t.frame_count())
      return {TimelapseFile::Status::kUnknownFrame, std::nullopt,
              "timelapse \"" + id + "\" has frames 0 to " + std::to_string(t.frame_count() - 1)};
    // Once done, the PNG is the timelapse's own (the sequence's exposure).
    if (format == ImageFormat::kPng && t.record.state == JobState::kDone)
      return {TimelapseFile::Status::kOk,
              ImageFile{frame_png_path(dir_of(id), index), "\"" + id + "-" + std::to_string(index) + "\"", true}, ""};
    render_id = t.record.render_ids[static_cast<std::size_t>(index)];
    if (render_id.empty())
      return {TimelapseFile::Status::kNotReady, std::nullopt,
              "frame " + std::to_string(index) + " has no render yet" +
                  (t.active() ? ": at most " + std::to_string(options_.frames_in_flight) +
                                    " frames of a timelapse render at once, in frame order"
                              : ": the timelapse is " + to_string(t.record.state))};
  }
  std::optional<ImageFile> file = jobs_.image(render_id, format);
  if (!file)
    return {TimelapseFile::Status::kNotReady, std::nullopt,
            "frame " + std::to_string(index) + " (render " + render_id +
                ") has no image yet: its first pass has not covered the whole frame"};
  // The render's PNG has the frame's own exposure until the timelapse is done.
  if (format == ImageFormat::kPng) file->final = false;
  return {TimelapseFile::Status::kOk, file, ""};
}

TimelapseFile TimelapseService::contact_sheet(const std::string& id) const {
  const std::lock_guard<std::mutex> lock(mu_);
  const auto it = timelapses_.find(id);
  if (it == timelapses_.end()) return {TimelapseFile::Status::kUnknownTimelapse, std::nullopt, ""};
  const Entry& t = *it->second;
  if (t.record.state == JobState::kDone && t.record.contact_sheet)
    return {TimelapseFile::Status::kOk, ImageFile{dir_of(id) / "contact_sheet.png", "\"" + id + "-sheet\"", true}, ""};
  return {TimelapseFile::Status::kNotReady, std::nullopt,
          "timelapse \"" + id + "\" is " + to_string(t.record.state) +
              ": the contact sheet is made once, when every frame is done"};
}

TimelapseFile TimelapseService::video(const std::string& id) const {
  const std::lock_guard<std::mutex> lock(mu_);
  const auto it = timelapses_.find(id);
  if (it == timelapses_.end()) return {TimelapseFile::Status::kUnknownTimelapse, std::nullopt, ""};
  const Entry& t = *it->second;
  if (t.record.state == JobState::kDone && t.record.video)
    return {TimelapseFile::Status::kOk, ImageFile{dir_of(id) / "video.mp4", "\"" + id + "-video\"", true}, ""};
  if (t.record.state == JobState::kDone)
    return {TimelapseFile::Status::kUnavailable, std::nullopt,
            "timelapse \"" + id + "\" has no video: " + t.record.video_reason};
  return {TimelapseFile::Status::kNotReady, std::nullopt,
          "timelapse \"" + id + "\" is " + to_string(t.record.state) + ": the video is made once, when every frame is done"};
}

}  // namespace skyfarm::server
