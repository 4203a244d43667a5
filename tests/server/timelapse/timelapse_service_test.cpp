// The timelapse service on a real JobService without the network: frames as
// render jobs in the timelapse's group, rendered by a simulated worker; the
// outputs made once when the last frame is done; the frames-in-flight window;
// a failed frame, cancel, restart, idempotency and the result cache.  Waits
// are bounded by a deadline and never asserted on.
#include "server/timelapse/timelapse_service.h"

#include <gtest/gtest.h>

#include <unistd.h>

#include <map>
#include <memory>
#include <thread>

#include "api/render_spec.h"
#include "common/image/exr_writer.h"
#include "common/image/png_writer.h"
#include "common/render/tile_renderer.h"
#include "server/timelapse/timelapse_contact_sheet.h"
#include "server/timelapse/timelapse_outputs.h"

namespace skyfarm::server {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

// 4 frames of 16 x 8 over an hour, 2 passes of 16 samples, 1 batch; a fixed
// EV so that the test knows every frame's exposure.
std::string request_text(int frames = 4, const std::string& extra = "") {
  return R"({"location": {"latitude_deg": 42.44, "longitude_deg": -76.48},
             "start": "2013-05-27T17:00:00-04:00", "end": "2013-05-27T18:00:00-04:00", "frames": )" +
         std::to_string(frames) + R"(,
             "camera": {"projection": "equirectangular", "width": 16, "height": 8},
             "spectral": {"batches": 1}, "quality": {"samples_per_pixel": 32}, "seed": 5)" +
         extra + "}";
}

fs::path fresh_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("skyfarm_tlsvc_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  return d;
}

// A worker in the test's thread: renders units exactly as a farm worker does
// (one setup per job, cached).
class SimulatedWorker {
 public:
  explicit SimulatedWorker(JobService& jobs, std::string name = "w0") : jobs_(jobs), name_(std::move(name)) {
    jobs_.worker_joined(name_, {{"cores", 1}, {"slots", 4}});
  }
  // Renders up to `max_units` units; returns how many there were.
  int work(int max_units) {
    int n = 0;
    while (n < max_units) {
      const auto a = jobs_.next_unit(name_);
      if (!a) break;
      jobs_.unit_done(name_, a->key, a->attempt, render(*a), 1);
      ++n;
    }
    return n;
  }
  // Takes one unit and reports it failed.
  bool fail_one(const std::string& message) {
    const auto a = jobs_.next_unit(name_);
    if (!a) return false;
    jobs_.unit_failed(name_, a->key, a->attempt, message);
    return true;
  }

 private:
  struct Setup {
    RenderSetup setup;
    std::unique_ptr<TileRenderer> renderer;
  };
  std::vector<std::uint8_t> render(const UnitAssignment& a) {
    auto& s = setups_[a.key.job_id];
    if (!s) {
      s = std::make_unique<Setup>();
      s->setup = make_render_setup(api::render_spec(api::parse_render_request(a.request_canonical)));
      s->renderer = std::make_unique<TileRenderer>(*s->setup.scene, *s->setup.camera, s->setup.plan);
    }
    FilmTile film = s->renderer->empty_tile(a.key.tile);
    PathCounters counters;
    s->renderer->render_unit({a.key.tile, a.key.batch, a.key.pass}, &film, &counters);
    return film.serialize();
  }
  JobService& jobs_;
  std::string name_;
  std::map<std::string, std::unique_ptr<Setup>> setups_;
};

// Works and polls until the timelapse is in a terminal state or 60 s pass.
nlohmann::json run_until_finished(TimelapseService& timelapses, SimulatedWorker& worker, const std::string& id) {
  const auto deadline = std::chrono::steady_clock::now() + 60s;
  nlohmann::json s;
  while (std::chrono::steady_clock::now() < deadline) {
    worker.work(8);
    s = *timelapses.status(id);
    const std::string state = s["state"];
    if (state == "done" || state == "failed" || state == "cancelled") return s;
    std::this_thread::sleep_for(5ms);
  }
  return s;
}

TimelapseOptions test_options(const std::string& ffmpeg = "/nonexistent/ffmpeg") {
  TimelapseOptions o;
  o.ffmpeg = ffmpeg;
  o.poll_interval = 50ms;
  return o;
}

