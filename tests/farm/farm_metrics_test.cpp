// /metrics of a real skyfarm-server after a tiny path render, a tiny LUT
// render and a few HTTP calls: the text is valid Prometheus exposition
// (0.0.4: HELP and TYPE before a family's samples, each sample
// `name{labels} value`, no series twice), the histograms exist and are
// consistent (`_bucket` cumulative in le, le="+Inf" == _count), the counters
// agree with the jobs' own status documents, and skyfarm_build_info is there.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <regex>
#include <set>
#include <sstream>

#include "tests/farm/farm_process.h"

namespace skyfarm {
namespace {

namespace fs = std::filesystem;
using testing::FarmServer;

constexpr const char* kPathRequest = R"({
  "sun": {"zenith_deg": 50, "azimuth_deg": 120},
  "camera": {"projection": "equirectangular", "width": 32, "height": 16},
  "spectral": {"batches": 2},
  "quality": {"samples_per_pixel": 8},
  "seed": 5
})";
constexpr const char* kLutRequest = R"({
  "method": "lut",
  "sun": {"zenith_deg": 50, "azimuth_deg": 120},
  "camera": {"projection": "equirectangular", "width": 32, "height": 16},
  "seed": 5
})";

// A parsed scrape: every sample by its series (name and labels as written),
// and the family each metric name was typed as.
struct Scrape {
  std::map<std::string, double> samples;
  std::map<std::string, std::string> types;  // family → counter, gauge, histogram
  std::vector<std::string> errors;

  double at(const std::string& series) const {
    const auto it = samples.find(series);
    return it == samples.end() ? -1.0 : it->second;
  }
};

// The family a sample name belongs to: a histogram's _bucket, _sum and
// _count belong to the histogram's name.
std::string family_of(const std::string& name, const std::map<std::string, std::string>& types) {
  for (const char* suffix : {"_bucket", "_sum", "_count"}) {
    const std::string s = suffix;
    if (name.size() > s.size() && name.ends_with(s)) {
      const std::string base = name.substr(0, name.size() - s.size());
      const auto it = types.find(base);
      if (it != types.end() && it->second == "histogram") return base;
    }
  }
  return name;
}

Scrape parse(const std::string& text) {
  Scrape s;
  const std::regex sample(
      R"(([a-zA-Z_:][a-zA-Z0-9_:]*)(\{[a-zA-Z_][a-zA-Z0-9_]*="(?:[^"\\]|\\.)*"(?:,[a-zA-Z_][a-zA-Z0-9_]*="(?:[^"\\]|\\.)*")*\})? (-?[0-9.]+(?:e[-+]?[0-9]+)?|NaN|[-+]Inf))");
  const std::regex help(R"(# HELP ([a-zA-Z_:][a-zA-Z0-9_:]*) .+)");
  const std::regex type(R"(# TYPE ([a-zA-Z_:][a-zA-Z0-9_:]*) (counter|gauge|histogram|summary|untyped))");
  std::set<std::string> helped, families_seen;
  std::string current;  // the family whose samples may follow
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);) {
    std::smatch m;
    if (std::regex_match(line, m, help)) {
      if (!helped.insert(m[1]).second) s.errors.push_back("HELP twice: " + line);
      continue;
    }
    if (std::regex_match(line, m, type)) {
      if (!helped.count(m[1])) s.errors.push_back("TYPE before HELP: " + line);
      if (!s.types.emplace(m[1], m[2]).second) s.errors.push_back("TYPE twice: " + line);
      current = m[1];
      continue;
    }
    if (!std::regex_match(line, m, sample)) {
      s.errors.push_back("not a sample line: " + line);
      continue;
    }
    const std::string family = family_of(m[1], s.types);
    if (family != current) s.errors.push_back("sample outside its family's block (no TYPE just before): " + line);
    families_seen.insert(family);
    const std::string series = m[1].str() + m[2].str();
    const double value = m[3] == "+Inf" ? INFINITY : m[3] == "-Inf" ? -INFINITY : std::stod(m[3]);
    if (!s.samples.emplace(series, value).second) s.errors.push_back("series twice: " + series);
  }
  return s;
}

