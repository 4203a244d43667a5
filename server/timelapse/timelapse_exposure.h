// One exposure for a timelapse's frames that does not pump from frame to
// frame: the automatic EV100 of each frame (png_writer.h
// auto_exposure_ev: the median luminance of its lit pixels) smoothed in time.
//
// Parameters
//   auto_ev100  per frame, in frame order
//   window      odd, >= 1: frame i gets the mean of frames i-k..i+k, k =
//               (window - 1) / 2, with k shrunk near the ends so that the
//               window stays centred (the first and last frames keep their
//               own EV).  A centred mean keeps a steady trend (the sky
//               darkening at sunset) exactly as it is, without lag or a bend
//               at the ends, and averages out frame-to-frame jitter (Monte
//               Carlo noise in the median).
#pragma once
#include <vector>

namespace skyfarm::server {

// Throws std::invalid_argument for an even or non-positive window.
std::vector<double> smoothed_exposure(const std::vector<double>& auto_ev100, int window);

}  // namespace skyfarm::server
