// Finding ffmpeg and encoding a timelapse video with it: a real H.264 MP4 from
// frame PNGs when ffmpeg is installed, clear reasons when it is missing or
// fails, and no half-written video left behind.
#include "server/timelapse/timelapse_video.h"

#include <gtest/gtest.h>

#include <unistd.h>

#include <fstream>

#include "common/film/image.h"
#include "common/image/png_writer.h"

namespace skyfarm::server {
namespace {

namespace fs = std::filesystem;

fs::path fresh_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("skyfarm_video_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

// n frame PNGs of w x h under dir, each a different grey.
void write_frames(const fs::path& dir, int n, int w, int h) {
  for (int i = 0; i < n; ++i) {
    Image image(w, h);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) image.set_rgb(x, y, Rgb{0.1 + 0.2 * i, 0.2, 0.3});
    char name[32];
    std::snprintf(name, sizeof name, "frame_%05d.png", i);
    PngWriteOptions o;
    o.exposure_ev = 3.0;
    write_png(image, dir / name, o);
  }
}

std::string head(const fs::path& p, std::size_t n) {
  std::ifstream in(p, std::ios::binary);
  std::string s(n, '\0');
  in.read(s.data(), static_cast<std::streamsize>(n));
  s.resize(static_cast<std::size_t>(in.gcount()));
  return s;
}

TEST(TimelapseVideo, FindsFfmpegOrSaysWhyNot) {
  const FfmpegLookup bogus = find_ffmpeg("/nonexistent/ffmpeg");
  EXPECT_FALSE(bogus.path);
  EXPECT_NE(bogus.reason.find("/nonexistent/ffmpeg"), std::string::npos) << bogus.reason;
  const FfmpegLookup unknown = find_ffmpeg("skyfarm-no-such-encoder");
  EXPECT_FALSE(unknown.path);
  EXPECT_NE(unknown.reason.find("PATH"), std::string::npos) << unknown.reason;
  const FfmpegLookup by_path = find_ffmpeg("/bin/sh");
  ASSERT_TRUE(by_path.path);
  EXPECT_EQ(*by_path.path, fs::path("/bin/sh"));
}

TEST(TimelapseVideo, EncodesH264FromTheFramePngs) {
  const FfmpegLookup ffmpeg = find_ffmpeg("");
  if (!ffmpeg.path) GTEST_SKIP() << "ffmpeg is not installed here (" << ffmpeg.reason << "): no video to check";
  const fs::path dir = fresh_dir("encode");
  write_frames(dir, 3, 15, 7);  // odd sides: padded to even for yuv420p
  const std::atomic<bool> stop{false};
  const VideoResult r = encode_video(*ffmpeg.path, dir, 24, dir / "video.mp4", dir / "ffmpeg.log",
                                     std::chrono::seconds(60), stop);
  ASSERT_TRUE(r.available) << r.reason;
  EXPECT_EQ(head(dir / "video.mp4", 8).substr(4), "ftyp") << "an ISO base media (MP4) file";
  EXPECT_FALSE(fs::exists(dir / "video.tmp.mp4"));
  // ffprobe comes with ffmpeg: the stream is H.264, yuv420p, 16 x 8, 3 frames.
  const fs::path ffprobe = ffmpeg.path->parent_path() / "ffprobe";
  if (fs::exists(ffprobe)) {
    const std::string cmd = ffprobe.string() +
                            " -v error -select_streams v:0 -count_frames -show_entries "
                            "stream=codec_name,pix_fmt,width,height,nb_read_frames -of csv=p=0 " +
                            (dir / "video.mp4").string() + " > " + (dir / "probe.txt").string();
    ASSERT_EQ(std::system(cmd.c_str()), 0);
    std::ifstream in(dir / "probe.txt");
    std::string line;
    std::getline(in, line);
    EXPECT_EQ(line, "h264,16,8,yuv420p,3");
  }
}

TEST(TimelapseVideo, AFailingFfmpegGivesItsReasonAndNoFile) {
  const fs::path dir = fresh_dir("fail");
  const fs::path fake = dir / "fake-ffmpeg";
  std::ofstream(fake) << "#!/bin/sh\necho 'Unknown encoder libx264' >&2\nexit 3\n";
  fs::permissions(fake, fs::perms::owner_all);
  const std::atomic<bool> stop{false};
  const VideoResult r = encode_video(fake, dir, 24, dir / "video.mp4", dir / "ffmpeg.log", std::chrono::seconds(30), stop);
  EXPECT_FALSE(r.available);
  EXPECT_EQ(r.reason, "ffmpeg exited with status 3: Unknown encoder libx264");
  EXPECT_FALSE(fs::exists(dir / "video.mp4"));
  const VideoResult missing = encode_video(dir / "absent", dir, 24, dir / "video.mp4", dir / "ffmpeg.log",
                                           std::chrono::seconds(30), stop);
  EXPECT_FALSE(missing.available);
  EXPECT_NE(missing.reason.find("cannot run ffmpeg"), std::string::npos) << missing.reason;
}

TEST(TimelapseVideo, AStuckFfmpegIsStopped) {
  const fs::path dir = fresh_dir("stuck");
  const fs::path fake = dir / "fake-ffmpeg";
  std::ofstream(fake) << "#!/bin/sh\nexec sleep 30\n";
  fs::permissions(fake, fs::perms::owner_all);
  const std::atomic<bool> stop{true};  // the server is stopping
  const VideoResult r = encode_video(fake, dir, 24, dir / "video.mp4", dir / "ffmpeg.log", std::chrono::seconds(30), stop);
  EXPECT_FALSE(r.available);
  EXPECT_NE(r.reason.find("stopped"), std::string::npos) << r.reason;
}

}  // namespace
}  // namespace skyfarm::server
