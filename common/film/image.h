// Image: the resolved picture the server serves and the writers encode —
// float buffers only (a 4096 × 2048 RGB image is 100 MB in float; per-pixel
// sums are never kept for the whole image, see FilmTile).
//
// Parameters
//   width, height     pixels (1 … kMaxDimension); row 0 is the TOP row, as in
//                     the camera's film and the EXR scan lines
//   layers.spectral   optional SpectralLayout {min_nm, max_nm, batches}: one
//                     extra channel per wavelength batch holding the band's
//                     mean spectral radiance (1/Δλ_b) ∫_band L dλ,
//                     W m⁻² sr⁻¹ nm⁻¹; band b covers batch_range(min, max, b, B)
//   layers.relative_error
//                     optional layer: the relative standard error of each
//                     pixel's luminance, sqrt(Var[Ȳ]) / Ȳ (dimensionless)
//
// Buffers
//   rgb     linear Rec.709/sRGB (D65) in ABSOLUTE units: computed from the mean
//           XYZ (Y in cd/m², K_m = 683 lm/W) with kXyzToLinearSrgb, so R = G =
//           B = Y for a D65-white pixel.  Out-of-gamut colours keep their
//           negative components (scene-linear data; the PNG writer clamps).
//           Interleaved R, G, B, row-major.
//   spectral  planar: channel b is width × height floats.
//   error   width × height floats; kUnknownError (+∞) where a pixel has no
//           estimate yet (fewer than 2 samples in some batch) or no meaningful
//           relative error (FilmTile::relative_standard_error is nullopt).
// A pixel that resolve() finds without a mean (some batch has no sample) gets
// RGB 0 and error kUnknownError; a band without samples gets 0.
//
// Metadata: string → string or number, written by the EXR writer as
// "skyfarm:<key>" attributes and by the PNG writer as text chunks.  The
// constructor sets kSoftwareVersion (software_version_text()); the keys below
// are the project's vocabulary (docs/exr-metadata.md).
#pragma once
#include <array>
#include <cstddef>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "common/film/film_tile.h"
#include "common/spectrum/color.h"

namespace skyfarm {

struct SpectralLayout {
  double min_nm;
  double max_nm;
  int batches;
};

struct ImageLayers {
  std::optional<SpectralLayout> spectral;
  bool relative_error = false;
};

using MetadataValue = std::variant<std::string, double>;

// The metadata vocabulary: every key any skyfarm output writes, one name per
// quantity.  docs/exr-metadata.md lists them with their types, units and
// which outputs carry them (renders, sky env maps, timelapse frames, the
// worker's local `render`); tests/farm/farm_exr_metadata_test.cpp checks the
// files against that list.  Call sites use these constants, never literals.
namespace metadata_key {
// --- Every image (a render, an env map, a frame) ---------------------------
inline constexpr const char kRequest[] = "request";                  // canonical request JSON
inline constexpr const char kSunZenithDeg[] = "sun_zenith_deg";
inline constexpr const char kSunAzimuthDeg[] = "sun_azimuth_deg";
inline constexpr const char kWavelengthMinNm[] = "wavelength_min_nm";
inline constexpr const char kWavelengthMaxNm[] = "wavelength_max_nm";
inline constexpr const char kSoftwareVersion[] = "software_version";  // software_version_text()
inline constexpr const char kMethod[] = "method";                     // "path" or "lut"
inline constexpr const char kEarthSunDistanceAu[] = "earth_sun_distance_au";
// --- Renders (farm and worker-local) ----------------------------------------
inline constexpr const char kSamplesPerPixel[] = "samples_per_pixel";
inline constexpr const char kEstimatedRelativeRms[] = "estimated_relative_rms";
// Per linear sRGB channel (error_estimate.h).
inline constexpr const char kEstimatedRelativeRmsR[] = "estimated_relative_rms_r";
inline constexpr const char kEstimatedRelativeRmsG[] = "estimated_relative_rms_g";
inline constexpr const char kEstimatedRelativeRmsB[] = "estimated_relative_rms_b";
// LUT renders and env maps: why the image is not the path tracer's.
inline constexpr const char kApproximate[] = "approximate";
// --- Sky env maps (/v1/sky/envmap.exr) ---------------------------------------
// Deprecated alias of kEarthSunDistanceAu, still written next to it: the
// API documented it before the vocabulary was one.
inline constexpr const char kSunEarthDistanceAuDeprecated[] = "sun_earth_distance_au";
inline constexpr const char kSunAngularRadiusDeg[] = "sun_angular_radius_deg";
inline constexpr const char kSunMode[] = "sun_mode";
inline constexpr const char kObserverAltitudeM[] = "observer_altitude_m";
inline constexpr const char kLayout[] = "layout";
inline constexpr const char kSunDiskX[] = "sun_disk_X";
inline constexpr const char kSunDiskY[] = "sun_disk_Y";
inline constexpr const char kSunDiskZ[] = "sun_disk_Z";
inline constexpr const char kSunDiskR[] = "sun_disk_R";
inline constexpr const char kSunDiskG[] = "sun_disk_G";
inline constexpr const char kSunDiskB[] = "sun_disk_B";
inline constexpr const char kSunDiskSolidAngleSr[] = "sun_disk_solid_angle_sr";
inline constexpr const char kSunDiskIlluminanceLux[] = "sun_disk_illuminance_lux";
inline constexpr const char kSunDirection[] = "sun_direction";
// --- Timelapse frame PNGs ------------------------------------------------------
inline constexpr const char kTimelapseFrameIndex[] = "timelapse_frame_index";
inline constexpr const char kTimelapseFrameTime[] = "timelapse_frame_time";
// The timelapse contact sheet PNG (no Image: its own two keys).
inline constexpr const char kContactSheetFrames[] = "contact_sheet_frames";
inline constexpr const char kContactSheetColumns[] = "contact_sheet_columns";
// --- Written by the file writers themselves (exr_writer.h, png_writer.h) -----
inline constexpr const char kHalfClampedValues[] = "half_clamped_values";
inline constexpr const char kSpectralBandEdgesNm[] = "spectral_band_edges_nm";
inline constexpr const char kErrorChannel[] = "error.Y";               // the error layer's description
inline constexpr const char kExposureEv100[] = "exposure_ev100";       // PNG only
inline constexpr const char kExposureScale[] = "exposure_scale";       // PNG only
// Colour management (color_management.h), each only when not the default:
inline constexpr const char kColorSpace[] = "color_space";  // EXR: not lin_rec709
inline constexpr const char kUnits[] = "units";              // EXR: not cd_m2
inline constexpr const char kUnitsScale[] = "units_scale";   // EXR: with kUnits; cd/m² × it = the values
inline constexpr const char kView[] = "view";                // PNG: not srgb
}  // namespace metadata_key

// Every key is written with this prefix: an EXR attribute "skyfarm:<key>",
// a PNG iTXt keyword "skyfarm:<key>" (standard attributes have none).
inline constexpr char kMetadataPrefix[] = "skyfarm:";

// kSoftwareVersion's value in every output: "skyfarm <version>".
std::string software_version_text();

class Image {
 public:
  static constexpr int kMaxDimension = 1 << 16;
  static constexpr float kUnknownError = std::numeric_limits<float>::infinity();

