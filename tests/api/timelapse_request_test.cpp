// Tests of the timelapse request: frame times from
// step_s or frames in start's offset, seeds, errors that name the field like
// render requests do, the frame cap, and the canonical form.
#include "api/timelapse_request.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "tests/support/test_files.h"

namespace skyfarm::api {
namespace {

using skyfarm::testing::kExamples;
using skyfarm::testing::read_text;

// A valid body plus `members` (", "-separated JSON members).
std::string body(const std::string& members) {
  return R"({"camera": {"projection": "equirectangular", "width": 16, "height": 8})" +
         (members.empty() ? std::string() : ", " + members) + "}";
}

// The fields named by the errors of `text` (empty when it parses).
std::vector<std::string> error_fields(const std::string& text, int max_frames = kMaxTimelapseFrames) {
  std::vector<std::string> out;
  try {
    parse_timelapse_request(text, max_frames);
  } catch (const ValidationError& e) {
    for (const auto& f : e.errors()) out.push_back(f.path);
  }
  return out;
}

std::string first_message(const std::string& text) {
  try {
    parse_timelapse_request(text);
  } catch (const ValidationError& e) {
    return e.errors().front().message();
  }
  return "";
}

TEST(TimelapseRequest, StepGivesFramesFromStartToEndInStartsOffset) {
  const TimelapseRequest r = parse_timelapse_request(
      body(R"("start": "2013-05-27T19:00:00-04:00", "end": "2013-05-27T20:00:00-04:00", "step_s": 1500)"));
  // 0, 25 and 50 minutes; 75 would pass the end.
  ASSERT_EQ(r.frame_count, 3);
  EXPECT_EQ(r.frame_time_text(0), "2013-05-27T19:00:00-04:00");
  EXPECT_EQ(r.frame_time_text(1), "2013-05-27T19:25:00-04:00");
  EXPECT_EQ(r.frame_time_text(2), "2013-05-27T19:50:00-04:00");
  EXPECT_EQ(r.frame_time(0).to_iso8601(), "2013-05-27T23:00:00Z");
  EXPECT_EQ(r.frame_time(2).to_iso8601(), "2013-05-27T23:50:00Z");
  EXPECT_FALSE(r.base.time.has_value()) << "the shared fields carry no time";
}

TEST(TimelapseRequest, FramesSpreadEvenlyWithBothEndsIncluded) {
  const TimelapseRequest r = parse_timelapse_request(
      body(R"("start": "2021-06-21T23:59:59Z", "end": "2021-06-22T00:00:00.500Z", "frames": 4)"));
  ASSERT_EQ(r.frame_count, 4);
  // 1.5 s in 3 gaps of 0.5 s, across midnight.
  EXPECT_EQ(r.frame_time_text(0), "2021-06-21T23:59:59Z");
  EXPECT_EQ(r.frame_time_text(1), "2021-06-21T23:59:59.500Z");
  EXPECT_EQ(r.frame_time_text(2), "2021-06-22T00:00:00Z");
  EXPECT_EQ(r.frame_time_text(3), "2021-06-22T00:00:00.500Z");
}

TEST(TimelapseRequest, PositiveOffsetsWithoutColonAreWrittenWithOne) {
  const TimelapseRequest r = parse_timelapse_request(
      body(R"("start": "2021-06-21T05:30:00+0530", "end": "2021-06-21T06:30:00+05:30", "frames": 2)"));
  EXPECT_EQ(r.frame_time_text(0), "2021-06-21T05:30:00+05:30");
  EXPECT_EQ(r.frame_time_text(1), "2021-06-21T06:30:00+05:30");
  EXPECT_EQ(r.frame_time(0).to_iso8601(), "2021-06-21T00:00:00Z");
}

TEST(TimelapseRequest, FrameRequestsCarryTheirTimeAndSeed) {
  const std::string range = R"("start": "2013-05-27T19:00:00-04:00", "end": "2013-05-27T19:10:00-04:00", "frames": 3, "seed": 40)";
  const TimelapseRequest same = parse_timelapse_request(body(range));
  EXPECT_TRUE(same.same_seed);
  const TimelapseRequest varied = parse_timelapse_request(body(range + R"(, "same_seed": false)"));
  for (int i = 0; i < 3; ++i) {
    const RenderRequest a = same.frame_request(i), b = varied.frame_request(i);
    ASSERT_TRUE(a.time.has_value());
    EXPECT_EQ(a.time->to_iso8601(), same.frame_time(i).to_iso8601());
    EXPECT_EQ(a.time_text, same.frame_time_text(i));
    EXPECT_EQ(a.seed, 40u);
    EXPECT_EQ(b.seed, 40u + static_cast<unsigned>(i));
    EXPECT_EQ(a.camera.width, 16);
  }
  EXPECT_NE(canonical_text(same.frame_request(0)), canonical_text(same.frame_request(1)));
}

// "atmosphere.refraction" reaches every frame, and its canonical text.
TEST(TimelapseRequest, FramesCarryRefraction) {
  const TimelapseRequest r = parse_timelapse_request(body(
      R"("start": "2013-05-27T20:00:00-04:00", "end": "2013-05-27T20:30:00-04:00", "frames": 2, )"
      R"("atmosphere": {"refraction": true})"));
  for (int i = 0; i < 2; ++i) {
    EXPECT_TRUE(r.frame_request(i).atmosphere.refraction);
    EXPECT_NE(canonical_text(r.frame_request(i)).find(R"("refraction":true)"), std::string::npos);
  }
}

TEST(TimelapseRequest, DefaultsAndOptions) {
  const std::string range = R"("start": "2013-05-27T19:00:00Z", "end": "2013-05-27T19:10:00Z", "frames": 3)";
  const TimelapseRequest d = parse_timelapse_request(body(range));
  EXPECT_EQ(d.exposure_smoothing_frames, kDefaultExposureSmoothingFrames);
  EXPECT_EQ(d.video_fps, kDefaultVideoFps);
  EXPECT_FALSE(d.base.output.exposure_ev.has_value()) << "automatic, smoothed exposure by default";
  const TimelapseRequest o = parse_timelapse_request(
      body(range + R"(, "exposure_smoothing_frames": 1, "video_fps": 60, "output": {"exposure_ev": 12}, "method": "lut")"));
  EXPECT_EQ(o.exposure_smoothing_frames, 1);
  EXPECT_EQ(o.video_fps, 60);
  EXPECT_EQ(o.base.output.exposure_ev, 12.0);
  EXPECT_EQ(o.base.method, Method::kLut);
}

// output.view (and the EXR's colour space) reach every frame's request and
// the timelapse's canonical text; a bad view names the field.
TEST(TimelapseRequest, OutputViewAndColourSpaceReachTheFrames) {
  const std::string range = R"("start": "2013-05-27T19:00:00Z", "end": "2013-05-27T19:10:00Z", "frames": 2)";
  const TimelapseRequest plain = parse_timelapse_request(body(range));
  const TimelapseRequest r =
      parse_timelapse_request(body(range + R"(, "output": {"view": "aces", "color_space": "acescg"})"));
  EXPECT_EQ(r.base.output.view, DisplayView::kAces);
  EXPECT_EQ(r.frame_request(1).output.view, DisplayView::kAces);
  EXPECT_EQ(r.frame_request(1).output.color_space, ColorSpace::kAcesCg);
  EXPECT_NE(canonical_text(r), canonical_text(plain));
  EXPECT_EQ(parse_timelapse_request(canonical_text(r)).base.output.view, DisplayView::kAces);
  try {
    parse_timelapse_request(body(range + R"(, "output": {"view": "filmic"})"));
    ADD_FAILURE() << "accepted";
  } catch (const ValidationError& e) {
    ASSERT_EQ(e.errors().size(), 1u);
    EXPECT_EQ(e.errors()[0].path, "output.view");
  }
}

TEST(TimelapseRequest, ErrorsNameTheField) {
  const std::string range = R"("start": "2013-05-27T19:00:00Z", "end": "2013-05-27T20:00:00Z")";
  struct Case {
    std::string body;
    std::string field;
  };
  const std::vector<Case> cases = {
      {body(R"("end": "2013-05-27T20:00:00Z", "frames": 3)"), "start"},
      {body(R"("start": "2013-05-27T20:00:00Z", "frames": 3)"), "end"},
      {body(R"("start": "2013-05-27 19:00", "end": "2013-05-27T20:00:00Z", "frames": 3)"), "start"},
      {body(R"("start": "1700-05-27T19:00:00Z", "end": "2013-05-27T20:00:00Z", "frames": 3)"), "start"},
      {body(R"("start": "2013-05-27T20:00:00Z", "end": "2013-05-27T19:00:00Z", "frames": 3)"), "end"},
      {body(range), "step_s"},
      {body(range + R"(, "step_s": 60, "frames": 3)"), "frames"},
      {body(range + R"(, "frames": 1)"), "frames"},
      {body(range + R"(, "frames": 2.5)"), "frames"},
      {body(range + R"(, "frames": 1001)"), "frames"},
      {body(range + R"(, "step_s": 0)"), "step_s"},
      {body(range + R"(, "step_s": "60")"), "step_s"},
      {body(range + R"(, "step_s": 7200)"), "step_s"},   // one frame only
      {body(range + R"(, "step_s": 1)"), "step_s"},      // 3601 frames
      {body(range + R"(, "frames": 3, "same_seed": 1)"), "same_seed"},
      {body(range + R"(, "frames": 3, "exposure_smoothing_frames": 4)"), "exposure_smoothing_frames"},
      {body(range + R"(, "frames": 3, "exposure_smoothing_frames": 0)"), "exposure_smoothing_frames"},
      {body(range + R"(, "frames": 3, "video_fps": 0)"), "video_fps"},
      {body(range + R"(, "frames": 3, "time": "2013-05-27T19:00:00Z")"), "time"},
      {body(range + R"(, "frames": 3, "sun": {"zenith_deg": 30, "azimuth_deg": 100})"), "sun.zenith_deg"},
      {body(range + R"(, "frames": 3, "output": {"exposure_ev": 99})"), "output.exposure_ev"},
      {body(range + R"(, "frames": 3, "frame_count": 3)"), "frame_count"},
      {R"({"camera": {"projection": "equirectangular", "width": -3}, )" + range + R"(, "frames": 3})", "camera.width"},
      {R"({)" + range + R"(, "frames": 3})", "camera"},
  };
  for (const Case& c : cases) {
    const auto fields = error_fields(c.body);
    EXPECT_NE(std::find(fields.begin(), fields.end(), c.field), fields.end())
        << c.body << " -> " << (fields.empty() ? "(no error)" : fields.front());
  }
  EXPECT_EQ(first_message(body(range + R"(, "step_s": 1)")),
            "step_s: gives 3601 frames; at most 1000 (a larger step_s, or frames), got 1");
  // "time" is refused once, with the reason, and is not listed among the allowed fields.
  const std::string with_time = body(range + R"(, "frames": 3, "time": "2013-05-27T19:00:00Z")");
  EXPECT_EQ(error_fields(with_time), std::vector<std::string>{"time"});
  const std::string unknown = first_message(body(range + R"(, "frames": 3, "fps": 3)"));
  EXPECT_TRUE(unknown.starts_with("fps: unknown field (allowed: location, sun, camera,")) << unknown;
  EXPECT_EQ(unknown.find("time"), std::string::npos) << unknown;
  // Every error at once, as for renders.
  EXPECT_EQ(error_fields(body(R"("frames": 1, "video_fps": 500)")).size(), 4u);
}

TEST(TimelapseRequest, TheFrameCapIsAParameter) {
  const std::string text = body(R"("start": "2013-05-27T19:00:00Z", "end": "2013-05-27T20:00:00Z", "frames": 12)");
  EXPECT_TRUE(error_fields(text, 12).empty());
  EXPECT_EQ(error_fields(text, 11), std::vector<std::string>{"frames"});
}

TEST(TimelapseRequest, HostileBodiesAreValidationErrors) {
  for (const char* text : {"", "{", "[]", "null", "{\"start\": {\"a\": [[[[[]]]]]}}", "{\"camera\": 1e999}"}) {
    EXPECT_THROW(parse_timelapse_request(text), ValidationError) << text;
  }
}

TEST(TimelapseRequest, CanonicalFormReadsBackToTheSameRequest) {
  const TimelapseRequest r = parse_timelapse_request(read_text(kExamples / "timelapse" / "ithaca_sunset_lut.json"));
  EXPECT_EQ(r.frame_count, 13);
  const std::string text = canonical_text(r);
  const TimelapseRequest again = parse_timelapse_request(text);
  EXPECT_EQ(canonical_text(again), text);
  EXPECT_EQ(again.frame_time_text(12), "2013-05-27T21:00:00-04:00");
  const nlohmann::json j = to_canonical_json(r);
  EXPECT_FALSE(j.contains("time"));
  EXPECT_EQ(j["step_s"], 600);
  EXPECT_TRUE(j["frames"].is_null());
  EXPECT_EQ(j["same_seed"], true);
}

}  // namespace
}  // namespace skyfarm::api
