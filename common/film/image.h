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
// constructor sets kSoftwareVersion; the keys below are the ones the server
// fills (any other key is allowed).
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

// Well-known metadata keys.
namespace metadata_key {
inline constexpr const char kRequest[] = "request";                  // canonical request JSON
inline constexpr const char kSunZenithDeg[] = "sun_zenith_deg";
inline constexpr const char kSunAzimuthDeg[] = "sun_azimuth_deg";
inline constexpr const char kSamplesPerPixel[] = "samples_per_pixel";
inline constexpr const char kWavelengthMinNm[] = "wavelength_min_nm";
inline constexpr const char kWavelengthMaxNm[] = "wavelength_max_nm";
inline constexpr const char kSoftwareVersion[] = "software_version";
inline constexpr const char kEstimatedRelativeRms[] = "estimated_relative_rms";
// Per linear sRGB channel (error_estimate.h).
inline constexpr const char kEstimatedRelativeRmsR[] = "estimated_relative_rms_r";
inline constexpr const char kEstimatedRelativeRmsG[] = "estimated_relative_rms_g";
inline constexpr const char kEstimatedRelativeRmsB[] = "estimated_relative_rms_b";
}  // namespace metadata_key

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
