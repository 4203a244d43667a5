#include "worker/asset_cache.h"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <vector>

#include "common/assets/asset_id.h"

namespace skyfarm {

namespace fs = std::filesystem;

namespace {

constexpr std::string_view kExtension = ".mesh";

std::optional<std::string> env(const char* name) {
  const char* v = std::getenv(name);
  if (v == nullptr || *v == '\0') return std::nullopt;
  return std::string(v);
}

}  // namespace

AssetDiskCache::AssetDiskCache(std::string dir, std::size_t max_bytes) : dir_(std::move(dir)), max_bytes_(max_bytes) {}

std::string AssetDiskCache::path(std::string_view id) const {
  return (fs::path(dir_) / (std::string(assets::asset_hex(id)) + std::string(kExtension))).string();
}

std::optional<std::string> AssetDiskCache::read(std::string_view id) const {
  if (!assets::is_asset_id(id)) return std::nullopt;
  const std::string file = path(id);
  std::ifstream in(file, std::ios::binary);
  if (!in) return std::nullopt;
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) return std::nullopt;
  std::error_code ec;  // a read-only cache still serves
  fs::last_write_time(file, fs::file_time_type::clock::now(), ec);
  return bytes;
}

void AssetDiskCache::write(std::string_view id, std::string_view bytes) {
  if (!assets::is_asset_id(id)) throw std::runtime_error("not an asset id: " + std::string(id));
  static std::atomic<unsigned> counter{0};
  std::lock_guard lock(mutex_);
  std::error_code ec;
  fs::create_directories(dir_, ec);
  if (ec) throw std::runtime_error("cannot create the asset cache " + dir_ + ": " + ec.message());
  const std::string target = path(id);
  const std::string tmp = target + ".tmp-" + std::to_string(::getpid()) + "-" + std::to_string(counter++);
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    if (!out.flush()) {
      fs::remove(tmp, ec);
      throw std::runtime_error("cannot write " + tmp);
    }
  }
  fs::rename(tmp, target, ec);
  if (ec) {
    fs::remove(tmp, ec);
    throw std::runtime_error("cannot store " + target);
  }
  evict(target);
}

void AssetDiskCache::remove(std::string_view id) {
  if (!assets::is_asset_id(id)) return;
  std::error_code ec;
  fs::remove(path(id), ec);
}

// Oldest use first, until the total fits.  Files another process removes
// meanwhile are skipped; temporaries (".mesh.tmp-...") are not counted.
void AssetDiskCache::evict(const std::string& keep) {
  struct File {
    fs::path path;
    std::uintmax_t bytes;
    fs::file_time_type used;
  };
  std::vector<File> files;
  std::uintmax_t total = 0;
  std::error_code ec;
  for (fs::directory_iterator it(dir_, ec), end; !ec && it != end; it.increment(ec)) {
    if (it->path().extension() != kExtension) continue;
    std::error_code e;
    const std::uintmax_t bytes = it->file_size(e);
    if (e) continue;
    const fs::file_time_type used = fs::last_write_time(it->path(), e);
    if (e) continue;
    files.push_back({it->path(), bytes, used});
    total += bytes;
  }
  std::sort(files.begin(), files.end(), [](const File& a, const File& b) { return a.used < b.used; });
  for (const File& f : files) {
    if (total <= max_bytes_) break;
    if (f.path == fs::path(keep)) continue;
    std::error_code e;
    if (fs::remove(f.path, e)) total -= f.bytes;
  }
}

std::string default_asset_cache_dir() {
  if (const auto dir = env("CACHE_DIRECTORY")) return (fs::path(dir->substr(0, dir->find(':'))) / "assets").string();
  std::optional<std::string> base = env("XDG_CACHE_HOME");
  if (!base) {
    if (const auto home = env("HOME"); home && ::access(home->c_str(), W_OK) == 0) base = *home + "/.cache";
  }
  if (base) return (fs::path(*base) / "skyfarm" / "assets").string();
  const std::string tmp = env("TMPDIR").value_or("/tmp");
  return (fs::path(tmp) / ("skyfarm-worker-" + std::to_string(::getuid())) / "assets").string();
}

}  // namespace skyfarm
