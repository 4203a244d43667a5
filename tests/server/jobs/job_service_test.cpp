// The farm's job service without the network: units handed out, rendered by
// a simulated worker, merged in canonical order whatever the arrival order;
// the final EXR equals `skyfarm-worker render` byte for byte; idempotency,
// the result cache, stale attempts, failures, cancellation and restarts.
#include "server/jobs/job_service.h"

#include <gtest/gtest.h>

#include <atomic>
#include <thread>

#include <algorithm>
#include <cstdlib>
#include <deque>
#include <fstream>
#include <functional>
#include <iterator>
#include <limits>
#include <map>
#include <memory>
#include <random>
#include <unistd.h>

#include "api/render_spec.h"
#include "common/image/exr_writer.h"
#include "common/image/png_writer.h"
#include "common/render/tile_renderer.h"
#include "server/jobs/disk_budget.h"
#include "server/jobs/job_ids.h"

namespace skyfarm::server {
namespace {

namespace fs = std::filesystem;

constexpr const char* kRequest = R"({
  "sun": {"zenith_deg": 50, "azimuth_deg": 140},
  "camera": {"projection": "equirectangular", "width": 40, "height": 20},
  "spectral": {"batches": 2},
  "quality": {"samples_per_pixel": 48},
  "output": {"half": false, "error_layer": true},
  "seed": 3
})";

fs::path fresh_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("skyfarm_js_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  return d;
}

