// The farm's wire protocol (api/wire.h): every message round-trips through
// its frames, and anything a peer could send that encode cannot produce is
// rejected with WireError, never a crash.
#include "api/wire.h"

#include <gtest/gtest.h>

#include <random>

namespace skyfarm::api {
namespace {

UnitRef sample_ref() { return UnitRef{"job-7f3a", 3, 1, 2, 0xFFFFFFFFFFFFFFF0ull}; }

void expect_round_trip(const Message& m) {
  const Frames frames = encode(m);
  ASSERT_GE(frames.size(), 2u);
  EXPECT_EQ(frames[0], command_name(command_of(m)));
  EXPECT_EQ(decode(frames), m) << frames[1];
}

TEST(WireTest, EveryMessageRoundTrips) {
  ReadyMsg ready{"host-12-ab", 16, 17, kProtocolVersion, {{"spectral", true}}, 1000, std::string("secret")};
  expect_round_trip(ready);
  ready.token.reset();
  ready.heartbeat_ms = 0;
  expect_round_trip(ready);
  ready.prefetch = 16;  // optional: absent reads as 0
  expect_round_trip(ready);
  EXPECT_EQ(encode(ReadyMsg{}).at(1).find("prefetch"), std::string::npos);
  expect_round_trip(HeartbeatMsg{});
  expect_round_trip(HeartbeatMsg{2500, true});
  expect_round_trip(UnitMsg{sample_ref(), R"({"camera":{"width":16}})"});
  std::string bytes = "SKFT";
  for (int i = 0; i < 300; ++i) bytes.push_back(static_cast<char>(i));  // binary, with NULs
  expect_round_trip(ResultMsg{sample_ref(), 123456789012ull, 0.25, bytes});
  expect_round_trip(FailedMsg{sample_ref(), "invalid request: camera.width: must be >= 1"});
  expect_round_trip(CancelMsg{42});
  expect_round_trip(DisconnectMsg{});
  expect_round_trip(DisconnectMsg{"unauthorized", true});
  expect_round_trip(ReregisterMsg{});
  const std::string id = "sha256:" + std::string(64, 'c');
  expect_round_trip(AssetGetMsg{id});
  expect_round_trip(AssetMsg{id, true, "", bytes});
  expect_round_trip(AssetMsg{id, false, "no asset " + id + " on this server", ""});
}

// ASSET carries the mesh file as a binary payload frame when ok, and no
// payload (but a reason) when not; ids are checked as the store names them.
TEST(WireTest, AssetMessagesCarryTheFileOrAReason) {
  const std::string id = "sha256:" + std::string(64, '0');
  const std::string file("SKYMESH1\0\0\0\1", 12);
  const Frames ok = encode(AssetMsg{id, true, "ignored when ok", file});
  ASSERT_EQ(ok.size(), 3u);
  EXPECT_EQ(ok[0], "ASSET");
  EXPECT_EQ(ok[2], file);
  EXPECT_EQ(ok[1].find("error"), std::string::npos) << ok[1];
  EXPECT_EQ(std::get<AssetMsg>(decode(ok)).error, "");
  const Frames refused = encode(AssetMsg{id, false, "", "ignored when not ok"});
  ASSERT_EQ(refused.size(), 2u);
  EXPECT_EQ(std::get<AssetMsg>(decode(refused)).error, "unknown error") << "a refusal always says something";
  const Frames get = encode(AssetGetMsg{id});
  ASSERT_EQ(get.size(), 2u);
  EXPECT_EQ(get[0], "ASSET_GET");
  EXPECT_EQ(command_from_name("ASSET_GET"), Command::kAssetGet);
  EXPECT_EQ(command_from_name("ASSET"), Command::kAsset);
  static_assert(kProtocolVersion >= 4, "ASSET_GET / ASSET are version 4");
  static_assert(kProtocolVersion == 5, "clouds are version 5");
  static_assert(kMaxAssetBytes == 168'000'016u, "the file of a mesh at the default MeshLimits");
}

// A probe unit says so ("kind": "probe"); a render unit's header is the
// version 1 header (no "kind"), and an unknown kind is refused.
TEST(WireTest, UnitKindTravelsAndRenderUnitsAreUnchanged) {
  expect_round_trip(UnitMsg{sample_ref(), R"({"directions":[]})", UnitKind::kProbe});
  const Frames render = encode(UnitMsg{sample_ref(), "{}"});
  EXPECT_EQ(render[1].find("kind"), std::string::npos) << render[1];
  const Frames probe = encode(UnitMsg{sample_ref(), "{}", UnitKind::kProbe});
  EXPECT_NE(probe[1].find(R"("kind":"probe")"), std::string::npos) << probe[1];
  const std::string header = R"({"job": "j", "tile": 0, "batch": 0, "pass": 0, "attempt": 1, "request": "{}", "kind": )";
  EXPECT_EQ(std::get<UnitMsg>(decode({"UNIT", header + R"("render"})"})).kind, UnitKind::kRender);
  EXPECT_THROW(decode({"UNIT", header + R"("film"})"}), WireError);
  EXPECT_THROW(decode({"UNIT", header + "7}"}), WireError);
}

// An adaptive render unit carries its tile's samples per pass per allocation
// block, as [even, odd] pairs; a uniform unit's header has none; counts out
// of range or of the wrong shape are refused.
TEST(WireTest, AdaptiveSamplesPerPassTravelAndAreChecked) {
  UnitMsg adaptive{sample_ref(), "{}"};
  adaptive.samples_per_pass = {{4, 64}, {16, 17}, {1, 1}};
  expect_round_trip(adaptive);
  const Frames frames = encode(adaptive);
  EXPECT_NE(frames[1].find(R"("samples_per_pass":[[4,64],[16,17],[1,1]])"), std::string::npos) << frames[1];
  EXPECT_EQ(encode(UnitMsg{sample_ref(), "{}"})[1].find("samples_per_pass"), std::string::npos);
  const std::string header = R"({"job": "j", "tile": 0, "batch": 0, "pass": 1, "attempt": 1, "request": "{}", )";
  for (const char* bad : {R"("samples_per_pass": []})", R"("samples_per_pass": [[4]]})",
                          R"("samples_per_pass": [[4, 0]]})", R"("samples_per_pass": [[4, 2.5]]})",
                          R"("samples_per_pass": [[4, 2000000]]})", R"("samples_per_pass": [4, 5]})",
                          R"("samples_per_pass": {"even": 4}})"})
    EXPECT_THROW(decode({"UNIT", header + bad}), WireError) << bad;
}

TEST(WireTest, ResultPayloadIsABinaryFrameNotJson) {
  const Frames f = encode(ResultMsg{sample_ref(), 1, 0.5, std::string("\0\1\2", 3)});
  ASSERT_EQ(f.size(), 3u);
  EXPECT_EQ(f[2], std::string("\0\1\2", 3));
  EXPECT_EQ(f[1].find("\\u0000"), std::string::npos);
  EXPECT_EQ(payload_bytes(f[2]), (std::vector<std::uint8_t>{0, 1, 2}));
}

TEST(WireTest, HeaderlessControlMessagesDecode) {
  EXPECT_TRUE(std::holds_alternative<HeartbeatMsg>(decode({"HEARTBEAT"})));
  EXPECT_TRUE(std::holds_alternative<DisconnectMsg>(decode({"DISCONNECT", ""})));
  EXPECT_TRUE(std::holds_alternative<ReregisterMsg>(decode({"REREGISTER", "{}"})));
}

TEST(WireTest, UnknownHeaderFieldsAreIgnored) {
  const auto m = decode({"CANCEL", R"({"attempt": 5, "reason": "job cancelled", "future": [1, 2]})"});
  EXPECT_EQ(std::get<CancelMsg>(m).attempt, 5u);
}

TEST(WireTest, FailedMessageIsCutToTheLimit) {
  const Frames f = encode(FailedMsg{sample_ref(), std::string(kMaxMessageBytes + 100, 'x')});
  EXPECT_EQ(std::get<FailedMsg>(decode(f)).message.size(), kMaxMessageBytes);
}

TEST(WireTest, MalformedMessagesAreRejected) {
  const std::string unit = R"("job": "j", "tile": 0, "batch": 0, "pass": 0, "attempt": 1)";
  const std::string asset = "sha256:" + std::string(64, 'a');
  const std::vector<Frames> bad = {
      {},
      {""},
      {"ready", "{}"},
      {"READY "},
      {"NOPE", "{}"},
      {"HEARTBEAT", "{}", "extra"},
      {"READY", "not json"},
      {"READY", "[1, 2]"},
      {"READY", "\"READY\""},
      {"READY", "{\"id\": \"w\""},
      {"READY", R"({"cores": 1, "slots": 1, "version": 1})"},                         // no id
      {"READY", R"({"id": "", "cores": 1, "slots": 1, "version": 1})"},               // empty id
      {"READY", R"({"id": "a\u0001b", "cores": 1, "slots": 1, "version": 1})"},       // control char
      {"READY", R"({"id": 7, "cores": 1, "slots": 1, "version": 1})"},
      {"READY", R"({"id": "w", "cores": 0, "slots": 1, "version": 1})"},
      {"READY", R"({"id": "w", "cores": 1, "slots": 0, "version": 1})"},
      {"READY", R"({"id": "w", "cores": 1, "slots": 100000, "version": 1})"},
      {"READY", R"({"id": "w", "cores": 1, "slots": 1.5, "version": 1})"},
      {"READY", R"({"id": "w", "cores": 1, "slots": "2", "version": 1})"},
      {"READY", R"({"id": "w", "cores": 1, "slots": 1, "version": "1"})"},
      {"READY", R"({"id": "w", "cores": 1, "slots": 1, "version": 1, "capabilities": []})"},
      {"READY", R"({"id": "w", "cores": 1, "slots": 1, "version": 1, "token": 5})"},
      {"READY", "{\"id\": \"" + std::string(kMaxIdBytes + 1, 'w') + "\", \"cores\": 1, \"slots\": 1, \"version\": 1}"},
      {"HEARTBEAT", R"({"draining": "yes"})"},
      {"HEARTBEAT", R"({"heartbeat_ms": -5})"},
      {"READY", R"({"id": "w", "cores": 1, "slots": 1, "version": 3, "prefetch": -1})"},
      {"UNIT", "{" + unit + "}"},                                                    // no request
      {"UNIT", R"({"job": "j", "tile": -1, "batch": 0, "pass": 0, "attempt": 1, "request": "{}"})"},
      {"UNIT", R"({"job": "j", "tile": 0, "batch": 0, "pass": 0, "attempt": -1, "request": "{}"})"},
      {"UNIT", R"({"job": "j", "tile": 99999999999, "batch": 0, "pass": 0, "attempt": 1, "request": "{}"})"},
      {"UNIT", R"({"job": "j", "tile": 0, "batch": 0, "pass": 0, "attempt": 1.0, "request": "{}"})"},
      {"RESULT", "{" + unit + R"(, "paths": 1, "seconds": 0.1})"},                   // no payload frame
      {"RESULT", "{" + unit + R"(, "paths": 1, "seconds": 0.1})", ""},               // empty payload
      {"RESULT", "{" + unit + R"(, "paths": 1, "seconds": -1})", "x"},
      {"RESULT", "{" + unit + R"(, "paths": -1, "seconds": 1})", "x"},
      {"RESULT", "{" + unit + R"(, "seconds": 1})", "x"},
      {"RESULT", "{" + unit + R"(, "paths": 1, "seconds": 1})", "x", "y"},
      {"FAILED", "{" + unit + "}"},
      {"FAILED", "{" + unit + R"(, "message": 3})"},
      {"CANCEL", "{}"},
      {"CANCEL", R"({"attempt": null})"},
      {"CANCEL", R"({"attempt": 18446744073709551616})"},                           // 2^64
      {"DISCONNECT", R"({"fatal": 1})"},
      {"CANCEL", std::string(100000, '[') + std::string(100000, ']')},              // deep nesting
      {"ASSET_GET", "{}"},
      {"ASSET_GET", R"({"id": "cube.obj"})"},
      {"ASSET_GET", R"({"id": "sha256:)" + std::string(64, 'A') + "\"}"},
      {"ASSET_GET", R"({"id": ")" + asset + "\"}", "payload"},
      {"ASSET", R"({"id": ")" + asset + "\"}", "file"},                                  // no ok
      {"ASSET", R"({"id": ")" + asset + R"(", "ok": 1})", "file"},
      {"ASSET", R"({"id": ")" + asset + R"(", "ok": true})"},                            // no payload
      {"ASSET", R"({"id": ")" + asset + R"(", "ok": true})", ""},                        // empty payload
      {"ASSET", R"({"id": ")" + asset + R"(", "ok": false, "error": "gone"})", "file"},  // payload on a refusal
      {"ASSET", R"({"id": ")" + asset + R"(", "ok": false})"},                           // no reason
      {"ASSET", R"({"id": "x", "ok": true})", "file"},
  };
  for (const Frames& f : bad) {
    std::string error;
    EXPECT_FALSE(try_decode(f, &error).has_value()) << (f.size() > 1 ? f[1].substr(0, 80) : "") << " decoded";
    EXPECT_FALSE(error.empty());
    EXPECT_THROW(decode(f), WireError);
  }
}

