// One metadata vocabulary in every image skyfarm writes: a farm render's EXR,
// `skyfarm-worker render`'s EXR, a sky env map and a timelapse frame PNG are
// made on a real server, and each file's skyfarm:* keys are checked against
// the table of docs/exr-metadata.md (parsed here): every key written is
// documented for that output with its type, every key documented "yes" for an
// output is written there, none documented "—" is.  The keys the outputs
// share carry the same names and types everywhere.
#include <gtest/gtest.h>

#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "common/film/image.h"
#include "common/image/exr_writer.h"
#include "common/image/png_writer.h"
#include "tests/farm/farm_process.h"

namespace skyfarm {
namespace {

namespace fs = std::filesystem;
using testing::FarmServer;

enum class Carried { kYes, kIf, kNever };

struct DocumentedKey {
  std::string type;                       // "string" or "number"
  std::map<std::string, Carried> outputs;  // column → presence
};

std::string trimmed(const std::string& s) {
  const auto b = s.find_first_not_of(' '), e = s.find_last_not_of(' ');
  return b == std::string::npos ? std::string() : s.substr(b, e - b + 1);
}

std::vector<std::string> cells(const std::string& row) {
  std::vector<std::string> out;
  std::string cell;
  for (std::size_t i = 1; i < row.size(); ++i) {  // after the leading '|'
    if (row[i] == '|') {
      out.push_back(trimmed(cell));
      cell.clear();
    } else {
      cell += row[i];
    }
  }
  return out;
}

// The key table of docs/exr-metadata.md: the table whose header begins
// "| key | type | unit | meaning |"; the columns after meaning are outputs.
std::map<std::string, DocumentedKey> documented_keys(std::vector<std::string>* outputs) {
  std::ifstream in(fs::path(SKYFARM_SOURCE_DIR) / "docs" / "exr-metadata.md");
  std::map<std::string, DocumentedKey> keys;
  bool in_table = false;
  for (std::string line; std::getline(in, line);) {
    if (!line.starts_with("|")) {
      in_table = false;
      continue;
    }
    const std::vector<std::string> c = cells(line);
    if (c.size() > 4 && c[0] == "key" && c[1] == "type" && c[2] == "unit" && c[3] == "meaning") {
      in_table = true;
      outputs->assign(c.begin() + 4, c.end());
      continue;
    }
    if (!in_table || c.empty() || c[0].starts_with("---")) continue;
    EXPECT_EQ(c.size(), 4 + outputs->size()) << line;
    if (c.size() != 4 + outputs->size() || c[0].size() < 3) continue;
    DocumentedKey k;
    k.type = c[1];
    EXPECT_TRUE(k.type == "string" || k.type == "number") << line;
    for (std::size_t i = 0; i < outputs->size(); ++i) {
      const std::string& v = c[4 + i];
      k.outputs[(*outputs)[i]] = v == "yes" ? Carried::kYes : v.starts_with("if ") ? Carried::kIf : Carried::kNever;
      EXPECT_TRUE(v == "yes" || v == "—" || v.starts_with("if ")) << line;
    }
    const std::string key = c[0].substr(1, c[0].size() - 2);  // inside the backquotes
    EXPECT_TRUE(keys.emplace(key, k).second) << key << " documented twice";
  }
  return keys;
}

// A file's skyfarm:* keys and their types.
using Written = std::map<std::string, std::string>;

Written exr_keys(const std::string& bytes, const fs::path& where) {
  std::ofstream(where, std::ios::binary) << bytes;
  const ExrFile exr = read_exr(where);
  Written w;
  const std::string prefix = kMetadataPrefix;
  for (const auto& [name, value] : exr.string_attributes)
    if (name.starts_with(prefix)) w[name.substr(prefix.size())] = "string";
  for (const auto& [name, value] : exr.number_attributes)
    if (name.starts_with(prefix)) w[name.substr(prefix.size())] = "number";
  return w;
}

// PNG text is text: a documented number must read back as one.
Written png_keys(const std::string& bytes, const fs::path& where, const std::map<std::string, DocumentedKey>& doc) {
  std::ofstream(where, std::ios::binary) << bytes;
  const PngFile png = read_png(where);
  Written w;
  const std::string prefix = kMetadataPrefix;
  for (const auto& [name, value] : png.text) {
    if (!name.starts_with(prefix)) continue;
    const std::string key = name.substr(prefix.size());
    std::string type = "string";
    const auto it = doc.find(key);
    if (it != doc.end() && it->second.type == "number") {
      std::size_t used = 0;
      try {
        (void)std::stod(value, &used);
      } catch (const std::exception&) {
      }
      if (used == value.size() && used > 0) type = "number";
    }
    w[key] = type;
  }
  return w;
}

void check_against_doc(const std::string& output, const Written& written,
                       const std::map<std::string, DocumentedKey>& doc) {
  for (const auto& [key, type] : written) {
    const auto it = doc.find(key);
    if (it == doc.end()) {
      ADD_FAILURE() << output << " writes skyfarm:" << key << ", which docs/exr-metadata.md does not list";
      continue;
    }
    EXPECT_EQ(type, it->second.type) << output << ": skyfarm:" << key;
    EXPECT_NE(it->second.outputs.at(output), Carried::kNever)
        << output << " writes skyfarm:" << key << " but the page says it never does";
  }
  for (const auto& [key, k] : doc) {
    if (k.outputs.at(output) == Carried::kYes) {
      EXPECT_TRUE(written.count(key)) << output << " lacks skyfarm:" << key << " (documented yes)";
    }
  }
}

constexpr const char* kRequest = R"({
  "sun": {"zenith_deg": 60, "azimuth_deg": 100},
  "camera": {"projection": "equirectangular", "width": 16, "height": 8},
  "spectral": {"batches": 2},
  "quality": {"samples_per_pixel": 4},
  "seed": 9
})";