TEST(TimelapseService, FramesRenderAsGroupedJobsAndTheOutputsAreMadeOnce) {
  const fs::path dir = fresh_dir("basic");
  JobService jobs(dir);
  TimelapseService timelapses(jobs, dir, test_options());
  const auto request = api::parse_timelapse_request(request_text(4, R"(, "output": {"exposure_ev": 9})"));
  const SubmitResult submitted = timelapses.submit(request, std::nullopt);
  EXPECT_TRUE(submitted.created);
  const auto first = *timelapses.status(submitted.id);
  EXPECT_EQ(first["state"], "queued");
  EXPECT_EQ(first["progress"]["frames_total"], 4);
  ASSERT_EQ(first["frames"].size(), 4u);
  for (const auto& f : first["frames"]) EXPECT_TRUE(f["render_id"].is_string()) << "every frame submitted at once";
  EXPECT_EQ(timelapses.contact_sheet(submitted.id).status, TimelapseFile::Status::kNotReady);
  EXPECT_EQ(timelapses.video(submitted.id).status, TimelapseFile::Status::kNotReady);

  SimulatedWorker worker(jobs);
  const auto done = run_until_finished(timelapses, worker, submitted.id);
  ASSERT_EQ(done["state"], "done") << done.dump(1);
  EXPECT_EQ(done["progress"]["fraction"], 1.0);
  EXPECT_EQ(done["progress"]["frames_done"], 4);
  EXPECT_EQ(done["contact_sheet"]["available"], true);
  EXPECT_EQ(done["video"]["available"], false);
  EXPECT_NE(done["video"]["reason"].get<std::string>().find("/nonexistent/ffmpeg"), std::string::npos);
  EXPECT_EQ(done["exposure"]["mode"], "fixed");
  for (int i = 0; i < 4; ++i) {
    const auto& f = done["frames"][static_cast<std::size_t>(i)];
    EXPECT_EQ(f["index"], i);
    EXPECT_EQ(f["time"], request.frame_time_text(i));
    EXPECT_EQ(f["state"], "done");
    EXPECT_EQ(f["exposure_ev100"], 9.0);
    // The frame's render is an ordinary job with the frame's time.
    const auto render = *jobs.status(f["render_id"]);
    EXPECT_EQ(render["state"], "done");
    const auto png = timelapses.frame_image(submitted.id, i, ImageFormat::kPng);
    ASSERT_EQ(png.status, TimelapseFile::Status::kOk);
    EXPECT_TRUE(png.file->final);
    const PngFile file = read_png(png.file->path);
    EXPECT_EQ(file.text.at("skyfarm:exposure_ev100"), "9");
    EXPECT_EQ(file.text.at("skyfarm:timelapse_frame_time"), request.frame_time_text(i));
    EXPECT_NE(file.text.at("skyfarm:request").find(request.frame_time(i).to_iso8601()), std::string::npos);
    const auto exr = timelapses.frame_image(submitted.id, i, ImageFormat::kExr);
    ASSERT_EQ(exr.status, TimelapseFile::Status::kOk);
    EXPECT_EQ(exr.file->path, jobs.image(f["render_id"], ImageFormat::kExr)->path);
  }
  const auto sheet = timelapses.contact_sheet(submitted.id);
  ASSERT_EQ(sheet.status, TimelapseFile::Status::kOk);
  const PngFile sheet_png = read_png(sheet.file->path);
  const ContactSheetLayout layout = contact_sheet_layout(4, 16, 8);
  EXPECT_EQ(sheet_png.width, layout.width);
  EXPECT_EQ(sheet_png.height, layout.height);
  EXPECT_EQ(timelapses.video(submitted.id).status, TimelapseFile::Status::kUnavailable);
  EXPECT_EQ(timelapses.frame_image(submitted.id, 4, ImageFormat::kPng).status, TimelapseFile::Status::kUnknownFrame);
  EXPECT_EQ(timelapses.frame_image("nope", 0, ImageFormat::kPng).status, TimelapseFile::Status::kUnknownTimelapse);
  // Made once: the files do not change on later requests.
  const auto written = fs::last_write_time(sheet.file->path);
  std::this_thread::sleep_for(120ms);
  timelapses.status(submitted.id);
  timelapses.poke();
  std::this_thread::sleep_for(120ms);
  EXPECT_EQ(fs::last_write_time(sheet.file->path), written);
}

