#include "api/curve_keys.h"

#include <fcntl.h>
#include <sodium.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <stdexcept>

#include <zmq.h>

namespace skyfarm::api {
namespace {

constexpr std::string_view kWorkerLabel = "skyfarm worker curve key v1";
constexpr std::string_view kServerLabel = "skyfarm server curve key v1";

void need_sodium() {
  if (sodium_init() < 0) throw std::runtime_error("libsodium cannot initialise");
}

CurveKeyPair derive(std::string_view secret, std::string_view label) {
  need_sodium();
  unsigned char master[32], sk[32], pk[32];
  crypto_generichash(master, sizeof master, reinterpret_cast<const unsigned char*>(secret.data()), secret.size(),
                     nullptr, 0);
  crypto_generichash(sk, sizeof sk, reinterpret_cast<const unsigned char*>(label.data()), label.size(), master,
                     sizeof master);
  crypto_scalarmult_base(pk, sk);
  CurveKeyPair out{z85_encode_key({reinterpret_cast<const char*>(pk), 32}),
                   z85_encode_key({reinterpret_cast<const char*>(sk), 32})};
  sodium_memzero(master, sizeof master);
  sodium_memzero(sk, sizeof sk);
  return out;
}

std::string read_whole(const std::string& path, const char* what) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(std::string("cannot read the ") + what + " " + path + ": " + std::strerror(errno));
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string trim(std::string s) {
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.pop_back();
  std::size_t b = 0;
  while (b < s.size() && std::isspace(static_cast<unsigned char>(s[b]))) ++b;
  return s.substr(b);
}

// The first line that is neither blank nor a # comment, trimmed.
std::string first_key_line(const std::string& text) {
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    line = trim(line);
    if (!line.empty() && line[0] != '#') return line;
  }
  return "";
}

// Writes `text` to a new file `path` with `mode`; false if it exists.
bool write_new_file(const std::string& path, const std::string& text, mode_t mode) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, mode);
  if (fd < 0) {
    if (errno == EEXIST) return false;
    throw std::runtime_error("cannot write " + path + ": " + std::strerror(errno));
  }
  ::fchmod(fd, mode);  // whatever the umask
  const bool ok = ::write(fd, text.data(), text.size()) == static_cast<ssize_t>(text.size());
  ::close(fd);
  if (!ok) throw std::runtime_error("cannot write " + path);
  return true;
}

}  // namespace

CurveKeyPair derive_worker_keys(std::string_view secret) { return derive(secret, kWorkerLabel); }
CurveKeyPair derive_server_keys(std::string_view secret) { return derive(secret, kServerLabel); }

CurveKeyPair generate_curve_keys() {
  char pub[41] = {}, sec[41] = {};
  if (zmq_curve_keypair(pub, sec) != 0) throw std::runtime_error("this libzmq has no CURVE support");
  return {pub, sec};
}

std::string random_secret() {
  need_sodium();
  unsigned char bytes[32];
  randombytes_buf(bytes, sizeof bytes);
  static constexpr char kHex[] = "0123456789abcdef";
  std::string out;
  for (unsigned char b : bytes) {
    out += kHex[b >> 4];
    out += kHex[b & 15];
  }
  return out;
}

std::string z85_encode_key(std::string_view bytes) {
  if (bytes.size() != 32) return "";
  char out[41] = {};
  if (!zmq_z85_encode(out, reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size())) return "";
  return out;
}

std::string z85_decode_key(std::string_view text) {
  if (text.size() != kZ85KeyChars) return "";
  const std::string z(text);
  std::uint8_t out[32];
  if (!zmq_z85_decode(out, z.c_str())) return "";
  return std::string(reinterpret_cast<const char*>(out), 32);
}

bool is_z85_key(std::string_view text) { return !z85_decode_key(text).empty(); }

std::string checked_secret(std::string text, const std::string& origin) {
  text = trim(std::move(text));
  if (text.size() < kMinSecretBytes)
    throw std::runtime_error(origin + ": the worker secret must be at least " + std::to_string(kMinSecretBytes) +
                             " characters (got " + std::to_string(text.size()) + ")");
  return text;
}

std::string read_secret_file(const std::string& path) { return checked_secret(read_whole(path, "secret file"), path); }

CurveKeyPair read_key_file(const std::string& path) {
  const std::string secret = first_key_line(read_whole(path, "key file"));
  if (!is_z85_key(secret))
    throw std::runtime_error(path + ": not a CURVE secret key (40 Z85 characters, as `keygen` writes)");
  char pub[41] = {};
  if (zmq_curve_public(pub, secret.c_str()) != 0) throw std::runtime_error("this libzmq has no CURVE support");
  return {pub, secret};
}

std::string read_public_key(const std::string& key_or_path) {
  if (is_z85_key(key_or_path)) return key_or_path;
  std::error_code ec;
  if (!std::filesystem::is_regular_file(key_or_path, ec))
    throw std::runtime_error("'" + key_or_path + "' is neither a public key (40 Z85 characters) nor a readable file");
  const std::string key = first_key_line(read_whole(key_or_path, "public key file"));
  if (!is_z85_key(key)) throw std::runtime_error(key_or_path + ": not a CURVE public key (40 Z85 characters)");
  return key;
}

void write_key_pair(const std::string& path, const CurveKeyPair& keys) {
  if (!write_new_file(path, keys.secret_key + "\n", 0600))
    throw std::runtime_error(path + " exists: not overwriting a key");
  const std::string pub = path + ".pub";
  std::filesystem::remove(pub);
  if (!write_new_file(pub, keys.public_key + "\n", 0644)) throw std::runtime_error("cannot write " + pub);
}

std::string ensure_secret_file(const std::string& path) {
  std::error_code ec;
  const std::filesystem::path p(path);
  if (p.has_parent_path()) {
    std::filesystem::create_directories(p.parent_path(), ec);
    ::chmod(p.parent_path().c_str(), 0700);
  }
  if (!std::filesystem::exists(p, ec)) write_new_file(path, random_secret() + "\n", 0600);
  return read_secret_file(path);
}

bool is_loopback_endpoint(const std::string& endpoint) {
  if (endpoint.rfind("ipc://", 0) == 0 || endpoint.rfind("inproc://", 0) == 0) return true;
  if (endpoint.rfind("tcp://", 0) != 0) return false;
  std::string host = endpoint.substr(6);
  if (const auto semi = host.find(';'); semi != std::string::npos) host = host.substr(semi + 1);  // source;dest
  if (!host.empty() && host[0] == '[') {
    const auto close = host.find(']');
    return close != std::string::npos && host.substr(1, close - 1) == "::1";
  }
  host = host.substr(0, host.rfind(':'));
  return host == "localhost" || host == "::1" || host.rfind("127.", 0) == 0;
}

int run_keygen_command(const std::string& program, const std::vector<std::string>& args) {
  if (args.size() != 1 || args[0].empty() || args[0][0] == '-') {
    std::cerr << program << " keygen: usage: " << program << " keygen PATH (writes PATH, the secret key, and PATH.pub)\n";
    return 2;
  }
  std::error_code ec;
  if (std::filesystem::exists(args[0], ec)) {
    std::cerr << program << " keygen: " << args[0] << " exists: not overwriting a key\n";
    return 2;
  }
  try {
    const CurveKeyPair keys = generate_curve_keys();
    write_key_pair(args[0], keys);
    std::cout << keys.public_key << "\n";
    return 0;
  } catch (const std::exception& e) {
    std::cerr << program << " keygen: " << e.what() << "\n";
    return 1;
  }
}

}  // namespace skyfarm::api