constexpr const char* kTimelapse = R"({
  "location": {"latitude_deg": 42.44, "longitude_deg": -76.48},
  "start": "2013-05-27T17:00:00-04:00", "end": "2013-05-27T18:00:00-04:00", "step_s": 3600,
  "camera": {"projection": "equirectangular", "width": 16, "height": 8},
  "method": "lut"
})";

std::string get_body(const FarmServer& server, const std::string& path) {
  auto c = server.client();
  const auto r = c.Get(path.c_str());
  return r && r->status == 200 ? r->body : std::string();
}

TEST(ExrMetadata, EveryOutputWritesTheDocumentedVocabulary) {
  std::vector<std::string> outputs;
  const auto doc = documented_keys(&outputs);
  ASSERT_EQ(outputs, (std::vector<std::string>{"render", "local", "envmap", "frame"}));
  ASSERT_GE(doc.size(), 30u);

  const fs::path dir = testing::fresh_dir("skyfarm_exr_metadata", "all");
  FarmServer server(dir / "data", 1);
  ASSERT_TRUE(server.ok()) << server.log();

  std::map<std::string, Written> written;
  const std::string local = testing::local_render_exr(kRequest, dir);
  ASSERT_FALSE(local.empty());
  written["local"] = exr_keys(local, dir / "local-copy.exr");

  const std::string id = server.submit(kRequest);
  ASSERT_FALSE(id.empty());
  ASSERT_EQ(server.wait(id, std::chrono::seconds(60))["state"], "done");
  written["render"] = exr_keys(server.download(id, "image.exr"), dir / "render.exr");

  const std::string envmap = get_body(server, "/v1/sky/envmap.exr?sun_zenith=60&sun_azimuth=90&width=32&sun=separate");
  ASSERT_FALSE(envmap.empty());
  written["envmap"] = exr_keys(envmap, dir / "envmap.exr");

  auto c = server.client();
  const auto posted = c.Post("/v1/timelapses", kTimelapse, "application/json");
  ASSERT_TRUE(posted);
  ASSERT_EQ(posted->status, 202) << posted->body;
  const std::string timelapse = nlohmann::json::parse(posted->body)["id"];
  std::string state;
  for (int i = 0; i < 1200 && state != "done" && state != "failed"; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    const std::string body = get_body(server, "/v1/timelapses/" + timelapse);
    if (!body.empty()) state = nlohmann::json::parse(body)["state"];
  }
  ASSERT_EQ(state, "done") << server.log();
  written["frame"] = png_keys(get_body(server, "/v1/timelapses/" + timelapse + "/frames/0.png"), dir / "frame.png", doc);

  for (const auto& output : outputs) {
    SCOPED_TRACE(output);
    ASSERT_FALSE(written[output].empty());
    check_against_doc(output, written[output], doc);
  }
  // The shared provenance, one name and type everywhere (no per-output synonyms).
  for (const char* key : {metadata_key::kRequest, metadata_key::kSoftwareVersion, metadata_key::kMethod,
                          metadata_key::kSunZenithDeg, metadata_key::kSunAzimuthDeg, metadata_key::kEarthSunDistanceAu,
                          metadata_key::kWavelengthMinNm, metadata_key::kWavelengthMaxNm})
    for (const auto& output : outputs) EXPECT_TRUE(written[output].count(key)) << output << " lacks " << key;
  // Non-default colour output adds its documented keys, nothing undocumented.
  std::string colour = kRequest;
  colour.replace(colour.find(R"("seed")"), 0, R"("output": {"color_space": "acescg", "units": "relative"}, )");
  const std::string colour_exr = testing::local_render_exr(colour, dir);
  ASSERT_FALSE(colour_exr.empty());
  const Written colour_keys = exr_keys(colour_exr, dir / "colour.exr");
  check_against_doc("local", colour_keys, doc);
  for (const char* key : {metadata_key::kColorSpace, metadata_key::kUnits, metadata_key::kUnitsScale})
    EXPECT_TRUE(colour_keys.count(key)) << key;
  // The env map's deprecated alias sits next to the canonical name.
  EXPECT_EQ(written["envmap"].count(metadata_key::kSunEarthDistanceAuDeprecated), 1u);
}

