#include "common/assets/asset_id.h"

#include <sodium.h>

namespace skyfarm::assets {

bool is_asset_id(std::string_view id) {
  if (id.size() != kAssetIdPrefix.size() + 64 || id.substr(0, kAssetIdPrefix.size()) != kAssetIdPrefix) return false;
  for (char c : id.substr(kAssetIdPrefix.size()))
    if (!((c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'))) return false;
  return true;
}

// libsodium's SHA-256 (already the project's CURVE key library); the hash
// functions need no sodium_init().
std::string sha256_hex(std::string_view bytes) {
  unsigned char digest[crypto_hash_sha256_BYTES];
  crypto_hash_sha256(digest, reinterpret_cast<const unsigned char*>(bytes.data()), bytes.size());
  static constexpr char kHex[] = "0123456789abcdef";
  std::string hex;
  hex.reserve(2 * sizeof digest);
  for (unsigned char b : digest) {
    hex += kHex[b >> 4];
    hex += kHex[b & 15];
  }
  return hex;
}

std::string asset_id_of(std::string_view file) { return std::string(kAssetIdPrefix) + sha256_hex(file); }

}  // namespace skyfarm::assets
