// Tests of the request's "clouds" (api/cloud_fields.h): the cloud examples,
// presets filling omitted fields, the meteorological wind direction, every
// rule naming its field, the canonical form (fully resolved, round trip, and
// absent for a clear sky), the LUT rule, timelapse frames and the spec.
#include "api/cloud_fields.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "api/render_request.h"
#include "api/render_spec.h"
#include "api/timelapse_request.h"
#include "tests/support/test_files.h"

namespace skyfarm::api {
namespace {

namespace fs = std::filesystem;
using skyfarm::testing::kExamples;
using skyfarm::testing::read_text;

const std::string kAsset = "sha256:" + std::string(64, 'a');

// A valid request body with `clouds` as its "clouds" member (none when empty)
// and `more` further members.
std::string body(const std::string& clouds, const std::string& more = "") {
  std::string b = R"({"sun": {"zenith_deg": 40, "azimuth_deg": 200}, "camera": {"projection": "fisheye"})";
  if (!clouds.empty()) b += R"(, "clouds": )" + clouds;
  if (!more.empty()) b += ", " + more;
  return b + "}";
}
std::string one_layer(const std::string& members) { return R"({"layers": [{)" + members + "}]}"; }

std::vector<std::string> error_messages(const std::string& text) {
  std::vector<std::string> out;
  try {
    parse_render_request(text);
  } catch (const ValidationError& e) {
    for (const auto& f : e.errors()) out.push_back(f.message());
  }
  return out;
}

CloudLayerSpec only_layer(const std::string& members) {
  const RenderRequest r = parse_render_request(body(one_layer(members)));
  EXPECT_EQ(r.clouds.layers.size(), 1u);
  return r.clouds.layers.at(0);
}

void expect_same_layer(const CloudLayerSpec& a, const CloudLayerSpec& b) {
  EXPECT_EQ(a.type, b.type);
  EXPECT_EQ(a.coverage, b.coverage);
  EXPECT_EQ(a.base_m, b.base_m);
  EXPECT_EQ(a.thickness_m, b.thickness_m);
  EXPECT_EQ(a.water_content_g_m3, b.water_content_g_m3);
  EXPECT_EQ(a.optical_depth, b.optical_depth);
  EXPECT_EQ(a.effective_radius_um, b.effective_radius_um);
  EXPECT_EQ(a.particle, b.particle);
  EXPECT_EQ(a.seed, b.seed);
  EXPECT_EQ(a.wind_m_s, b.wind_m_s);
  EXPECT_EQ(a.scale_m, b.scale_m);
  EXPECT_EQ(a.detail_scale_m, b.detail_scale_m);
  EXPECT_EQ(a.erosion, b.erosion);
}

std::vector<fs::path> cloud_examples() {
  std::vector<fs::path> out;
  for (const auto& entry : fs::directory_iterator(kExamples))
    if (entry.path().filename().string().starts_with("clouds_") && entry.path().extension() == ".json")
      out.push_back(entry.path());
  std::sort(out.begin(), out.end());
  return out;
}

// --- Examples ------------------------------------------------------------------

TEST(CloudFieldsExamples, EachParsesWithCloudsAndRoundTrips) {
  const auto files = cloud_examples();
  ASSERT_EQ(files.size(), 4u);
  for (const auto& file : files) {
    SCOPED_TRACE(file.filename().string());
    const RenderRequest r = parse_render_request(read_text(file));
    EXPECT_FALSE(r.clouds.layers.empty());
    const std::string canonical = canonical_text(r);
    const RenderRequest again = parse_render_request(canonical);
    EXPECT_EQ(canonical_text(again), canonical);
    ASSERT_EQ(again.clouds.layers.size(), r.clouds.layers.size());
    for (std::size_t i = 0; i < r.clouds.layers.size(); ++i) expect_same_layer(again.clouds.layers[i], r.clouds.layers[i]);
  }
}

TEST(CloudFieldsExamples, ParisAfternoonIsAWestWindCumulus) {
  const RenderRequest r = parse_render_request(read_text(kExamples / "clouds_cumulus_paris.json"));
  EXPECT_DOUBLE_EQ(r.location.latitude_deg, 48.8566);
  EXPECT_EQ(r.time_text, "2026-07-15T17:00:00+02:00");
  const CloudLayerSpec& layer = r.clouds.layers.at(0);
  EXPECT_EQ(layer.type, CloudType::kCumulus);
  EXPECT_EQ(layer.coverage, 0.35);
  EXPECT_EQ(layer.seed, 7u);
  EXPECT_EQ(layer.wind_m_s, glm::dvec2(8.0, 0.0));  // blowing towards the east
  // Omitted: the cumulus preset's.
  const CloudLayerSpec preset = cloud_layer_preset(CloudType::kCumulus);
  EXPECT_EQ(layer.water_content_g_m3, preset.water_content_g_m3);
  EXPECT_EQ(layer.erosion, preset.erosion);
}

TEST(CloudFieldsExamples, OrbitCameraIsAt400km) {
  const RenderRequest r = parse_render_request(read_text(kExamples / "clouds_from_orbit.json"));
  EXPECT_EQ(r.location.altitude_m, 400000.0);
  EXPECT_EQ(r.clouds.layers.size(), 2u);
}

// --- Presets -------------------------------------------------------------------

TEST(CloudFieldsPresets, TheTypeFillsEveryOmittedField) {
  for (const char* name : {"cumulus", "stratocumulus", "stratus", "cirrus", "custom"}) {
    SCOPED_TRACE(name);
    CloudType type;
    ASSERT_TRUE(parse_cloud_type(name, &type));
    CloudLayerSpec expected = cloud_layer_preset(type);
    expected.optical_depth = 0.0;  // no optical depth given: the water content rules
    expect_same_layer(only_layer(std::string(R"("type": ")") + name + "\""), expected);
  }
  // The presets differ where the genera do (a test that could fail if the
  // type were ignored).
  EXPECT_NE(only_layer(R"("type": "stratus")").base_m, only_layer(R"("type": "cirrus")").base_m);
  EXPECT_EQ(only_layer(R"("type": "cirrus")").particle, CloudParticle::kIce);
}

TEST(CloudFieldsPresets, GivenFieldsOverrideThePreset) {
  const CloudLayerSpec s = only_layer(R"("type": "stratus", "coverage": 0.25, "base_m": 100, "erosion": 0.9)");
  EXPECT_EQ(s.coverage, 0.25);
  EXPECT_EQ(s.base_m, 100.0);
  EXPECT_EQ(s.erosion, 0.9);
  EXPECT_EQ(s.thickness_m, cloud_layer_preset(CloudType::kStratus).thickness_m);
}

TEST(CloudFieldsPresets, AnotherParticleTakesItsOwnTypicalRadius) {
  EXPECT_EQ(only_layer(R"("type": "cumulus", "particle": "ice")").effective_radius_um, kIceRadius_um);
  EXPECT_EQ(only_layer(R"("type": "cirrus", "particle": "water")").effective_radius_um, kWaterRadius_um);
  EXPECT_EQ(only_layer(R"("type": "cirrus", "particle": "ice")").effective_radius_um,
            cloud_layer_preset(CloudType::kCirrus).effective_radius_um);
  EXPECT_EQ(only_layer(R"("type": "cumulus", "particle": "ice", "effective_radius_um": 80)").effective_radius_um, 80.0);
}

TEST(CloudFieldsPresets, OpticalDepthReplacesTheWaterContent) {
  const CloudLayerSpec tau = only_layer(R"("type": "stratus", "optical_depth": 20)");
  EXPECT_EQ(tau.optical_depth, 20.0);
  const CloudLayerSpec zero = only_layer(R"("type": "stratus", "optical_depth": 0)");
  EXPECT_EQ(zero.optical_depth, 0.0);
  EXPECT_EQ(zero.water_content_g_m3, 0.0);  // a layer of optical depth 0 scatters nothing
  const CloudLayerSpec water = only_layer(R"("type": "stratus", "water_content_g_m3": 0.7)");
  EXPECT_EQ(water.water_content_g_m3, 0.7);
  EXPECT_EQ(water.optical_depth, 0.0);
}

// --- Wind ----------------------------------------------------------------------

// Meteorological convention: the direction the wind blows FROM, clockwise
// from north; the velocity points the other way.
TEST(CloudFieldsWind, FromDirectionGivesTheVelocityBlowingAway) {
  const glm::dvec2 west = wind_from_direction(8.0, 270.0);
  EXPECT_NEAR(west.x, 8.0, 1e-12);
  EXPECT_NEAR(west.y, 0.0, 1e-12);
  const glm::dvec2 north = wind_from_direction(8.0, 0.0);
  EXPECT_NEAR(north.x, 0.0, 1e-12);
  EXPECT_NEAR(north.y, -8.0, 1e-12);
  EXPECT_EQ(wind_from_direction(8.0, 360.0), north);
  EXPECT_EQ(wind_from_direction(5.0, 90.0), glm::dvec2(-5.0, 0.0));
  EXPECT_EQ(wind_from_direction(5.0, 180.0), glm::dvec2(0.0, 5.0));
  // A south-west wind blows towards the north-east: both components +s/sqrt(2).
  const glm::dvec2 sw = wind_from_direction(10.0, 225.0);
  EXPECT_NEAR(sw.x, 10.0 / std::sqrt(2.0), 1e-12);
  EXPECT_NEAR(sw.y, 10.0 / std::sqrt(2.0), 1e-12);
  EXPECT_NEAR(std::hypot(wind_from_direction(7.0, 123.0).x, wind_from_direction(7.0, 123.0).y), 7.0, 1e-12);
}

TEST(CloudFieldsWind, BothSpellingsReadTheSameAndTheCanonicalIsTheVector) {
  const CloudLayerSpec polar = only_layer(R"("type": "cumulus", "wind": {"speed_m_s": 8, "from_deg": 270})");
  const CloudLayerSpec vector = only_layer(R"("type": "cumulus", "wind_m_s": [8, 0])");
  EXPECT_EQ(polar.wind_m_s, vector.wind_m_s);
  const Json j = to_canonical_json(parse_render_request(body(one_layer(R"("type": "cumulus", "wind": {"speed_m_s": 8, "from_deg": 0})"))));
  const Json& layer = j.at("clouds").at("layers").at(0);
  EXPECT_FALSE(layer.contains("wind"));
  EXPECT_EQ(layer.at("wind_m_s"), Json::array({0.0, -8.0}));
}

// --- Validation ----------------------------------------------------------------

TEST(CloudFieldsErrors, EachRuleNamesItsFullPath) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {one_layer(R"("type": "cumulus", "coverage": 1.5)"), "clouds.layers[0].coverage: must be a number in [0, 1], got 1.5"},
      {R"({"layers": [{"type": "cumulus"}, {"type": "stratus", "base_m": -1}]})",
       "clouds.layers[1].base_m: must be a number in [0, 20000], got -1"},
      {one_layer(R"("type": "cumulus", "thickness_m": 0)"), "clouds.layers[0].thickness_m: must be a number in (0, 20000], got 0"},
      {one_layer(R"("type": "cumulus", "water_content_g_m3": -0.1)"),
       "clouds.layers[0].water_content_g_m3: must be a number in [0, 10], got -0.1"},
      {one_layer(R"("type": "cumulus", "optical_depth": 1001)"),
       "clouds.layers[0].optical_depth: must be a number in [0, 1000], got 1001"},
      {one_layer(R"("type": "cumulus", "effective_radius_um": 0.4)"),
       "clouds.layers[0].effective_radius_um: must be a number in [0.5, 25] for water droplets, got 0.4"},
      {one_layer(R"("type": "cirrus", "effective_radius_um": 300)"),
       "clouds.layers[0].effective_radius_um: must be a number in [5, 200] for ice crystals, got 300"},
      {one_layer(R"("type": "cumulus", "particle": "hail")"),
       "clouds.layers[0].particle: must be one of water, ice, got \"hail\""},
      {one_layer(R"("type": "cumulus", "seed": 1.5)"), "clouds.layers[0].seed: must be an integer, got 1.5"},
      {one_layer(R"("type": "cumulus", "wind_m_s": [1e300, 0])"),
       "clouds.layers[0].wind_m_s[0]: must be a number in [-100, 100], got 1e+300"},
      {one_layer(R"("type": "cumulus", "wind": {"speed_m_s": 101, "from_deg": 0})"),
       "clouds.layers[0].wind.speed_m_s: must be a number in [0, 100], got 101"},
      {one_layer(R"("type": "cumulus", "wind": {"speed_m_s": 5, "from_deg": 400})"),
       "clouds.layers[0].wind.from_deg: must be a number in [0, 360], got 400"},
      {one_layer(R"("type": "cumulus", "detail_scale_m": 5)"), "clouds.layers[0].detail_scale_m: must be a number >= 10, got 5"},
      {one_layer(R"("type": "cumulus", "erosion": 2)"), "clouds.layers[0].erosion: must be a number in [0, 1], got 2"},
      {R"({"layers": {}})", "clouds.layers: must be an array, got {}"},
      {R"([])", "clouds: must be an object, got []"},
      {R"({"volumes": [{}]})", "clouds.volumes[0].asset: required: the id POST /v1/assets answered (\"sha256:...\")"},
      {R"({"volumes": [{"asset": ")" + kAsset + R"(", "density_scale": 2}]})",
       "clouds.volumes[0].density_scale: must be a number in [0, 1], got 2"},
      {R"({"volumes": [{"asset": ")" + kAsset + R"(", "grid": ""}]})",
       "clouds.volumes[0].grid: must be a string of 1 to 64 characters, got \"\""},
      {R"({"volumes": [{"asset": ")" + kAsset + R"(", "placement": {"translate_m": [0, 0, 1e6]}}]})",
       "clouds.volumes[0].placement.translate_m[2]: must be a number in [-200000, 200000], got 1000000.0"},
      {R"({"volumes": [{"asset": ")" + kAsset + R"(", "placement": {"offset": 1}}]})",
       "clouds.volumes[0].placement.offset: unknown field (allowed: translate_m, rotate_deg, scale)"},
  };
  for (const auto& [clouds, message] : cases) {
    SCOPED_TRACE(clouds);
    const auto messages = error_messages(body(clouds));
    ASSERT_EQ(messages.size(), 1u) << (messages.empty() ? "parsed" : messages[0]);
    EXPECT_EQ(messages[0], message);
  }
}

