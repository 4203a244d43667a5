// Tests of the render request: the examples in api/examples/, the
// bad requests in api/examples/bad/ with their expected first error, defaults,
// error collection, hostile bodies and the canonical form.
#include "api/render_request.h"
#include "api/probe_request.h"

#include <gtest/gtest.h>

#include "common/assets/mesh_file.h"
#include "common/assets/mesh_import.h"
#include "common/assets/vdb_import.h"
#include "common/assets/volume_file.h"
#include "server/assets/asset_store.h"
#include "tests/support/test_files.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <variant>
#include <vector>

namespace skyfarm::api {
namespace {

namespace fs = std::filesystem;

using skyfarm::testing::kExamples;
using skyfarm::testing::read_text;

// The examples of one kind: probe*.json are probes, the others render requests.
std::vector<fs::path> json_files(const fs::path& dir, bool probes) {
  std::vector<fs::path> out;
  for (const auto& entry : fs::directory_iterator(dir)) {
    const std::string name = entry.path().filename().string();
    if (entry.path().extension() != ".json" || name == "expected_errors.json") continue;
    if (name.starts_with("probe") == probes) out.push_back(entry.path());
  }
  std::sort(out.begin(), out.end());
  return out;
}

// An example's body as the farm would get it: a mesh object's "asset" that
// is a file path (relative to the example's folder; skyfarm-worker render
// reads it) becomes the id POST /v1/assets would answer for that file, the
// SHA-256 of its imported canonical mesh.  A path that does not import is a
// failure here, not a skip.
std::string with_asset_ids(const fs::path& file) {
  nlohmann::json body = nlohmann::json::parse(read_text(file));
  if (!body.is_object() || (!body.contains("objects") && !body.contains("clouds"))) return read_text(file);
  // Cloud volumes likewise: the SHA-256 of the SKYVOL1 file the server's OpenVDB import writes.
  if (body.contains("clouds") && body["clouds"].is_object() && body["clouds"].contains("volumes"))
    for (auto& volume : body["clouds"]["volumes"]) {
      if (!volume.is_object() || !volume.contains("asset") || !volume["asset"].is_string()) continue;
      const std::string asset = volume["asset"].get<std::string>();
      if (server::is_asset_id(asset)) continue;
      const fs::path volume_file = file.parent_path() / asset;
      assets::VolumeGrid grid;
      std::string error;
      EXPECT_TRUE(fs::exists(volume_file)) << volume_file;
      EXPECT_TRUE(assets::import_vdb(read_text(volume_file), volume.value("grid", ""), {}, &grid, &error))
          << volume_file << ": " << error;
      volume["asset"] = "sha256:" + server::sha256_hex(assets::encode_volume_file(grid));
    }
  if (!body.contains("objects") || !body["objects"].is_array()) return body.dump();
  for (auto& object : body["objects"]) {
    if (!object.is_object() || !object.contains("asset") || !object["asset"].is_string()) continue;
    const std::string asset = object["asset"].get<std::string>();
    if (server::is_asset_id(asset)) continue;
    const fs::path mesh_file = file.parent_path() / asset;
    std::string format = mesh_file.extension().string();
    if (!format.empty()) format.erase(0, 1);
    assets::TriangleMesh mesh;
    std::string error;
    EXPECT_TRUE(fs::exists(mesh_file)) << mesh_file;
    EXPECT_TRUE(assets::import_mesh(read_text(mesh_file), format, assets::MeshLimits{}, &mesh, &error))
        << mesh_file << ": " << error;
    object["asset"] = "sha256:" + server::sha256_hex(assets::encode_mesh_file(mesh));
  }
  return body.dump();
}

// The errors a body gets (empty when it parses).
std::vector<FieldError> errors_of(std::string_view body) {
  try {
    parse_render_request(body);
  } catch (const ValidationError& e) {
    return e.errors();
  }
  return {};
}

std::vector<std::string> messages_of(std::string_view body) {
  std::vector<std::string> out;
  for (const auto& e : errors_of(body)) out.push_back(e.message());
  return out;
}

// A valid body with one more top-level member.
std::string with(const std::string& member) {
  return R"({"sun": {"zenith_deg": 30, "azimuth_deg": 180}, "camera": {"projection": "fisheye"})" +
         (member.empty() ? std::string() : ", " + member) + "}";
}

// --- Examples -------------------------------------------------------------

TEST(RenderRequestExamples, EveryGoodExampleParsesAndRoundTrips) {
  const auto files = json_files(kExamples, false);
  ASSERT_GE(files.size(), 5u);
  for (const auto& file : files) {
    SCOPED_TRACE(file.filename().string());
    RenderRequest r;
    ASSERT_NO_THROW(r = parse_render_request(with_asset_ids(file)));
    const std::string canonical = canonical_text(r);
    RenderRequest again;
    ASSERT_NO_THROW(again = parse_render_request(canonical)) << canonical;
    EXPECT_EQ(canonical_text(again), canonical);
  }
}

// The mesh example names a mesh the repository ships, small enough to read.
TEST(RenderRequestExamples, MeshExampleNamesAShippedSmallMesh) {
  const auto body = nlohmann::json::parse(read_text(kExamples / "objects_mesh.json"));
  int meshes = 0;
  for (const auto& object : body.at("objects")) {
    if (object.at("shape") != "mesh") continue;
    ++meshes;
    const fs::path file = kExamples / object.at("asset").get<std::string>();
    SCOPED_TRACE(file.string());
    assets::TriangleMesh mesh;
    std::string error;
    ASSERT_TRUE(assets::import_mesh(read_text(file), "obj", assets::MeshLimits{}, &mesh, &error)) << error;
    EXPECT_GT(mesh.triangle_count(), 12u);
    EXPECT_LE(mesh.triangle_count(), 500u);
  }
  EXPECT_EQ(meshes, 1);
  const RenderRequest r = parse_render_request(with_asset_ids(kExamples / "objects_mesh.json"));
  EXPECT_TRUE(server::is_asset_id(r.objects.at(0).asset)) << r.objects.at(0).asset;
}

TEST(RenderRequestExamples, EveryBadExampleGetsItsExpectedError) {
  const auto expected = nlohmann::json::parse(read_text(kExamples / "bad" / "expected_errors.json"));
  const auto files = json_files(kExamples / "bad", false);
  ASSERT_GE(files.size(), 40u);
  for (const auto& file : files) {
    const std::string name = file.filename().string();
    SCOPED_TRACE(name);
    ASSERT_TRUE(expected.contains(name)) << "no expected error listed";
    const auto errors = errors_of(read_text(file));
    ASSERT_EQ(errors.size(), 1u) << (errors.empty() ? "parsed" : ValidationError(errors).what());
    EXPECT_EQ(errors[0].message(), expected[name].get<std::string>());
  }
}

TEST(RenderRequestExamples, IndexListsOnlyExistingFiles) {
  const auto expected = nlohmann::json::parse(read_text(kExamples / "bad" / "expected_errors.json"));
  for (auto it = expected.begin(); it != expected.end(); ++it)
    EXPECT_TRUE(fs::exists(kExamples / "bad" / it.key())) << it.key();
}

TEST(RenderRequestExamples, SunsetExampleReadsAsWritten) {
  const RenderRequest r = parse_render_request(read_text(kExamples / "sunset_equirect.json"));
  EXPECT_DOUBLE_EQ(r.location.latitude_deg, 42.44);
  EXPECT_DOUBLE_EQ(r.location.longitude_deg, -76.48);
  ASSERT_TRUE(r.time.has_value());
  EXPECT_EQ(r.time->to_iso8601(), "2013-05-28T00:30:00Z");
  EXPECT_EQ(r.time_text, "2013-05-27T20:30:00-04:00");
  EXPECT_EQ(r.camera.projection, Projection::kEquirectangular);
  EXPECT_EQ(r.camera.width, 2048);
  EXPECT_EQ(r.camera.height, 1024);
  ASSERT_TRUE(r.atmosphere.aerosol.has_value());
  EXPECT_DOUBLE_EQ(r.atmosphere.aerosol->optical_depth_550, 0.15);
  EXPECT_EQ(r.spectral.batches, 8);
  EXPECT_EQ(r.quality.target_relative_error, 0.01);
  EXPECT_EQ(r.quality.time_limit_s, 600.0);
  EXPECT_FALSE(r.output.exposure_ev.has_value());
  EXPECT_TRUE(r.output.spectral_channels);
  EXPECT_FALSE(r.output.half);
  EXPECT_EQ(r.seed, 7u);
  EXPECT_EQ(r.priority, 60);
}

TEST(RenderRequestExamples, CustomAtmosphereExampleHasBothConstituents) {
  const RenderRequest r = parse_render_request(read_text(kExamples / "custom_atmosphere.json"));
  const auto& a = r.atmosphere;
  EXPECT_EQ(a.preset, AtmospherePreset::kCustom);
  EXPECT_FALSE(a.aerosol.has_value());
  ASSERT_EQ(a.constituents.size(), 2u);
  EXPECT_EQ(a.constituents[0].name, "air");
  EXPECT_TRUE(std::holds_alternative<ExponentialDensity>(a.constituents[0].density));
  EXPECT_TRUE(std::holds_alternative<RayleighPhaseSpec>(a.constituents[0].phase));
  EXPECT_EQ(a.constituents[1].name, "ozone");
  const auto& layers = std::get<LayersDensity>(a.constituents[1].density).layers;
  ASSERT_EQ(layers.size(), 2u);
  EXPECT_DOUBLE_EQ(layers[0].width_m, 25000.0);
  EXPECT_DOUBLE_EQ(layers[1].constant_term, 8.0 / 3.0);
  EXPECT_TRUE(a.constituents[1].scattering_per_m.wavelengths_nm.empty());
  EXPECT_EQ(a.constituents[1].absorption_per_m.values.size(), 7u);
  EXPECT_TRUE(std::holds_alternative<SpectralTable>(a.ground_albedo));
  EXPECT_EQ(r.method, Method::kLut);
  EXPECT_EQ(r.camera.height, 512);  // derived from width 1024 at 2:1
}

// --- Defaults -------------------------------------------------------------

TEST(RenderRequestDefaults, MinimalRequestGetsEveryDefault) {
  const RenderRequest r = parse_render_request(with(""));
  EXPECT_EQ(r.location.latitude_deg, 0.0);
  EXPECT_EQ(r.location.longitude_deg, 0.0);
  EXPECT_EQ(r.location.altitude_m, 0.0);
  EXPECT_FALSE(r.time.has_value());
  EXPECT_FALSE(r.time_text.has_value());
  EXPECT_EQ(r.sun.zenith_deg, 30.0);
  EXPECT_EQ(r.sun.azimuth_deg, 180.0);
  EXPECT_DOUBLE_EQ(r.sun.angular_radius_deg, 0.2666);
  EXPECT_FALSE(r.sun.irradiance.has_value());
  EXPECT_EQ(r.camera.projection, Projection::kFisheye);
  EXPECT_EQ(r.camera.width, 512);
  EXPECT_EQ(r.camera.height, 512);
  EXPECT_EQ(r.camera.fov_deg, 180.0);
  EXPECT_EQ(r.camera.yaw_deg, 0.0);
  EXPECT_EQ(r.atmosphere.preset, AtmospherePreset::kEarth);
  EXPECT_EQ(r.atmosphere.ozone_du, 300.0);
  ASSERT_TRUE(r.atmosphere.aerosol.has_value());
  EXPECT_EQ(r.atmosphere.aerosol->optical_depth_550, 0.1);
  EXPECT_EQ(r.atmosphere.aerosol->angstrom_exponent, 1.3);
  EXPECT_EQ(r.atmosphere.aerosol->asymmetry, 0.7);
  EXPECT_EQ(r.atmosphere.aerosol->single_scattering_albedo, 0.9);
  EXPECT_EQ(r.atmosphere.aerosol->phase, AerosolPhase::kHenyeyGreenstein);
  EXPECT_EQ(std::get<double>(r.atmosphere.ground_albedo), 0.3);
  EXPECT_EQ(r.atmosphere.planet_radius_m, 6371000.0);
  EXPECT_EQ(r.atmosphere.top_altitude_m, 100000.0);
  EXPECT_EQ(r.spectral.min_nm, 360.0);
  EXPECT_EQ(r.spectral.max_nm, 830.0);
  EXPECT_EQ(r.spectral.batches, 1);
  EXPECT_EQ(r.quality.samples_per_pixel, 64);
  EXPECT_FALSE(r.quality.target_relative_error.has_value());
  EXPECT_FALSE(r.quality.time_limit_s.has_value());
  EXPECT_EQ(r.method, Method::kPath);
  EXPECT_FALSE(r.output.exposure_ev.has_value());
  EXPECT_FALSE(r.output.spectral_channels);
  EXPECT_FALSE(r.output.error_layer);
  EXPECT_TRUE(r.output.half);
  EXPECT_EQ(r.seed, 1u);
  EXPECT_EQ(r.priority, 50);
}

// "1 % in at most 2 minutes": a target error or a time limit without a sample
// count is not capped at the default 64 samples.
TEST(RenderRequestDefaults, TargetOrTimeLimitWithoutSamplesHasNoSampleCap) {
  EXPECT_EQ(parse_render_request(with(R"("quality": {"target_relative_error": 0.01})")).quality.samples_per_pixel,
            QualitySpec::kMaxSamplesPerPixel);
  EXPECT_EQ(parse_render_request(with(R"("quality": {"time_limit_s": 120})")).quality.samples_per_pixel,
            QualitySpec::kMaxSamplesPerPixel);
  EXPECT_EQ(parse_render_request(with(R"("quality": {"target_relative_error": 0.01, "time_limit_s": 120})"))
                .quality.samples_per_pixel,
            QualitySpec::kMaxSamplesPerPixel);
  EXPECT_EQ(parse_render_request(with(R"("quality": {"target_relative_error": 0.01, "samples_per_pixel": 32})"))
                .quality.samples_per_pixel,
            32);
  EXPECT_EQ(parse_render_request(with(R"("quality": {"target_relative_error": null})")).quality.samples_per_pixel,
            64);
  EXPECT_EQ(parse_render_request(with(R"("quality": {})")).quality.samples_per_pixel, 64);
}

TEST(RenderRequestDefaults, SizeAndFieldOfViewFollowTheProjection) {
  auto camera = [](const std::string& c) {
    return parse_render_request(R"({"sun": {"zenith_deg": 30, "azimuth_deg": 0}, "camera": )" + c + "}").camera;
  };
  auto eq = camera(R"({"projection": "equirectangular"})");
  EXPECT_EQ(eq.width, 1024);
  EXPECT_EQ(eq.height, 512);
  EXPECT_EQ(eq.fov_deg, 360.0);
  auto persp = camera(R"({"projection": "perspective"})");
  EXPECT_EQ(persp.width, 960);
  EXPECT_EQ(persp.height, 540);
  EXPECT_EQ(persp.fov_deg, 60.0);
  // A lone side keeps the default aspect.
  auto wide = camera(R"({"projection": "perspective", "width": 1920})");
  EXPECT_EQ(wide.height, 1080);
  auto tall = camera(R"({"projection": "equirectangular", "height": 1000})");
  EXPECT_EQ(tall.width, 2000);
  auto odd = camera(R"({"projection": "equirectangular", "width": 1})");
  EXPECT_EQ(odd.height, 1);
  // Equirectangular ignores fov_deg (but it must still be sensible).
  EXPECT_EQ(camera(R"({"projection": "equirectangular", "fov_deg": 60})").fov_deg, 360.0);
  EXPECT_EQ(camera(R"({"projection": "fisheye", "fov_deg": 220})").fov_deg, 220.0);
  // The largest image allowed.
  auto big = camera(R"({"projection": "equirectangular", "width": 16384, "height": 8192})");
  EXPECT_EQ(big.width * static_cast<long long>(big.height), 16384LL * 8192);
}

TEST(RenderRequestDefaults, EarthClearHasNoAerosolUnlessGiven) {
  auto atmosphere = [](const std::string& a) {
    return parse_render_request(with(R"("atmosphere": )" + a)).atmosphere;
  };
  EXPECT_FALSE(atmosphere(R"({"preset": "earth_clear"})").aerosol.has_value());
  EXPECT_TRUE(atmosphere(R"({"preset": "earth_clear", "aerosol": {}})").aerosol.has_value());
  EXPECT_FALSE(atmosphere(R"({"preset": "earth", "aerosol": null})").aerosol.has_value());
  const auto a = atmosphere(R"({"aerosol": {"optical_depth_550": 0.3, "phase": "cornette_shanks"}})");
  ASSERT_TRUE(a.aerosol.has_value());
  EXPECT_EQ(a.aerosol->optical_depth_550, 0.3);
  EXPECT_EQ(a.aerosol->asymmetry, 0.7);
  EXPECT_EQ(a.aerosol->phase, AerosolPhase::kCornetteShanks);
}

// "atmosphere.refraction": off by default and then absent from the canonical
// text (every earlier request keeps its hash), written when on; the probe
// reads it through the same atmosphere rules.
TEST(RenderRequestDefaults, RefractionIsOffAndUnwrittenByDefault) {
  const RenderRequest plain = parse_render_request(with(R"("atmosphere": {})"));
  EXPECT_FALSE(plain.atmosphere.refraction);
  EXPECT_EQ(canonical_text(plain).find("refraction"), std::string::npos);
  const RenderRequest off = parse_render_request(with(R"("atmosphere": {"refraction": false})"));
  EXPECT_EQ(canonical_text(off), canonical_text(plain));
  const RenderRequest on = parse_render_request(with(R"("atmosphere": {"refraction": true})"));
  EXPECT_TRUE(on.atmosphere.refraction);
  EXPECT_NE(canonical_text(on).find(R"("refraction":true)"), std::string::npos);
  EXPECT_TRUE(parse_render_request(canonical_text(on)).atmosphere.refraction) << "round trip";
  EXPECT_TRUE(parse_probe_request(R"({"sun": {"zenith_deg": 90.5, "azimuth_deg": 0},
      "atmosphere": {"refraction": true}, "directions": [{"zenith_deg": 90, "azimuth_deg": 0}],
      "wavelengths_nm": [550]})")
                  .atmosphere.refraction);
}

TEST(RenderRequestDefaults, NullMeansAbsentForFieldsWithoutADefaultValue) {
  const RenderRequest r = parse_render_request(with(
      R"("time": "2013-05-27T09:30:00-04:00", "quality": {"target_relative_error": null, "time_limit_s": null},
         "output": {"exposure_ev": null})"));
  EXPECT_FALSE(r.quality.target_relative_error.has_value());
  EXPECT_FALSE(r.output.exposure_ev.has_value());
  EXPECT_TRUE(r.time.has_value());
  // "time": null with sun angles is a request without a time.
  EXPECT_FALSE(parse_render_request(with(R"("time": null)")).time.has_value());
}

// --- Errors ---------------------------------------------------------------

TEST(RenderRequestErrors, CollectsEveryInvalidField) {
  const auto m = messages_of(R"({
    "location": {"latitude_deg": 91, "longitude_deg": "west"},
    "sun": {"zenith_deg": 30, "azimuth_deg": 180},
    "camera": {"projection": "fisheye", "width": -3, "lens": "wide"},
    "spectral": {"batches": 65},
    "seed": -1, "priority": 101})");
  const std::vector<std::string> expected = {
      "location.latitude_deg: must be a number in [-90, 90], got 91",
      "location.longitude_deg: must be a number, got \"west\"",
      "camera.lens: unknown field (allowed: projection, width, height, yaw_deg, pitch_deg, roll_deg, fov_deg)",
      "camera.width: must be an integer in [1, 16384], got -3",
      "spectral.batches: must be an integer in [1, 64], got 65",
      "seed: must be an integer in [0, 18446744073709551615], got -1",
      "priority: must be an integer in [0, 100], got 101",
  };
  EXPECT_EQ(m, expected);
}

TEST(RenderRequestErrors, WhatListsEveryErrorOnItsOwnLine) {
  try {
    parse_render_request(R"({"camera": {"projection": "fisheye"}, "seed": "x", "priority": "y"})");
    FAIL() << "accepted";
  } catch (const ValidationError& e) {
    EXPECT_STREQ(e.what(),
                 "time: required unless sun.zenith_deg and sun.azimuth_deg are given\n"
                 "seed: must be an integer, got \"x\"\n"
                 "priority: must be an integer, got \"y\"");
  }
}

TEST(RenderRequestErrors, UnknownFieldsAreRejectedAtEveryLevel) {
  for (const auto& [body, message] : std::vector<std::pair<std::string, std::string>>{
           {with(R"("colour": 1)"),
            "colour: unknown field (allowed: location, time, sun, camera, atmosphere, spectral, quality, method, "
            "output, seed, priority, objects, clouds, name)"},
           {with(R"("quality": {"spp": 4})"),
            "quality.spp: unknown field (allowed: samples_per_pixel, target_relative_error, time_limit_s, adaptive)"},
           {with(R"("output": {"png": true})"),
            "output.png: unknown field (allowed: exposure_ev, spectral_channels, error_layer, half, color_space, units, "
            "view)"},
           {with(R"("spectral": {"step_nm": 5})"), "spectral.step_nm: unknown field (allowed: min_nm, max_nm, batches)"},
           {with(R"("atmosphere": {"aerosol": {"type": "urban"}})"),
            "atmosphere.aerosol.type: unknown field (allowed: optical_depth_550, angstrom_exponent, asymmetry, "
            "single_scattering_albedo, phase)"},
           {R"({"sun": {"zenith_deg": 30, "azimuth_deg": 180, "elevation_deg": 60}, "camera": {"projection": "fisheye"}})",
            "sun.elevation_deg: unknown field (allowed: zenith_deg, azimuth_deg, angular_radius_deg, irradiance)"},
       }) {
    EXPECT_EQ(messages_of(body), std::vector<std::string>{message}) << body;
  }
}

TEST(RenderRequestErrors, WrongTypesNameTheExpectedType) {
  EXPECT_EQ(messages_of(with(R"("location": {"latitude_deg": "north"})")),
            std::vector<std::string>{"location.latitude_deg: must be a number, got \"north\""});
  EXPECT_EQ(messages_of(with(R"("location": {"latitude_deg": true})")),
            std::vector<std::string>{"location.latitude_deg: must be a number, got true"});
  EXPECT_EQ(messages_of(with(R"("location": {"latitude_deg": null})")),
            std::vector<std::string>{"location.latitude_deg: must be a number, got null"});
  EXPECT_EQ(messages_of(with(R"("location": {"latitude_deg": [1, 2]})")),
            std::vector<std::string>{"location.latitude_deg: must be a number, got [1,2]"});
  EXPECT_EQ(messages_of(with(R"("output": {"half": "yes"})")),
            std::vector<std::string>{"output.half: must be a boolean, got \"yes\""});
  EXPECT_EQ(messages_of(with(R"("method": 1)")), std::vector<std::string>{"method: must be one of path, lut, got 1"});
  EXPECT_EQ(messages_of(with(R"("atmosphere": null)")),
            std::vector<std::string>{"atmosphere: must be an object, got null"});
}

TEST(RenderRequestErrors, IntegersMayBeWrittenWithAZeroFraction) {
  const RenderRequest r = parse_render_request(
      R"({"sun": {"zenith_deg": 30, "azimuth_deg": 180}, "camera": {"projection": "fisheye", "width": 3.0, "height": 2e2},
          "seed": 1e3, "priority": 7.0})");
  EXPECT_EQ(r.camera.width, 3);
  EXPECT_EQ(r.camera.height, 200);
  EXPECT_EQ(r.seed, 1000u);
  EXPECT_EQ(r.priority, 7);
  EXPECT_EQ(messages_of(with(R"("priority": 3.5)")), std::vector<std::string>{"priority: must be an integer, got 3.5"});
}

