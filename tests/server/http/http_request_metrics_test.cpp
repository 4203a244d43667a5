// HTTP request metrics: paths are labelled by their route template (bounded
// cardinality, whatever ids clients send), methods outside the HTTP verbs
// and unknown paths fold into "other", and the histogram exposition is
// cumulative in `le` with +Inf equal to _count.
#include "server/http/http_request_metrics.h"

#include <gtest/gtest.h>

#include <regex>
#include <string>

#include "server/http/http_metrics.h"

namespace skyfarm::server {
namespace {

TEST(HttpRequestMetrics, PathMatchesTemplateSegmentBySegment) {
  EXPECT_TRUE(path_matches_template("/v1/renders/{id}", "/v1/renders/abc"));
  EXPECT_FALSE(path_matches_template("/v1/renders/{id}", "/v1/renders/"));
  EXPECT_FALSE(path_matches_template("/v1/renders/{id}", "/v1/renders/a/b"));
  EXPECT_TRUE(path_matches_template("/v1/renders/{id}/image.exr", "/v1/renders/x1/image.exr"));
  EXPECT_FALSE(path_matches_template("/v1/renders/{id}/image.exr", "/v1/renders/x1/image.png"));
  EXPECT_TRUE(path_matches_template("/v1/t/{id}/frames/{n}.png", "/v1/t/a/frames/12.png"));
  EXPECT_FALSE(path_matches_template("/v1/t/{id}/frames/{n}.png", "/v1/t/a/frames/.png"));
  EXPECT_TRUE(path_matches_template("/", "/"));
  EXPECT_FALSE(path_matches_template("/", "/x"));
}

TEST(HttpRequestMetrics, RoutesAreTemplatesAndCardinalityIsBounded) {
  HttpRequestMetrics m;
  m.set_routes({{"GET", "/v1/renders/{id}"}, {"DELETE", "/v1/renders/{id}"}, {"GET", "/v1/sky/envmap.exr"},
                {"GET", "/v1/sky/{x}"}, {"GET", "/metrics"}});
  EXPECT_EQ(m.route_of("/v1/sky/envmap.exr"), "/v1/sky/envmap.exr");  // the literal wins over {x}
  EXPECT_EQ(m.route_of("/v1/sky/other"), "/v1/sky/{x}");
  EXPECT_EQ(m.route_of("/nope/123"), "other");
  for (int i = 0; i < 50; ++i) {
    m.observe("GET", "/v1/renders/job-" + std::to_string(i), 200, 0.002);
    m.observe("BREW", "/pot-" + std::to_string(i), 404, 0.002);
  }
  m.observe("DELETE", "/v1/renders/job-1", 204, std::nullopt);  // counted, not timed
  std::string text;
  m.append(text);
  EXPECT_NE(text.find("skyfarm_http_requests_total{code=\"200\",method=\"GET\",route=\"/v1/renders/{id}\"} 50\n"),
            std::string::npos) << text;
  EXPECT_NE(text.find("skyfarm_http_requests_total{code=\"404\",method=\"other\",route=\"other\"} 50\n"),
            std::string::npos) << text;
  EXPECT_NE(text.find("skyfarm_http_requests_total{code=\"204\",method=\"DELETE\",route=\"/v1/renders/{id}\"} 1\n"),
            std::string::npos) << text;
  EXPECT_EQ(text.find("job-"), std::string::npos) << "a raw id became a label";
  EXPECT_EQ(text.find("pot-"), std::string::npos) << "a raw path became a label";
  const std::string count =
      "skyfarm_http_request_duration_seconds_count{code_class=\"2xx\",method=\"GET\",route=\"/v1/renders/{id}\"} 50\n";
  EXPECT_NE(text.find(count), std::string::npos) << text;
  // 0.002 s is within the first bucket (5 ms).
  EXPECT_NE(text.find("skyfarm_http_request_duration_seconds_bucket{code_class=\"2xx\",method=\"GET\",route=\"/v1/"
                      "renders/{id}\",le=\"0.005\"} 50\n"),
            std::string::npos) << text;
  EXPECT_EQ(text.find("code_class=\"2xx\",method=\"DELETE\""), std::string::npos) << "an untimed request was timed";
}

TEST(HttpMetrics, HistogramExpositionIsCumulativeWithInfEqualToCount) {
  const double bounds[] = {0.1, 1.0, 10.0};
  MetricsHistogram h(bounds);
  for (const double v : {0.0625, 0.5, 0.75, 3.0, 30.0}) h.observe(v);  // exact in binary
  std::string out;
  append_histogram(out, "skyfarm_test_seconds", "A test.", {{"a=\"x\"", h.snapshot()}});
  EXPECT_EQ(out,
            "# HELP skyfarm_test_seconds A test.\n"
            "# TYPE skyfarm_test_seconds histogram\n"
            "skyfarm_test_seconds_bucket{a=\"x\",le=\"0.1\"} 1\n"
            "skyfarm_test_seconds_bucket{a=\"x\",le=\"1\"} 3\n"
            "skyfarm_test_seconds_bucket{a=\"x\",le=\"10\"} 4\n"
            "skyfarm_test_seconds_bucket{a=\"x\",le=\"+Inf\"} 5\n"
            "skyfarm_test_seconds_sum{a=\"x\"} 34.3125\n"
            "skyfarm_test_seconds_count{a=\"x\"} 5\n");
}

TEST(HttpMetrics, BuildInfoNamesVersionCommitCompilerAndBuildType) {
  std::string out;
  append_build_info(out);
  const std::regex line(
      R"re(skyfarm_build_info\{version="([^"]+)",git_commit="([0-9a-f]+|unknown)",compiler="[^"]+",build_type="[^"]+"\} 1\n)re");
  std::smatch m;
  ASSERT_TRUE(std::regex_search(out, m, line)) << out;
  EXPECT_EQ(m[1], SKYFARM_VERSION);
  EXPECT_NE(out.find("# TYPE skyfarm_build_info gauge\n"), std::string::npos) << out;
}

TEST(HttpMetrics, LabelValuesAreEscaped) {
  EXPECT_EQ(escaped_label_value("a\"b\\c\nd"), "a\\\"b\\\\c\\nd");
}

}  // namespace
}  // namespace skyfarm::server