TEST(CloudFieldsErrors, LayerAndVolumeCountsAreCapped) {
  std::string layers = R"({"layers": [)";
  for (std::size_t i = 0; i <= kMaxCloudLayers; ++i) layers += std::string(i ? "," : "") + R"({"type": "cirrus"})";
  layers += "]}";
  EXPECT_EQ(error_messages(body(layers)).at(0), "clouds.layers: must have 0 to 8 entries, got 9 entries");
  std::string volumes = R"({"volumes": [)";
  for (std::size_t i = 0; i <= kMaxCloudVolumes; ++i)
    volumes += std::string(i ? "," : "") + R"({"asset": ")" + kAsset + R"("})";
  volumes += "]}";
  EXPECT_EQ(error_messages(body(volumes)).at(0), "clouds.volumes: must have 0 to 16 entries, got 17 entries");
}

TEST(CloudFieldsErrors, EveryErrorOfALayerIsListed) {
  const auto messages = error_messages(body(one_layer(R"("type": "cumulus", "coverage": -1, "erosion": 3, "fog": 1)")));
  ASSERT_EQ(messages.size(), 3u);
  EXPECT_TRUE(messages[0].starts_with("clouds.layers[0].fog: unknown field")) << messages[0];
}

// An invalid clouds member leaves the spec it reads into as it was.
TEST(CloudFieldsErrors, InvalidInputLeavesTheSpecUnchanged) {
  CloudsSpec clouds;
  clouds.layers.resize(2);
  clouds.layers[0].coverage = 0.123;
  for (const std::string text : {one_layer(R"("type": "stratus", "coverage": 1.5)"),
                                 std::string(R"({"layers": [{"type": "stratus"}, {"type": "x"}]})"),
                                 std::string(R"({"layers": [{"type": "stratus"}], "volumes": [{"asset": "x"}]})")}) {
    SCOPED_TRACE(text);
    const Json top = {{"clouds", Json::parse(text)}};
    Errors errors;
    read_clouds(Fields(top, "", errors), clouds);
    EXPECT_FALSE(errors.empty());
    ASSERT_EQ(clouds.layers.size(), 2u);
    EXPECT_EQ(clouds.layers[0].coverage, 0.123);
    EXPECT_EQ(clouds.layers[0].type, CloudType::kCumulus);
    EXPECT_TRUE(clouds.volumes.empty());
  }
}