TEST(RenderRequestErrors, SunAnglesBothOrNeither) {
  const std::string camera = R"("camera": {"projection": "fisheye"})";
  const std::string time = R"("time": "2013-05-27T09:30:00-04:00")";
  // Both, or neither with a time: fine.
  EXPECT_TRUE(messages_of("{" + camera + R"(, "sun": {"zenith_deg": 0, "azimuth_deg": 360}})").empty());
  EXPECT_TRUE(messages_of("{" + camera + ", " + time + R"(, "sun": {"angular_radius_deg": 0}})").empty());
  EXPECT_TRUE(messages_of("{" + camera + ", " + time + R"(, "sun": {"zenith_deg": null, "azimuth_deg": null}})").empty());
  // One alone: one error, with or without a time.
  EXPECT_EQ(messages_of("{" + camera + ", " + time + R"(, "sun": {"zenith_deg": 10}})"),
            std::vector<std::string>{"sun.azimuth_deg: required when sun.zenith_deg is given"});
  EXPECT_EQ(messages_of("{" + camera + R"(, "sun": {"azimuth_deg": 10}})"),
            std::vector<std::string>{"sun.zenith_deg: required when sun.azimuth_deg is given"});
  // Neither and no time: "now" is never a default.
  EXPECT_EQ(messages_of("{" + camera + R"(, "sun": {}})"),
            std::vector<std::string>{"time: required unless sun.zenith_deg and sun.azimuth_deg are given"});
  EXPECT_EQ(messages_of("{" + camera + R"(, "time": null})"),
            std::vector<std::string>{"time: required unless sun.zenith_deg and sun.azimuth_deg are given"});
  // Angles given with a time: both kept (the angles replace the computed position).
  const RenderRequest r = parse_render_request("{" + camera + ", " + time + R"(, "sun": {"zenith_deg": 10, "azimuth_deg": 20}})");
  EXPECT_TRUE(r.time.has_value());
  EXPECT_EQ(r.sun.zenith_deg, 10.0);
}

