// The server <-> worker protocol of the render farm, as ZeroMQ multipart
// frames.  The server binds a ROUTER, every worker connects a DEALER; the
// connection is CurveZMQ (encrypted, each worker authenticated by its public
// key in the server's ZAP handler: api/curve_keys.h, server/broker/broker.h), so
// everything below rides inside CURVE.  A DEALER sends and receives
//
//     [command] [header JSON object] [payload]        (payload: RESULT, ASSET only)
//
// and the ROUTER sees the peer's routing identity as an extra first frame
// (server/broker/broker.cpp strips and adds it; this file never sees it).  The
// command frame is the ASCII name below; the header is a JSON object (an
// empty header frame, or none at all, reads as {} for commands without
// required fields); results travel as binary FilmTile::serialize() bytes,
// never as JSON floats, and assets as their mesh file's bytes.
//
//   command     direction        header fields                                  payload
//   READY       worker -> server id, cores, slots, version, capabilities,      -
//                                heartbeat_ms?, prefetch?, token? (token: sent by
//                                workers given --token, ignored: not a credential)
//   HEARTBEAT   both ways        heartbeat_ms? (sender's interval),            -
//                                draining? (worker: send no more units)
//   UNIT        server -> worker job, tile, batch, pass, attempt, request,     -
//                                kind?, samples_per_pass? (request:
//                                api::canonical_text of the job)
//   RESULT      worker -> server job, tile, batch, pass, attempt, paths,        FilmTile bytes
//                                seconds
//   FAILED      worker -> server job, tile, batch, pass, attempt, message       -
//   CANCEL      server -> worker attempt                                        -
//   DISCONNECT  both ways        reason?, fatal? (server: do not reconnect)     -
//   REREGISTER  server -> worker -  (the server does not know this peer: READY) -
//   ASSET_GET   worker -> server id ("sha256:<64 hex>")                         -
//   ASSET       server -> worker id, ok, error? (ok false: why)                 the mesh file (ok only)
//
// Unit kinds: "render" (kind absent) is a render unit (tile, batch, pass of
// the job's RenderPlan) answered with FilmTile bytes.  "probe" is a unit of a
// radiance probe (request: the ProbeRequest's canonical text; tile = the
// unit's index in its probe_plan, common/render/probe_answer.h; batch = pass
// = 0) answered with ProbeUnitSums bytes (common/render/probe_units.h); the
// server sends them only to workers whose READY capabilities hold "probe":
// kProbeUnitsVersion.
//
// prefetch: units the worker accepts beyond its `slots`, queued behind the
// ones it renders (absent or 0: none, the server sends at most `slots`).  The
// server uses them only when units are short: it sizes each worker's credit
// from the render time its RESULTs report so that the worker holds about the
// broker's pipeline_target of work (server/broker/broker.h), between `slots` and
// `slots + prefetch`, so that tiny units do not leave a worker idle for a
// round trip after each.  A field older peers ignore: no version change.
//
// samples_per_pass: [[even, odd], ...], an adaptive render's samples per
// pixel in this pass for each allocation block of the tile (row-major) and
// the pixels of each parity of x + y (RenderPlan::sample_range,
// common/render/sample_allocation.h); absent: the plan's uniform count.
//
// Assets: a UNIT's request may name mesh assets by id (its "objects").  A
// worker that lacks one asks with ASSET_GET and the server answers ASSET:
// with ok, the canonical mesh file (common/assets/mesh_file.h, at most
// kMaxAssetBytes) as the payload frame, which the worker checks against the
// id (its SHA-256) before using it; without ok, no payload and "error", a
// sentence (the asset is not in the server's store).  An ASSET_GET is not a
// unit's answer: the worker's units wait for the asset, their RESULT or
// FAILED follows.  Only a registered worker is answered (others get
// REREGISTER); a worker asks once per asset it has no copy of, and again
// only when no answer came (a timeout, a new connection).
//
// Versioning: READY carries kProtocolVersion (2 since samples_per_pass: a
// version 1 worker would ignore it and render the wrong samples; 3 since the
// pooled ground of an observer at 0 m, render_plan.h: a version 2 worker
// would trace every sample of those pixels; 4 since ASSET_GET / ASSET: a
// version 3 worker would fail every unit whose request has objects; 5 since
// clouds: a version 4 worker would fail every unit whose request has clouds,
// and cannot fetch cloud volumes); the
// server refuses another version with a fatal DISCONNECT.  CURVE changed no
// message (version 3 then): an older worker fails the handshake (NULL
// mechanism) before any READY, which is the refusal it gets.  Decoding is
// strict: an unknown command, a header that is not a JSON object, a missing
// or mistyped field, a value out of range or a wrong frame count throws
// WireError (the receivers count such messages and drop them; nothing here
// trusts the peer).  Unknown extra header fields are ignored, so later
// versions may add fields.
#pragma once
#include <cstddef>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include <nlohmann/json.hpp>