TEST(CloudFieldsErrors, LutTakesLayersButNotVolumes) {
  const RenderRequest lut = parse_render_request(body(one_layer(R"("type": "stratus")"), R"("method": "lut")"));
  EXPECT_EQ(lut.method, Method::kLut);
  EXPECT_EQ(lut.clouds.layers.size(), 1u);
  const auto messages =
      error_messages(body(R"({"volumes": [{"asset": ")" + kAsset + R"("}]})", R"("method": "lut")"));
  ASSERT_EQ(messages.size(), 1u);
  EXPECT_EQ(messages[0],
            "clouds.volumes: the lut method renders cloud layers only: cloud volumes need \"method\": \"path\"");
}

// --- Canonical form ------------------------------------------------------------

// A clear sky's canonical text has no "clouds", and empty clouds mean the
// same clear sky (the same text, so the same hash and cached result).
TEST(CloudFieldsCanonical, ClearSkyTextIsUnchanged) {
  const std::string clear = canonical_text(parse_render_request(body("")));
  EXPECT_EQ(clear.find("clouds"), std::string::npos) << clear;
  EXPECT_EQ(canonical_text(parse_render_request(body("{}"))), clear);
  EXPECT_EQ(canonical_text(parse_render_request(body(R"({"layers": [], "volumes": []})"))), clear);
  for (const auto& entry : fs::directory_iterator(kExamples)) {
    const std::string name = entry.path().filename().string();
    if (entry.path().extension() != ".json" || name.starts_with("clouds_") || name.starts_with("objects_") ||
        name.starts_with("probe"))
      continue;
    SCOPED_TRACE(name);
    EXPECT_FALSE(to_canonical_json(parse_render_request(read_text(entry.path()))).contains("clouds"));
  }
}

