#include "api/render_request.h"

#include <algorithm>
#include <cmath>

#include "api/cloud_fields.h"
#include "api/job_name.h"
#include "api/object_fields.h"

namespace skyfarm::api {
namespace {

constexpr int kMaxSide = 16384;
constexpr std::int64_t kMaxPixels = std::int64_t{16384} * 8192;

constexpr Choice<Projection> kProjections[] = {{"equirectangular", Projection::kEquirectangular},
                                               {"fisheye", Projection::kFisheye},
                                               {"perspective", Projection::kPerspective}};

// The names of common/image/color_management.h, in its order (one list).
constexpr Choice<ColorSpace> kColorSpaces[] = {{kColorSpaceNames[0].first, kColorSpaceNames[0].second},
                                               {kColorSpaceNames[1].first, kColorSpaceNames[1].second},
                                               {kColorSpaceNames[2].first, kColorSpaceNames[2].second},
                                               {kColorSpaceNames[3].first, kColorSpaceNames[3].second}};
constexpr Choice<RadiometricUnits> kUnits[] = {{kRadiometricUnitsNames[0].first, kRadiometricUnitsNames[0].second},
                                               {kRadiometricUnitsNames[1].first, kRadiometricUnitsNames[1].second},
                                               {kRadiometricUnitsNames[2].first, kRadiometricUnitsNames[2].second}};
constexpr Choice<DisplayView> kViews[] = {{kDisplayViewNames[0].first, kDisplayViewNames[0].second},
                                          {kDisplayViewNames[1].first, kDisplayViewNames[1].second}};
static_assert(std::size(kColorSpaces) == kColorSpaceNames.size() && std::size(kUnits) == kRadiometricUnitsNames.size() &&
              std::size(kViews) == kDisplayViewNames.size());

// Per-projection defaults and field-of-view rule.
struct ProjectionRules {
  int width;
  int height;
  double fov_deg;  // default (equirectangular: always 360, the field is ignored)
  Range fov;
  std::string_view fov_context;
};

ProjectionRules rules_for(Projection p) {
  switch (p) {
    case Projection::kFisheye:
      return {512, 512, 180.0, Range::open_closed(0, 360), " for a fisheye camera"};
    case Projection::kPerspective:
      return {960, 540, 60.0, Range::open_closed(0, 179), " for a perspective camera"};
    case Projection::kEquirectangular:
      break;
  }
  return {1024, 512, 360.0, Range::open_closed(0, 360), " for an equirectangular camera"};
}

// --- "camera.width" / "camera.height": defaults per projection, a lone side
// keeps the default aspect, at most kMaxPixels in all.
void read_camera_size(const Fields& f, const std::optional<Projection>& projection, CameraSpec& cam) {
  Errors& e = f.errors();
  const ProjectionRules r = rules_for(projection.value_or(Projection::kEquirectangular));
  const bool width_given = f.find("width"), height_given = f.find("height");
  int w = r.width, h = r.height;
  const bool width_ok = !width_given || f.integer("width", 1, kMaxSide, w);
  const bool height_ok = !height_given || f.integer("height", 1, kMaxSide, h);
  if (!width_ok || !height_ok || !projection) return;
  if (width_given && !height_given)
    h = std::max(1, static_cast<int>(std::lround(double(w) * r.height / r.width)));
  if (height_given && !width_given) {
    w = std::max(1, static_cast<int>(std::lround(double(h) * r.width / r.height)));
    if (w > kMaxSide) {
      e.add(f.path_of("width"), "must be an integer in [1, 16384] (derived from camera.height with the default aspect)",
            std::to_string(w));
      return;
    }
  }
  const std::int64_t pixels = std::int64_t{w} * h;
  if (pixels > kMaxPixels) {
    e.add(f.path(), "width * height must be at most 134217728 (16384 * 8192)",
          std::to_string(w) + " * " + std::to_string(h) + " = " + std::to_string(pixels));
    return;
  }
  cam.width = w;
  cam.height = h;
}

// --- "camera.fov_deg": range and default per projection.
void read_fov(const Fields& f, const std::optional<Projection>& projection, CameraSpec& cam) {
  const Json* v = f.find("fov_deg");
  if (!projection) {  // the rule is unknown: check the type only
    if (v) read_number(*v, f.path_of("fov_deg"), Range::any(), f.errors());
    return;
  }
  const ProjectionRules r = rules_for(*projection);
  cam.fov_deg = r.fov_deg;
  if (!v) return;
  auto fov = read_number(*v, f.path_of("fov_deg"), r.fov, f.errors(), r.fov_context);
  if (fov && *projection != Projection::kEquirectangular) cam.fov_deg = *fov;
}

// --- "camera" (required)
void read_camera(const Fields& top, CameraSpec& cam) {
  Errors& e = top.errors();
  const std::string path = top.path_of("camera");
  const Json* v = top.find("camera");
  if (!v) {
    e.add(path, "required");
    return;
  }
  if (!expect_object(*v, path, e)) return;
  Fields f(*v, path, e);
  f.allow_only({"projection", "width", "height", "yaw_deg", "pitch_deg", "roll_deg", "fov_deg"});
  std::optional<Projection> projection;
  if (!f.find("projection")) e.add(f.path_of("projection"), "required");
  else if (Projection p; f.choice("projection", kProjections, p)) projection = p;
  if (projection) cam.projection = *projection;
  read_camera_size(f, projection, cam);
  f.number("yaw_deg", Range::closed(-360, 360), cam.yaw_deg);
  f.number("pitch_deg", Range::closed(-90, 90), cam.pitch_deg);
  f.number("roll_deg", Range::closed(-180, 180), cam.roll_deg);
  read_fov(f, projection, cam);
}

// --- "spectral"
void read_spectral(const Fields& top, SpectralSpec& s) {
  const Json* v = top.find("spectral");
  Errors& e = top.errors();
  if (!v || !expect_object(*v, top.path_of("spectral"), e)) return;
  Fields f(*v, top.path_of("spectral"), e);
  f.allow_only({"min_nm", "max_nm", "batches"});
  const Range range = Range::closed(kMinSpectralNm, kMaxSpectralNm);
  const bool min_ok = !f.find("min_nm") || f.number("min_nm", range, s.min_nm);
  const bool max_ok = !f.find("max_nm") || f.number("max_nm", range, s.max_nm);
  if (min_ok && max_ok && !(s.max_nm > s.min_nm)) {
    const Json* max = f.find("max_nm");
    e.add(f.path_of("max_nm"), "must be greater than spectral.min_nm (" + format_number(s.min_nm) + ")",
          max ? value_text(*max) : format_number(s.max_nm));
  }
  f.integer("batches", 1, 64, s.batches);
}

// --- "quality"
void read_quality(const Fields& top, QualitySpec& q) {
  const Json* v = top.find("quality");
  if (!v || !expect_object(*v, top.path_of("quality"), top.errors())) return;
  Fields f(*v, top.path_of("quality"), top.errors());
  f.allow_only({"samples_per_pixel", "target_relative_error", "time_limit_s", "adaptive"});
  f.integer("samples_per_pixel", 1, QualitySpec::kMaxSamplesPerPixel, q.samples_per_pixel);
  f.optional_number("target_relative_error", Range::open_closed(0, 1), q.target_relative_error);
  f.optional_number("time_limit_s", Range::open_closed(0, 604800), q.time_limit_s);
  f.boolean("adaptive", q.adaptive);
  if (!v->contains("samples_per_pixel") && (q.target_relative_error || q.time_limit_s))
    q.samples_per_pixel = QualitySpec::kMaxSamplesPerPixel;
}

// --- "output"
void read_output(const Fields& top, OutputSpec& o) {
  const Json* v = top.find("output");
  if (!v || !expect_object(*v, top.path_of("output"), top.errors())) return;
  Fields f(*v, top.path_of("output"), top.errors());
  f.allow_only({"exposure_ev", "spectral_channels", "error_layer", "half", "color_space", "units", "view"});
  f.optional_number("exposure_ev", Range::closed(-50, 50), o.exposure_ev);
  f.boolean("spectral_channels", o.spectral_channels);
  f.boolean("error_layer", o.error_layer);
  f.boolean("half", o.half);
  f.choice("color_space", kColorSpaces, o.color_space);
  f.choice("units", kUnits, o.units);
  f.choice("view", kViews, o.view);
}

// Written only when not the default, so that the requests of before keep
// their canonical text (their hash, their cached results).
Json output_json(const OutputSpec& o) {
  Json j = {{"exposure_ev", optional_number_json(o.exposure_ev)},
            {"spectral_channels", o.spectral_channels},
            {"error_layer", o.error_layer},
            {"half", o.half}};
  if (o.color_space != ColorSpace::kLinRec709) j["color_space"] = std::string(name_of(kColorSpaces, o.color_space));
  if (o.units != RadiometricUnits::kCdM2) j["units"] = std::string(name_of(kUnits, o.units));
  if (o.view != DisplayView::kSrgb) j["view"] = std::string(name_of(kViews, o.view));
  return j;
}

// --- The whole request.
RenderRequest read_render_request(const Json& body, Errors& e) {
  if (!body.is_object()) throw ValidationError({FieldError{"", "must be a JSON object", value_text(body)}});
  Fields top(body, "", e);
  top.allow_only({"location", "time", "sun", "camera", "atmosphere", "spectral", "quality", "method", "output",
                  "seed", "priority", "objects", "clouds", "name"});
  RenderRequest r;
  read_location(top, r.location);
  read_time(top, r.time, r.time_text);
  read_sun(top, r.sun);
  require_time_or_sun(top);
  read_camera(top, r.camera);
  read_atmosphere(top, r.atmosphere);
  read_objects(top, r.objects);
  read_clouds(top, r.clouds);
  read_spectral(top, r.spectral);
  read_quality(top, r.quality);
  read_method(top, r.method);
  read_output(top, r.output);
  read_seed(top, r.seed);
  top.integer("priority", 0, 100, r.priority);
  read_job_name(top, r.name);
  if (r.method == Method::kLut && !r.objects.empty())
    e.add("objects", "the lut method renders the sky alone: objects need \"method\": \"path\"");
  // The LUT renderer ray-marches cloud layers; placed volumes need the path tracer.
  if (r.method == Method::kLut && !r.clouds.volumes.empty())
    e.add("clouds.volumes", "the lut method renders cloud layers only: cloud volumes need \"method\": \"path\"");
  e.throw_if_any();
  return r;
}

// --- Canonical camera: yaw in [0, 360), roll in (-180, 180], equirectangular fov 360.
Json camera_json(const CameraSpec& c) {
  double yaw = std::fmod(c.yaw_deg, 360.0);
  if (yaw < 0) yaw += 360.0;
  if (yaw >= 360.0) yaw = 0.0;
  const double roll = c.roll_deg == -180.0 ? 180.0 : c.roll_deg;
  const double fov = c.projection == Projection::kEquirectangular ? 360.0 : c.fov_deg;
  return {{"projection", std::string(name_of(kProjections, c.projection))},
          {"width", c.width},
          {"height", c.height},
          {"yaw_deg", canonical_number(yaw)},
          {"pitch_deg", canonical_number(c.pitch_deg)},
          {"roll_deg", canonical_number(roll)},
          {"fov_deg", canonical_number(fov)}};
}

// "adaptive" is written only when true, so that the requests of before it
// keep their canonical text (their hash, their cached results).
Json quality_json(const QualitySpec& q) {
  Json j = {{"samples_per_pixel", q.samples_per_pixel},
            {"target_relative_error", optional_number_json(q.target_relative_error)},
            {"time_limit_s", optional_number_json(q.time_limit_s)}};
  if (q.adaptive) j["adaptive"] = true;
  return j;
}

}  // namespace

RenderRequest parse_render_request(std::string_view json_text) {
  return guarded([&] {
    Errors errors;
    const Json body = parse_json_object(json_text, errors);
    return read_render_request(body, errors);
  });
}

RenderRequest parse_render_request(const nlohmann::json& body) {
  return guarded([&] {
    Errors errors;
    return read_render_request(body, errors);
  });
}

nlohmann::json to_canonical_json(const RenderRequest& r) {
  Json j = {{"location", location_json(r.location)},
          {"time", time_json(r.time)},
          {"sun", sun_json(r.sun)},
          {"camera", camera_json(r.camera)},
          {"atmosphere", atmosphere_json(r.atmosphere)},
          {"spectral",
           {{"min_nm", canonical_number(r.spectral.min_nm)},
            {"max_nm", canonical_number(r.spectral.max_nm)},
            {"batches", r.spectral.batches}}},
          {"quality", quality_json(r.quality)},
          {"method", std::string(name_of(kMethods, r.method))},
          {"output", output_json(r.output)},
          {"seed", r.seed},
          {"priority", r.priority}};
  // Written only when there are objects: requests without keep their text.
  if (!r.objects.empty()) j["objects"] = objects_json(r.objects);
  // Likewise clouds: a clear-sky request keeps its text (its hash, its cache).
  if (!r.clouds.empty()) j["clouds"] = clouds_json(r.clouds);
  return j;
}

std::string canonical_text(const RenderRequest& request) { return to_canonical_json(request).dump(); }

}  // namespace skyfarm::api
