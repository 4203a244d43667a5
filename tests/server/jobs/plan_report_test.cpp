// The plan report's "clouds" entry (server/jobs/job.h plan_report): the
// layers by type and the volumes of a cloudy request, nothing at all for a
// clear sky (whose report stays as it was).
#include <gtest/gtest.h>

#include <string>

#include "api/render_request.h"
#include "common/render/render_plan.h"
#include "server/jobs/job.h"

namespace skyfarm::server {
namespace {

const std::string kSky = R"("sun": {"zenith_deg": 40, "azimuth_deg": 200}, "camera": {"projection": "fisheye"})";

TEST(PlanReportClouds, ClearSkyHasNoCloudsEntry) {
  const auto report = plan_report(api::parse_render_request("{" + kSky + "}"), RenderPlan{});
  EXPECT_FALSE(report.contains("clouds"));
  EXPECT_TRUE(report.contains("constituents"));
  const auto empty = plan_report(api::parse_render_request("{" + kSky + R"(, "clouds": {"layers": []}})"), RenderPlan{});
  EXPECT_EQ(empty, report);
}

TEST(PlanReportClouds, LayersByTypeAndVolumesAreCounted) {
  const std::string asset = "sha256:" + std::string(64, 'c');
  const auto request = api::parse_render_request(
      "{" + kSky + R"(, "clouds": {"layers": [{"type": "stratocumulus"}, {"type": "cirrus"}],
                        "volumes": [{"asset": ")" + asset + R"("}]}})");
  const auto report = plan_report(request, RenderPlan{});
  ASSERT_TRUE(report.contains("clouds"));
  EXPECT_EQ(report["clouds"]["layers"], 2);
  EXPECT_EQ(report["clouds"]["layer_types"], nlohmann::json::array({"stratocumulus", "cirrus"}));
  EXPECT_EQ(report["clouds"]["volumes"], 1);
}

}  // namespace
}  // namespace skyfarm::server