TEST(WireTest, RandomBytesNeverCrashTheDecoder) {
  std::mt19937 rng(7);
  const std::vector<std::string> commands = {"READY",  "HEARTBEAT",  "UNIT",      "RESULT", "FAILED",
                                             "CANCEL", "DISCONNECT", "ASSET_GET", "ASSET"};
  for (int i = 0; i < 3000; ++i) {
    Frames f;
    f.push_back(i % 4 == 0 ? std::string(1 + rng() % 8, static_cast<char>(rng())) : commands[rng() % commands.size()]);
    const int frames = static_cast<int>(rng() % 4);
    for (int k = 0; k < frames; ++k) {
      std::string s(rng() % 64, '\0');
      for (auto& c : s) c = static_cast<char>(i % 3 == 0 ? "{}[]\":,0a"[rng() % 9] : rng());
      f.push_back(s);
    }
    (void)try_decode(f);  // must return, whatever it says
  }
}

TEST(WireTest, CommandNamesAreFixed) {
  EXPECT_EQ(command_name(Command::kReady), "READY");
  EXPECT_EQ(command_name(Command::kReregister), "REREGISTER");
  EXPECT_EQ(command_from_name("CANCEL"), Command::kCancel);
  EXPECT_FALSE(command_from_name("cancel").has_value());
}

}  // namespace
}  // namespace skyfarm::api
