// The timelapse request: the render request's fields
// without "time", plus the time range and how it is cut into frames.  Field
// by field rules: docs/request-schema.md "Timelapse request".
//
// Parameters (top-level fields besides the render request's)
//   start, end          ISO 8601 with a UTC offset (years 1800-2200), end
//                       after start; frame times are written in start's offset
//   step_s | frames     exactly one: seconds between frames (>= 0.001; frames
//                       at start, start + step, ... up to end), or the frame
//                       count (>= 2; start and end included, evenly spaced)
//   same_seed           true (default): every frame renders with the request's
//                       seed, so noise does not flicker from frame to frame;
//                       false: frame i uses seed + i
//   exposure_smoothing_frames
//                       odd integer in [1, 999], default 5: with automatic
//                       exposure (output.exposure_ev null, the default) frame
//                       i's PNG EV100 is the mean of the automatic EV100 of
//                       frames i-k..i+k (k = (n-1)/2, shrunk near the ends to
//                       stay centred), so the video does not pump; a number in
//                       output.exposure_ev fixes every frame's EV100 instead
//   video_fps           integer in [1, 120], default 24
//   name                a label, as in render requests (api/job_name.h); left
//                       out of the canonical form; each frame's render is
//                       named "<name> (frame i of n)"
// At most `max_frames` frames (default kMaxTimelapseFrames); more is a 400
// naming "frames" or "step_s".  Frame times are computed in whole
// milliseconds.  "time", "sun.zenith_deg" and "sun.azimuth_deg" are refused:
// each frame's sun comes from its time.
#pragma once
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "api/render_request.h"

namespace skyfarm::api {

inline constexpr int kMaxTimelapseFrames = 1000;
inline constexpr int kDefaultExposureSmoothingFrames = 5;
inline constexpr int kDefaultVideoFps = 24;

struct TimelapseRequest {
  RenderRequest base;  // every frame's fields; base.time is unset
  UtcInstant start, end;
  std::string start_text, end_text;  // as the client wrote them
  std::optional<double> step_s;      // exactly one of step_s and frames
  std::optional<int> frames;
  bool same_seed = true;
  int exposure_smoothing_frames = kDefaultExposureSmoothingFrames;
  int video_fps = kDefaultVideoFps;

  // Derived at parse time.
  int frame_count = 0;
  int utc_offset_minutes = 0;  // start's offset; frame times are written in it
  bool utc_offset_is_z = false;

  // Frame i's instant (milliseconds since the Unix epoch) and its ISO 8601
  // text in start's offset, e.g. "2013-05-27T09:30:00-04:00".
  std::int64_t frame_unix_ms(int i) const;
  UtcInstant frame_time(int i) const;
  std::string frame_time_text(int i) const;
  // The render request of frame i: base with the frame's time and seed.
  RenderRequest frame_request(int i) const;
};

// Parses and validates a timelapse body.  Throws ValidationError listing
// every invalid field (render fields by the same paths as render requests);
// no other exception escapes, whatever the input.
TimelapseRequest parse_timelapse_request(std::string_view json_text, int max_frames = kMaxTimelapseFrames);

// Every field with its default filled in (the render fields in their
// canonical form, start and end as written): parsing it gives the same
// request back; equal texts mean equal timelapses.
nlohmann::json to_canonical_json(const TimelapseRequest& request);
std::string canonical_text(const TimelapseRequest& request);

}  // namespace skyfarm::api
