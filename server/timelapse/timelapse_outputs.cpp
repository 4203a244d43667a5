#include "server/timelapse/timelapse_outputs.h"

#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "common/film/image.h"
#include "common/image/exr_writer.h"
#include "common/image/png_writer.h"
#include "server/timelapse/timelapse_contact_sheet.h"
#include "server/timelapse/timelapse_exposure.h"
#include "server/timelapse/timelapse_video.h"

namespace skyfarm::server {
namespace {

namespace fs = std::filesystem;

// A frame's linear RGB and skyfarm:* metadata from its EXR.
Image load_frame(const fs::path& exr_path) {
  const ExrFile exr = read_exr(exr_path);
  const auto r = exr.channels.find("R"), g = exr.channels.find("G"), b = exr.channels.find("B");
  if (r == exr.channels.end() || g == exr.channels.end() || b == exr.channels.end())
    throw std::runtime_error(exr_path.string() + " has no R, G, B channels");
  const std::size_t n = static_cast<std::size_t>(exr.width) * static_cast<std::size_t>(exr.height);
  std::vector<float> rgb(3 * n);
  for (std::size_t i = 0; i < n; ++i) {
    rgb[3 * i] = r->second.values[i];
    rgb[3 * i + 1] = g->second.values[i];
    rgb[3 * i + 2] = b->second.values[i];
  }
  // A frame written in another colour space or other units (output.color_space,
  // output.units) back to linear Rec.709 in cd/m^2, what the PNG expects.
  const std::string prefix = kExrMetadataPrefix;
  const std::string color_space_key = prefix + metadata_key::kColorSpace, units_key = prefix + metadata_key::kUnits,
                    units_scale_key = prefix + metadata_key::kUnitsScale;
  if (const auto it = exr.string_attributes.find(color_space_key); it != exr.string_attributes.end()) {
    const std::optional<ColorSpace> space = color_space_named(it->second);
    if (!space) throw std::runtime_error(exr_path.string() + ": unknown colour space '" + it->second + "'");
    convert_color_space(*space, ColorSpace::kLinRec709, rgb.data(), n);
  }
  double to_cd_m2 = 1.0;
  if (const auto it = exr.number_attributes.find(units_scale_key); it != exr.number_attributes.end()) {
    if (!(it->second > 0.0) || !std::isfinite(it->second))
      throw std::runtime_error(exr_path.string() + ": bad " + units_scale_key);
    to_cd_m2 = 1.0 / it->second;
  }
  Image image(exr.width, exr.height);
  for (int y = 0; y < exr.height; ++y)
    for (int x = 0; x < exr.width; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * static_cast<std::size_t>(exr.width) + static_cast<std::size_t>(x);
      image.set_rgb(x, y, Rgb{to_cd_m2 * rgb[3 * i], to_cd_m2 * rgb[3 * i + 1], to_cd_m2 * rgb[3 * i + 2]});
    }
  for (const auto& [key, value] : exr.string_attributes)
    if (key.starts_with(prefix) && key != color_space_key && key != units_key)
      image.set_metadata(key.substr(prefix.size()), value);
  for (const auto& [key, value] : exr.number_attributes)
    if (key.starts_with(prefix) && key != units_scale_key) image.set_metadata(key.substr(prefix.size()), value);
  return image;
}

// Every frame's EV100: fixed, or automatic and smoothed in time.
std::vector<double> frame_exposures(const std::vector<FrameInput>& frames, const OutputSettings& settings,
                                    const std::atomic<bool>& stop) {
  if (settings.fixed_ev100) return std::vector<double>(frames.size(), *settings.fixed_ev100);
  std::vector<double> metered;
  for (const FrameInput& f : frames) {
    if (stop) return {};
    metered.push_back(auto_exposure_ev(load_frame(f.exr)));
  }
  return smoothed_exposure(metered, settings.smoothing_frames);
}

}  // namespace

fs::path frame_png_path(const fs::path& dir, int index) {
  char name[32];
  std::snprintf(name, sizeof name, "frame_%05d.png", index);
  return dir / "frames" / name;
}

OutputsReport build_timelapse_outputs(const std::vector<FrameInput>& frames, const OutputSettings& settings,
                                      const fs::path& dir, const std::atomic<bool>& stop) {
  OutputsReport report;
  if (frames.empty()) throw std::runtime_error("a timelapse without frames");
  report.ev100 = frame_exposures(frames, settings, stop);
  if (stop) {
    report.stopped = true;
    return report;
  }
  std::error_code ec;
  fs::create_directories(dir / "frames", ec);
  if (ec) throw FileWriteError("cannot create " + (dir / "frames").string() + ": " + ec.message());
  std::optional<ContactSheet> sheet;
  for (std::size_t i = 0; i < frames.size(); ++i) {
    if (stop) {
      report.stopped = true;
      return report;
    }
    Image image = load_frame(frames[i].exr);
    image.set_metadata(metadata_key::kTimelapseFrameIndex, static_cast<double>(i));
    image.set_metadata(metadata_key::kTimelapseFrameTime, frames[i].label);
    PngWriteOptions png;
    png.exposure_ev = report.ev100[i];
    png.view = settings.view;
    write_png(image, frame_png_path(dir, static_cast<int>(i)), png);
    if (!sheet) sheet.emplace(static_cast<int>(frames.size()), image.width(), image.height());
    sheet->add(static_cast<int>(i), image, report.ev100[i], frames[i].label);
  }
  sheet->write(dir / "contact_sheet.png");

  const FfmpegLookup ffmpeg = find_ffmpeg(settings.ffmpeg);
  if (!ffmpeg.path) {
    report.video_reason = ffmpeg.reason;
    return report;
  }
  const VideoResult video = encode_video(*ffmpeg.path, dir / "frames", settings.fps, dir / "video.mp4",
                                         dir / "ffmpeg.log", settings.ffmpeg_timeout, stop);
  if (stop && !video.available) {
    report.stopped = true;
    return report;
  }
  report.video = video.available;
  report.video_reason = video.reason;
  return report;
}

}  // namespace skyfarm::server
