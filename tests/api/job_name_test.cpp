// Tests of "name" (api/job_name.h) in render and timelapse requests: what is
// accepted, each refusal naming "name", and the canonical request (hashed,
// written into the EXR) left unchanged by it.
#include "api/job_name.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "api/render_request.h"
#include "api/timelapse_request.h"

namespace skyfarm::api {
namespace {

const std::string kRender =
    R"({"time": "2013-05-27T20:25:00-04:00", "location": {"latitude_deg": 42.44, "longitude_deg": -76.5},
        "camera": {"projection": "fisheye", "width": 32, "height": 32})";
const std::string kTimelapse =
    R"({"start": "2013-05-27T19:00:00Z", "end": "2013-05-27T20:00:00Z", "frames": 3,
        "camera": {"projection": "equirectangular", "width": 16, "height": 8})";

// The body with one more member (`member` is `"name": ...`), closed.
std::string with(const std::string& body, const std::string& member) {
  return body + (member.empty() ? "" : ", " + member) + "}";
}

// The paths the errors name (empty when it parses).
std::vector<std::string> render_errors(const std::string& text) {
  std::vector<std::string> out;
  try {
    parse_render_request(text);
  } catch (const ValidationError& e) {
    for (const auto& f : e.errors()) out.push_back(f.path);
  }
  return out;
}

std::vector<std::string> timelapse_errors(const std::string& text) {
  std::vector<std::string> out;
  try {
    parse_timelapse_request(text);
  } catch (const ValidationError& e) {
    for (const auto& f : e.errors()) out.push_back(f.path);
  }
  return out;
}

TEST(JobName, ValidNamesAreKeptAsWritten) {
  EXPECT_EQ(parse_render_request(with(kRender, R"("name": "Ithaca sunset, west")")).name, "Ithaca sunset, west");
  // 200 code points of 2 bytes each: the limit counts characters, not bytes.
  std::string accents;
  for (int i = 0; i < 200; ++i) accents += "\xc3\xa9";  // U+00E9
  EXPECT_EQ(parse_render_request(with(kRender, "\"name\": \"" + accents + "\"")).name, accents);
  EXPECT_EQ(parse_render_request(with(kRender, R"("name": "\u65e5\u6ca1 \ud83c\udf05")")).name,
            "\xe6\x97\xa5\xe6\xb2\xa1 \xf0\x9f\x8c\x85");
}

TEST(JobName, AbsentNullAndEmptyMeanNoName) {
  EXPECT_FALSE(parse_render_request(with(kRender, "")).name);
  EXPECT_FALSE(parse_render_request(with(kRender, R"("name": null)")).name);
  EXPECT_FALSE(parse_render_request(with(kRender, R"("name": "")")).name);
}

TEST(JobName, InvalidNamesAreRefusedNamingTheField) {
  const std::vector<std::string> bad = {
      R"("name": 42)",                                  // wrong type
      R"("name": ["a"])",                               // wrong type
      R"("name": {"text": "a"})",                       // wrong type
      "\"name\": \"" + std::string(201, 'x') + "\"",    // too long
      R"("name": "line\nbreak")",                       // control character
      R"("name": "tab\there")",                         // control character
      R"("name": "c1\u0085")",                          // C1 control (NEL)
  };
  for (const std::string& member : bad) {
    EXPECT_EQ(render_errors(with(kRender, member)), std::vector<std::string>{"name"}) << member;
    EXPECT_EQ(timelapse_errors(with(kTimelapse, member)), std::vector<std::string>{"name"}) << member;
  }
  EXPECT_TRUE(render_errors(with(kRender, "\"name\": \"" + std::string(200, 'x') + "\"")).empty());
  try {
    parse_render_request(with(kRender, "\"name\": \"" + std::string(201, 'x') + "\""));
    FAIL() << "a 201-character name was accepted";
  } catch (const ValidationError& e) {
    EXPECT_EQ(e.errors().front().value, "201 characters");
  }
}

TEST(JobName, InvalidUtf8IsRefused) {
  EXPECT_TRUE(valid_job_name("ok"));
  EXPECT_FALSE(valid_job_name(""));
  EXPECT_FALSE(valid_job_name("\xc3"));              // truncated sequence
  EXPECT_FALSE(valid_job_name("\xc0\xaf"));          // overlong '/'
  EXPECT_FALSE(valid_job_name("\xed\xa0\x80"));      // surrogate U+D800
  EXPECT_FALSE(valid_job_name("\xf4\x90\x80\x80"));  // above U+10FFFF
  EXPECT_FALSE(valid_job_name("a\x7f"));             // DEL
  EXPECT_TRUE(valid_job_name(std::string(200, 'a')));
  EXPECT_FALSE(valid_job_name(std::string(201, 'a')));
}

TEST(JobName, TheCanonicalRequestIsUnchangedByTheName) {
  const RenderRequest plain = parse_render_request(with(kRender, ""));
  const RenderRequest named = parse_render_request(with(kRender, R"("name": "first light")"));
  EXPECT_EQ(canonical_text(named), canonical_text(plain));
  EXPECT_FALSE(to_canonical_json(named).contains("name"));
  // The canonical text reads back to the request without its name.
  EXPECT_FALSE(parse_render_request(canonical_text(named)).name);

  const TimelapseRequest tl_plain = parse_timelapse_request(with(kTimelapse, ""));
  const TimelapseRequest tl_named = parse_timelapse_request(with(kTimelapse, R"("name": "dusk")"));
  EXPECT_EQ(canonical_text(tl_named), canonical_text(tl_plain));
  EXPECT_EQ(tl_named.base.name, "dusk");
  // Each frame is a render named after its timelapse; its canonical text is
  // the unnamed frame's.
  EXPECT_EQ(tl_named.frame_request(1).name, "dusk (frame 2 of 3)");
  EXPECT_FALSE(tl_plain.frame_request(1).name);
  EXPECT_EQ(canonical_text(tl_named.frame_request(1)), canonical_text(tl_plain.frame_request(1)));
}

}  // namespace
}  // namespace skyfarm::api
