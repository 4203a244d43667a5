// CurveZMQ credentials of the farm's server and workers (api/wire.h rides
// inside CURVE).  Both ends use this file, so they agree on:
//
//   shared secret  a text file (or SKYFARM_WORKER_SECRET) of at least
//                  kMinSecretBytes bytes; trailing whitespace is ignored.  It
//                  never goes on the wire: both ends derive key pairs from it,
//                  the worker pair and (unless the server has its own key
//                  file) the server pair, as
//                    master = BLAKE2b-256(secret)
//                    secret key = BLAKE2b-256(label, key = master)
//                  with the labels "skyfarm worker curve key v1" and
//                  "skyfarm server curve key v1"; the public key is
//                  crypto_scalarmult_base of the secret key.
//   key file       `keygen PATH`: PATH holds the secret key (Z85, 40
//                  characters, mode 0600), PATH.pub the public key.  Reading
//                  PATH takes its first line that is not blank or a `#`
//                  comment and recomputes the public key from it.
//   public key     40 Z85 characters, or a file holding them (a .pub file).
#pragma once
#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace skyfarm::api {

inline constexpr std::size_t kMinSecretBytes = 16;
inline constexpr std::size_t kZ85KeyChars = 40;

// Z85 text of a CURVE key pair.
struct CurveKeyPair {
  std::string public_key;
  std::string secret_key;
  bool operator==(const CurveKeyPair&) const = default;
};

CurveKeyPair derive_worker_keys(std::string_view secret);
CurveKeyPair derive_server_keys(std::string_view secret);
CurveKeyPair generate_curve_keys();
// 64 hex characters of fresh randomness: a shared secret the server makes itself.
std::string random_secret();

// True for 40 characters of the Z85 alphabet that decode to 32 bytes.
bool is_z85_key(std::string_view text);
// 32 bytes <-> 40 characters; an empty string for anything else.
std::string z85_encode_key(std::string_view bytes);
std::string z85_decode_key(std::string_view text);

// Each throws std::runtime_error naming the path and what is wrong.
std::string read_secret_file(const std::string& path);
// Checks a secret given in text (the environment): the same rules as a file.
std::string checked_secret(std::string text, const std::string& origin);
CurveKeyPair read_key_file(const std::string& path);
// KEY (Z85 text) or PATH of a file holding one.
std::string read_public_key(const std::string& key_or_path);
// Writes PATH (secret, 0600) and PATH.pub; refuses to overwrite PATH.
void write_key_pair(const std::string& path, const CurveKeyPair& keys);
// Writes `secret` to `path` (0600), creating its folder, unless the file
// exists; returns the secret the file holds.
std::string ensure_secret_file(const std::string& path);

// Loopback endpoints (127.x, localhost, ::1, ipc://, inproc://): nothing
// beyond this machine can reach them.
bool is_loopback_endpoint(const std::string& endpoint);

// `PROGRAM keygen PATH`: writes a key pair; the exit code (2: bad arguments or
// an existing PATH).
int run_keygen_command(const std::string& program, const std::vector<std::string>& args);

}  // namespace skyfarm::api
