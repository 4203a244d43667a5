// A timelapse's video: its frame PNGs encoded by ffmpeg (the Debian package),
// run as a subprocess with an argument vector (no shell).
//
// Parameters
//   ffmpeg (find_ffmpeg)   the server's --ffmpeg / SKYFARM_FFMPEG: a path
//                          (must be an executable file), a bare name looked
//                          up on PATH, or "" for "ffmpeg" on PATH
//   frames_dir             frame_00000.png, frame_00001.png, ... (frame order)
//   fps                    frames per second of the video
//   out                    the MP4; written as out's stem + ".tmp.mp4" first,
//                          renamed onto `out` only when ffmpeg succeeded
//   log                    ffmpeg's stdout and stderr (the reason on failure)
//   timeout, stop          ffmpeg is killed (SIGKILL) past the timeout or as
//                          soon as *stop is true (server shutdown)
// The command: ffmpeg -nostdin -hide_banner -loglevel error -y -framerate FPS
//   -start_number 0 -i frames_dir/frame_%05d.png -vf pad=ceil(iw/2)*2:ceil(ih/2)*2
//   -c:v libx264 -pix_fmt yuv420p -movflags +faststart OUT.tmp.mp4
// i.e. H.264 in yuv420p, which needs even dimensions: an odd side gets one
// black row or column.
#pragma once
#include <atomic>
#include <chrono>
#include <filesystem>
#include <optional>
#include <string>

namespace skyfarm::server {

struct FfmpegLookup {
  std::optional<std::filesystem::path> path;  // found
  std::string reason;                         // why not, when not found
};

FfmpegLookup find_ffmpeg(const std::string& configured);

struct VideoResult {
  bool available = false;
  std::string reason;  // when not available
};

VideoResult encode_video(const std::filesystem::path& ffmpeg, const std::filesystem::path& frames_dir, int fps,
                         const std::filesystem::path& out, const std::filesystem::path& log,
                         std::chrono::seconds timeout, const std::atomic<bool>& stop);

}  // namespace skyfarm::server