  // All pixels 0 (error layer: kUnknownError).  Throws std::invalid_argument
  // for a size outside [1, kMaxDimension] or a bad spectral layout
  // (min < max finite, 1 ≤ batches ≤ FilmTile::kMaxBatches).
  Image(int width, int height, ImageLayers layers = {});

  int width() const { return width_; }
  int height() const { return height_; }
  std::size_t pixel_count() const { return static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_); }

  // Writes the tile's pixels (the part inside the image; a tile must lie
  // inside it) from its sums: RGB = kXyzToLinearSrgb · mean XYZ, spectral
  // band means, relative errors.  Throws std::invalid_argument for a tile
  // outside the image, or whose batch count differs from the spectral
  // layout's when the image has spectral channels.
  void resolve(const FilmTile& tile);

  // --- RGB -------------------------------------------------------------------
  const std::vector<float>& rgb() const { return rgb_; }
  std::array<float, 3> rgb(int x, int y) const;
  void set_rgb(int x, int y, const Rgb& c);
  // Sets RGB = kXyzToLinearSrgb · xyz (absolute XYZ, cd/m²).
  void set_xyz(int x, int y, const Xyz& xyz);
  // Luminance of a pixel from its RGB, cd/m² (row 2 of kLinearSrgbToXyz:
  // 0.2126 R + 0.7152 G + 0.0722 B).
  double luminance(int x, int y) const;

  // --- Spectral channels -----------------------------------------------------
  bool has_spectral() const { return spectral_layout_.has_value(); }
  const std::optional<SpectralLayout>& spectral_layout() const { return spectral_layout_; }
  int spectral_batches() const { return spectral_layout_ ? spectral_layout_->batches : 0; }
  // Band b's centre wavelength (edge_b + edge_{b+1}) / 2, nm; and its edges.
  double band_center_nm(int b) const;
  WavelengthRange band_range(int b) const;
  // Channel b, width × height floats, row-major.  Throws std::logic_error
  // without spectral channels, std::out_of_range for a bad b.
  const float* spectral_channel(int b) const;
  float spectral(int x, int y, int b) const { return spectral_channel(b)[offset(x, y)]; }
  void set_spectral(int x, int y, int b, float band_mean_radiance);

  // --- Relative standard error -----------------------------------------------
  bool has_error_layer() const { return !error_.empty(); }
  // width × height floats (empty without the layer).
  const std::vector<float>& relative_error() const { return error_; }
  // nullopt where unknown (or without the layer).
  std::optional<float> relative_error(int x, int y) const;
  void set_relative_error(int x, int y, std::optional<double> e);

  // --- Metadata ----------------------------------------------------------------
  const std::map<std::string, MetadataValue>& metadata() const { return metadata_; }
  void set_metadata(const std::string& key, MetadataValue value) { metadata_[key] = std::move(value); }

 private:
  std::size_t offset(int x, int y) const;

  int width_, height_;
  std::optional<SpectralLayout> spectral_layout_;
  std::vector<float> rgb_;
  std::vector<float> spectral_;
  std::vector<float> error_;
  std::map<std::string, MetadataValue> metadata_;
};

}  // namespace skyfarm