// The canonical text of an example without clouds, byte for byte as the
// parser wrote it before requests had clouds (its hash names cached results).
TEST(CloudFieldsCanonical, ClearSkyExampleKeepsItsTextFromBeforeClouds) {
  const std::string before =
      R"({"atmosphere":{"aerosol":{"angstrom_exponent":1.3,"asymmetry":0.7,"optical_depth_550":0.1,)"
      R"("phase":"henyey_greenstein","single_scattering_albedo":0.9},"ground_albedo":0.2,)"
      R"("ozone_du":320.0,"planet_radius_m":6371000.0,"preset":"earth","top_altitude_m":100000.0},)"
      R"("camera":{"fov_deg":180.0,"height":1024,"pitch_deg":90.0,"projection":"fisheye","roll_deg":0.0,)"
      R"("width":1024,"yaw_deg":0.0},"location":{"altitude_m":35.0,"latitude_deg":48.8566,)"
      R"("longitude_deg":2.3522},"method":"path","output":{"error_layer":true,"exposure_ev":null,)"
      R"("half":true,"spectral_channels":false},"priority":50,"quality":{"samples_per_pixel":256,)"
      R"("target_relative_error":null,"time_limit_s":null},"seed":1,"spectral":{"batches":1,)"
      R"("max_nm":830.0,"min_nm":360.0},"sun":{"angular_radius_deg":0.2666,"azimuth_deg":null,)"
      R"("irradiance":null,"zenith_deg":null},"time":"2021-06-21T11:50:00Z"})";
  EXPECT_EQ(canonical_text(parse_render_request(read_text(kExamples / "noon_fisheye.json"))), before);
}

