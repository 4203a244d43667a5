// What a timelapse makes once every frame is done, written under its folder
// <data-dir>/timelapses/<id>/ (each file atomically: readers see the old file
// or the complete new one):
//   frames/frame_00000.png ...  each frame's EXR exposed at its EV100
//                               (png_writer.h), with the EXR's skyfarm:*
//                               metadata; the video's input
//   contact_sheet.png           timelapse_contact_sheet.h
//   video.mp4                   timelapse_video.h (when ffmpeg can be run)
//   ffmpeg.log                  what ffmpeg said
//
// Parameters (OutputSettings)
//   fixed_ev100        output.exposure_ev of the request: every frame at that
//                      EV100; none: each frame's automatic EV100 smoothed over
//                      smoothing_frames frames (timelapse_exposure.h)
//   smoothing_frames   odd, >= 1
//   view               output.view of the request: the frames' PNG view
//                      (color_management.h; the contact sheet stays srgb)
//   fps                the video's frame rate
//   ffmpeg             the server's --ffmpeg (find_ffmpeg); looked up here, so
//                      an ffmpeg installed while the server runs is used
//   ffmpeg_timeout     ffmpeg is stopped after this long
// Every frame EXR is read twice when the exposure is automatic (once to
// meter, once to write), so memory holds one frame and the sheet.
#pragma once
#include <atomic>
#include <chrono>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "common/image/color_management.h"

namespace skyfarm::server {

struct FrameInput {
  std::filesystem::path exr;  // the frame's final EXR (its render's image.exr)
  std::string label;          // its time, drawn under its thumbnail
};

struct OutputSettings {
  std::optional<double> fixed_ev100;
  int smoothing_frames = 5;
  DisplayView view = DisplayView::kSrgb;
  int fps = 24;
  std::string ffmpeg;
  std::chrono::seconds ffmpeg_timeout{600};
};

struct OutputsReport {
  bool stopped = false;        // *stop became true: the outputs are incomplete
  std::vector<double> ev100;   // per frame
  bool video = false;
  std::string video_reason;    // when there is no video
};

// The frame PNG of frame i under `dir`.
std::filesystem::path frame_png_path(const std::filesystem::path& dir, int index);

// Throws std::runtime_error when a frame EXR cannot be read, FileWriteError
// when an output cannot be written.  A missing or failing ffmpeg is not an
// error: the report says why there is no video.
OutputsReport build_timelapse_outputs(const std::vector<FrameInput>& frames, const OutputSettings& settings,
                                      const std::filesystem::path& dir, const std::atomic<bool>& stop);

}  // namespace skyfarm::server