TEST(RenderRequestErrors, TimeRules) {
  const RenderRequest r = parse_render_request(with(R"("time": "2013-05-27T09:30:00-04:00")"));
  ASSERT_TRUE(r.time.has_value());
  EXPECT_EQ(r.time->to_iso8601(), "2013-05-27T13:30:00Z");
  EXPECT_TRUE(messages_of(with(R"("time": "1800-01-01T00:00:00Z")")).empty());
  EXPECT_TRUE(messages_of(with(R"("time": "2200-12-31T23:59:59Z")")).empty());
  EXPECT_EQ(messages_of(with(R"("time": "2201-01-01T00:00:00Z")")),
            std::vector<std::string>{"time: year must be in [1800, 2200], got \"2201-01-01T00:00:00Z\""});
  const auto m = messages_of(with(R"("time": "2013-02-29T00:00:00Z")"));
  ASSERT_EQ(m.size(), 1u);
  EXPECT_TRUE(m[0].starts_with("time: must be ISO 8601 with a UTC offset (")) << m[0];
}

TEST(RenderRequestErrors, PresetRestrictions) {
  const std::string air = R"({"name": "air", "density": {"type": "exponential", "scale_height_m": 8000},
      "scattering_per_m": {"wavelengths_nm": [550], "values": [1.3e-5]}, "phase": {"type": "rayleigh"}})";
  EXPECT_TRUE(messages_of(with(R"("atmosphere": {"preset": "custom", "constituents": [)" + air + "]}")).empty());
  EXPECT_EQ(messages_of(with(R"("atmosphere": {"preset": "custom", "ozone_du": 300, "aerosol": null, "constituents": [)" + air + "]}")),
            (std::vector<std::string>{"atmosphere.ozone_du: not allowed with preset custom, got 300",
                                      "atmosphere.aerosol: not allowed with preset custom, got null"}));
  EXPECT_EQ(messages_of(with(R"("atmosphere": {"preset": "earth_clear", "constituents": [)" + air + "]}")),
            std::vector<std::string>{"atmosphere.constituents: only allowed with preset custom"});
  // With an unknown preset the other fields are still checked, without cascading.
  EXPECT_EQ(messages_of(with(R"("atmosphere": {"preset": "venus", "ozone_du": -1})")),
            (std::vector<std::string>{"atmosphere.preset: must be one of earth, earth_clear, custom, got \"venus\"",
                                      "atmosphere.ozone_du: must be a number in [0, 1000], got -1"}));
}

