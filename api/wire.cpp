#include "api/wire.h"

#include <array>
#include <cmath>
#include <limits>
#include <type_traits>

#include "common/assets/asset_id.h"

namespace skyfarm::api {
namespace {

using Json = nlohmann::json;

constexpr int kMaxHeaderDepth = 32;

constexpr std::array<std::pair<Command, std::string_view>, 10> kCommandNames{{
    {Command::kReady, "READY"},
    {Command::kHeartbeat, "HEARTBEAT"},
    {Command::kUnit, "UNIT"},
    {Command::kResult, "RESULT"},
    {Command::kFailed, "FAILED"},
    {Command::kCancel, "CANCEL"},
    {Command::kDisconnect, "DISCONNECT"},
    {Command::kReregister, "REREGISTER"},
    {Command::kAssetGet, "ASSET_GET"},
    {Command::kAsset, "ASSET"},
}};

[[noreturn]] void fail(const std::string& what) { throw WireError(what); }

// --- Header parsing ---------------------------------------------------------

// Nesting depth of a JSON text (outside strings), so a hostile header cannot
// drive the parser or the destructor into deep recursion.
bool depth_within(std::string_view text, int max_depth) {
  int depth = 0;
  bool in_string = false, escaped = false;
  for (const char c : text) {
    if (in_string) {
      if (escaped) escaped = false;
      else if (c == '\\') escaped = true;
      else if (c == '"') in_string = false;
    } else if (c == '"') {
      in_string = true;
    } else if (c == '{' || c == '[') {
      if (++depth > max_depth) return false;
    } else if (c == '}' || c == ']') {
      --depth;
    }
  }
  return true;
}

Json parse_header(const std::string& text) {
  if (text.empty()) return Json::object();
  if (text.size() > kMaxHeaderBytes) fail("header larger than " + std::to_string(kMaxHeaderBytes) + " bytes");
  if (!depth_within(text, kMaxHeaderDepth)) fail("header nested too deeply");
  Json header = Json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (header.is_discarded()) fail("header is not valid JSON");
  if (!header.is_object()) fail("header is not a JSON object");
  return header;
}

const Json* field(const Json& header, const char* name, bool required) {
  const auto it = header.find(name);
  if (it == header.end() || it->is_null()) {
    if (required) fail(std::string("missing field \"") + name + "\"");
    return nullptr;
  }
  return &*it;
}

std::string get_string(const Json& h, const char* name, std::size_t max_bytes, bool required = true,
                       bool allow_empty = false) {
  const Json* v = field(h, name, required);
  if (!v) return {};
  if (!v->is_string()) fail(std::string("\"") + name + "\" must be a string");
  const auto& s = v->get_ref<const std::string&>();
  if (s.empty() && !allow_empty) fail(std::string("\"") + name + "\" must not be empty");
  if (s.size() > max_bytes) fail(std::string("\"") + name + "\" longer than " + std::to_string(max_bytes) + " bytes");
  return s;
}

long long get_int(const Json& h, const char* name, long long lo, long long hi, bool required = true,
                  long long fallback = 0) {
  const Json* v = field(h, name, required);
  if (!v) return fallback;
  if (!v->is_number_integer()) fail(std::string("\"") + name + "\" must be an integer");
  if (v->is_number_unsigned() && v->get<std::uint64_t>() > static_cast<std::uint64_t>(hi))
    fail(std::string("\"") + name + "\" out of range");
  const long long x = v->is_number_unsigned() ? static_cast<long long>(v->get<std::uint64_t>()) : v->get<long long>();
  if (x < lo || x > hi) fail(std::string("\"") + name + "\" out of range [" + std::to_string(lo) + ", " +
                             std::to_string(hi) + "]");
  return x;
}

std::uint64_t get_u64(const Json& h, const char* name, bool required = true) {
  const Json* v = field(h, name, required);
  if (!v) return 0;
  if (!v->is_number_integer()) fail(std::string("\"") + name + "\" must be an integer");
  if (!v->is_number_unsigned() && v->get<long long>() < 0) fail(std::string("\"") + name + "\" must be >= 0");
  return v->get<std::uint64_t>();
}

double get_seconds(const Json& h, const char* name) {
  const Json* v = field(h, name, true);
  if (!v->is_number()) fail(std::string("\"") + name + "\" must be a number");
  const double x = v->get<double>();
  if (!std::isfinite(x) || x < 0.0) fail(std::string("\"") + name + "\" must be finite and >= 0");
  return x;
}

bool get_bool(const Json& h, const char* name) {
  const Json* v = field(h, name, false);
  if (!v) return false;
  if (!v->is_boolean()) fail(std::string("\"") + name + "\" must be a boolean");
  return v->get<bool>();
}

constexpr long long kMaxIndex = std::numeric_limits<int>::max();

UnitRef read_unit_ref(const Json& h) {
  UnitRef u;
  u.job = get_string(h, "job", kMaxIdBytes);
  u.tile = static_cast<int>(get_int(h, "tile", 0, kMaxIndex));
  u.batch = static_cast<int>(get_int(h, "batch", 0, kMaxIndex));
  u.pass = static_cast<int>(get_int(h, "pass", 0, kMaxIndex));
  u.attempt = get_u64(h, "attempt");
  return u;
}

Json write_unit_ref(const UnitRef& u) {
  return Json{{"job", u.job}, {"tile", u.tile}, {"batch", u.batch}, {"pass", u.pass}, {"attempt", u.attempt}};
}

// --- Per-message encode / decode --------------------------------------------

Json header_of(const ReadyMsg& m) {
  Json h{{"id", m.id},           {"cores", m.cores},
         {"slots", m.slots},     {"version", m.version},
         {"capabilities", m.capabilities.is_object() ? m.capabilities : Json::object()}};
  if (m.heartbeat_ms > 0) h["heartbeat_ms"] = m.heartbeat_ms;
  if (m.prefetch > 0) h["prefetch"] = m.prefetch;
  if (m.token) h["token"] = *m.token;
  return h;
}
Json header_of(const HeartbeatMsg& m) {
  Json h = Json::object();
  if (m.heartbeat_ms > 0) h["heartbeat_ms"] = m.heartbeat_ms;
  if (m.draining) h["draining"] = true;
  return h;
}
Json header_of(const UnitMsg& m) {
  Json h = write_unit_ref(m.unit);
  h["request"] = m.request;
  if (m.kind == UnitKind::kProbe) h["kind"] = "probe";  // absent: render (the version 1 UNIT)
  if (!m.samples_per_pass.empty()) {
    Json n = Json::array();
    for (const auto& [even, odd] : m.samples_per_pass) n.push_back(Json::array({even, odd}));
    h["samples_per_pass"] = std::move(n);
  }
  return h;
}
Json header_of(const ResultMsg& m) {
  Json h = write_unit_ref(m.unit);
  h["paths"] = m.paths;
  h["seconds"] = std::isfinite(m.seconds) && m.seconds > 0.0 ? m.seconds : 0.0;
  return h;
}
Json header_of(const FailedMsg& m) {
  Json h = write_unit_ref(m.unit);
  std::string text = m.message.substr(0, kMaxMessageBytes);
  if (text.empty()) text = "unknown error";
  h["message"] = text;
  return h;
}
Json header_of(const CancelMsg& m) { return Json{{"attempt", m.attempt}}; }
Json header_of(const DisconnectMsg& m) {
  Json h = Json::object();
  if (!m.reason.empty()) h["reason"] = m.reason.substr(0, kMaxMessageBytes);
  if (m.fatal) h["fatal"] = true;
  return h;
}
Json header_of(const ReregisterMsg&) { return Json::object(); }
Json header_of(const AssetGetMsg& m) { return Json{{"id", m.id}}; }
Json header_of(const AssetMsg& m) {
  Json h{{"id", m.id}, {"ok", m.ok}};
  if (!m.ok) {
    std::string text = m.error.substr(0, kMaxMessageBytes);
    if (text.empty()) text = "unknown error";
    h["error"] = text;
  }
  return h;
}

ReadyMsg read_ready(const Json& h) {
  ReadyMsg m;
  m.id = get_string(h, "id", kMaxIdBytes);
  for (const unsigned char c : m.id)
    if (c < 0x20 || c == 0x7f) fail("\"id\" contains control characters");
  m.cores = static_cast<int>(get_int(h, "cores", 1, 1 << 20));
  m.slots = static_cast<int>(get_int(h, "slots", 1, kMaxSlots));
  m.version = static_cast<int>(get_int(h, "version", 0, kMaxIndex));
  if (const Json* caps = field(h, "capabilities", false)) {
    if (!caps->is_object()) fail("\"capabilities\" must be an object");
    m.capabilities = *caps;
  }
  m.heartbeat_ms = static_cast<int>(get_int(h, "heartbeat_ms", 1, 3600 * 1000, false, 0));
  m.prefetch = static_cast<int>(get_int(h, "prefetch", 0, kMaxSlots, false, 0));
  if (field(h, "token", false)) m.token = get_string(h, "token", 4096, true, true);
  return m;
}
HeartbeatMsg read_heartbeat(const Json& h) {
  HeartbeatMsg m;
  m.heartbeat_ms = static_cast<int>(get_int(h, "heartbeat_ms", 1, 3600 * 1000, false, 0));
  m.draining = get_bool(h, "draining");
  return m;
}
UnitMsg read_unit(const Json& h) {
  UnitMsg m;
  m.unit = read_unit_ref(h);
  m.request = get_string(h, "request", kMaxHeaderBytes);
  const std::string kind = get_string(h, "kind", 16, false);
  if (kind == "probe") m.kind = UnitKind::kProbe;
  else if (!kind.empty() && kind != "render") fail("\"kind\" must be render or probe");
  if (const Json* n = field(h, "samples_per_pass", false)) {
    if (!n->is_array() || n->empty() || n->size() > kMaxAllocationBlocks)
      fail("\"samples_per_pass\" must be a non-empty array of at most " + std::to_string(kMaxAllocationBlocks) +
           " [even, odd] pairs");
    for (const Json& pair : *n) {
      int v[2] = {0, 0};
      for (std::size_t i = 0; i < 2; ++i) {
        if (!pair.is_array() || pair.size() != 2 || !pair[i].is_number_integer() || pair[i].get<long long>() < 1 ||
            pair[i].get<long long>() > kMaxSamplesPerPass)
          fail("\"samples_per_pass\" must hold [even, odd] pairs of integers in [1, " +
               std::to_string(kMaxSamplesPerPass) + "]");
        v[i] = static_cast<int>(pair[i].get<long long>());
      }
      m.samples_per_pass.emplace_back(v[0], v[1]);
    }
  }
  return m;
}
ResultMsg read_result(const Json& h, const std::string& payload) {
  ResultMsg m;
  m.unit = read_unit_ref(h);
  m.paths = get_u64(h, "paths");
  m.seconds = get_seconds(h, "seconds");
  if (payload.empty()) fail("RESULT without a film tile payload");
  m.film_tile = payload;
  return m;
}
FailedMsg read_failed(const Json& h) {
  FailedMsg m;
  m.unit = read_unit_ref(h);
  m.message = get_string(h, "message", kMaxMessageBytes, true, true);
  return m;
}
CancelMsg read_cancel(const Json& h) { return CancelMsg{get_u64(h, "attempt")}; }
DisconnectMsg read_disconnect(const Json& h) {
  DisconnectMsg m;
  m.reason = get_string(h, "reason", kMaxMessageBytes, false, true);
  m.fatal = get_bool(h, "fatal");
  return m;
}

std::string read_asset_id(const Json& h) {
  std::string id = get_string(h, "id", kMaxIdBytes);
  if (!assets::is_asset_id(id)) fail("\"id\" must be sha256: and 64 lowercase hex digits");
  return id;
}
AssetGetMsg read_asset_get(const Json& h) { return AssetGetMsg{read_asset_id(h)}; }
AssetMsg read_asset(const Json& h, const Frames& frames) {
  AssetMsg m;
  m.id = read_asset_id(h);
  const Json* ok = field(h, "ok", true);
  if (!ok->is_boolean()) fail("\"ok\" must be a boolean");
  m.ok = ok->get<bool>();
  if (m.ok) {
    if (frames.size() != 3 || frames[2].empty()) fail("ASSET with ok needs the mesh file as a payload frame");
    if (frames[2].size() > kMaxAssetBytes)
      fail("ASSET payload larger than " + std::to_string(kMaxAssetBytes) + " bytes");
    m.file = frames[2];
  } else {
    if (frames.size() != 2) fail("ASSET without ok has no payload frame");
    m.error = get_string(h, "error", kMaxMessageBytes);
  }
  return m;
}

}  // namespace

std::string_view command_name(Command command) {
  for (const auto& [c, name] : kCommandNames)
    if (c == command) return name;
  return "?";
}

std::optional<Command> command_from_name(std::string_view name) {
  for (const auto& [c, n] : kCommandNames)
    if (n == name) return c;
  return std::nullopt;
}

Command command_of(const Message& message) {
  return std::visit(
      [](const auto& m) -> Command {
        using T = std::decay_t<decltype(m)>;
        if constexpr (std::is_same_v<T, ReadyMsg>) return Command::kReady;
        else if constexpr (std::is_same_v<T, HeartbeatMsg>) return Command::kHeartbeat;
        else if constexpr (std::is_same_v<T, UnitMsg>) return Command::kUnit;
        else if constexpr (std::is_same_v<T, ResultMsg>) return Command::kResult;
        else if constexpr (std::is_same_v<T, FailedMsg>) return Command::kFailed;
        else if constexpr (std::is_same_v<T, CancelMsg>) return Command::kCancel;
        else if constexpr (std::is_same_v<T, DisconnectMsg>) return Command::kDisconnect;
        else if constexpr (std::is_same_v<T, ReregisterMsg>) return Command::kReregister;
        else if constexpr (std::is_same_v<T, AssetGetMsg>) return Command::kAssetGet;
        else return Command::kAsset;
      },
      message);
}

Frames encode(const Message& message) {
  Frames frames;
  frames.emplace_back(command_name(command_of(message)));
  frames.push_back(std::visit([](const auto& m) { return header_of(m).dump(); }, message));
  if (const auto* r = std::get_if<ResultMsg>(&message)) frames.push_back(r->film_tile);
  if (const auto* a = std::get_if<AssetMsg>(&message); a && a->ok) frames.push_back(a->file);
  return frames;
}

Message decode(const Frames& frames) {
  if (frames.empty()) fail("empty message");
  const std::optional<Command> command = command_from_name(frames[0]);
  if (!command) fail("unknown command \"" + frames[0].substr(0, 32) + "\"");
  const std::size_t expected = *command == Command::kResult || *command == Command::kAsset ? 3 : 2;
  if (frames.size() > expected) fail("too many frames for " + std::string(command_name(*command)));
  if (*command == Command::kResult && frames.size() != 3) fail("RESULT needs a header and a payload frame");
  const Json header = parse_header(frames.size() > 1 ? frames[1] : std::string());
  switch (*command) {
    case Command::kReady: return read_ready(header);
    case Command::kHeartbeat: return read_heartbeat(header);
    case Command::kUnit: return read_unit(header);
    case Command::kResult: return read_result(header, frames[2]);
    case Command::kFailed: return read_failed(header);
    case Command::kCancel: return read_cancel(header);
    case Command::kDisconnect: return read_disconnect(header);
    case Command::kReregister: return ReregisterMsg{};
    case Command::kAssetGet: return read_asset_get(header);
    case Command::kAsset: return read_asset(header, frames);
  }
  fail("unknown command");
}

std::optional<Message> try_decode(const Frames& frames, std::string* error) {
  try {
    return decode(frames);
  } catch (const std::exception& e) {  // WireError, or a json type error we did not foresee
    if (error) *error = e.what();
    return std::nullopt;
  }
}

}  // namespace skyfarm::api