std::string read_file(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// A simulated worker: renders an assignment exactly as a farm worker does,
// with its setup cached per request (as a farm worker caches it per job).
struct CachedSetup {
  RenderSetup setup;
  std::unique_ptr<TileRenderer> renderer;
};
const TileRenderer& renderer_for(const std::string& request_canonical) {
  static std::map<std::string, std::unique_ptr<CachedSetup>> cache;
  auto& entry = cache[request_canonical];
  if (!entry) {
    entry = std::make_unique<CachedSetup>();
    entry->setup = make_render_setup(api::render_spec(api::parse_render_request(request_canonical)));
    entry->renderer = std::make_unique<TileRenderer>(*entry->setup.scene, *entry->setup.camera, entry->setup.plan);
  }
  return *entry->renderer;
}

std::vector<std::uint8_t> render_assignment(const UnitAssignment& a) {
  const TileRenderer& renderer = renderer_for(a.request_canonical);
  FilmTile film = renderer.empty_tile(a.key.tile);
  PathCounters counters;
  WorkUnit unit{a.key.tile, a.key.batch, a.key.pass, {}};
  for (const auto& [even, odd] : a.samples_per_pass) unit.samples.push_back({even, odd});
  renderer.render_unit(unit, &film, &counters);
  return film.serialize();
}

// "w<i>" (built without operator+, which trips a GCC 12 -Wrestrict false positive).
std::string worker_name(std::uint64_t i) {
  std::string name = std::to_string(i);
  name.insert(name.begin(), 'w');
  return name;
}

// Hands out up to `batch` units, then returns their results in a shuffled order.
void run_shuffled(JobService& service, std::mt19937& rng, std::size_t batch, int max_rounds = 100000) {
  for (int round = 0; round < max_rounds; ++round) {
    std::vector<UnitAssignment> got;
    while (got.size() < batch) {
      auto a = service.next_unit(worker_name(got.size() % 3));
      if (!a) break;
      got.push_back(*a);
    }
    if (got.empty()) return;
    std::shuffle(got.begin(), got.end(), rng);
    for (const auto& a : got)
      service.unit_done(worker_name(a.attempt % 3), a.key, a.attempt, render_assignment(a), 1);
  }
}

// `skyfarm-worker render` of `request` in `dir`; the EXR's bytes ("" on failure).
std::string local_render_exr(const fs::path& dir, const char* request = kRequest) {
  fs::create_directories(dir);
  std::ofstream(dir / "request.json") << request;
  const std::string cmd = std::string(SKYFARM_WORKER_BINARY) + " render " + (dir / "request.json").string() +
                          " -o " + (dir / "local.exr").string() + " > /dev/null 2>&1";
  EXPECT_EQ(std::system(cmd.c_str()), 0);
  return read_file(dir / "local.exr");
}

TEST(JobService, ShuffledUnitsGiveTheSameExrBytesAsALocalRender) {
  const fs::path dir = fresh_dir("bytes");
  JobService service(dir);
  const auto submitted = service.submit(api::parse_render_request(kRequest), std::nullopt);
  EXPECT_TRUE(submitted.created);
  EXPECT_FALSE(service.image(submitted.id, ImageFormat::kExr).has_value()) << "no image before the first pass";
  std::mt19937 rng(4);
  // Workers (simulated) "w0".."w2" join.
  for (int w = 0; w < 3; ++w) service.worker_joined(worker_name(w), {{"cores", 2}, {"slots", 2}});
  run_shuffled(service, rng, 7);
  const auto status = service.status(submitted.id);
  ASSERT_TRUE(status);
  EXPECT_EQ((*status)["state"], "done");
  EXPECT_EQ((*status)["stopped_by"], "samples");
  EXPECT_EQ((*status)["progress"]["units_done"], (*status)["progress"]["units_total"]);
  EXPECT_EQ((*status)["progress"]["samples_per_pixel"], 48);
  EXPECT_EQ((*status)["plan"]["passes"], 3);
  EXPECT_FALSE((*status)["error"]["history"].empty());
  EXPECT_EQ((*status)["error"]["pixels_without_estimate"], 0) << "every traced pixel has >= 2 samples per batch";
  EXPECT_EQ((*status)["plan"]["batches"], 2);
  EXPECT_EQ((*status)["plan"]["roulette_control"], true) << "sun 50 deg from the zenith";
  const auto image = service.image(submitted.id, ImageFormat::kExr);
  ASSERT_TRUE(image);
  EXPECT_TRUE(image->final);
  EXPECT_EQ(read_file(image->path), local_render_exr(dir / "local")) << "farm EXR must equal the local render's";
}

TEST(JobService, IdempotencyKeyAndResultCache) {
  JobService service(fresh_dir("idem"));
  const auto request = api::parse_render_request(kRequest);
  const auto a = service.submit(request, std::string("key-1"));
  const auto b = service.submit(request, std::string("key-1"));
  EXPECT_EQ(a.id, b.id);
  EXPECT_FALSE(b.created);
  auto other = request;
  other.seed = 4;
  EXPECT_THROW(service.submit(other, std::string("key-1")), IdempotencyConflict);
  // The same request without a key while the first is queued: the same job.
  EXPECT_EQ(service.submit(request, std::nullopt).id, a.id);
  // A different priority renders the same image: still the same job.
  auto urgent = request;
  urgent.priority = 90;
  EXPECT_EQ(service.submit(urgent, std::nullopt).id, a.id);
  std::mt19937 rng(1);
  run_shuffled(service, rng, 4);
  const auto cached = service.submit(request, std::nullopt);
  EXPECT_EQ(cached.id, a.id);
  EXPECT_TRUE(cached.from_cache);
  EXPECT_EQ(service.job_count(), 1u);
}

TEST(JobService, StaleAttemptsAreDroppedAndTimeoutsRequeue) {
  ServiceLimits limits;
  limits.unit_timeout_s = 1.0;
  JobService service(fresh_dir("stale"), limits);
  const auto id = service.submit(api::parse_render_request(kRequest), std::nullopt).id;
  const auto first = service.next_unit("slow");
  ASSERT_TRUE(first);
  service.check_timeouts(Clock::now() + std::chrono::seconds(5));
  const auto cancelled = service.take_cancelled_attempts();
  ASSERT_EQ(cancelled.size(), 1u);
  EXPECT_EQ(cancelled[0], (std::pair<std::string, std::uint64_t>("slow", first->attempt)));
  // The slow worker's late result is ignored; the unit comes back with a new attempt.
  service.unit_done("slow", first->key, first->attempt, render_assignment(*first), 1);
  EXPECT_EQ((*service.status(id))["progress"]["units_done"], 0);
  const auto again = service.next_unit("fast");
  ASSERT_TRUE(again);
  EXPECT_EQ(again->key, first->key);
  EXPECT_NE(again->attempt, first->attempt);
  service.unit_done("fast", again->key, again->attempt, render_assignment(*again), 1);
  EXPECT_EQ((*service.status(id))["progress"]["units_done"], 1);
}

TEST(JobService, LostWorkerUnitsAreRequeued) {
  JobService service(fresh_dir("lost"));
  service.submit(api::parse_render_request(kRequest), std::nullopt);
  service.worker_joined("doomed", {{"cores", 1}});
  const auto a = service.next_unit("doomed");
  ASSERT_TRUE(a);
  service.worker_left("doomed");
  const auto b = service.next_unit("other");
  ASSERT_TRUE(b);
  EXPECT_EQ(b->key, a->key);
  EXPECT_EQ(service.workers().size(), 0u);
}

TEST(JobService, UnitFailingOnThreeWorkersFailsTheJobWithTheMessage) {
  JobService service(fresh_dir("fail"));
  const auto id = service.submit(api::parse_render_request(kRequest), std::nullopt).id;
  for (int w = 0; w < 3; ++w) {
    const auto a = service.next_unit(worker_name(w));
    ASSERT_TRUE(a);
    service.unit_failed(worker_name(w), a->key, a->attempt, "out of memory on " + worker_name(w));
  }
  const auto s = *service.status(id);
  EXPECT_EQ(s["state"], "failed");
  EXPECT_EQ(s["stopped_by"], "failed");
  EXPECT_NE(s["failure"].get<std::string>().find("out of memory on w2"), std::string::npos);
  EXPECT_FALSE(service.next_unit("w9").has_value());
}

// Progress events are taken at most every 100 ms per job (a status document
// per merged unit bounded a big farm); one held back is emitted by the
// broker's timeout check, so the last event always shows the last merge.
TEST(JobService, AHeldBackProgressEventIsEmittedByTheTimeoutCheck) {
  JobService service(fresh_dir("events"));
  const auto id = service.submit(api::parse_render_request(kRequest), std::nullopt).id;
  std::vector<std::pair<UnitAssignment, std::vector<std::uint8_t>>> results;
  for (int i = 0; i < 4; ++i) {
    const auto a = service.next_unit("w");
    ASSERT_TRUE(a);
    results.emplace_back(*a, render_assignment(*a));
  }
  for (const auto& [a, bytes] : results) service.unit_done("w", a.key, a.attempt, bytes, 1);
  std::this_thread::sleep_for(std::chrono::milliseconds(150));
  service.check_timeouts(Clock::now());
  const auto events = service.events_after(id, 0, std::chrono::milliseconds(0));
  ASSERT_FALSE(events.empty());
  EXPECT_EQ(events.back().type, "progress");
  EXPECT_EQ(events.back().data["progress"]["units_done"], 4);
}

TEST(JobService, CancelStopsDispatchAndListsAttempts) {
  JobService service(fresh_dir("cancel"));
  const auto id = service.submit(api::parse_render_request(kRequest), std::nullopt).id;
  const auto a = service.next_unit("w");
  ASSERT_TRUE(a);
  EXPECT_TRUE(service.cancel(id));
  EXPECT_EQ((*service.status(id))["state"], "cancelled");
  EXPECT_EQ(service.take_cancelled_attempts().size(), 1u);
  EXPECT_FALSE(service.next_unit("w").has_value());
  EXPECT_FALSE(service.cancel("no-such-job"));
  const auto events = service.events_after(id, 0, std::chrono::milliseconds(0));
  ASSERT_FALSE(events.empty());
  EXPECT_EQ(events.back().type, "cancelled");
}

TEST(JobService, RestartResumesFromMergedPassesWithIdenticalBytes) {
  const fs::path dir = fresh_dir("restart");
  std::string id;
  std::mt19937 rng(9);
  {
    JobService service(dir);
    id = service.submit(api::parse_render_request(kRequest), std::nullopt).id;
    // Half the units, some left in flight when the server "dies".
    for (int i = 0; i < 9; ++i) {
      const auto a = service.next_unit("w");
      ASSERT_TRUE(a);
      if (i % 3 != 2) service.unit_done("w", a->key, a->attempt, render_assignment(*a), 1);
    }
    EXPECT_GT((*service.status(id))["progress"]["units_done"].get<int>(), 0);
  }
  JobService restarted(dir);
  const auto s = *restarted.status(id);
  EXPECT_EQ(s["state"], "queued");
  EXPECT_GT(s["progress"]["units_done"].get<int>(), 0) << "merged passes survive the restart";
  run_shuffled(restarted, rng, 5);
  EXPECT_EQ((*restarted.status(id))["state"], "done");
  EXPECT_EQ(read_file(*&restarted.image(id, ImageFormat::kExr)->path), local_render_exr(dir / "local"));
  // And a done job stays downloadable after another restart, with the same
  // report: what stopped it, its run time and its error history.
  const auto before = *restarted.status(id);
  JobService again(dir);
  const auto after = *again.status(id);
  EXPECT_EQ(after["state"], "done");
  EXPECT_TRUE(fs::exists(again.image(id, ImageFormat::kPng)->path));
  EXPECT_EQ(after["stopped_by"], "samples");
  EXPECT_EQ(after["error"]["history"], before["error"]["history"]);
  EXPECT_EQ(after["error"]["estimated_relative_rms"], before["error"]["estimated_relative_rms"]);
  EXPECT_GE(before["error"]["history"].size(), 2u) << "an entry per observed pass: " << before["error"]["history"].dump();
  EXPECT_NEAR(after["elapsed_s"].get<double>(), before["elapsed_s"].get<double>(), 1e-6);
  EXPECT_GT(after["elapsed_s"].get<double>(), 0.0);
}

TEST(JobService, PreviewAfterFirstPassWithChangingEtag) {
  JobService service(fresh_dir("preview"));
  const auto id = service.submit(api::parse_render_request(kRequest), std::nullopt).id;
  const auto s = *service.status(id);
  const int first_pass_units = s["plan"]["tiles"].get<int>() * s["plan"]["batches"].get<int>();
  for (int i = 0; i < first_pass_units; ++i) {
    const auto a = service.next_unit("w");
    ASSERT_TRUE(a);
    EXPECT_EQ(a->key.pass, 0) << "pass 0 of every tile comes first";
    service.unit_done("w", a->key, a->attempt, render_assignment(*a), 1);
  }
  const auto preview = service.image(id, ImageFormat::kPng);
  ASSERT_TRUE(preview);
  EXPECT_FALSE(preview->final);
  const auto a = service.next_unit("w");
  ASSERT_TRUE(a);
  service.unit_done("w", a->key, a->attempt, render_assignment(*a), 1);
  EXPECT_NE(service.image(id, ImageFormat::kPng)->etag, preview->etag);
}

// Previews are written outside the service's lock: clients fetching them
// while every unit merges get a file that exists when they get it (or the
// final image once done), versions never go back, and no overtaken preview
// is left behind.
TEST(JobService, ConcurrentPreviewFetchesDuringMergesLeaveOnlyTheFinalImage) {
  const fs::path dir = fresh_dir("concurrent-previews");
  JobService service(dir);
  const auto id = service.submit(api::parse_render_request(kRequest), std::nullopt).id;
  std::atomic<bool> done{false};
  std::atomic<int> fetched{0}, problems{0};
  std::vector<std::thread> clients;
  for (int c = 0; c < 4; ++c) {
    clients.emplace_back([&, c] {
      std::string last_etag;
      while (!done.load()) {
        const auto file = service.image(id, c % 2 ? ImageFormat::kPng : ImageFormat::kExr);
        if (!file) continue;
        ++fetched;
        if (file->final) return;
        std::error_code ec;
        if (!fs::exists(file->path, ec) && service.image(id, ImageFormat::kExr)->etag == file->etag) ++problems;
        // "job-<units>": the version never goes back for one client.
        const int units = std::stoi(file->etag.substr(file->etag.rfind('-') + 1));
        if (!last_etag.empty() && units < std::stoi(last_etag.substr(last_etag.rfind('-') + 1))) ++problems;
        last_etag = file->etag;
      }
    });
  }
  while (const auto a = service.next_unit("w")) service.unit_done("w", a->key, a->attempt, render_assignment(*a), 1);
  ASSERT_EQ((*service.status(id))["state"], "done");
  done = true;
  for (auto& t : clients) t.join();
  EXPECT_EQ(problems.load(), 0);
  EXPECT_GT(fetched.load(), 0);
  EXPECT_TRUE(service.image(id, ImageFormat::kExr)->final);
  int previews = 0;
  for (const auto& e : fs::directory_iterator(dir / "jobs" / id))
    if (e.path().filename().string().rfind("preview-", 0) == 0) ++previews;
  EXPECT_EQ(previews, 0);
}

TEST(JobService, UnwritableDataDirectoryIsAStorageError) {
  EXPECT_THROW(JobService("/proc/skyfarm-cannot-write-here"), StorageError);
}

TEST(JobService, HigherPriorityJobsGoFirst) {
  JobService service(fresh_dir("priority"));
  auto low = api::parse_render_request(kRequest);
  low.priority = 10;
  auto high = low;
  high.priority = 90;
  high.seed = 77;
  const auto low_id = service.submit(low, std::nullopt).id;
  const auto high_id = service.submit(high, std::nullopt).id;
  const auto a = service.next_unit("w");
  ASSERT_TRUE(a);
  EXPECT_EQ(a->key.job_id, high_id);
  EXPECT_NE(low_id, high_id);
}

}  // namespace
}  // namespace skyfarm::server