TEST(RenderRequestErrors, OneEntryTablesAreConstantsExceptTheSunSpectrum) {
  const RenderRequest r = parse_render_request(with(
      R"("atmosphere": {"ground_albedo": {"wavelengths_nm": [550], "values": [1]}})"));
  EXPECT_EQ(std::get<SpectralTable>(r.atmosphere.ground_albedo).values.size(), 1u);
  // The sun's table is 0 outside its range: one entry would be a single line.
  EXPECT_EQ(messages_of(R"({"sun": {"zenith_deg": 30, "azimuth_deg": 180, "irradiance": {"wavelengths_nm": [550], "values": [1.8]}},
                            "camera": {"projection": "fisheye"}})"),
            std::vector<std::string>{"sun.irradiance.wavelengths_nm: must have 2 to 100000 entries, got 1 entry"});
}

// --- Hostile bodies -------------------------------------------------------

TEST(RenderRequestHostile, DepthBombIsOneClearError) {
  for (std::size_t depth : {33u, 100u, 100000u}) {
    const std::string bomb = std::string(depth, '[') + std::string(depth, ']');
    EXPECT_EQ(messages_of(bomb), std::vector<std::string>{"(request): JSON nested deeper than 32 levels"});
    EXPECT_EQ(messages_of(with(R"("camera2": )" + bomb)),
              std::vector<std::string>{"(request): JSON nested deeper than 32 levels"});
  }
  // An unterminated bomb too (the depth is seen before the end of input).
  EXPECT_EQ(messages_of(std::string(1000000, '[')), std::vector<std::string>{"(request): JSON nested deeper than 32 levels"});
  // 32 levels are read normally (and this one is an unknown field).
  const std::string deep = R"({"x": )" + std::string(31, '[') + std::string(31, ']') + "}";
  const auto m = messages_of(deep);
  ASSERT_FALSE(m.empty());
  EXPECT_TRUE(m[0].starts_with("x: unknown field")) << m[0];
}

