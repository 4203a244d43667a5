// The render request: parsing with field-named validation errors
// and the canonical form the farm hashes.  Field by field rules:
// docs/request-schema.md.
#pragma once
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "api/field_error.h"
#include "api/json_fields.h"
#include "common/atmosphere/atmosphere_spec.h"
#include "common/camera/camera_spec.h"
#include "common/clouds/cloud_spec.h"
#include "common/image/color_management.h"
#include "common/objects/object_spec.h"
#include "common/sun/sun_spec.h"
#include "common/sun/utc_time.h"

namespace skyfarm::api {

// "spectral": the wavelength range rendered and how many batches it is cut into.
// One batch by default: each path then carries its 4 wavelengths across the
// whole range, importance-sampled for the eye, so one path estimates every
// colour.  Cut into B batches, a pixel needs B paths for one estimate of the
// whole spectrum, and the noise of paths in different batches adds: measured
// on a noon 128x64 equirect with the same 2^20 paths, 4 batches gave 4.58 %
// relative RMS error and 1 batch 2.88 %, 2.9x the efficiency
// (docs/experiments/2026-11-22-path-tracer-variance.md).  More batches are for spectral EXR channels (one per batch).
struct SpectralSpec {
  double min_nm = 360.0;
  double max_nm = 830.0;
  int batches = 1;
};

// "quality": when a render stops (whichever comes first).  Without
// samples_per_pixel, a request that gives a target error or a time limit has
// no sample cap below kMaxSamplesPerPixel ("1 % in at most 2 minutes" runs
// until one of those); one that gives neither gets 64.
struct QualitySpec {
  static constexpr int kDefaultSamplesPerPixel = 64;
  static constexpr int kMaxSamplesPerPixel = 1048576;
  int samples_per_pixel = kDefaultSamplesPerPixel;
  std::optional<double> target_relative_error;  // image relative RMS error
  std::optional<double> time_limit_s;
  // Variance-aware sample allocation after a uniform pilot pass
  // (common/render/sample_allocation.h); path-traced renders only.
  bool adaptive = false;
};

// "output": what the result files carry.
struct OutputSpec {
  std::optional<double> exposure_ev;  // PNG exposure; none = automatic
  bool spectral_channels = false;     // one EXR channel per wavelength batch
  bool error_layer = false;           // relative standard error per pixel
  bool half = true;                   // EXR half floats (else 32-bit floats)
  // Colour management at write time (common/image/color_management.h).
  ColorSpace color_space = ColorSpace::kLinRec709;  // EXR RGB primaries
  RadiometricUnits units = RadiometricUnits::kCdM2;  // EXR RGB units
  DisplayView view = DisplayView::kSrgb;             // PNG view
};

// A validated render request, every default filled in.
struct RenderRequest {
  Location location;
  std::optional<UtcInstant> time;
  std::optional<std::string> time_text;  // "time" as the client wrote it
  SunSpec sun;
  CameraSpec camera;
  AtmosphereSpec atmosphere;
  std::vector<ObjectSpec> objects;  // api/object_fields.h
  CloudsSpec clouds;                // api/cloud_fields.h; empty: a clear sky
  SpectralSpec spectral;
  QualitySpec quality;
  Method method = Method::kPath;
  OutputSpec output;
  std::uint64_t seed = 1;
  int priority = 50;
  // A label (api/job_name.h), never in the canonical request: it does not
  // change what is rendered, so it changes neither the hash nor the EXR.
  std::optional<std::string> name;
};

// Parses and validates a request body.  Throws ValidationError listing every
// invalid field; no other exception escapes, whatever the input.
RenderRequest parse_render_request(std::string_view json_text);
RenderRequest parse_render_request(const nlohmann::json& body);
inline RenderRequest parse_render_request(const std::string& json_text) {
  return parse_render_request(std::string_view(json_text));
}
inline RenderRequest parse_render_request(const char* json_text) {
  return parse_render_request(std::string_view(json_text));
}

// Every field with its default filled in and equivalent spellings unified
// (docs/request-schema.md "Canonical form"): requests that mean the same give
// the same to_canonical_json(r).dump(); parsing it gives the same request back
// (but for "name", which is left out: it labels a render, it is not rendered).
nlohmann::json to_canonical_json(const RenderRequest& request);
// to_canonical_json(request).dump(): the text the farm hashes.
std::string canonical_text(const RenderRequest& request);

}  // namespace skyfarm::api