namespace skyfarm::server {
namespace {

// Quality modes: a target error stops the job at the first whole
// pass whose estimate meets it, with the same bytes as a local render that
// stops by the same rule, whatever order the results arrive in.
TEST(JobService, TargetErrorStopsAtAWholePassWithLocalBytes) {
  // Looking away from the sun: the estimate falls as 1/sqrt(samples)
  // (0.111 after one pass of 16, 0.079 at 32, about 0.065 at 48, with the
  // roulette control of a sun 50 deg from the zenith), so 0.07 stops after 3
  // of the 16 passes, as `skyfarm-worker render` does.
  constexpr const char* kTargeted = R"({
    "sun": {"zenith_deg": 50, "azimuth_deg": 140},
    "camera": {"projection": "perspective", "width": 40, "height": 20, "yaw_deg": 320, "pitch_deg": 10,
               "fov_deg": 60},
    "spectral": {"batches": 2},
    "quality": {"samples_per_pixel": 256, "target_relative_error": 0.07},
    "output": {"half": false},
    "seed": 5
  })";
  const fs::path dir = fresh_dir("target");
  JobService service(dir);
  const auto id = service.submit(api::parse_render_request(kTargeted), std::nullopt).id;
  std::mt19937 rng(12);
  run_shuffled(service, rng, 9);
  const auto s = *service.status(id);
  ASSERT_EQ(s["state"], "done");
  EXPECT_EQ(s["stopped_by"], "target_error");
  EXPECT_LT(s["progress"]["samples_per_pixel"].get<int>(), 256);
  EXPECT_LE(s["error"]["estimated_relative_rms"].get<double>(), 0.07);
  EXPECT_EQ(s["progress"]["samples_per_pixel"], 48) << s["error"]["history"].dump();
  // The history falls pass after pass, the last entry at the target.
  const auto& h = s["error"]["history"];
  ASSERT_GE(h.size(), 2u);
  EXPECT_GT(h[0]["estimated_relative_rms"].get<double>(), h.back()["estimated_relative_rms"].get<double>());
  // Per linear sRGB channel too, in the status and in every history entry:
  // each falls with the passes and stays of the luminance's order.
  const auto& rgb = s["error"]["estimated_relative_rms_rgb"];
  ASSERT_TRUE(rgb.is_object()) << rgb.dump();
  for (const char* c : {"r", "g", "b"}) {
    SCOPED_TRACE(c);
    EXPECT_GT(rgb[c].get<double>(), 0.0);
    EXPECT_LT(rgb[c].get<double>(), 3.0 * s["error"]["estimated_relative_rms"].get<double>());
    EXPECT_GT(h[0]["estimated_relative_rms_rgb"][c].get<double>(), h.back()["estimated_relative_rms_rgb"][c].get<double>());
  }

  EXPECT_EQ(read_file(service.image(id, ImageFormat::kExr)->path), local_render_exr(dir / "local", kTargeted));
}

TEST(JobService, TimeLimitStopsAtTheNextWholePass) {
  auto request = api::parse_render_request(kRequest);
  request.quality.time_limit_s = 1e-9;  // already over when the first pass completes
  JobService service(fresh_dir("time"));
  const auto id = service.submit(request, std::nullopt).id;
  std::mt19937 rng(2);
  run_shuffled(service, rng, 3);
  const auto s = *service.status(id);
  ASSERT_EQ(s["state"], "done");
  EXPECT_EQ(s["stopped_by"], "time_limit");
  EXPECT_EQ(s["progress"]["samples_per_pixel"], 16) << "one whole pass";
}

}  // namespace
}  // namespace skyfarm::server

namespace skyfarm::server {
namespace {

// A mirror-symmetric view (centred on the sun's azimuth): the farm renders
// half the tiles and its EXR equals the local render's.
TEST(JobService, MirroredJobRendersHalfAndMatchesTheLocalRender) {
  constexpr const char* kMirrored = R"({
    "sun": {"zenith_deg": 50, "azimuth_deg": 140},
    "camera": {"projection": "equirectangular", "width": 64, "height": 32, "yaw_deg": 140},
    "spectral": {"batches": 2},
    "quality": {"samples_per_pixel": 32},
    "output": {"half": false}
  })";
  const fs::path dir = fresh_dir("mirror");
  JobService service(dir);
  const auto id = service.submit(api::parse_render_request(kMirrored), std::nullopt).id;
  const auto before = *service.status(id);
  EXPECT_EQ(before["plan"]["mirrored"], true);
  EXPECT_EQ(before["plan"]["tiles"], 1);  // the left 32 columns
  EXPECT_EQ(before["plan"]["pooled_ground_row"], 17);  // an observer at 0 m: rows 17-31 see only the ground
  std::mt19937 rng(6);
  run_shuffled(service, rng, 4);
  ASSERT_EQ((*service.status(id))["state"], "done");
  EXPECT_EQ(read_file(service.image(id, ImageFormat::kExr)->path), local_render_exr(dir / "local", kMirrored));
}