TEST(CloudFieldsCanonical, EveryFieldIsWrittenResolved) {
  const Json j = to_canonical_json(parse_render_request(body(
      R"({"layers": [{"type": "stratus", "optical_depth": 12}, {"type": "cirrus"}],
          "volumes": [{"asset": ")" + kAsset + R"(", "placement": {"rotate_deg": [270, 0, 0], "scale": 2}}]})")));
  const Json& clouds = j.at("clouds");
  const Json& stratus = clouds.at("layers").at(0);
  for (const char* key : {"type", "coverage", "base_m", "thickness_m", "optical_depth", "effective_radius_um",
                          "particle", "seed", "wind_m_s", "scale_m", "detail_scale_m", "erosion"})
    EXPECT_TRUE(stratus.contains(key)) << key;
  EXPECT_FALSE(stratus.contains("water_content_g_m3"));
  EXPECT_EQ(stratus.at("optical_depth"), 12.0);
  const Json& cirrus = clouds.at("layers").at(1);
  EXPECT_EQ(cirrus.at("water_content_g_m3"), cloud_layer_preset(CloudType::kCirrus).water_content_g_m3);
  EXPECT_EQ(cirrus.at("particle"), "ice");
  const Json& volume = clouds.at("volumes").at(0);
  EXPECT_EQ(volume.at("grid"), "density");
  EXPECT_EQ(volume.at("placement").at("rotate_deg"), Json::array({-90.0, 0.0, 0.0}));
  EXPECT_EQ(volume.at("placement").at("scale"), Json::array({2.0, 2.0, 2.0}));
  EXPECT_EQ(volume.at("particle"), "water");
  // And it reads back to the same text.
  const std::string text = j.dump();
  EXPECT_EQ(canonical_text(parse_render_request(text)), text);
}

// Requests that mean the same clouds give the same text.
TEST(CloudFieldsCanonical, EquivalentSpellingsGiveOneText) {
  EXPECT_EQ(canonical_text(parse_render_request(body(one_layer(R"("type": "cumulus", "wind": {"speed_m_s": 8, "from_deg": 270})")))),
            canonical_text(parse_render_request(body(one_layer(R"("type": "cumulus", "wind_m_s": [8, -0.0])")))));
  EXPECT_EQ(canonical_text(parse_render_request(body(one_layer(R"("type": "stratus")")))),
            canonical_text(parse_render_request(body(one_layer(
                R"("type": "stratus", "coverage": 1, "base_m": 400, "thickness_m": 400, "particle": "water")")))));
}

// --- Beyond the parser ---------------------------------------------------------

TEST(CloudFieldsSpec, RenderSpecCarriesTheClouds) {
  const RenderRequest r = parse_render_request(read_text(kExamples / "clouds_from_orbit.json"));
  const RenderSpec spec = render_spec(r);
  ASSERT_EQ(spec.clouds.layers.size(), 2u);
  EXPECT_EQ(spec.clouds.layers[1].type, CloudType::kCirrus);
  EXPECT_EQ(spec.clouds.layers[0].seed, 11u);
  EXPECT_TRUE(render_spec(parse_render_request(body(""))).clouds.empty());
}

TEST(CloudFieldsTimelapse, EveryFrameHasTheClouds) {
  const TimelapseRequest t = parse_timelapse_request(
      R"({"camera": {"projection": "fisheye", "width": 16, "height": 16},
          "start": "2026-07-15T16:00:00+02:00", "end": "2026-07-15T18:00:00+02:00", "frames": 3,
          "clouds": {"layers": [{"type": "cumulus", "wind": {"speed_m_s": 8, "from_deg": 270}}]}})");
  for (int i = 0; i < t.frame_count; ++i) {
    const RenderRequest frame = t.frame_request(i);
    ASSERT_EQ(frame.clouds.layers.size(), 1u);
    EXPECT_EQ(frame.clouds.layers[0].wind_m_s, glm::dvec2(8.0, 0.0));
    EXPECT_TRUE(to_canonical_json(frame).contains("clouds"));
  }
  EXPECT_TRUE(to_canonical_json(t).contains("clouds"));
  // The errors keep the render request's paths.
  try {
    parse_timelapse_request(R"({"camera": {"projection": "fisheye"}, "start": "2026-07-15T16:00:00Z",
        "end": "2026-07-15T18:00:00Z", "frames": 3, "clouds": {"layers": [{"type": "fog"}]}})");
    ADD_FAILURE() << "parsed";
  } catch (const ValidationError& e) {
    ASSERT_EQ(e.errors().size(), 1u);
    EXPECT_EQ(e.errors()[0].path, "clouds.layers[0].type");
  }
}

}  // namespace
}  // namespace skyfarm::api