TEST(TimelapseService, AutomaticExposureIsSmoothedOverTheSequence) {
  const fs::path dir = fresh_dir("exposure");
  JobService jobs(dir);
  TimelapseService timelapses(jobs, dir, test_options());
  const auto id = timelapses.submit(api::parse_timelapse_request(request_text(4, R"(, "exposure_smoothing_frames": 3)")),
                                    std::nullopt)
                      .id;
  SimulatedWorker worker(jobs);
  const auto done = run_until_finished(timelapses, worker, id);
  ASSERT_EQ(done["state"], "done") << done.dump(1);
  EXPECT_EQ(done["exposure"]["mode"], "auto_smoothed");
  // Each frame's EV is the centred mean of the frames' own automatic EVs.
  std::vector<double> metered;
  for (const auto& f : done["frames"]) {
    const ExrFile exr = read_exr(jobs.image(f["render_id"], ImageFormat::kExr)->path);
    Image image(exr.width, exr.height);
    for (int y = 0; y < exr.height; ++y)
      for (int x = 0; x < exr.width; ++x) {
        const std::size_t k = static_cast<std::size_t>(y * exr.width + x);
        image.set_rgb(x, y, Rgb{exr.channels.at("R").values[k], exr.channels.at("G").values[k], exr.channels.at("B").values[k]});
      }
    metered.push_back(auto_exposure_ev(image));
  }
  const auto& f = done["frames"];
  EXPECT_DOUBLE_EQ(f[0]["exposure_ev100"].get<double>(), metered[0]);
  EXPECT_DOUBLE_EQ(f[1]["exposure_ev100"].get<double>(), (metered[0] + metered[1] + metered[2]) / 3);
  EXPECT_DOUBLE_EQ(f[2]["exposure_ev100"].get<double>(), (metered[1] + metered[2] + metered[3]) / 3);
  EXPECT_DOUBLE_EQ(f[3]["exposure_ev100"].get<double>(), metered[3]);
  EXPECT_GT(metered[0], metered[3]) << "the sky darkens towards the evening";
}

TEST(TimelapseService, OnlyAWindowOfFramesIsSubmittedAtOnceInFrameOrder) {
  const fs::path dir = fresh_dir("window");
  JobService jobs(dir);
  TimelapseOptions options = test_options();
  options.frames_in_flight = 2;
  TimelapseService timelapses(jobs, dir, options);
  const auto id = timelapses.submit(api::parse_timelapse_request(request_text(5)), std::nullopt).id;
  const auto first = *timelapses.status(id);
  EXPECT_TRUE(first["frames"][0]["render_id"].is_string());
  EXPECT_TRUE(first["frames"][1]["render_id"].is_string());
  EXPECT_TRUE(first["frames"][2]["render_id"].is_null());
  EXPECT_EQ(first["frames"][2]["state"], "queued");
  EXPECT_EQ(timelapses.frame_image(id, 2, ImageFormat::kExr).status, TimelapseFile::Status::kNotReady);
  SimulatedWorker worker(jobs);
  const auto done = run_until_finished(timelapses, worker, id);
  ASSERT_EQ(done["state"], "done") << done.dump(1);
  EXPECT_EQ(jobs.job_count(), 5u);
}

TEST(TimelapseService, AFailedFrameFailsTheTimelapseNamingTheFrame) {
  const fs::path dir = fresh_dir("failed");
  JobService jobs(dir);
  TimelapseService timelapses(jobs, dir, test_options());
  const auto id = timelapses.submit(api::parse_timelapse_request(request_text(3)), std::nullopt).id;
  // The first unit handed out (frame 0's) fails on three workers.
  for (const char* w : {"a", "b", "c"}) {
    SimulatedWorker worker(jobs, w);
    ASSERT_TRUE(worker.fail_one("out of memory"));
  }
  const auto deadline = std::chrono::steady_clock::now() + 30s;
  nlohmann::json s;
  while (std::chrono::steady_clock::now() < deadline && (s = *timelapses.status(id))["state"] != "failed")
    std::this_thread::sleep_for(5ms);
  ASSERT_EQ(s["state"], "failed") << s.dump(1);
  const std::string failure = s["failure"];
  EXPECT_TRUE(failure.starts_with("frame 0 (2013-05-27T17:00:00-04:00, render ")) << failure;
  EXPECT_NE(failure.find("out of memory"), std::string::npos) << failure;
  // The other frames were stopped.
  for (int i = 1; i < 3; ++i)
    EXPECT_EQ((*jobs.status(s["frames"][static_cast<std::size_t>(i)]["render_id"]))["state"], "cancelled");
  EXPECT_EQ(s["video"]["available"], false);
}

TEST(TimelapseService, CancelStopsEveryFrame) {
  const fs::path dir = fresh_dir("cancel");
  JobService jobs(dir);
  TimelapseService timelapses(jobs, dir, test_options());
  const auto id = timelapses.submit(api::parse_timelapse_request(request_text(3)), std::nullopt).id;
  SimulatedWorker worker(jobs);
  worker.work(2);
  EXPECT_TRUE(timelapses.cancel(id));
  const auto s = *timelapses.status(id);
  EXPECT_EQ(s["state"], "cancelled");
  for (const auto& f : s["frames"]) EXPECT_EQ((*jobs.status(f["render_id"]))["state"], "cancelled");
  EXPECT_EQ(worker.work(100), 0) << "no unit of a cancelled timelapse is handed out";
  EXPECT_EQ(timelapses.contact_sheet(id).status, TimelapseFile::Status::kNotReady);
  EXPECT_TRUE(timelapses.cancel(id)) << "cancelling again is a no-op";
  EXPECT_FALSE(timelapses.cancel("nope"));
}