// method "lut": one pass of one sample per pixel and batch, labelled
// approximate, no Monte Carlo estimate, and the farm's bytes equal a local
// LUT render's (the tables are deterministic).
TEST(JobService, LutJobIsOnePassApproximateAndMatchesTheLocalRender) {
  constexpr const char* kLut = R"({
    "sun": {"zenith_deg": 50, "azimuth_deg": 140},
    "camera": {"projection": "fisheye", "width": 48, "height": 48, "pitch_deg": 90, "fov_deg": 180},
    "spectral": {"batches": 2},
    "method": "lut",
    "output": {"half": false}
  })";
  const fs::path dir = fresh_dir("lut");
  JobService service(dir);
  const auto id = service.submit(api::parse_render_request(kLut), std::nullopt).id;
  const auto before = *service.status(id);
  EXPECT_EQ(before["method"], "lut");
  EXPECT_EQ(before["approximate"], true);
  EXPECT_EQ(before["plan"]["passes"], 1);
  EXPECT_EQ(before["plan"]["units"], 4 * 2);  // 2 x 2 tiles x 2 batches
  std::mt19937 rng(8);
  run_shuffled(service, rng, 3);
  const auto s = *service.status(id);
  ASSERT_EQ(s["state"], "done");
  EXPECT_EQ(s["progress"]["samples_per_pixel"], 1);
  EXPECT_TRUE(s["error"]["estimated_relative_rms"].is_null()) << "a LUT render has no Monte Carlo estimate";
  EXPECT_EQ(read_file(service.image(id, ImageFormat::kExr)->path), local_render_exr(dir / "local", kLut));
}

// output.color_space / units / view: the server converts when it writes, as
// `skyfarm-worker render` does (the same EXR bytes); the values are the
// default job's, through OCIO's Rec.709 -> AP0 and divided by 683; the PNG
// names its view.  The request hash differs (different files).
TEST(JobService, ColourManagedOutputsMatchTheLocalRenderAndTheDefaultJob) {
  constexpr const char* kPlain = R"({
    "sun": {"zenith_deg": 85, "azimuth_deg": 140},
    "camera": {"projection": "fisheye", "width": 32, "height": 32, "pitch_deg": 90, "fov_deg": 180},
    "method": "lut",
    "output": {"half": false}
  })";
  constexpr const char* kManaged = R"({
    "sun": {"zenith_deg": 85, "azimuth_deg": 140},
    "camera": {"projection": "fisheye", "width": 32, "height": 32, "pitch_deg": 90, "fov_deg": 180},
    "method": "lut",
    "output": {"half": false, "color_space": "aces2065-1", "units": "w_m2_sr", "view": "aces"}
  })";
  const fs::path dir = fresh_dir("colour");
  JobService service(dir);
  const auto plain = service.submit(api::parse_render_request(kPlain), std::nullopt).id;
  const auto managed = service.submit(api::parse_render_request(kManaged), std::nullopt).id;
  EXPECT_NE(plain, managed);
  std::mt19937 rng(5);
  run_shuffled(service, rng, 4);
  ASSERT_EQ((*service.status(managed))["state"], "done");
  const fs::path exr = service.image(managed, ImageFormat::kExr)->path;
  EXPECT_EQ(read_file(exr), local_render_exr(dir / "local", kManaged));
  const ExrFile a = read_exr(service.image(plain, ImageFormat::kExr)->path), b = read_exr(exr);
  EXPECT_EQ(b.string_attributes.at("skyfarm:color_space"), "aces2065-1");
  EXPECT_EQ(b.string_attributes.at("skyfarm:units"), "w_m2_sr");
  ASSERT_TRUE(b.chromaticities.has_value());
  EXPECT_NEAR((*b.chromaticities)[2].y, -0.077, 1e-7);
  std::size_t lit = 0;
  for (std::size_t i = 0; i < a.channels.at("R").values.size(); ++i) {
    float v[3] = {a.channels.at("R").values[i], a.channels.at("G").values[i], a.channels.at("B").values[i]};
    if (v[1] > 0) ++lit;
    convert_color_space(ColorSpace::kLinRec709, ColorSpace::kAces2065_1, v, 1);
    const char* names[3] = {"R", "G", "B"};
    for (int c = 0; c < 3; ++c)
      EXPECT_NEAR(b.channels.at(names[c]).values[i], v[c] / 683.0, 1e-6 * std::abs(v[c]) / 683.0 + 1e-30) << i;
  }
  EXPECT_GT(lit, 0u);
  EXPECT_EQ(read_png(service.image(managed, ImageFormat::kPng)->path).text.at("skyfarm:view"), "aces");
  EXPECT_FALSE(read_png(service.image(plain, ImageFormat::kPng)->path).text.contains("skyfarm:view"));
}

// "quality.adaptive": pass 0 is a uniform pilot; no unit of a later pass is
// handed out before the pilot is merged everywhere; later units carry their
// tile's samples per allocation block; the EXR equals the local render's,
// also across a restart that resumes with the stored allocation.
constexpr const char* kAdaptive = R"({
  "sun": {"zenith_deg": 80, "azimuth_deg": 100},
  "camera": {"projection": "equirectangular", "width": 64, "height": 48},
  "spectral": {"batches": 2},
  "quality": {"samples_per_pixel": 40, "adaptive": true},
  "output": {"half": false},
  "seed": 7
})";

TEST(JobService, AdaptiveJobAllocatesAfterItsPilotAndMatchesTheLocalRender) {
  const fs::path dir = fresh_dir("adaptive");
  JobService service(dir);
  const auto id = service.submit(api::parse_render_request(kAdaptive), std::nullopt).id;
  EXPECT_EQ((*service.status(id))["plan"]["adaptive"], true);
  const int pilot_units = 4 * 2;  // 2 x 2 tiles x 2 batches
  std::vector<UnitAssignment> pilot;
  while (auto a = service.next_unit("w")) pilot.push_back(*a);
  ASSERT_EQ(static_cast<int>(pilot.size()), pilot_units) << "later passes wait for the allocation";
  for (const auto& a : pilot) {
    EXPECT_EQ(a.key.pass, 0);
    EXPECT_TRUE(a.samples_per_pass.empty());
  }
  for (const auto& a : pilot) service.unit_done("w", a.key, a.attempt, render_assignment(a), 1);
  const auto after_pilot = *service.status(id);
  ASSERT_TRUE(after_pilot["plan"].contains("samples_per_pass_after_pilot"));
  EXPECT_LT(after_pilot["plan"]["samples_per_pass_after_pilot"]["min"].get<int>(),
            after_pilot["plan"]["samples_per_pass_after_pilot"]["max"].get<int>());
  EXPECT_TRUE(fs::exists(dir / "jobs" / id / "allocation.json"));
  const auto next = service.next_unit("w");
  ASSERT_TRUE(next);
  EXPECT_EQ(next->key.pass, 1);
  EXPECT_EQ(next->samples_per_pass.size(), 16u) << "4 x 4 blocks of 8 pixels per 32-pixel tile";
  service.unit_done("w", next->key, next->attempt, render_assignment(*next), 1);
  std::mt19937 rng(8);
  run_shuffled(service, rng, 5);
  const auto done = *service.status(id);
  ASSERT_EQ(done["state"], "done");
  EXPECT_NEAR(done["progress"]["samples_per_pixel"].get<double>(), 40.0, 1.5) << "the mean stays the request's";
  EXPECT_EQ(read_file(service.image(id, ImageFormat::kExr)->path), local_render_exr(dir / "local", kAdaptive));
}

