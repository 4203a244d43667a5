// skyfarm-server's timelapse flags: --ffmpeg / SKYFARM_FFMPEG and
// --max-timelapse-frames / SKYFARM_MAX_TIMELAPSE_FRAMES.
#include <gtest/gtest.h>

#include <cstdlib>

#include "server/server_options.h"

namespace skyfarm::server {
namespace {

TEST(TimelapseServerOptions, DefaultsFlagsAndEnvironment) {
  ServerOptions d;
  ASSERT_EQ(parse_server_options({}, &d), "");
  EXPECT_EQ(d.ffmpeg, "") << "ffmpeg on PATH";
  EXPECT_EQ(d.max_timelapse_frames, 1000);
  ::setenv("SKYFARM_FFMPEG", "/opt/ffmpeg/bin/ffmpeg", 1);
  ServerOptions e;
  ASSERT_EQ(parse_server_options({"--max-timelapse-frames", "50"}, &e), "");
  ::unsetenv("SKYFARM_FFMPEG");
  EXPECT_EQ(e.ffmpeg, "/opt/ffmpeg/bin/ffmpeg");
  EXPECT_EQ(e.max_timelapse_frames, 50);
  ServerOptions f;
  EXPECT_EQ(parse_server_options({"--max-timelapse-frames", "1"}, &f), "--max-timelapse-frames: invalid value '1'");
  EXPECT_EQ(parse_server_options({"--ffmpeg"}, &f), "--ffmpeg: a value is required");
  EXPECT_NE(std::string(kServerUsage).find("--ffmpeg PATH"), std::string::npos);
}

}  // namespace
}  // namespace skyfarm::server
