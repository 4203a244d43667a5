#include "api/timelapse_request.h"

#include <cmath>
#include <cstdio>

namespace skyfarm::api {
namespace {

// The render request's top-level fields a timelapse shares ("time" excluded).
constexpr std::string_view kRenderFields[] = {"location", "sun",    "camera", "atmosphere", "spectral", "quality",
                                              "method",   "output", "seed",   "priority", "clouds",
                                              "name"};
// Used in place of "time" while the shared fields are validated (the render
// parser needs a time or sun angles); any valid instant will do.
constexpr const char* kPlaceholderTime = "2000-01-01T00:00:00Z";

std::int64_t unix_ms(const UtcInstant& t) { return t.unix_seconds * 1000 + std::llround(t.fraction * 1000.0); }

std::int64_t floor_div(std::int64_t a, std::int64_t b) { return a / b - ((a % b != 0) && ((a < 0) != (b < 0))); }

UtcInstant instant_from_ms(std::int64_t ms) {
  UtcInstant t;
  t.unix_seconds = floor_div(ms, 1000);
  t.fraction = static_cast<double>(ms - t.unix_seconds * 1000) / 1000.0;
  return t;
}

// The UTC offset of a valid ISO 8601 text: "Z", or the last '+'/'-' (the
// date's hyphens come before the time, which always precedes the offset).
void read_offset(const std::string& text, int* minutes, bool* is_z) {
  *minutes = 0;
  *is_z = !text.empty() && text.back() == 'Z';
  if (*is_z) return;
  const std::size_t sign = text.find_last_of("+-");
  if (sign == std::string::npos) return;
  std::string digits;
  for (std::size_t i = sign + 1; i < text.size(); ++i)
    if (text[i] >= '0' && text[i] <= '9') digits.push_back(text[i]);
  if (digits.size() != 4) return;
  const int total = std::stoi(digits.substr(0, 2)) * 60 + std::stoi(digits.substr(2, 2));
  *minutes = text[sign] == '-' ? -total : total;
}

std::string offset_text(int minutes, bool is_z) {
  if (is_z) return "Z";
  char buf[16];
  const int m = std::abs(minutes);
  std::snprintf(buf, sizeof buf, "%c%02d:%02d", minutes < 0 ? '-' : '+', m / 60, m % 60);
  return buf;
}

// "start" / "end": required instants, end after start.
void read_range(const Fields& top, TimelapseRequest& r, bool* valid) {
  Errors& e = top.errors();
  std::optional<UtcInstant> start, end;
  std::optional<std::string> start_text, end_text;
  for (const char* name : {"start", "end"})
    if (!top.find_value(name)) e.add(top.path_of(name), "required (ISO 8601 with a UTC offset)");
  read_instant(top, "start", start, start_text);
  read_instant(top, "end", end, end_text);
  *valid = start && end;
  if (!*valid) return;
  r.start = *start;
  r.end = *end;
  r.start_text = *start_text;
  r.end_text = *end_text;
  if (unix_ms(r.end) <= unix_ms(r.start)) {
    e.add(top.path_of("end"), "must be after start (" + r.start_text + ")", value_text(*top.find("end")));
    *valid = false;
  }
  read_offset(r.start_text, &r.utc_offset_minutes, &r.utc_offset_is_z);
}

// "step_s" | "frames": exactly one; the frame count it gives in [2, max_frames].
void read_frame_count(const Fields& top, bool range_valid, int max_frames, TimelapseRequest& r) {
  Errors& e = top.errors();
  const bool step_given = top.find_value("step_s"), frames_given = top.find_value("frames");
  if (!step_given && !frames_given) {
    e.add(top.path_of("step_s"), "required: give step_s (seconds between frames) or frames (a count)");
    return;
  }
  if (step_given && frames_given) {
    e.add(top.path_of("frames"), "not allowed together with step_s (give one of them)",
          value_text(*top.find("frames")));
    return;
  }
  if (frames_given) {
    int n = 0;
    if (!top.integer("frames", 2, max_frames, n)) return;
    r.frames = n;
    r.frame_count = n;
    return;
  }
  std::optional<double> step;
  if (!top.optional_number("step_s", Range::closed(0.001, 1e10), step) || !range_valid) return;
  r.step_s = *step;
  const std::int64_t span_ms = unix_ms(r.end) - unix_ms(r.start);
  const std::int64_t step_ms = std::llround(*step * 1000.0);
  const std::int64_t n = span_ms / step_ms + 1;
  const std::string given = value_text(*top.find("step_s"));
  if (n < 2) {
    e.add(top.path_of("step_s"),
          "must be at most end - start (" + format_number(static_cast<double>(span_ms) / 1000.0) +
              " s) to give at least 2 frames",
          given);
  } else if (n > max_frames) {
    e.add(top.path_of("step_s"),
          "gives " + std::to_string(n) + " frames; at most " + std::to_string(max_frames) +
              " (a larger step_s, or frames)",
          given);
  } else {
    r.frame_count = static_cast<int>(n);
  }
}

// "same_seed", "exposure_smoothing_frames", "video_fps".
void read_options(const Fields& top, TimelapseRequest& r) {
  top.boolean("same_seed", r.same_seed);
  if (const Json* v = top.find("exposure_smoothing_frames")) {
    int k = r.exposure_smoothing_frames;
    if (top.integer("exposure_smoothing_frames", 1, 999, k)) {
      if (k % 2 == 0) top.errors().add(top.path_of("exposure_smoothing_frames"), "must be an odd integer in [1, 999]",
                                       value_text(*v));
      else r.exposure_smoothing_frames = k;
    }
  }
  top.integer("video_fps", 1, 120, r.video_fps);
}

// The render fields, validated by the render request's own parser so that
// their errors carry the same paths and messages.
void read_render_fields(const Json& body, bool range_valid, TimelapseRequest& r, Errors& e) {
  Json shared = Json::object();
  for (std::string_view name : kRenderFields)
    if (const auto it = body.find(std::string(name)); it != body.end()) shared[std::string(name)] = *it;
  shared["time"] = range_valid ? r.start_text : kPlaceholderTime;
  try {
    r.base = parse_render_request(shared);
  } catch (const ValidationError& ex) {
    for (const FieldError& f : ex.errors()) e.add(f.path, f.rule, f.value);
  }
}

// Fields a timelapse refuses: its frames take their time, and the sun's
// position from it, from start/end.
void refuse_fixed_time(const Fields& top) {
  Errors& e = top.errors();
  if (const Json* t = top.find_value("time"))
    e.add(top.path_of("time"),
          "not allowed in a timelapse request (frame times come from start, end and step_s or frames)",
          value_text(*t));
  const Json* sun = top.find("sun");
  if (!sun || !sun->is_object()) return;
  for (const char* name : {"zenith_deg", "azimuth_deg"})
    if (const auto it = sun->find(name); it != sun->end() && !it->is_null())
      e.add(child_path("sun", name), "not allowed in a timelapse request (the sun moves with each frame's time)",
            value_text(*it));
}

TimelapseRequest read_timelapse_request(const Json& body, int max_frames, Errors& e) {
  if (!body.is_object()) throw ValidationError({FieldError{"", "must be a JSON object", value_text(body)}});
  {
    // "time" gets its own error (refuse_fixed_time), not "unknown field".
    Json others = body;
    others.erase("time");
    Fields(others, "", e).allow_only({"location", "sun", "camera", "atmosphere", "spectral", "quality", "method",
                                      "output", "seed", "priority", "clouds", "name", "start", "end", "step_s", "frames",
                                      "same_seed", "exposure_smoothing_frames", "video_fps"});
  }
  Fields top(body, "", e);
  TimelapseRequest r;
  refuse_fixed_time(top);
  bool range_valid = false;
  read_range(top, r, &range_valid);
  read_frame_count(top, range_valid, max_frames, r);
  read_options(top, r);
  read_render_fields(body, range_valid, r, e);
  e.throw_if_any();
  r.base.time.reset();
  r.base.time_text.reset();
  return r;
}

}  // namespace

std::int64_t TimelapseRequest::frame_unix_ms(int i) const {
  const std::int64_t start_ms = unix_ms(start);
  if (step_s) return start_ms + static_cast<std::int64_t>(i) * std::llround(*step_s * 1000.0);
  const std::int64_t span = unix_ms(end) - start_ms, gaps = frame_count - 1;
  return start_ms + (static_cast<std::int64_t>(i) * span + gaps / 2) / gaps;  // rounded to the nearest ms
}

UtcInstant TimelapseRequest::frame_time(int i) const { return instant_from_ms(frame_unix_ms(i)); }

std::string TimelapseRequest::frame_time_text(int i) const {
  // The local wall-clock time is the UTC one plus the offset.
  std::string text =
      instant_from_ms(frame_unix_ms(i) + static_cast<std::int64_t>(utc_offset_minutes) * 60000).to_iso8601();
  text.pop_back();  // to_iso8601's "Z"
  return text + offset_text(utc_offset_minutes, utc_offset_is_z);
}

RenderRequest TimelapseRequest::frame_request(int i) const {
  RenderRequest r = base;
  r.time = frame_time(i);
  r.time_text = frame_time_text(i);
  if (!same_seed) r.seed = base.seed + static_cast<std::uint64_t>(i);
  // Each frame is listed among the renders under its timelapse's name.
  if (base.name) r.name = *base.name + " (frame " + std::to_string(i + 1) + " of " + std::to_string(frame_count) + ")";
  return r;
}

TimelapseRequest parse_timelapse_request(std::string_view json_text, int max_frames) {
  return guarded([&] {
    Errors errors;
    const Json body = parse_json_object(json_text, errors);
    return read_timelapse_request(body, max_frames, errors);
  });
}

nlohmann::json to_canonical_json(const TimelapseRequest& r) {
  nlohmann::json j = to_canonical_json(r.base);
  j.erase("time");
  j["start"] = r.start_text;
  j["end"] = r.end_text;
  j["step_s"] = r.step_s ? nlohmann::json(canonical_number(*r.step_s)) : nlohmann::json(nullptr);
  j["frames"] = r.frames ? nlohmann::json(*r.frames) : nlohmann::json(nullptr);
  j["same_seed"] = r.same_seed;
  j["exposure_smoothing_frames"] = r.exposure_smoothing_frames;
  j["video_fps"] = r.video_fps;
  return j;
}

std::string canonical_text(const TimelapseRequest& request) { return to_canonical_json(request).dump(); }

}  // namespace skyfarm::api