TEST(JobService, AdaptiveJobResumesWithItsStoredAllocation) {
  const fs::path dir = fresh_dir("adaptive_restart");
  std::string id;
  {
    JobService service(dir);
    id = service.submit(api::parse_render_request(kAdaptive), std::nullopt).id;
    // The pilot and two units of pass 1, one more left in flight.
    for (int i = 0; i < 11; ++i) {
      const auto a = service.next_unit("w");
      ASSERT_TRUE(a);
      if (i < 10) service.unit_done("w", a->key, a->attempt, render_assignment(*a), 1);
    }
  }
  JobService restarted(dir);
  const auto resumed = *restarted.status(id);
  EXPECT_TRUE(resumed["plan"].contains("samples_per_pass_after_pilot"));
  EXPECT_EQ(resumed["error"]["history"].size(), 1u) << "the pilot's entry survives the restart";
  std::mt19937 rng(10);
  run_shuffled(restarted, rng, 3);
  const auto done = *restarted.status(id);
  ASSERT_EQ(done["state"], "done");
  EXPECT_EQ(done["error"]["history"].size(), 3u);
  EXPECT_EQ(read_file(restarted.image(id, ImageFormat::kExr)->path), local_render_exr(dir / "local", kAdaptive));
  EXPECT_EQ((*JobService(dir).status(id))["progress"]["samples_per_pixel"], done["progress"]["samples_per_pixel"])
      << "a done adaptive job's mean samples per pixel, after another restart";
  // A restart in the middle of the pilot: the tiles merged before it are read
  // back for their statistics, and the bytes are still the local render's.
  {
    const fs::path mid = dir / "mid_pilot";
    std::string mid_id;
    {
      JobService service(mid);
      mid_id = service.submit(api::parse_render_request(kAdaptive), std::nullopt).id;
      for (int i = 0; i < 5; ++i) {
        const auto a = service.next_unit("w");
        service.unit_done("w", a->key, a->attempt, render_assignment(*a), 1);
      }
    }
    JobService resumed(mid);
    std::mt19937 rng2(11);
    run_shuffled(resumed, rng2, 3);
    ASSERT_EQ((*resumed.status(mid_id))["state"], "done");
    EXPECT_EQ(read_file(resumed.image(mid_id, ImageFormat::kExr)->path), local_render_exr(dir / "local", kAdaptive));
  }
  // Without its allocation the job cannot tell its pilot from later passes: it fails, saying why.
  const std::string lost_id = [&] {
    JobService service(dir / "lost");
    const std::string j = service.submit(api::parse_render_request(kAdaptive), std::nullopt).id;
    for (int i = 0; i < 10; ++i) {
      const auto a = service.next_unit("w");
      service.unit_done("w", a->key, a->attempt, render_assignment(*a), 1);
    }
    return j;
  }();
  fs::remove(dir / "lost" / "jobs" / lost_id / "allocation.json");
  JobService lost(dir / "lost");
  const auto s = *lost.status(lost_id);
  EXPECT_EQ(s["state"], "failed");
  EXPECT_NE(s["failure"].get<std::string>().find("allocation"), std::string::npos) << s["failure"];
}

// The queue limit counts at most 16 passes of a job: "1 % in at most 2
// minutes" (no sample cap: 65536 passes) of a 512x256 frame is accepted; a
// render that alone exceeds the limit is refused, saying so.  Unit counts
// are 64-bit: 16384 x 8192 with no sample cap is 8.6e9 units.
TEST(JobService, OpenEndedRendersFitTheQueueAndAnOversizedOneIsRefusedByName) {
  const fs::path dir = fresh_dir("queue");
  ServiceLimits limits;
  limits.max_queue_units = 5000;
  JobService service(dir, limits);
  const auto open_ended = service.submit(api::parse_render_request(R"({
    "sun": {"zenith_deg": 30, "azimuth_deg": 180},
    "camera": {"projection": "equirectangular", "width": 512, "height": 256},
    "quality": {"target_relative_error": 0.01, "time_limit_s": 120}})"), std::nullopt);
  EXPECT_TRUE(open_ended.created);
  const auto s = *service.status(open_ended.id);
  EXPECT_EQ(s["plan"]["passes"], 65536);
  EXPECT_EQ(s["progress"]["units_total"].get<std::int64_t>(), 64LL * 65536);
  // Its progress is towards the target and the time limit, not the 65536 passes: a first pass
  // at an estimate of e is (0.01 / e)^2 of the way, t seconds t / 120 of it.
  std::vector<UnitAssignment> pilot;
  for (int i = 0; i < 64; ++i) pilot.push_back(*service.next_unit("w"));
  for (const auto& a : pilot) service.unit_done("w", a.key, a.attempt, render_assignment(a), 1);
  const auto after_pass = *service.status(open_ended.id);
  const double e = after_pass["error"]["estimated_relative_rms"].get<double>();
  const double elapsed = after_pass["elapsed_s"].get<double>();
  EXPECT_NEAR(after_pass["progress"]["fraction"].get<double>(),
              std::max({0.0001 / (e * e), elapsed / 120.0, 64.0 / (64.0 * 65536)}), 1e-3);
  EXPECT_GT(after_pass["progress"]["fraction"].get<double>(), 0.001) << after_pass["progress"];
  EXPECT_LT(after_pass["eta_s"].get<double>(), 3600.0) << "not the 65536 passes' eta";
  service.cancel(open_ended.id);
  // 1024 units waiting (16 passes of 64 tiles) and 128 more fit under 5000.
  EXPECT_TRUE(service.submit(api::parse_render_request(R"({"sun": {"zenith_deg": 30, "azimuth_deg": 10},
      "camera": {"projection": "equirectangular", "width": 256, "height": 128}})"), std::nullopt).created);
  const auto huge = api::parse_render_request(R"({"sun": {"zenith_deg": 30, "azimuth_deg": 10},
    "camera": {"projection": "equirectangular", "width": 16384, "height": 8192},
    "quality": {"target_relative_error": 0.01}})");
  EXPECT_EQ(api::render_plan_for(huge, Sun::from_spec(huge.sun, huge.location, huge.time)).unit_count(),
            131072LL * 65536);
  try {
    service.submit(huge, std::nullopt);
    FAIL() << "2 million units waiting is over the limit of 5000";
  } catch (const CapacityExceeded& e) {
    EXPECT_NE(std::string(e.what()).find("this render alone"), std::string::npos) << e.what();
  }
}