namespace skyfarm::api {

inline constexpr int kProtocolVersion = 5;
// The READY capability "probe" of a worker that runs probe units.
inline constexpr int kProbeUnitsVersion = 1;

// Bounds on what a peer may send (a header is small JSON; the request text of
// a unit may carry tables such as sun.irradiance).
inline constexpr std::size_t kMaxHeaderBytes = 16u << 20;
inline constexpr std::size_t kMaxIdBytes = 256;
inline constexpr std::size_t kMaxMessageBytes = 64u << 10;  // FAILED text (longer ones are cut on encode)
inline constexpr int kMaxSlots = 1024;
inline constexpr int kMaxSamplesPerPass = 1 << 20;
inline constexpr std::size_t kMaxAllocationBlocks = 1 << 16;
// The largest mesh file an ASSET carries: the file of a mesh at the default
// MeshLimits (2 M triangles, 6 M vertices), 168 MB.  It is more than the
// broker's 64 MiB inbound limit, which applies to what workers send; a
// worker's socket takes frames this large (farm_worker.cpp).
inline constexpr std::size_t kMaxAssetBytes = 16 + 24 * std::size_t{6'000'000} + 12 * std::size_t{2'000'000};

// One ZeroMQ message: its frames as byte strings (identity frame excluded).
using Frames = std::vector<std::string>;

class WireError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

enum class Command {
  kReady,
  kHeartbeat,
  kUnit,
  kResult,
  kFailed,
  kCancel,
  kDisconnect,
  kReregister,
  kAssetGet,
  kAsset
};

std::string_view command_name(Command command);
std::optional<Command> command_from_name(std::string_view name);

// --- Messages -----------------------------------------------------------------

struct ReadyMsg {
  std::string id;                 // worker id, unique per worker process
  int cores = 1;                  // hardware threads it renders with
  int slots = 1;                  // units it may hold at once (its credit)
  int version = kProtocolVersion;
  nlohmann::json capabilities = nlohmann::json::object();  // e.g. {"spectral": true}
  int heartbeat_ms = 0;           // the worker's heartbeat interval (0: not told)
  std::optional<std::string> token;
  int prefetch = 0;               // units it queues beyond its slots (0: none)
  bool operator==(const ReadyMsg&) const = default;
};

struct HeartbeatMsg {
  int heartbeat_ms = 0;   // the sender's heartbeat interval (0: not told)
  bool draining = false;  // worker: finishing its units, send no more
  bool operator==(const HeartbeatMsg&) const = default;
};

// The unit fields shared by UNIT, RESULT and FAILED.
struct UnitRef {
  std::string job;
  int tile = 0, batch = 0, pass = 0;
  std::uint64_t attempt = 0;
  bool operator==(const UnitRef&) const = default;
};

enum class UnitKind { kRender, kProbe };

struct UnitMsg {
  UnitRef unit;
  std::string request;  // canonical request text
  UnitKind kind = UnitKind::kRender;
  // samples_per_pass: per allocation block of the tile, (even, odd); empty: absent (uniform).
  std::vector<std::pair<int, int>> samples_per_pass{};
  bool operator==(const UnitMsg&) const = default;
};

struct ResultMsg {
  UnitRef unit;
  std::uint64_t paths = 0;
  double seconds = 0.0;
  std::string film_tile;  // FilmTile::serialize() (probe: ProbeUnitSums::serialize()) bytes, not checked here
  bool operator==(const ResultMsg&) const = default;
};

struct FailedMsg {
  UnitRef unit;
  std::string message;
  bool operator==(const FailedMsg&) const = default;
};

struct CancelMsg {
  std::uint64_t attempt = 0;
  bool operator==(const CancelMsg&) const = default;
};

struct DisconnectMsg {
  std::string reason;
  bool fatal = false;  // server -> worker: a refusal (protocol version, worker id in use); do not retry
  bool operator==(const DisconnectMsg&) const = default;
};

struct ReregisterMsg {
  bool operator==(const ReregisterMsg&) const = default;
};

struct AssetGetMsg {
  std::string id;  // "sha256:<64 hex>" (common/assets/asset_id.h)
  bool operator==(const AssetGetMsg&) const = default;
};

struct AssetMsg {
  std::string id;
  bool ok = false;
  std::string error;  // when not ok: why the server has no such asset
  std::string file;   // when ok: the canonical mesh file's bytes (not checked here)
  bool operator==(const AssetMsg&) const = default;
};

using Message = std::variant<ReadyMsg, HeartbeatMsg, UnitMsg, ResultMsg, FailedMsg, CancelMsg, DisconnectMsg,
                             ReregisterMsg, AssetGetMsg, AssetMsg>;

Command command_of(const Message& message);

// --- Encoding and decoding --------------------------------------------------

Frames encode(const Message& message);
// Throws WireError (with what was wrong) for anything encode could not have produced.
Message decode(const Frames& frames);
// decode that returns nullopt instead of throwing; *error (if given) gets the reason.
std::optional<Message> try_decode(const Frames& frames, std::string* error = nullptr);

// The byte payload of a RESULT as the backend takes it.
inline std::vector<std::uint8_t> payload_bytes(const std::string& payload) {
  return {payload.begin(), payload.end()};
}

}  // namespace skyfarm::api