TEST(TimelapseService, ARestartedServiceShowsTheTimelapseAndFinishesIt) {
  const fs::path dir = fresh_dir("restart");
  std::string id;
  nlohmann::json before;
  {
    JobService jobs(dir);
    TimelapseService timelapses(jobs, dir, test_options());
    id = timelapses.submit(api::parse_timelapse_request(request_text(3)), std::nullopt).id;
    SimulatedWorker worker(jobs);
    worker.work(3);  // frames 0..2 get pass 0 (grouped), none is finished
    before = *timelapses.status(id);
    EXPECT_EQ(before["state"], "running");
  }
  JobService jobs(dir);
  TimelapseService timelapses(jobs, dir, test_options());
  ASSERT_EQ(timelapses.count(), 1u);
  const auto after = *timelapses.status(id);
  for (std::size_t i = 0; i < 3; ++i) EXPECT_EQ(after["frames"][i]["render_id"], before["frames"][i]["render_id"]);
  // The group is set again: the remaining passes go out pass by pass.
  SimulatedWorker worker(jobs);
  const auto done = run_until_finished(timelapses, worker, id);
  ASSERT_EQ(done["state"], "done") << done.dump(1);
  EXPECT_EQ(timelapses.contact_sheet(id).status, TimelapseFile::Status::kOk);
  // Still there, done, after one more restart.
  JobService jobs2(dir);
  TimelapseService again(jobs2, dir, test_options());
  EXPECT_EQ((*again.status(id))["state"], "done");
}

// A name labels the timelapse (status and list) and its frames' renders,
// and survives a restart; the canonical request (its "request") has none.
TEST(TimelapseService, ANameLabelsTheTimelapseAndItsFramesAcrossARestart) {
  const fs::path dir = fresh_dir("name");
  std::string id;
  {
    JobService jobs(dir);
    TimelapseService timelapses(jobs, dir, test_options());
    id = timelapses.submit(api::parse_timelapse_request(request_text(18, R"(, "name": "Ithaca evening")")), std::nullopt)
             .id;
    const nlohmann::json status = *timelapses.status(id);
    EXPECT_EQ(status["name"], "Ithaca evening");
    EXPECT_FALSE(status["request"].contains("name"));
    EXPECT_EQ(timelapses.list(0, 10)[0]["name"], "Ithaca evening");
    const std::string frame = status["frames"][1]["render_id"];
    EXPECT_EQ((*jobs.status(frame))["name"], "Ithaca evening (frame 2 of 18)");
    // Unnamed: null.  (Its frames differ from the named one's by their
    // exposure: frames of equal requests would be one render, and the
    // render keeps the name it was first given.)
    const std::string other =
        timelapses.submit(api::parse_timelapse_request(request_text(2, R"(, "output": {"exposure_ev": 12})")), std::nullopt)
            .id;
    EXPECT_TRUE((*timelapses.status(other))["name"].is_null());
  }
  JobService jobs(dir);
  TimelapseService timelapses(jobs, dir, test_options());
  EXPECT_EQ((*timelapses.status(id))["name"], "Ithaca evening");
  // Frames submitted after the restart (beyond the first 16, submitted at
  // once) are named too.
  SimulatedWorker worker(jobs);
  const nlohmann::json done = run_until_finished(timelapses, worker, id);
  ASSERT_EQ(done["state"], "done") << done.dump(1);
  for (const nlohmann::json& f : done["frames"])
    EXPECT_EQ((*jobs.status(f["render_id"].get<std::string>()))["name"],
              "Ithaca evening (frame " + std::to_string(f["index"].get<int>() + 1) + " of 18)");
}

TEST(TimelapseService, IdempotencyKeysAndTheResultCache) {
  const fs::path dir = fresh_dir("idem");
  JobService jobs(dir);
  TimelapseService timelapses(jobs, dir, test_options());
  const auto request = api::parse_timelapse_request(request_text(2));
  const auto a = timelapses.submit(request, std::string("k1"));
  const auto b = timelapses.submit(request, std::string("k1"));
  EXPECT_EQ(a.id, b.id);
  EXPECT_FALSE(b.created);
  EXPECT_THROW(timelapses.submit(api::parse_timelapse_request(request_text(3)), std::string("k1")), IdempotencyConflict);
  const auto c = timelapses.submit(request, std::nullopt);
  EXPECT_EQ(c.id, a.id) << "an identical active timelapse answers";
  EXPECT_EQ(timelapses.count(), 1u);
  // Listing: newest first.
  const auto other = timelapses.submit(api::parse_timelapse_request(request_text(3)), std::nullopt);
  const auto list = timelapses.list(0, 10);
  ASSERT_EQ(list.size(), 2u);
  EXPECT_EQ(list[0]["id"], other.id);
  EXPECT_EQ(list[1]["id"], a.id);
  EXPECT_EQ(timelapses.list(1, 10).size(), 1u);
}

}  // namespace
}  // namespace skyfarm::server