// Checks every histogram series of `name`: buckets non-decreasing in le, the
// last le="+Inf" and equal to _count; returns the number of series.
int check_histogram(const Scrape& s, const std::string& name) {
  // Group the buckets by their labels other than le, in the order written
  // (std::map orders by text, so collect le values and sort numerically).
  std::map<std::string, std::vector<std::pair<double, double>>> buckets;
  const std::regex bucket(name + R"re(_bucket\{(.*)le="([^"]+)"\})re");
  for (const auto& [series, value] : s.samples) {
    std::smatch m;
    if (!std::regex_match(series, m, bucket)) continue;
    std::string labels = m[1];
    if (!labels.empty()) labels.pop_back();  // the comma before le
    const double le = m[2] == "+Inf" ? INFINITY : std::stod(m[2]);
    buckets[labels].emplace_back(le, value);
  }
  for (auto& [labels, list] : buckets) {
    std::sort(list.begin(), list.end());
    for (std::size_t i = 1; i < list.size(); ++i)
      EXPECT_LE(list[i - 1].second, list[i].second) << name << "{" << labels << "} le=" << list[i].first;
    EXPECT_TRUE(std::isinf(list.back().first)) << name << "{" << labels << "} has no +Inf bucket";
    const std::string suffix = labels.empty() ? "" : "{" + labels + "}";
    EXPECT_EQ(list.back().second, s.at(name + "_count" + suffix)) << name << suffix;
    EXPECT_GE(s.at(name + "_sum" + suffix), 0.0) << name << suffix;
  }
  return static_cast<int>(buckets.size());
}

std::string scrape_text(const FarmServer& server) {
  auto c = server.client();
  const auto r = c.Get("/metrics");
  return r && r->status == 200 ? r->body : std::string();
}

TEST(FarmMetrics, ScrapeAfterRendersHasHistogramsCountersAndBuildInfo) {
  const fs::path dir = testing::fresh_dir("skyfarm_farm_metrics", "scrape");
  FarmServer server(dir / "data", 1);
  ASSERT_TRUE(server.ok()) << server.log();

  const Scrape before = parse(scrape_text(server));
  EXPECT_TRUE(before.errors.empty()) << ::testing::PrintToString(before.errors);
  // Every family exists before anything happened (a dashboard's queries
  // must not depend on traffic to find their names).
  for (const char* family : {"skyfarm_unit_duration_seconds", "skyfarm_job_duration_seconds",
                             "skyfarm_samples_total", "skyfarm_units_completed_total", "skyfarm_build_info",
                             "skyfarm_http_requests_total", "skyfarm_http_request_duration_seconds"})
    EXPECT_TRUE(before.types.count(family)) << family;
  EXPECT_EQ(before.types.at("skyfarm_unit_duration_seconds"), "histogram");
  EXPECT_EQ(before.types.at("skyfarm_samples_total"), "counter");
  EXPECT_EQ(before.at("skyfarm_samples_total"), 0.0);
  EXPECT_EQ(before.at("skyfarm_unit_duration_seconds_count{method=\"path\"}"), 0.0);

  const std::string path_id = server.submit(kPathRequest), lut_id = server.submit(kLutRequest);
  ASSERT_FALSE(path_id.empty());
  ASSERT_FALSE(lut_id.empty());
  const nlohmann::json path_status = server.wait(path_id, std::chrono::seconds(60));
  const nlohmann::json lut_status = server.wait(lut_id, std::chrono::seconds(60));
  ASSERT_EQ(path_status["state"], "done") << path_status.dump();
  ASSERT_EQ(lut_status["state"], "done") << lut_status.dump();
  auto c = server.client();
  const auto missing = c.Get("/v1/renders/no-such-job");
  ASSERT_TRUE(missing);
  EXPECT_EQ(missing->status, 404);

  // The logger counts a response just after it is sent: poll until the 404 shows.
  const std::string not_found =
      "skyfarm_http_requests_total{code=\"404\",method=\"GET\",route=\"/v1/renders/{id}\"}";
  Scrape after = parse(scrape_text(server));
  for (int i = 0; i < 100 && after.at(not_found) < 1.0; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    after = parse(scrape_text(server));
  }
  EXPECT_TRUE(after.errors.empty()) << ::testing::PrintToString(after.errors);
  EXPECT_EQ(after.at(not_found), 1.0);
  // The status polls were GETs of /v1/renders/{id}, answered 200 and timed.
  EXPECT_GE(after.at("skyfarm_http_requests_total{code=\"200\",method=\"GET\",route=\"/v1/renders/{id}\"}"), 2.0);
  EXPECT_GE(after.at("skyfarm_http_request_duration_seconds_count{code_class=\"2xx\",method=\"GET\",route=\"/v1/"
                     "renders/{id}\"}"),
            2.0);
  EXPECT_EQ(after.at("skyfarm_http_requests_total{code=\"202\",method=\"POST\",route=\"/v1/renders\"}"), 2.0);
  for (const auto& [series, value] : after.samples)
    EXPECT_EQ(series.find("no-such-job"), std::string::npos) << "a raw path became a label: " << series;

  // Units: each merged exactly once, so the counter is the jobs' unit totals.
  const double path_units = path_status["progress"]["units_total"].get<double>();
  const double lut_units = lut_status["progress"]["units_total"].get<double>();
  EXPECT_EQ(after.at("skyfarm_units_completed_total"), path_units + lut_units);
  EXPECT_EQ(after.at("skyfarm_unit_duration_seconds_count{method=\"path\"}"), path_units);
  EXPECT_EQ(after.at("skyfarm_unit_duration_seconds_count{method=\"lut\"}"), lut_units);
  EXPECT_GT(after.at("skyfarm_unit_duration_seconds_sum{method=\"path\"}"), 0.0);
  // Samples: at least one path per pixel sample of the path render.
  EXPECT_GE(after.at("skyfarm_samples_total"), 32.0 * 16.0 * 8.0);
  EXPECT_EQ(after.at("skyfarm_job_duration_seconds_count{kind=\"render\",state=\"done\"}"), 2.0);
  EXPECT_EQ(after.at("skyfarm_job_duration_seconds_count{kind=\"render\",state=\"failed\"}"), 0.0);
  EXPECT_EQ(check_histogram(after, "skyfarm_unit_duration_seconds"), 2);
  // kind="render" and kind="timelapse", each by done, failed, cancelled.
  EXPECT_EQ(check_histogram(after, "skyfarm_job_duration_seconds"), 6);
  EXPECT_EQ(after.at("skyfarm_job_duration_seconds_count{kind=\"timelapse\",state=\"done\"}"), 0.0);
  EXPECT_GE(check_histogram(after, "skyfarm_http_request_duration_seconds"), 2);
  // Counters never go down between scrapes.
  for (const auto& [series, value] : before.samples) {
    const auto type = before.types.find(series.substr(0, series.find('{')));
    if (type != before.types.end() && type->second == "counter") {
      EXPECT_GE(after.at(series), value) << series;
    }
  }

  // build_info: one series, value 1, the four labels.
  int build_series = 0;
  const std::regex build(
      R"(skyfarm_build_info\{version="[^"]+",git_commit="[^"]+",compiler="[^"]+",build_type="[^"]+"\})");
  for (const auto& [series, value] : after.samples)
    if (series.starts_with("skyfarm_build_info")) {
      ++build_series;
      EXPECT_TRUE(std::regex_match(series, build)) << series;
      EXPECT_EQ(value, 1.0);
    }
  EXPECT_EQ(build_series, 1);
}

}  // namespace
}  // namespace skyfarm
