// PNG output of an Image: a display-referred sRGB preview of the absolute
// linear RGB, via libpng; 8-bit display-space pixels as they are
// (write_png_rgb8); and a reader for tests and tools.
//
// Parameters (PngWriteOptions)
//   exposure_ev      EV100, the photographic exposure value at ISO 100
//                    (below); std::nullopt (default) = automatic
//   auto_percentile  which luminance percentile the automatic exposure meters,
//                    in (0, 1); default 0.5 (the median)
//   bit_depth        8 (default) or 16 bits per channel
//   view             DisplayView (color_management.h): srgb (default; the
//                    clip below) or aces (ACES 1.0 SDR output transform after
//                    the exposure, instead of the clip and the sRGB curve)
//
// Exposure convention (a reflected-light meter, ISO 2720:1974, calibration
// constant K = 12.5 cd/m²).  A camera at ISO S meters a luminance L as
// EV = log2(L S / K); at ISO 100, EV100 = log2(8 L).  Exposing at EV100 maps
// the metered luminance L_m = 2^EV100 / 8 cd/m² to middle grey, 18 % linear:
//
//     scale = 0.18 / L_m = 0.18 · 2^(3 − EV100)          (exposure_scale)
//
// so one EV more halves the brightness, and the numbers are the ones a
// photographer knows: EV100 ≈ 15 for a sunny day (L_m = 4096 cd/m²; "sunny
// 16"), ≈ 12 for an overcast sky.
// Automatic exposure (auto_exposure_ev): L_m = the auto_percentile-th
// percentile of the pixel luminances that are > 0 and finite (pixels with no
// samples, or outside a fisheye circle, are 0 and ignored), so EV100 =
// log2(8 L_m).  A percentile does not care how bright the few sun-disk pixels
// are, unlike a mean (and even unlike a log-average when the disk is large
// on a small image).  Images of more than 2^20 pixels are metered on a
// regular subsample (every k-th pixel).  No lit pixel: EV100 = 0.
//
// Encoding: each linear component v → clamp(scale · v, 0, 1) (a hard clip:
// the sun and out-of-gamut negatives clip; no tone curve) → sRGB transfer
// (srgb_encode, IEC 61966-2-1) → round(· (2^bits − 1)).  The file is RGB
// (colour type 2), non-interlaced, with an sRGB chunk (perceptual intent) and
// the matching gAMA and cHRM, and iTXt text chunks:
//   skyfarm:<key>            each Image metadata entry (numbers in shortest
//                            round-trip decimal)
//   skyfarm:exposure_ev100   the EV100 used;  skyfarm:exposure_scale  the scale
//   skyfarm:view             the view, when not srgb
// Keys are restricted to PNG's keyword rules (1–79 Latin-1 characters):
// other characters become '_', longer keys are cut.
//
// Writing is atomic (AtomicFile: path + ".tmp", then rename); every failure
// throws FileWriteError naming the path, and leaves no file at path.
#pragma once
#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "common/film/image.h"
#include "common/image/atomic_file.h"
#include "common/image/color_management.h"

namespace skyfarm {

struct PngWriteOptions {
  std::optional<double> exposure_ev;
  double auto_percentile = 0.5;
  int bit_depth = 8;
  DisplayView view = DisplayView::kSrgb;
};

struct PngWriteReport {
  double exposure_ev;  // EV100 used
  double scale;        // exposure_scale(exposure_ev)
};

// Middle grey of the reflected-light-meter convention above (linear).
inline constexpr double kMiddleGrey = 0.18;

// scale = 0.18 · 2^(3 − EV100): display value per cd/m².
double exposure_scale(double ev100);
// EV100 metering the percentile-th luminance of the lit pixels (above).
// Throws std::invalid_argument unless 0 < percentile < 1.
double auto_exposure_ev(const Image& image, double percentile = 0.5);

// Throws std::invalid_argument for bad options, FileWriteError if the file
// cannot be written.
PngWriteReport write_png(const Image& image, const std::filesystem::path& path, const PngWriteOptions& options = {});

// Writes 8-bit sRGB-encoded pixels as they are (interleaved RGB, top row
// first; width * height * 3 bytes), with the same chunks as write_png and
// `text` as iTXt chunks: for images drawn in display space (contact sheets).
// Throws std::invalid_argument for a size mismatch, FileWriteError if the
// file cannot be written.
void write_png_rgb8(const std::filesystem::path& path, int width, int height, const std::vector<std::uint8_t>& rgb,
                    const std::map<std::string, std::string>& text = {});

// --- Reading (tests and tools) ---------------------------------------------
struct PngFile {
  int width = 0, height = 0;
  int bit_depth = 0;                 // 8 or 16
  std::vector<std::uint16_t> rgb;    // encoded values as stored, interleaved RGB, top row first
  std::map<std::string, std::string> text;
  bool has_srgb_chunk = false;
};

// Reads an RGB (or grey / palette / with alpha: converted to RGB) PNG.
// Throws std::runtime_error naming the path on failure.
PngFile read_png(const std::filesystem::path& path);

}  // namespace skyfarm