// A long job's history keeps its whole span in at most 512 entries: a 1x1
// frame of 700 passes (a pass takes well under a millisecond).
TEST(JobService, ALongJobsHistoryIsThinnedNotTruncated) {
  const fs::path dir = fresh_dir("history");
  JobService service(dir);
  const auto id = service.submit(api::parse_render_request(R"({"sun": {"zenith_deg": 40, "azimuth_deg": 10},
    "camera": {"projection": "perspective", "width": 1, "height": 1, "pitch_deg": 30},
    "quality": {"samples_per_pixel": 11200}, "seed": 2})"), std::nullopt).id;
  while (const auto a = service.next_unit("w")) service.unit_done("w", a->key, a->attempt, render_assignment(*a), 1);
  const auto s = *service.status(id);
  ASSERT_EQ(s["state"], "done");
  const auto& h = s["error"]["history"];
  EXPECT_LE(h.size(), 512u);
  EXPECT_GT(h.size(), 256u);
  EXPECT_EQ(h.front()["samples_per_pixel"], 16);
  EXPECT_EQ(h.back()["samples_per_pixel"], 11200);
  for (std::size_t i = 1; i < h.size(); ++i)
    EXPECT_LT(h[i - 1]["samples_per_pixel"].get<int>(), h[i]["samples_per_pixel"].get<int>()) << i;
  EXPECT_EQ((*JobService(dir).status(id))["error"]["history"], h) << "the report holds the same history";
}

}  // namespace
}  // namespace skyfarm::server

namespace skyfarm::server {
namespace {

// --- Results exactly as asked ------------------------------------------------

FilmTile decoded(const std::vector<std::uint8_t>& bytes) { return FilmTile::deserialize(bytes); }

// `good` copied into a tile of another geometry (the pixels both have).
std::vector<std::uint8_t> regeometried(const FilmTile& good, int width, int height, int batches) {
  FilmTile bad(good.x0(), good.y0(), width, height, batches);
  for (int b = 0; b < std::min(batches, good.batches()); ++b)
    for (int y = good.y0(); y < good.y0() + std::min(height, good.height()); ++y)
      for (int x = good.x0(); x < good.x0() + std::min(width, good.width()); ++x)
        bad.set_sums(x, y, b, good.sums(x, y, b));
  return bad.serialize();
}

// The first pixel of the unit's batch with samples, changed by `change`.
std::vector<std::uint8_t> with_pixel(FilmTile film, int batch, void (*change)(PixelBatchSums*)) {
  for (int y = film.y0(); y < film.y0() + film.height(); ++y)
    for (int x = film.x0(); x < film.x0() + film.width(); ++x)
      if (film.sums(x, y, batch).n > 0) {
        PixelBatchSums s = film.sums(x, y, batch);
        change(&s);
        film.set_sums(x, y, batch, s);
        return film.serialize();
      }
  ADD_FAILURE() << "no pixel with samples";
  return film.serialize();
}

std::uint64_t refused(const JobService& service) { return service.metrics()["results_refused"].get<std::uint64_t>(); }

// Each kind of wrong result is refused, counted and its unit handed out again
// at once (never left waiting); the job then finishes with the local render's bytes.
TEST(JobService, ResultsNotExactlyAsAskedAreRefusedCountedAndRequeued) {
  const fs::path dir = fresh_dir("refuse");
  JobService service(dir);
  const auto id = service.submit(api::parse_render_request(kRequest), std::nullopt).id;
  using Bad = std::function<std::vector<std::uint8_t>(const FilmTile&, int batch)>;
  const std::vector<std::pair<std::string, Bad>> cases = {
      {"wrong width", [](const FilmTile& g, int) { return regeometried(g, g.width() - 1, g.height(), g.batches()); }},
      {"wrong height", [](const FilmTile& g, int) { return regeometried(g, g.width(), g.height() + 1, g.batches()); }},
      {"wrong batches", [](const FilmTile& g, int) { return regeometried(g, g.width(), g.height(), g.batches() + 1); }},
      {"one sample too many",
       [](const FilmTile& g, int b) { return with_pixel(g, b, [](PixelBatchSums* s) { s->n += 1.0; }); }},
      {"one sample too few",
       [](const FilmTile& g, int b) { return with_pixel(g, b, [](PixelBatchSums* s) { s->n -= 1.0; }); }},
      {"samples in another batch",
       [](const FilmTile& g, int b) {
         FilmTile f = g;
         f.set_sums(g.x0(), g.y0(), 1 - b, g.sums(g.x0(), g.y0(), b));
         return f.serialize();
       }},
      {"NaN sum",
       [](const FilmTile& g, int b) {
         return with_pixel(g, b, [](PixelBatchSums* s) { s->sum_y = std::numeric_limits<double>::quiet_NaN(); });
       }},
      {"negative sum of squares",
       [](const FilmTile& g, int b) { return with_pixel(g, b, [](PixelBatchSums* s) { s->sum_r2 = -1.0; }); }},
      {"unreadable", [](const FilmTile&, int) { return std::vector<std::uint8_t>{1, 2, 3}; }},
  };
  std::uint64_t expected_refused = 0;
  for (const auto& [name, make_bad] : cases) {
    SCOPED_TRACE(name);
    const auto a = service.next_unit("liar");
    ASSERT_TRUE(a);
    const std::uint64_t requeues = service.metrics()["requeues"].get<std::uint64_t>();
    const auto good = render_assignment(*a);
    service.unit_done("liar", a->key, a->attempt, make_bad(decoded(good), a->key.batch), 1);
    EXPECT_EQ(refused(service), ++expected_refused);
    EXPECT_EQ(service.metrics()["requeues"].get<std::uint64_t>(), requeues + 1);
    EXPECT_EQ((*service.status(id))["state"], "running");
    // The same unit comes straight back, to be rendered by an honest worker.
    const auto again = service.next_unit("honest");
    ASSERT_TRUE(again);
    EXPECT_EQ(again->key, a->key);
    EXPECT_NE(again->attempt, a->attempt);
    service.unit_done("honest", again->key, again->attempt, good, 1);
  }
  // The liar failed a unit each time, but never the same one three times.
  std::mt19937 rng(3);
  run_shuffled(service, rng, 5);
  ASSERT_EQ((*service.status(id))["state"], "done");
  EXPECT_EQ(refused(service), expected_refused) << "honest results are all accepted";
  EXPECT_EQ(read_file(service.image(id, ImageFormat::kExr)->path), local_render_exr(dir / "local"));
}

// A unit refused from three distinct workers fails its job, saying why,
// instead of going round for ever.
TEST(JobService, AUnitRefusedFromThreeWorkersFailsItsJob) {
  JobService service(fresh_dir("refuse3"));
  const auto id = service.submit(api::parse_render_request(kRequest), std::nullopt).id;
  std::optional<UnitKey> first;
  for (int w = 0; w < 3; ++w) {
    const auto a = service.next_unit(worker_name(w));
    ASSERT_TRUE(a);
    if (!first) first = a->key;
    EXPECT_EQ(a->key, *first) << "the refused unit comes back first";
    const FilmTile g = decoded(render_assignment(*a));
    service.unit_done(worker_name(w), a->key, a->attempt, regeometried(g, g.width() - 1, g.height(), g.batches()), 1);
  }
  const auto s = *service.status(id);
  EXPECT_EQ(s["state"], "failed");
  EXPECT_NE(s["failure"].get<std::string>().find("do not match"), std::string::npos) << s["failure"];
  EXPECT_EQ(refused(service), 3u);
}

// The expected counts follow the renderer where it leaves samples out or
// adds fewer: a fisheye's pixels the image circle crosses (jitter outside
// it), pixels outside the circle, and the pooled ground rows of an observer
// at 0 m; honest results of such jobs are all accepted.
TEST(JobService, HonestResultsOfFisheyeAndPooledGroundJobsAreAllAccepted) {
  constexpr const char* kFisheye = R"({
    "sun": {"zenith_deg": 50, "azimuth_deg": 140},
    "camera": {"projection": "fisheye", "width": 40, "height": 40, "pitch_deg": 90, "fov_deg": 180},
    "spectral": {"batches": 2},
    "quality": {"samples_per_pixel": 32},
    "output": {"half": false},
    "seed": 5
  })";
  const fs::path dir = fresh_dir("honest");
  JobService service(dir);
  const auto fisheye = service.submit(api::parse_render_request(kFisheye), std::nullopt).id;
  const auto ground = service.submit(api::parse_render_request(R"({
    "sun": {"zenith_deg": 50, "azimuth_deg": 140},
    "camera": {"projection": "equirectangular", "width": 48, "height": 24},
    "quality": {"samples_per_pixel": 32}, "seed": 6})"), std::nullopt).id;
  EXPECT_TRUE((*service.status(ground))["plan"]["pooled_ground_row"].is_number());
  std::mt19937 rng(5);
  run_shuffled(service, rng, 6);
  EXPECT_EQ((*service.status(fisheye))["state"], "done");
  EXPECT_EQ((*service.status(ground))["state"], "done");
  EXPECT_EQ(refused(service), 0u);
  EXPECT_EQ(read_file(service.image(fisheye, ImageFormat::kExr)->path), local_render_exr(dir / "local", kFisheye));
}

}  // namespace
}  // namespace skyfarm::server

