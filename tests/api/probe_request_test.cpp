// Tests of the radiance probe request: api/examples/probe*.json,
// the probe_*.json bad requests with their expected first error, defaults,
// the fields it shares with the render request, and its canonical form.
#include "api/probe_request.h"

#include <gtest/gtest.h>

#include "tests/support/test_files.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace skyfarm::api {
namespace {

namespace fs = std::filesystem;

using skyfarm::testing::kExamples;
using skyfarm::testing::read_text;

std::vector<fs::path> probe_files(const fs::path& dir) {
  std::vector<fs::path> out;
  for (const auto& entry : fs::directory_iterator(dir))
    if (entry.path().extension() == ".json" && entry.path().filename().string().starts_with("probe"))
      out.push_back(entry.path());
  std::sort(out.begin(), out.end());
  return out;
}

std::vector<std::string> messages_of(std::string_view body) {
  std::vector<std::string> out;
  try {
    parse_probe_request(body);
  } catch (const ValidationError& e) {
    for (const auto& err : e.errors()) out.push_back(err.message());
  }
  return out;
}

// A valid probe with one more top-level member.
std::string with(const std::string& member) {
  return R"({"sun": {"zenith_deg": 30, "azimuth_deg": 180}, "directions": [{"zenith_deg": 0, "azimuth_deg": 0}],
             "wavelengths_nm": [550])" +
         (member.empty() ? std::string() : ", " + member) + "}";
}

TEST(ProbeRequestExamples, EveryGoodExampleParsesAndRoundTrips) {
  const auto files = probe_files(kExamples);
  ASSERT_GE(files.size(), 1u);
  for (const auto& file : files) {
    SCOPED_TRACE(file.filename().string());
    ProbeRequest r;
    ASSERT_NO_THROW(r = parse_probe_request(read_text(file)));
    const std::string canonical = canonical_text(r);
    ProbeRequest again;
    ASSERT_NO_THROW(again = parse_probe_request(canonical)) << canonical;
    EXPECT_EQ(canonical_text(again), canonical);
  }
}

TEST(ProbeRequestExamples, EveryBadProbeGetsItsExpectedError) {
  const auto expected = nlohmann::json::parse(read_text(kExamples / "bad" / "expected_errors.json"));
  const auto files = probe_files(kExamples / "bad");
  ASSERT_GE(files.size(), 5u);
  for (const auto& file : files) {
    const std::string name = file.filename().string();
    SCOPED_TRACE(name);
    ASSERT_TRUE(expected.contains(name)) << "no expected error listed";
    const auto m = messages_of(read_text(file));
    ASSERT_EQ(m.size(), 1u) << (m.empty() ? "parsed" : m[0]);
    EXPECT_EQ(m[0], expected[name].get<std::string>());
  }
}

TEST(ProbeRequestExamples, ProbeExampleReadsAsWritten) {
  const ProbeRequest r = parse_probe_request(read_text(kExamples / "probe.json"));
  EXPECT_DOUBLE_EQ(r.location.latitude_deg, 42.44);
  ASSERT_TRUE(r.time.has_value());
  EXPECT_EQ(r.time->to_iso8601(), "2013-05-27T13:30:00Z");
  ASSERT_EQ(r.directions.size(), 3u);
  EXPECT_EQ(r.directions[1].zenith_deg, 60.0);
  EXPECT_EQ(r.directions[1].azimuth_deg, 90.0);
  EXPECT_EQ(r.wavelengths_nm, (std::vector<double>{450, 550, 650}));
  EXPECT_EQ(r.samples, 4096);
  EXPECT_EQ(r.seed, 1u);
  EXPECT_EQ(r.method, Method::kPath);
}

TEST(ProbeRequestDefaults, MinimalProbeGetsEveryDefault) {
  const ProbeRequest r = parse_probe_request(with(""));
  EXPECT_EQ(r.samples, 4096);
  EXPECT_EQ(r.seed, 1u);
  EXPECT_EQ(r.method, Method::kPath);
  EXPECT_EQ(r.atmosphere.preset, AtmospherePreset::kEarth);
  EXPECT_EQ(r.atmosphere.ozone_du, 300.0);
  EXPECT_TRUE(r.atmosphere.aerosol.has_value());
  EXPECT_EQ(r.location.altitude_m, 0.0);
  EXPECT_FALSE(r.time.has_value());
  EXPECT_EQ(parse_probe_request(with(R"("method": "lut", "samples": 1000000000)")).method, Method::kLut);
}