TEST(RenderRequestHostile, BodyThatIsNotAnObject) {
  EXPECT_EQ(messages_of("[]"), std::vector<std::string>{"(request): must be a JSON object, got []"});
  EXPECT_EQ(messages_of("3"), std::vector<std::string>{"(request): must be a JSON object, got 3"});
  EXPECT_EQ(messages_of("null"), std::vector<std::string>{"(request): must be a JSON object, got null"});
  EXPECT_EQ(messages_of("\"render\""), std::vector<std::string>{"(request): must be a JSON object, got \"render\""});
  // The json overload has the same rule.
  try {
    parse_render_request(nlohmann::json::array({1, 2}));
    FAIL() << "accepted";
  } catch (const ValidationError& e) {
    EXPECT_EQ(e.errors().at(0).message(), "(request): must be a JSON object, got [1,2]");
  }
}

TEST(RenderRequestHostile, MalformedJsonIsOneErrorWithEmptyPath) {
  for (const std::string body : {"", "{", "{\"camera\": }", "{} {}", "{'a': 1}", "{\"a\": NaN}", "{\"a\": Infinity}",
                                 "\xff\xfe", "{\"a\": \"\xc3\x28\"}", "{\"a\": 01}", "/* c */ {}"}) {
    const auto errors = errors_of(body);
    ASSERT_EQ(errors.size(), 1u) << body;
    EXPECT_EQ(errors[0].path, "");
    EXPECT_TRUE(errors[0].rule.starts_with("malformed JSON: parse error at line ")) << errors[0].rule;
  }
}

TEST(RenderRequestHostile, GiantAndNonFiniteNumbers) {
  EXPECT_EQ(parse_render_request(with(R"("seed": 18446744073709551615)")).seed, 18446744073709551615u);
  EXPECT_EQ(parse_render_request(with(R"("seed": 0)")).seed, 0u);
  EXPECT_EQ(messages_of(with(R"("seed": 18446744073709551616)")),
            std::vector<std::string>{"seed: must be an integer in [0, 18446744073709551615], got 1.8446744073709552e+19"});
  EXPECT_EQ(messages_of(with(R"("seed": -9223372036854775809)")),
            std::vector<std::string>{"seed: must be an integer in [0, 18446744073709551615], got -9.223372036854776e+18"});
  EXPECT_EQ(messages_of(with(R"("priority": 99999999999999999999999999999)")),
            std::vector<std::string>{"priority: must be an integer in [0, 100], got 1e+29"});
  EXPECT_EQ(messages_of(with(R"("priority": 18446744073709551615)")),
            std::vector<std::string>{"priority: must be an integer in [0, 100], got 18446744073709551615"});
  EXPECT_EQ(messages_of(with(R"("priority": -9223372036854775808)")),
            std::vector<std::string>{"priority: must be an integer in [0, 100], got -9223372036854775808"});
  EXPECT_EQ(messages_of(with(R"("priority": 1e400)")),
            std::vector<std::string>{"priority: must be a finite number, got 1e400"});
  // Such a number stops the parse: it is the only error listed.
  EXPECT_EQ(messages_of(R"({"camera": 1, "sun": {"irradiance": {"wavelengths_nm": [500], "values": [-1e999]}}})"),
            std::vector<std::string>{"sun.irradiance.values[0]: must be a finite number, got -1e999"});
  EXPECT_EQ(messages_of(with(R"("location": {"altitude_m": -1e999})")),
            std::vector<std::string>{"location.altitude_m: must be a finite number, got -1e999"});
  EXPECT_EQ(messages_of(with(R"("location": {"altitude_m": 1e300})")),
            std::vector<std::string>{"location.altitude_m: must be a number in [0, 100000000], got 1e+300"});
  EXPECT_EQ(messages_of(with(R"("location": {"latitude_deg": 1e-400})")), std::vector<std::string>{});
  // Through the json overload a NaN can arrive; it is named as such.
  nlohmann::json body = nlohmann::json::parse(with(""));
  body["location"]["latitude_deg"] = std::nan("");
  try {
    parse_render_request(body);
    FAIL() << "accepted";
  } catch (const ValidationError& e) {
    EXPECT_EQ(e.errors().at(0).message(), "location.latitude_deg: must be a finite number, got NaN");
  }
}

TEST(RenderRequestHostile, DuplicateKeysAreErrors) {
  EXPECT_EQ(messages_of(R"({"sun": {"zenith_deg": 30, "azimuth_deg": 180, "zenith_deg": 40}, "camera": {"projection": "fisheye"}})"),
            std::vector<std::string>{"sun.zenith_deg: duplicate field"});
}

TEST(RenderRequestHostile, HugeValuesAreQuotedShortly) {
  const std::string big(100000, 'x');
  const auto m = messages_of(with(R"("method": ")" + big + "\""));
  ASSERT_EQ(m.size(), 1u);
  EXPECT_LT(m[0].size(), 200u);
  const auto k = messages_of(with("\"" + big + "\": 1"));
  ASSERT_EQ(k.size(), 1u);
  EXPECT_LT(k[0].size(), 400u);
  const auto unterminated = messages_of(R"({"camera": ")" + big);
  ASSERT_EQ(unterminated.size(), 1u);
  EXPECT_LT(unterminated[0].size(), 400u);
  std::string array = "[";
  for (int i = 0; i < 100000; ++i) array += (i ? ",1" : "1");
  array += "]";
  const auto a = messages_of(with(R"("seed": )" + array));
  ASSERT_EQ(a.size(), 1u);
  EXPECT_LT(a[0].size(), 200u);
}

TEST(RenderRequestHostile, MessagesAreSafeToEmbedInJson) {
  // Through the json overload keys and strings may hold anything.
  nlohmann::json body = nlohmann::json::parse(with(""));
  body["a\nb\xff"] = 1;
  body["time"] = "2013-05-27T09:30:00+01:00\n\xff";
  try {
    parse_render_request(body);
    FAIL() << "accepted";
  } catch (const ValidationError& e) {
    const std::string what = e.what();
    ASSERT_EQ(e.errors().size(), 2u) << what;
    EXPECT_EQ(std::count(what.begin(), what.end(), '\n'), 1);  // the line break between the two errors
    EXPECT_NO_THROW((void)nlohmann::json(what).dump());
  }
}