namespace skyfarm::server {
namespace {

// --- Fair scheduling -------------------------------------------------------------

// A huge job (256 passes of 2 batches) submitted first and a small one
// (2 passes of 2 batches) after it, equal priority, three workers each
// taking one unit at a time from a broker loop: the small job finishes while
// the huge one has done only a sliver of its work.
TEST(JobService, ASmallJobBehindAHugeOneOfEqualPriorityFinishesFirst) {
  JobService service(fresh_dir("fair"));
  const auto huge = service.submit(api::parse_render_request(R"({"sun": {"zenith_deg": 50, "azimuth_deg": 140},
    "camera": {"projection": "equirectangular", "width": 16, "height": 8},
    "spectral": {"batches": 2}, "quality": {"samples_per_pixel": 4096}, "seed": 1})"), std::nullopt).id;
  const auto small = service.submit(api::parse_render_request(R"({"sun": {"zenith_deg": 50, "azimuth_deg": 140},
    "camera": {"projection": "equirectangular", "width": 16, "height": 8},
    "spectral": {"batches": 2}, "quality": {"samples_per_pixel": 32}, "seed": 2})"), std::nullopt).id;
  const std::vector<std::string> workers = {"w0", "w1", "w2"};
  for (const auto& w : workers) service.worker_joined(w, {{"cores", 1}, {"slots", 1}});
  std::deque<std::pair<std::string, UnitAssignment>> held;  // oldest first
  int steps = 0;
  while ((*service.status(small))["state"] != "done" && steps < 100) {
    ++steps;
    for (const auto& w : workers) {
      const bool busy = std::any_of(held.begin(), held.end(), [&](const auto& h) { return h.first == w; });
      if (busy) continue;
      if (auto a = service.next_unit(w)) held.emplace_back(w, *a);
    }
    ASSERT_FALSE(held.empty());
    const auto [w, a] = held.front();
    held.pop_front();
    service.unit_done(w, a.key, a.attempt, render_assignment(a), 1);
  }
  EXPECT_EQ((*service.status(small))["state"], "done");
  const auto h = *service.status(huge);
  EXPECT_EQ(h["state"], "running");
  EXPECT_LE(h["progress"]["units_done"].get<int>(), 8) << "of " << h["progress"]["units_total"];
  EXPECT_LE(steps, 12);
}

// Priorities still win outright: while the urgent job has work, no unit of
// the earlier, less urgent job is handed out.
TEST(JobService, AHigherPriorityTakesEveryUnitWhileItHasWork) {
  JobService service(fresh_dir("priority_all"));
  auto low = api::parse_render_request(kRequest);
  low.priority = 10;
  auto high = low;
  high.priority = 90;
  high.seed = 77;
  const auto low_id = service.submit(low, std::nullopt).id;
  const auto high_id = service.submit(high, std::nullopt).id;
  const int high_units = (*service.status(high_id))["plan"]["units"].get<int>();
  for (int i = 0; i < high_units; ++i) {
    const auto a = service.next_unit("w");
    ASSERT_TRUE(a);
    EXPECT_EQ(a->key.job_id, high_id) << i;
  }
  const auto next = service.next_unit("w");
  ASSERT_TRUE(next);
  EXPECT_EQ(next->key.job_id, low_id);
}

}  // namespace
}  // namespace skyfarm::server

namespace skyfarm::server {
namespace {

// --- Disk budget, reclaiming and retention ----------------------------------------

int tile_files(const fs::path& dir) {
  int n = 0;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec))
    if (e.path().filename().string().rfind("tile_", 0) == 0) ++n;
  return n;
}

std::int64_t disk_used(const JobService& s) { return s.metrics()["disk_used_bytes"].get<std::int64_t>(); }

void finish_all(JobService& service) {
  while (const auto a = service.next_unit("w")) service.unit_done("w", a->key, a->attempt, render_assignment(*a), 1);
}

// A job whose files would not fit in the budget is refused before anything
// is made, saying what it needs and what is free; a small one still fits.
TEST(JobService, AdmissionRefusesAJobOverTheDiskBudgetAndCreatesNothing) {
  const fs::path dir = fresh_dir("disk_admission");
  ServiceLimits limits;
  limits.max_disk_bytes = 4 << 20;
  JobService service(dir, limits);
  EXPECT_EQ(service.metrics()["disk_budget_bytes"].get<std::int64_t>(), 4 << 20);
  const auto big = api::parse_render_request(R"({"sun": {"zenith_deg": 30, "azimuth_deg": 10},
    "camera": {"projection": "equirectangular", "width": 512, "height": 256}, "spectral": {"batches": 2}})");
  try {
    service.submit(big, std::string("key-big"));
    FAIL() << "512 x 256 x 2 batches of tiles is ~19 MB, over 4 MiB";
  } catch (const InsufficientStorage& e) {
    const std::string m = e.what();
    const auto at = m.find("needs about ");
    ASSERT_NE(at, std::string::npos) << m;
    EXPECT_GE(std::stoi(m.substr(at + 12)), 18) << "at least its tiles: " << m;
    EXPECT_NE(m.find("MiB free"), std::string::npos) << m;
    EXPECT_NE(m.find("purge=true"), std::string::npos) << m;
  }
  EXPECT_EQ(service.job_count(), 0u);
  EXPECT_TRUE(fs::is_empty(dir / "jobs")) << "nothing is created on refusal";
  const auto small = service.submit(api::parse_render_request(kRequest), std::string("key-big"));
  EXPECT_TRUE(small.created) << "the refused request's key was not taken";
}