TEST(ProbeRequestErrors, SharesTheRenderRequestFieldRules) {
  EXPECT_EQ(messages_of(with(R"("location": {"latitude_deg": "north"})")),
            std::vector<std::string>{"location.latitude_deg: must be a number, got \"north\""});
  EXPECT_EQ(messages_of(with(R"("atmosphere": {"preset": "custom"})")),
            std::vector<std::string>{"atmosphere.constituents: required with preset custom"});
  EXPECT_EQ(messages_of(with(R"("seed": -1)")),
            std::vector<std::string>{"seed: must be an integer in [0, 18446744073709551615], got -1"});
  EXPECT_EQ(messages_of(R"({"directions": [{"zenith_deg": 0, "azimuth_deg": 0}], "wavelengths_nm": [550]})"),
            std::vector<std::string>{"time: required unless sun.zenith_deg and sun.azimuth_deg are given"});
}

TEST(ProbeRequestErrors, CollectsEveryInvalidDirectionAndWavelength) {
  const auto m = messages_of(R"({"sun": {"zenith_deg": 30, "azimuth_deg": 180},
      "directions": [{"zenith_deg": -1, "azimuth_deg": 0}, 5, {"zenith_deg": 0, "azimuth_deg": 361}],
      "wavelengths_nm": [550, 229], "samples": 0})");
  const std::vector<std::string> expected = {
      "directions[0].zenith_deg: must be a number in [0, 180], got -1",
      "directions[1]: must be an object, got 5",
      "directions[2].azimuth_deg: must be a number in [0, 360], got 361",
      "wavelengths_nm[1]: must be a number in [230, 2500], got 229",
      "samples: must be an integer in [1, 1000000000], got 0",
  };
  EXPECT_EQ(m, expected);
}

TEST(ProbeRequestErrors, LimitsOnCounts) {
  std::string many = "[";
  for (int i = 0; i < 10001; ++i) many += (i ? ",550" : "550");
  many += "]";
  EXPECT_EQ(messages_of(R"({"sun": {"zenith_deg": 30, "azimuth_deg": 180}, "directions": [{"zenith_deg": 0, "azimuth_deg": 0}],
                           "wavelengths_nm": )" + many + "}"),
            std::vector<std::string>{"wavelengths_nm: must have 1 to 10000 entries, got 10001 entries"});
  EXPECT_EQ(messages_of(with(R"("depth": )" + std::string(50, '[') + std::string(50, ']'))),
            std::vector<std::string>{"(request): JSON nested deeper than 32 levels"});
  EXPECT_EQ(messages_of("[]"), std::vector<std::string>{"(request): must be a JSON object, got []"});
}

TEST(ProbeRequestCanonical, SameMeaningSameText) {
  auto text = [](const std::string& body) { return canonical_text(parse_probe_request(body)); };
  EXPECT_EQ(text(R"({"time": "2013-05-27T09:30:00-04:00", "directions": [{"zenith_deg": 10, "azimuth_deg": 360}],
                     "wavelengths_nm": [550]})"),
            text(R"({"method": "path", "samples": 4096.0, "seed": 1, "wavelengths_nm": [550.0],
                     "directions": [{"azimuth_deg": 0, "zenith_deg": 10}], "time": "2013-05-27T13:30:00Z",
                     "atmosphere": {"preset": "earth"}})"));
  EXPECT_NE(text(with(R"("samples": 100)")), text(with(R"("samples": 200)")));
  const nlohmann::json c = to_canonical_json(parse_probe_request(with("")));
  for (const char* key : {"location", "time", "sun", "atmosphere", "directions", "wavelengths_nm", "samples", "seed",
                          "method"})
    EXPECT_TRUE(c.contains(key)) << key;
}

}  // namespace
}  // namespace skyfarm::api