TEST(RenderRequestHostile, ErrorListIsCapped) {
  std::string body = R"({"sun": {"zenith_deg": 30, "azimuth_deg": 180}, "camera": {"projection": "fisheye"})";
  for (int i = 0; i < 1000; ++i) body += ", \"x" + std::to_string(i) + "\": 1";
  body += "}";
  const auto errors = errors_of(body);
  ASSERT_EQ(errors.size(), kMaxErrors + 1);
  EXPECT_EQ(errors.back().message(), "(request): too many errors; only the first 100 are listed");
}

TEST(RenderRequestHostile, MutatedExamplesNeverThrowAnythingElse) {
  std::mt19937 rng(12345);
  const auto files = json_files(kExamples, false);
  const std::string alphabet = "{}[]\",:0123456789.eE+-aeflnrstux \\";
  int accepted = 0, rejected = 0;
  for (int i = 0; i < 3000; ++i) {
    std::string text = read_text(files[i % files.size()]);
    const int edits = 1 + static_cast<int>(rng() % 4);
    for (int k = 0; k < edits && !text.empty(); ++k) {
      const std::size_t at = rng() % text.size();
      switch (rng() % 4) {
        case 0: text[at] = alphabet[rng() % alphabet.size()]; break;
        case 1: text.erase(at, 1 + rng() % 8); break;
        case 2: text.insert(at, 1, alphabet[rng() % alphabet.size()]); break;
        default: text.resize(at); break;
      }
    }
    try {
      const RenderRequest r = parse_render_request(text);
      EXPECT_EQ(canonical_text(parse_render_request(canonical_text(r))), canonical_text(r));
      ++accepted;
    } catch (const ValidationError& e) {
      EXPECT_FALSE(e.errors().empty());
      ++rejected;
    } catch (...) {
      ADD_FAILURE() << "non-ValidationError exception for: " << text;
    }
  }
  EXPECT_GT(rejected, 0);
  EXPECT_GT(accepted + rejected, 0);
}

// --- Canonical form -------------------------------------------------------

TEST(RenderRequestCanonical, SameMeaningSameText) {
  auto text = [](const std::string& body) { return canonical_text(parse_render_request(body)); };
  // Defaults written out or left out, key order, 42 vs 42.0, the UTC offset.
  EXPECT_EQ(text(R"({"time": "2013-05-27T09:30:00-04:00", "camera": {"projection": "fisheye"}})"),
            text(R"({"seed": 1, "camera": {"width": 512.0, "projection": "fisheye", "fov_deg": 180},
                     "location": {"latitude_deg": 0.0, "longitude_deg": -0.0}, "time": "2013-05-27T13:30Z",
                     "method": "path", "priority": 50, "output": {"exposure_ev": null, "half": true},
                     "atmosphere": {"preset": "earth", "ozone_du": 300, "aerosol": {"optical_depth_550": 0.1}},
                     "spectral": {"min_nm": 360, "max_nm": 830, "batches": 1},
                     "quality": {"samples_per_pixel": 64, "target_relative_error": null}})"));
  // earth_clear is earth without aerosols.
  EXPECT_EQ(text(with(R"("atmosphere": {"preset": "earth_clear"})")),
            text(with(R"("atmosphere": {"preset": "earth", "aerosol": null})")));
  // Angles with the same meaning; equirectangular ignores fov_deg.
  EXPECT_EQ(text(R"({"sun": {"zenith_deg": 30, "azimuth_deg": 360}, "camera": {"projection": "equirectangular", "yaw_deg": -90, "roll_deg": -180, "fov_deg": 10}})"),
            text(R"({"sun": {"zenith_deg": 30, "azimuth_deg": 0}, "camera": {"projection": "equirectangular", "yaw_deg": 270, "roll_deg": 180}})"));
  // Different meaning, different text.
  EXPECT_NE(text(with(R"("seed": 1)")), text(with(R"("seed": 2)")));
  EXPECT_NE(text(with(R"("atmosphere": {"preset": "earth"})")), text(with(R"("atmosphere": {"preset": "earth_clear"})")));
}

TEST(RenderRequestCanonical, EveryFieldIsPresent) {
  const nlohmann::json c = to_canonical_json(parse_render_request(with("")));
  for (const char* key : {"location", "time", "sun", "camera", "atmosphere", "spectral", "quality", "method", "output",
                          "seed", "priority"})
    EXPECT_TRUE(c.contains(key)) << key;
  EXPECT_TRUE(c["time"].is_null());
  EXPECT_EQ(c["camera"]["width"], 512);
  EXPECT_TRUE(c["camera"]["width"].is_number_integer());
  EXPECT_EQ(c["atmosphere"]["preset"], "earth");
  EXPECT_EQ(c["atmosphere"]["aerosol"]["phase"], "henyey_greenstein");
  EXPECT_TRUE(c["quality"]["time_limit_s"].is_null());
  EXPECT_EQ(c["output"]["half"], true);
  EXPECT_EQ(c["seed"], 1u);
  EXPECT_EQ(c["sun"]["angular_radius_deg"], 0.2666);
  EXPECT_TRUE(c["sun"]["irradiance"].is_null());
}

// "quality.adaptive" (sample_allocation.h) is in the canonical text only
// when true, so requests written before it keep their text and hash.
TEST(RenderRequestCanonical, AdaptiveOnlyWhenAsked) {
  const RenderRequest plain = parse_render_request(with(R"("quality": {"samples_per_pixel": 64})"));
  EXPECT_FALSE(plain.quality.adaptive);
  EXPECT_FALSE(to_canonical_json(plain)["quality"].contains("adaptive"));
  EXPECT_EQ(canonical_text(plain), canonical_text(parse_render_request(with(R"("quality": {"adaptive": false})"))));
  const RenderRequest adaptive = parse_render_request(with(R"("quality": {"adaptive": true})"));
  EXPECT_TRUE(adaptive.quality.adaptive);
  EXPECT_EQ(to_canonical_json(adaptive)["quality"]["adaptive"], true);
  EXPECT_EQ(parse_render_request(canonical_text(adaptive)).quality.adaptive, true);
  const std::vector<FieldError> errors = errors_of(with(R"("quality": {"adaptive": "yes"})"));
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_EQ(errors[0].path, "quality.adaptive");
}

