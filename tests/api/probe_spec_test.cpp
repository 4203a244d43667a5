// The translation of a probe request into the renderer's spec
// (api/probe_spec.h) and the answer document (api/probe_answer.h): the
// directions become unit vectors in the observer frame, the unit budget
// counts the request's canonical text, and the document gives back what the
// request asked with the renderer's numbers.
#include "api/probe_spec.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "api/probe_answer.h"

namespace skyfarm::api {
namespace {

const char* kBody = R"({"sun": {"zenith_deg": 50, "azimuth_deg": 120},
    "directions": [{"zenith_deg": 0, "azimuth_deg": 0}, {"zenith_deg": 90, "azimuth_deg": 90}],
    "wavelengths_nm": [450, 550, 650], "samples": 1000, "seed": 7, "method": "path"})";

TEST(ProbeSpec, CarriesTheRequestsChoices) {
  const ProbeRequest request = parse_probe_request(kBody);
  const ProbeSpec spec = probe_spec(request);
  ASSERT_EQ(spec.directions.size(), 2u);
  EXPECT_NEAR(spec.directions[0].z, 1.0, 1e-15);  // straight up
  EXPECT_NEAR(spec.directions[1].x, 1.0, 1e-15);  // on the horizon, east
  EXPECT_NEAR(spec.directions[1].z, 0.0, 1e-15);
  EXPECT_EQ(spec.wavelengths_nm, (std::vector<double>{450, 550, 650}));
  EXPECT_EQ(spec.samples, 1000);
  EXPECT_EQ(spec.seed, 7u);
  EXPECT_FALSE(spec.lut);
  EXPECT_EQ(spec.unit_text_bytes, canonical_text(request).size());
  EXPECT_EQ(probe_plan(spec).pairs, 6u);
}

TEST(ProbeAnswerJson, GivesBackTheRequestWithTheNumbers) {
  const ProbeRequest request = parse_probe_request(kBody);
  ProbeAnswer answer;
  answer.radiance = {{1, 2, 3}, {4, 5, 6}};
  answer.standard_error = std::vector<std::vector<double>>{{0.1, 0.2, 0.3}, {0.4, 0.5, 0.6}};
  answer.nonfinite_paths = 2;
  answer.sun_zenith_deg = 50.0;
  answer.sun_azimuth_deg = 120.0;
  const nlohmann::json doc = probe_answer_json(request, answer);
  EXPECT_EQ(doc["units"], "W m-2 sr-1 nm-1");
  EXPECT_EQ(doc["directions"][1]["azimuth_deg"], 90.0);
  EXPECT_EQ(doc["radiance"][1][2], 6.0);
  EXPECT_EQ(doc["standard_error"][0][1], 0.2);
  EXPECT_EQ(doc["samples"], 1000);
  EXPECT_EQ(doc["method"], "path");
  EXPECT_EQ(doc["approximate"], false);
  EXPECT_EQ(doc["sun"]["zenith_deg"], 50.0);
  EXPECT_EQ(doc["nonfinite_paths"], 2u);

  // "lut": no standard error, no samples, approximate.
  nlohmann::json body = nlohmann::json::parse(kBody);
  body["method"] = "lut";
  const ProbeRequest lut = parse_probe_request(body);
  EXPECT_TRUE(probe_spec(lut).lut);
  answer.standard_error.reset();
  answer.nonfinite_paths = 0;
  const nlohmann::json lut_doc = probe_answer_json(lut, answer);
  EXPECT_TRUE(lut_doc["standard_error"].is_null());
  EXPECT_TRUE(lut_doc["samples"].is_null());
  EXPECT_EQ(lut_doc["method"], "lut");
  EXPECT_EQ(lut_doc["approximate"], true);
}

}  // namespace
}  // namespace skyfarm::api
