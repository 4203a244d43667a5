// Group scheduling in the JobService: the frames of one timelapse
// share out their passes, so pass p of every frame is handed out before pass
// p + 1 of any, and frame 1 starts long before frame 0 has all its passes;
// a group is one tenant of the fair share between jobs of one priority.
#include "server/jobs/job_service.h"

#include <gtest/gtest.h>

#include <unistd.h>

#include <map>

namespace skyfarm::server {
namespace {

namespace fs = std::filesystem;

// 16 x 8, 2 batches, 3 passes of 16 samples: 2 units per pass per frame.
std::string frame_request(int seed) {
  return R"({"sun": {"zenith_deg": 50, "azimuth_deg": 140},
             "camera": {"projection": "equirectangular", "width": 16, "height": 8},
             "spectral": {"batches": 2}, "quality": {"samples_per_pixel": 48}, "seed": )" +
         std::to_string(seed) + "}";
}

fs::path fresh_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("skyfarm_tls_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  return d;
}

struct Handed {
  int frame;
  int pass;
};

// Submits `frames` jobs (grouped or not) and hands out every unit without
// returning any result: the order the farm would start them in.
std::vector<Handed> hand_out_all(JobService& service, int frames, const std::string& group,
                                 std::vector<std::string>* ids_out = nullptr) {
  std::map<std::string, int> frame_of;
  std::vector<std::string> ids;
  for (int f = 0; f < frames; ++f) {
    const std::string id = service.submit(api::parse_render_request(frame_request(100 + f)), std::nullopt).id;
    if (!group.empty()) {
      EXPECT_TRUE(service.set_group(id, group));
    }
    frame_of[id] = f;
    ids.push_back(id);
  }
  service.worker_joined("w0", {{"cores", 1}, {"slots", 64}});
  std::vector<Handed> out;
  while (auto a = service.next_unit("w0")) out.push_back({frame_of.at(a->key.job_id), a->key.pass});
  if (ids_out) *ids_out = ids;
  return out;
}

TEST(TimelapseScheduling, GroupedFramesGetPassPOfEveryFrameBeforePassPPlus1OfAny) {
  JobService service(fresh_dir("grouped"));
  const auto handed = hand_out_all(service, 3, "timelapse-a");
  ASSERT_EQ(handed.size(), 3u * 3u * 2u);  // frames x passes x units per pass
  for (std::size_t i = 1; i < handed.size(); ++i)
    EXPECT_LE(handed[i - 1].pass, handed[i].pass) << "unit " << i << " went back to an earlier pass";
  // Frame 1's first unit comes before frame 0's last pass is handed out.
  std::size_t first_of_frame1 = handed.size(), last_of_frame0 = 0;
  for (std::size_t i = 0; i < handed.size(); ++i) {
    if (handed[i].frame == 1) first_of_frame1 = std::min(first_of_frame1, i);
    if (handed[i].frame == 0) last_of_frame0 = i;
  }
  EXPECT_LT(first_of_frame1, last_of_frame0);
  // Within a pass, frames in order: pass 0 is frame 0, 0, 1, 1, 2, 2.
  for (int k = 0; k < 6; ++k) EXPECT_EQ(handed[static_cast<std::size_t>(k)].frame, k / 2);
}

TEST(TimelapseScheduling, WithoutAGroupJobsShareTheWorkersInTurn) {
  JobService service(fresh_dir("plain"));
  const auto handed = hand_out_all(service, 3, "");
  ASSERT_EQ(handed.size(), 18u);
  // Equal priority, nothing returned: the job with the fewest units in
  // flight is served, so the three take turns; each still pass by pass.
  for (std::size_t i = 0; i < handed.size(); ++i) EXPECT_EQ(handed[i].frame, static_cast<int>(i % 3)) << i;
  std::map<int, int> last_pass;
  for (const auto& h : handed) {
    EXPECT_GE(h.pass, last_pass[h.frame]);
    last_pass[h.frame] = h.pass;
  }
}

// A group is one tenant of the fair share: two frames of a timelapse and a
// plain job of the same priority get half the units each.
TEST(TimelapseScheduling, AGroupCountsAsOneTenant) {
  JobService service(fresh_dir("tenant"));
  const std::string a = service.submit(api::parse_render_request(frame_request(1)), std::nullopt).id;
  const std::string b = service.submit(api::parse_render_request(frame_request(2)), std::nullopt).id;
  ASSERT_TRUE(service.set_group(a, "timelapse-c"));
  ASSERT_TRUE(service.set_group(b, "timelapse-c"));
  const std::string plain = service.submit(api::parse_render_request(frame_request(3)), std::nullopt).id;
  int to_plain = 0;
  for (int i = 0; i < 8; ++i) {
    const auto u = service.next_unit("w0");
    ASSERT_TRUE(u);
    to_plain += u->key.job_id == plain;
  }
  EXPECT_EQ(to_plain, 4);
}

TEST(TimelapseScheduling, RequeuedUnitsOfALostWorkerGoFirst) {
  JobService service(fresh_dir("requeue"));
  std::vector<std::string> ids;
  const auto handed = hand_out_all(service, 2, "timelapse-b", &ids);
  ASSERT_EQ(handed.size(), 12u);
  // The worker is lost with every unit: they come back pass by pass again.
  service.worker_left("w0");
  service.worker_joined("w1", {{"cores", 1}, {"slots", 64}});
  int last_pass = 0, count = 0;
  while (auto a = service.next_unit("w1")) {
    EXPECT_GE(a->key.pass, last_pass);
    last_pass = a->key.pass;
    ++count;
  }
  EXPECT_EQ(count, 12);
}

TEST(TimelapseScheduling, GroupsOfUnknownJobsAndSummaries) {
  JobService service(fresh_dir("summary"));
  EXPECT_FALSE(service.set_group("nope", "g"));
  EXPECT_FALSE(service.summary("nope").has_value());
  const std::string id = service.submit(api::parse_render_request(frame_request(7)), std::nullopt).id;
  std::vector<std::pair<std::string, JobState>> seen;
  service.set_state_observer([&](const std::string& job, JobState state) { seen.emplace_back(job, state); });
  const auto s = service.summary(id);
  ASSERT_TRUE(s);
  EXPECT_EQ(s->state, JobState::kQueued);
  EXPECT_EQ(s->fraction, 0.0);
  EXPECT_FALSE(s->estimated_relative_rms.has_value());
  service.cancel(id);
  EXPECT_EQ(service.summary(id)->state, JobState::kCancelled);
  ASSERT_EQ(seen.size(), 1u);
  EXPECT_EQ(seen[0], std::make_pair(id, JobState::kCancelled));
  service.set_state_observer({});
}

}  // namespace
}  // namespace skyfarm::server