// output.color_space, output.units and output.view (color_management.h):
// every name parses, defaults stay out of the canonical text (so requests
// written before them keep their hash), and a bad name is an error naming the field.
TEST(RenderRequestOutputColor, NamesParseAndDefaultsStayOutOfTheCanonicalText) {
  const RenderRequest plain = parse_render_request(with(""));
  EXPECT_EQ(plain.output.color_space, ColorSpace::kLinRec709);
  EXPECT_EQ(plain.output.units, RadiometricUnits::kCdM2);
  EXPECT_EQ(plain.output.view, DisplayView::kSrgb);
  const nlohmann::json c = to_canonical_json(plain);
  for (const char* key : {"color_space", "units", "view"}) EXPECT_FALSE(c["output"].contains(key)) << key;
  EXPECT_EQ(canonical_text(plain), canonical_text(parse_render_request(with(
                                       R"("output": {"color_space": "lin_rec709", "units": "cd_m2", "view": "srgb"})"))));

  const std::pair<const char*, ColorSpace> spaces[] = {{"acescg", ColorSpace::kAcesCg},
                                                       {"aces2065-1", ColorSpace::kAces2065_1},
                                                       {"cie_xyz", ColorSpace::kCieXyz}};
  for (const auto& [name, space] : spaces) {
    const RenderRequest r = parse_render_request(with(std::string(R"("output": {"color_space": ")") + name + "\"}"));
    EXPECT_EQ(r.output.color_space, space) << name;
    EXPECT_EQ(to_canonical_json(r)["output"]["color_space"], name);
    EXPECT_EQ(parse_render_request(canonical_text(r)).output.color_space, space) << name;
    EXPECT_NE(canonical_text(r), canonical_text(plain)) << name;
  }
  const RenderRequest r = parse_render_request(with(R"("output": {"units": "relative", "view": "aces"})"));
  EXPECT_EQ(r.output.units, RadiometricUnits::kRelative);
  EXPECT_EQ(r.output.view, DisplayView::kAces);
  EXPECT_EQ(to_canonical_json(r)["output"]["units"], "relative");
  EXPECT_EQ(to_canonical_json(r)["output"]["view"], "aces");
  EXPECT_EQ(parse_render_request(with(R"("output": {"units": "w_m2_sr"})")).output.units, RadiometricUnits::kWM2Sr);
}

TEST(RenderRequestOutputColor, UnknownNamesAreErrorsNamingTheField) {
  EXPECT_EQ(messages_of(with(R"("output": {"color_space": "srgb"})")),
            std::vector<std::string>{
                "output.color_space: must be one of lin_rec709, acescg, aces2065-1, cie_xyz, got \"srgb\""});
  EXPECT_EQ(messages_of(with(R"("output": {"units": "nits"})")),
            std::vector<std::string>{"output.units: must be one of cd_m2, relative, w_m2_sr, got \"nits\""});
  EXPECT_EQ(messages_of(with(R"("output": {"view": "agx"})")),
            std::vector<std::string>{"output.view: must be one of srgb, aces, got \"agx\""});
  const std::vector<FieldError> errors = errors_of(with(R"("output": {"color_space": 709})"));
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_EQ(errors[0].path, "output.color_space");
}

TEST(RenderRequestCanonical, CustomAtmosphereKeepsOnlyItsFields) {
  const nlohmann::json c = to_canonical_json(parse_render_request(read_text(kExamples / "custom_atmosphere.json")));
  const auto& a = c["atmosphere"];
  EXPECT_EQ(a["preset"], "custom");
  EXPECT_FALSE(a.contains("ozone_du"));
  EXPECT_FALSE(a.contains("aerosol"));
  ASSERT_EQ(a["constituents"].size(), 2u);
  EXPECT_TRUE(a["constituents"][0]["absorption_per_m"].is_null());
  EXPECT_TRUE(a["constituents"][1]["scattering_per_m"].is_null());
  EXPECT_TRUE(a["constituents"][1]["phase"].is_null());  // no scattering: no phase
  EXPECT_EQ(a["constituents"][1]["density"]["layers"].size(), 2u);
}

}  // namespace
}  // namespace skyfarm::api

namespace skyfarm::api {
namespace {

// "atmosphere.ground": named materials get their kind, custom ones their
// tables; the canonical text round-trips and a request without a ground
// material writes no "ground" (its hash, and so its seed, is unchanged).
TEST(GroundMaterial, NamedAndCustomMaterialsParseAndRoundTrip) {
  const RenderRequest water = parse_render_request(
      with(R"("atmosphere": {"ground": {"material": {"name": "water", "roughness": 0.05}}})"));
  ASSERT_TRUE(water.atmosphere.ground_material);
  EXPECT_EQ(water.atmosphere.ground_material->kind, material::MaterialKind::kDielectric);
  EXPECT_FALSE(water.atmosphere.ground_material->custom);
  EXPECT_EQ(water.atmosphere.ground_material->roughness_x, 0.05);
  EXPECT_TRUE(water.atmosphere.ground_material->multiple_bounce);

  const RenderRequest paint = parse_render_request(with(
      R"("atmosphere": {"ground": {"material": {"name": "paint", "kind": "diffuse", "wavelengths_nm": [400, 700],)"
      R"( "albedo": [0.2, 0.6], "roughness": [0.3, 0.1], "distribution": "beckmann", "multiple_bounce": false}}})"));
  ASSERT_TRUE(paint.atmosphere.ground_material);
  const material::SurfaceSpec& s = *paint.atmosphere.ground_material;
  EXPECT_TRUE(s.custom);
  EXPECT_EQ(s.kind, material::MaterialKind::kDiffuse);
  EXPECT_EQ(s.albedo, (std::vector<double>{0.2, 0.6}));
  EXPECT_EQ(s.roughness_x, 0.3);
  EXPECT_EQ(s.roughness_y, 0.1);
  EXPECT_EQ(s.distribution, material::MicrofacetModel::beckmann);
  EXPECT_FALSE(s.multiple_bounce);

  for (const RenderRequest* r : {&water, &paint}) {
    const std::string canonical = canonical_text(*r);
    EXPECT_EQ(canonical_text(parse_render_request(canonical)), canonical);
    EXPECT_TRUE(to_canonical_json(*r)["atmosphere"].contains("ground"));
  }
  EXPECT_FALSE(to_canonical_json(parse_render_request(with("")))["atmosphere"].contains("ground"));
}

TEST(GroundMaterial, EveryBadMaterialIsAnErrorNamingItsField) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {R"({"name": "unobtainium"})", "atmosphere.ground.material.name"},
      {R"({"name": "gold", "roughness": 3})", "atmosphere.ground.material.roughness"},
      {R"({"name": "gold", "roughness": 0.0001})", "atmosphere.ground.material.roughness"},
      {R"({"name": "gold", "roughness": [0.1, 0]})", "atmosphere.ground.material.roughness"},
      {R"({"name": "gold", "kind": "conductor"})", "atmosphere.ground.material.kind"},
      {R"({"name": "gold", "distribution": "phong"})", "atmosphere.ground.material.distribution"},
      {R"({"name": "gold", "shininess": 3})", "atmosphere.ground.material.shininess"},
      {R"({"roughness": 0.2})", "atmosphere.ground.material.name"},
      {R"({"kind": "conductor", "wavelengths_nm": [400, 700], "n": [0.2, 0.3], "k": [3]})",
       "atmosphere.ground.material.k"},
      {R"({"kind": "conductor", "wavelengths_nm": [400, 700], "n": [0.2, 0.3]})", "atmosphere.ground.material.k"},
      {R"({"kind": "dielectric", "wavelengths_nm": [400, 700], "n": [0.5, 1.5]})",
       "atmosphere.ground.material.n[0]"},
      {R"({"kind": "conductor", "wavelengths_nm": [400, 700], "n": [-1, 0.3], "k": [3, 3]})",
       "atmosphere.ground.material.n[0]"},
      {R"({"kind": "diffuse", "wavelengths_nm": [700, 400], "albedo": [0.2, 0.3]})",
       "atmosphere.ground.material.wavelengths_nm[1]"},
      {R"({"kind": "diffuse", "wavelengths_nm": [400, 700], "albedo": [0.2, 1.3]})",
       "atmosphere.ground.material.albedo[1]"},
      {R"({"kind": "diffuse", "wavelengths_nm": [400, 700], "n": [1.5, 1.5], "albedo": [0.2, 0.3]})",
       "atmosphere.ground.material.n"},
      {R"({"kind": "metal", "wavelengths_nm": [400, 700], "n": [1, 1], "k": [1, 1]})",
       "atmosphere.ground.material.kind"},
  };
  for (const auto& [material, field] : cases) {
    const auto errors = errors_of(with(R"("atmosphere": {"ground": {"material": )" + material + "}}"));
    ASSERT_FALSE(errors.empty()) << material;
    bool named = false;
    for (const auto& e : errors) named = named || e.path == field;
    EXPECT_TRUE(named) << material << " -> " << errors.front().message();
  }
  EXPECT_FALSE(errors_of(with(R"("atmosphere": {"ground": {}})")).empty());
  EXPECT_FALSE(errors_of(with(R"("atmosphere": {"ground": 0.3})")).empty());
  const auto both = errors_of(with(R"("atmosphere": {"ground_albedo": 0.2, "ground": {"material": {"name": "snow"}}})"));
  ASSERT_EQ(both.size(), 1u);
  EXPECT_EQ(both.front().path, "atmosphere.ground");
}