// The estimate is what a job really writes at most: each tile file has
// exactly its estimated size, and the finished directory fits the estimate.
TEST(JobService, TheDiskEstimateBoundsWhatAJobWrites) {
  const fs::path dir = fresh_dir("disk_estimate");
  JobService service(dir);
  const auto request = api::parse_render_request(kRequest);
  const auto id = service.submit(request, std::nullopt).id;
  const RenderPlan plan = api::render_plan_for(request, Sun::from_spec(request.sun, request.location, request.time));
  const int first_pass = plan.tile_count() * plan.batches;
  for (int i = 0; i < first_pass; ++i) {
    const auto a = service.next_unit("w");
    service.unit_done("w", a->key, a->attempt, render_assignment(*a), 1);
  }
  // A tile is written at most once a second while it merges: past that, the
  // timeout check writes what merged since (every batch of the first pass).
  std::this_thread::sleep_for(std::chrono::milliseconds(1100));
  service.check_timeouts(Clock::now());
  for (int t = 0; t < plan.tile_count(); ++t)
    EXPECT_EQ(static_cast<std::int64_t>(fs::file_size(dir / "jobs" / id / ("tile_" + std::to_string(t) + ".bin"))),
              tile_file_bytes(plan, t));
  ASSERT_TRUE(service.image(id, ImageFormat::kExr));  // a preview
  const std::int64_t peak = directory_bytes(dir / "jobs" / id);
  EXPECT_GE(disk_used(service), peak) << "used counts the job's files";
  EXPECT_LE(disk_used(service), directory_bytes(dir)) << "and what else the data directory held at start";
  finish_all(service);
  EXPECT_LE(peak, estimated_job_bytes(request, plan));
  EXPECT_LE(directory_bytes(dir / "jobs" / id), estimated_job_bytes(request, plan));
}

// A cancelled job's tiles (and preview) go at once; its status stays.  A
// done job's tiles go once its image is written: its status keeps the
// counts, also after a restart, and its image is still served.
TEST(JobService, CancelledAndDoneJobsKeepNoTiles) {
  const fs::path dir = fresh_dir("disk_reclaim");
  std::string cancelled, done;
  std::int64_t used_before_restart = 0;
  nlohmann::json done_status;
  {
    JobService service(dir);
    cancelled = service.submit(api::parse_render_request(kRequest), std::nullopt).id;
    for (int i = 0; i < 6; ++i) {
      const auto a = service.next_unit("w");
      service.unit_done("w", a->key, a->attempt, render_assignment(*a), 1);
    }
    EXPECT_GT(tile_files(dir / "jobs" / cancelled), 0);
    const std::int64_t with_tiles = disk_used(service);
    ASSERT_TRUE(service.cancel(cancelled));
    EXPECT_EQ(tile_files(dir / "jobs" / cancelled), 0);
    EXPECT_LT(disk_used(service), with_tiles);
    const auto s = *service.status(cancelled);
    EXPECT_EQ(s["state"], "cancelled");
    EXPECT_EQ(s["expired"], false);
    EXPECT_FALSE(service.image(cancelled, ImageFormat::kPng).has_value());

    auto other = api::parse_render_request(kRequest);
    other.seed = 11;
    done = service.submit(other, std::nullopt).id;
    finish_all(service);
    done_status = *service.status(done);
    ASSERT_EQ(done_status["state"], "done");
    EXPECT_EQ(tile_files(dir / "jobs" / done), 0);
    EXPECT_TRUE(fs::exists(service.image(done, ImageFormat::kExr)->path));
    used_before_restart = disk_used(service);
    EXPECT_GE(used_before_restart, directory_bytes(dir / "jobs"));
  }
  JobService restarted(dir);
  const auto s = *restarted.status(done);
  EXPECT_EQ(s["progress"], done_status["progress"]);
  EXPECT_EQ(s["error"]["history"], done_status["error"]["history"]);
  EXPECT_TRUE(fs::exists(restarted.image(done, ImageFormat::kExr)->path));
  // The restarted service counts what is on disk.
  EXPECT_EQ(disk_used(restarted), directory_bytes(dir));
  EXPECT_GE(disk_used(restarted), directory_bytes(dir / "jobs"));
  EXPECT_GT(directory_bytes(dir / "jobs"), 0);
}

// Purge removes a finished job's files and record; an active one is
// cancelled first.  The disk it held is free again.
TEST(JobService, PurgeRemovesFilesAndRecordAndFreesTheDisk) {
  const fs::path dir = fresh_dir("disk_purge");
  JobService service(dir);
  const auto request = api::parse_render_request(kRequest);
  const auto id = service.submit(request, std::string("k1")).id;
  EXPECT_EQ(service.submit(request, std::string("k2")).id, id) << "a second key, by the result cache";
  finish_all(service);
  ASSERT_EQ((*service.status(id))["state"], "done");
  const std::int64_t used = disk_used(service);
  EXPECT_EQ(service.purge(id).kind, PurgeOutcome::kPurged);
  EXPECT_FALSE(service.status(id).has_value());
  EXPECT_FALSE(fs::exists(dir / "jobs" / id));
  EXPECT_LT(disk_used(service), used);
  EXPECT_EQ(service.purge(id).kind, PurgeOutcome::kUnknown);
  EXPECT_EQ(service.job_count(), 0u);
  // Neither its key nor the result cache points at it any more.
  const auto again = service.submit(request, std::string("k1"));
  EXPECT_TRUE(again.created);
  EXPECT_NE(again.id, id);
  EXPECT_EQ(service.submit(request, std::string("k2")).id, again.id) << "k2 no longer names the purged job";
  // An active job: cancelled, then removed; its units are called back.
  const auto a = service.next_unit("w");
  ASSERT_TRUE(a);
  EXPECT_EQ(service.purge(again.id).kind, PurgeOutcome::kPurged);
  EXPECT_EQ(service.take_cancelled_attempts().size(), 1u);
  service.unit_done("w", a->key, a->attempt, render_assignment(*a), 1);  // late: dropped
  EXPECT_FALSE(service.next_unit("w").has_value());
  // A timelapse's frame is not purged alone.
  const auto frame = service.submit(request, std::nullopt).id;
  ASSERT_TRUE(service.set_group(frame, "timelapse-x"));
  EXPECT_EQ(service.purge(frame).kind, PurgeOutcome::kConflict);
  // And the records are gone after a restart too.
  JobService restarted(dir);
  EXPECT_FALSE(restarted.status(id).has_value());
  EXPECT_FALSE(restarted.status(again.id).has_value());
  EXPECT_TRUE(restarted.status(frame).has_value());
}

// Jobs finished longer than the retention ago lose their directory; the
// record stays, marked expired, without images, also after a restart.
TEST(JobService, FinishedJobsExpireAfterTheRetention) {
  const fs::path dir = fresh_dir("disk_expire");
  ServiceLimits limits;
  limits.retention_hours = 2.0;
  std::string id;
  {
    JobService service(dir, limits);
    id = service.submit(api::parse_render_request(kRequest), std::nullopt).id;
    finish_all(service);
    ASSERT_EQ((*service.status(id))["state"], "done");
    EXPECT_EQ(service.expire_finished(unix_now() + 3600.0), 0u) << "an hour later: kept";
    EXPECT_EQ(service.expire_finished(unix_now() + 3.0 * 3600.0), 1u);
    EXPECT_FALSE(fs::exists(dir / "jobs" / id));
    const auto s = *service.status(id);
    EXPECT_EQ(s["state"], "done");
    EXPECT_EQ(s["expired"], true);
    EXPECT_FALSE(service.image(id, ImageFormat::kExr).has_value());
    // The result cache does not hand out an expired job.
    EXPECT_TRUE(service.submit(api::parse_render_request(kRequest), std::nullopt).created);
  }
  JobService restarted(dir, limits);
  EXPECT_EQ((*restarted.status(id))["expired"], true);
  EXPECT_FALSE(fs::exists(dir / "jobs" / id)) << "an expired job's directory is not made again";
}

}  // namespace
}  // namespace skyfarm::server
