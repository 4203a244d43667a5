// OpenEXR output of an Image (absolute units, Rec.709/D65,
// optional spectral channels after the published spectral-OpenEXR layout),
// and a reader for tests and tools.
//
// Parameters (ExrWriteOptions)
//   half               R, G, B as HALF (default) or FLOAT.  HALF holds at
//                      most 65504 cd/m²: larger values (the sun's disk,
//                      ~1e9 cd/m²) are clamped to ±65504 and counted
//                      (ExrWriteReport, attribute skyfarm:half_clamped_values);
//                      ask for FLOAT to keep the disk's absolute radiance.
//   spectral_channels  write the image's spectral channels (if it has them)
//   error_layer        write the image's relative-error layer (if it has it)
//   compression        kZip (default; lossless), kPiz (lossless), kNone
//   latlong_envmap     set the standard `envmap` attribute to LATLONG; only
//                      for an equirectangular image laid out as OpenEXR's
//                      lat-long convention expects (the caller knows)
//   color_space        ColorSpace of R, G, B (color_management.h): lin_rec709
//                      (default: the image's RGB as it is), acescg,
//                      aces2065-1, cie_xyz; converted at write time
//   units              RadiometricUnits of R, G, B: cd_m2 (default), relative
//                      (times the PNG's exposure scale 0.18 · 2^(3 − EV100)),
//                      w_m2_sr (cd/m² / 683); spectral channels keep theirs
//   exposure_ev        EV100 of the relative units; std::nullopt (default) =
//                      automatic, as the PNG's (auto_exposure_ev, median)
//
// The file (scan lines, top row first, data window = display window =
// [0, width − 1] × [0, height − 1]):
//   channels
//     R, G, B            linear Rec.709 in cd/m² (HALF or FLOAT); or the
//                        color_space and units asked for
//     S0.<λ>nm           one per spectral band, FLOAT: the band's mean
//                        spectral radiance, W m⁻² sr⁻¹ nm⁻¹, named by the band
//                        centre λ with six decimals and ',' as the decimal
//                        separator, e.g. "S0.536,250000nm" (spectral_channel_name)
//     error.Y            FLOAT: relative standard error of the luminance,
//                        sqrt(Var[Y]) / Y (dimensionless); +inf = unknown
//   attributes
//     chromaticities     Rec.709 primaries, D65 white (0.3127, 0.3290); or
//                        those of the color_space (chromaticities_of)
//     whiteLuminance     1.0: RGB (1, 1, 1) is 1 cd/m² (OpenEXR's meaning:
//                        "the luminance, in nits, of the RGB value (1, 1, 1)");
//                        1 / units_scale in other units
//     skyfarm:color_space  (string, only when not lin_rec709)
//     skyfarm:units, skyfarm:units_scale  (string; double, the factor that
//                        turned cd/m² into the values: only when not cd_m2)
//     spectralLayoutVersion = "1.0", emissiveUnits = "W.m^-2.sr^-1"
//                        (only with spectral channels; see below)
//     skyfarm:<key>      each Image metadata entry: a string as a string
//                        attribute, a number as a double attribute
//     skyfarm:spectral_band_edges_nm  (string "e0,e1,…,eB", with spectral channels)
//     skyfarm:error.Y    (string, what the error channel means, with it)
//     skyfarm:half_clamped_values     (double, with HALF RGB)
//     envmap             (LATLONG, when asked)
//
// Spectral layout.  Fichet, Pacanowski, Wilkie (2021), "An OpenEXR Layout for
// Spectral Images", JCGT 10(3), http://jcgt.org/published/0010/03/01/, and its
// reference implementation (github.com/afichet/spectral-exr,
// EXRSpectralImage::getEmissiveChannelName): an emissive, unpolarised
// spectrum is stored as channels "S0." + the wavelength with ',' for the
// decimal point + a unit ("nm"), next to a regular RGB preview, with the
// string attributes spectralLayoutVersion = "1.0" and emissiveUnits =
// "W.m^-2.sr^-1".  The reference reader accepts only that units string, and
// pbrt-v4's SpectralFilm writes the same string for per-nm spectral radiance
// values, so the channels hold W m⁻² sr⁻¹ nm⁻¹ under that label.
//
// Writing is atomic (AtomicFile: path + ".tmp", then rename); every failure
// throws FileWriteError naming the path, and leaves no file at path.
#pragma once
#include <array>
#include <cstddef>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "common/film/image.h"
#include "common/image/atomic_file.h"
#include "common/image/color_management.h"

namespace skyfarm {

enum class ExrCompression { kNone, kZip, kPiz };

struct ExrWriteOptions {
  bool half = true;
  bool spectral_channels = true;
  bool error_layer = true;
  ExrCompression compression = ExrCompression::kZip;
  bool latlong_envmap = false;
  ColorSpace color_space = ColorSpace::kLinRec709;
  RadiometricUnits units = RadiometricUnits::kCdM2;
  std::optional<double> exposure_ev = std::nullopt;
};

struct ExrWriteReport {
  // R, G, B values outside ±65504 clamped for HALF output.
  std::size_t clamped_half_values = 0;
};

inline constexpr const char* kExrMetadataPrefix = kMetadataPrefix;  // image.h
inline constexpr char kExrErrorChannel[] = "error.Y";
inline constexpr char kSpectralLayoutVersion[] = "1.0";
inline constexpr char kSpectralEmissiveUnits[] = "W.m^-2.sr^-1";
inline constexpr float kHalfMax = 65504.0f;

// "S0.<λ with six decimals, ',' as decimal separator>nm", locale-independent;
// e.g. 536.25 → "S0.536,250000nm".
std::string spectral_channel_name(double wavelength_nm);

ExrWriteReport write_exr(const Image& image, const std::filesystem::path& path, const ExrWriteOptions& options = {});

// --- Reading (tests and tools) ---------------------------------------------
enum class ExrPixelType { kHalf, kFloat, kUint };

struct ExrChannel {
  ExrPixelType type;          // as stored in the file
  std::vector<float> values;  // width × height, row-major, top row first
};

struct ExrFile {
  int width = 0, height = 0;
  std::map<std::string, ExrChannel> channels;
  std::map<std::string, std::string> string_attributes;
  std::map<std::string, double> number_attributes;  // float, double and int attributes
  // red, green, blue, white: (x, y) each.
  std::optional<std::array<Chromaticity, 4>> chromaticities;
};

// Reads every channel as float and the string, number and chromaticities
// attributes.  Throws std::runtime_error naming the path on failure.
ExrFile read_exr(const std::filesystem::path& path);

}  // namespace skyfarm