// "objects": shapes, the Lambertian shorthand, placements and their
// canonical spellings; a request without objects writes none (its hash, and
// so its cached results, are unchanged).
TEST(SceneObjects, ObjectsParseWithDefaultsAndOneCanonicalSpelling) {
  const std::string id = "sha256:" + std::string(64, 'c');
  const RenderRequest r = parse_render_request(with(
      R"("objects": [{"name": "chrome ball", "shape": "sphere", "material": {"name": "chrome"},)"
      R"( "translate_m": [0, 5, 0.5], "scale": 0.5},)"
      R"( {"shape": "box", "albedo": 0.18, "rotate_deg": [350, -90, 180], "scale": [1, 2, -3]},)"
      R"( {"shape": "mesh", "asset": ")" + id + R"("}])"));
  ASSERT_EQ(r.objects.size(), 3u);
  EXPECT_EQ(r.objects[0].name, "chrome ball");
  EXPECT_EQ(r.objects[0].shape, ShapeKind::kSphere);
  EXPECT_EQ(r.objects[0].placement.scale, glm::dvec3(0.5));
  EXPECT_EQ(r.objects[0].placement.translate_m, glm::dvec3(0, 5, 0.5));
  EXPECT_EQ(r.objects[0].material.kind, material::MaterialKind::kConductor);
  EXPECT_EQ(r.objects[1].placement.rotate_deg, glm::dvec3(-10, -90, 180));
  EXPECT_EQ(r.objects[1].placement.scale, glm::dvec3(1, 2, -3));
  EXPECT_EQ(r.objects[1].material.albedo, (std::vector<double>{0.18, 0.18}));
  EXPECT_EQ(r.objects[2].asset, id);
  EXPECT_EQ(r.objects[2].material.albedo, (std::vector<double>{0.5, 0.5}));  // the default
  const Json canonical = to_canonical_json(r);
  ASSERT_TRUE(canonical.contains("objects"));
  EXPECT_EQ(canonical["objects"][1]["albedo"], 0.18);
  EXPECT_EQ(canonical["objects"][0]["scale"], Json::array({0.5, 0.5, 0.5}));
  EXPECT_EQ(canonical_text(parse_render_request(canonical_text(r))), canonical_text(r));
  // The same scene spelled otherwise: the same canonical text.
  const RenderRequest same = parse_render_request(with(
      R"("objects": [{"name": "chrome ball", "shape": "sphere", "material": {"name": "chrome", "roughness": 0},)"
      R"( "translate_m": [0, 5, 0.5], "rotate_deg": [0, 360, -360], "scale": [0.5, 0.5, 0.5]},)"
      R"( {"shape": "box", "albedo": 0.18, "rotate_deg": [-10, 270, -180], "scale": [1, 2, -3]},)"
      R"( {"shape": "mesh", "asset": ")" + id + R"(", "albedo": 0.5}])"));
  EXPECT_EQ(canonical_text(same), canonical_text(r));
  EXPECT_FALSE(to_canonical_json(parse_render_request(with(""))).contains("objects"));
  EXPECT_FALSE(to_canonical_json(parse_render_request(with(R"("objects": [])"))).contains("objects"));
}

TEST(SceneObjects, EveryBadObjectIsAnErrorNamingItsField) {
  const std::string id = "sha256:" + std::string(64, 'c');
  const std::vector<std::pair<std::string, std::string>> cases = {
      {R"({})", "objects[0].shape"},
      {R"({"shape": "torus"})", "objects[0].shape"},
      {R"({"shape": "mesh"})", "objects[0].asset"},
      {R"({"shape": "mesh", "asset": "bunny.obj"})", "objects[0].asset"},
      {R"({"shape": "mesh", "asset": "sha256:ABC"})", "objects[0].asset"},
      {R"({"shape": "sphere", "asset": ")" + id + R"("})", "objects[0].asset"},
      {R"({"shape": "sphere", "albedo": 1.5})", "objects[0].albedo"},
      {R"({"shape": "sphere", "albedo": 0.5, "material": {"name": "gold"}})", "objects[0].albedo"},
      {R"({"shape": "sphere", "material": {"name": "unobtainium"}})", "objects[0].material.name"},
      {R"({"shape": "sphere", "material": "gold"})", "objects[0].material"},
      {R"({"shape": "sphere", "scale": 0})", "objects[0].scale"},
      {R"({"shape": "sphere", "scale": [1, 0, 1]})", "objects[0].scale[1]"},
      {R"({"shape": "sphere", "scale": [1, 1]})", "objects[0].scale"},
      {R"({"shape": "sphere", "scale": "big"})", "objects[0].scale"},
      {R"({"shape": "sphere", "translate_m": [0, 1e9, 0]})", "objects[0].translate_m[1]"},
      {R"({"shape": "sphere", "rotate_deg": [0, 400, 0]})", "objects[0].rotate_deg[1]"},
      {R"({"shape": "sphere", "colour": "red"})", "objects[0].colour"},
      {R"({"shape": "sphere", "name": ""})", "objects[0].name"},
  };
  for (const auto& [object, field] : cases) {
    const auto errors = errors_of(with(R"("objects": [)" + object + "]"));
    ASSERT_FALSE(errors.empty()) << object;
    bool named = false;
    for (const auto& e : errors) named = named || e.path == field;
    EXPECT_TRUE(named) << object << " -> " << errors.front().message();
  }
  EXPECT_FALSE(errors_of(with(R"("objects": {"shape": "sphere"})")).empty());
  EXPECT_FALSE(errors_of(with(R"("objects": [3])")).empty());
  std::string many = R"("objects": [)";
  for (int i = 0; i <= 1000; ++i) many += std::string(i ? "," : "") + R"({"shape": "sphere"})";
  EXPECT_FALSE(errors_of(with(many + "]")).empty());
  const auto lut = errors_of(with(R"("method": "lut", "objects": [{"shape": "sphere"}])"));
  ASSERT_EQ(lut.size(), 1u);
  EXPECT_EQ(lut.front().path, "objects");
}

}  // namespace
}  // namespace skyfarm::api