// software_version reads "skyfarm <version>" in renders and env maps alike,
// and the env map's deprecated distance equals the canonical one.
TEST(ExrMetadata, SoftwareVersionAndDistanceAgreeAcrossOutputs) {
  const fs::path dir = testing::fresh_dir("skyfarm_exr_metadata", "values");
  FarmServer server(dir / "data", 0);
  ASSERT_TRUE(server.ok()) << server.log();
  const std::string bytes = get_body(server, "/v1/sky/envmap.exr?sun_zenith=30&sun_azimuth=180&width=16");
  ASSERT_FALSE(bytes.empty());
  std::ofstream(dir / "envmap.exr", std::ios::binary) << bytes;
  const ExrFile envmap = read_exr(dir / "envmap.exr");
  const std::string prefix = kMetadataPrefix;
  EXPECT_EQ(envmap.string_attributes.at(prefix + metadata_key::kSoftwareVersion),
            std::string("skyfarm ") + SKYFARM_VERSION);
  EXPECT_EQ(software_version_text(), std::string("skyfarm ") + SKYFARM_VERSION);
  const double canonical = envmap.number_attributes.at(prefix + metadata_key::kEarthSunDistanceAu);
  EXPECT_EQ(envmap.number_attributes.at(prefix + metadata_key::kSunEarthDistanceAuDeprecated), canonical);
  // The Earth-Sun distance stays within 0.983-1.017 au (perihelion, aphelion).
  EXPECT_NEAR(canonical, 1.0, 0.0175);
  const std::string local = testing::local_render_exr(kRequest, dir);
  ASSERT_FALSE(local.empty());
  std::ofstream(dir / "local-copy.exr", std::ios::binary) << local;
  EXPECT_EQ(read_exr(dir / "local-copy.exr").string_attributes.at(prefix + metadata_key::kSoftwareVersion),
            software_version_text());
}

}  // namespace
}  // namespace skyfarm
