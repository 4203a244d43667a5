#include "server/jobs/tile_merger.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>

#include "common/film/error_estimate.h"
#include "common/film/ground_pool.h"
#include "common/film/mirror_image.h"
#include "common/image/atomic_file.h"
#include "server/jobs/job_errors.h"

namespace skyfarm::server {
namespace {

constexpr char kMagic[4] = {'S', 'K', 'T', 'M'};
constexpr std::uint32_t kVersion = 1;

FilmTile empty_tile(const RenderPlan& plan, int t) {
  int x0 = 0, y0 = 0, w = 0, h = 0;
  plan.tile_rect(t, &x0, &y0, &w, &h);
  return FilmTile(x0, y0, w, h, plan.batches);
}

}  // namespace

TileMerger::TileMerger(const RenderPlan& plan, std::filesystem::path dir, std::size_t memory_budget_bytes,
                       bool create_dir, std::chrono::milliseconds persist_interval)
    : plan_(plan), dir_(std::move(dir)), budget_(memory_budget_bytes),
      persist_interval_(std::max(persist_interval, std::chrono::milliseconds(0))) {
  std::error_code ec;
  if (create_dir) std::filesystem::create_directories(dir_, ec);
  if (ec) throw StorageError("cannot create " + dir_.string() + ": " + ec.message());
  file_bytes_.assign(static_cast<std::size_t>(plan_.tile_count()), 0);
  cache_.resize(static_cast<std::size_t>(plan_.tile_count()));
  lru_pos_.resize(static_cast<std::size_t>(plan_.tile_count()));
  next_index_.assign(static_cast<std::size_t>(plan_.tile_count()), 0);
  waiting_.resize(static_cast<std::size_t>(plan_.tile_count()));
  persisted_at_.resize(static_cast<std::size_t>(plan_.tile_count()));
  is_dirty_.assign(static_cast<std::size_t>(plan_.tile_count()), 0);
  load();
}

TileMerger::~TileMerger() {
  try {
    flush();
  } catch (const std::exception&) {
    // What is not on disk is rendered again after a restart.
  }
}

void TileMerger::mark_dirty(int t) {
  if (is_dirty_[static_cast<std::size_t>(t)]) return;
  is_dirty_[static_cast<std::size_t>(t)] = 1;
  dirty_.push_back(t);
}

void TileMerger::flush() {
  while (!dirty_.empty()) {
    const int t = dirty_.back();
    persist(t, tile(t));
  }
}

void TileMerger::flush_due(std::chrono::steady_clock::time_point now) {
  const std::vector<int> dirty = dirty_;
  for (const int t : dirty)
    if (now - persisted_at_[static_cast<std::size_t>(t)] >= persist_interval_) persist(t, tile(t));
}

bool TileMerger::merged(const WorkUnit& u) const {
  return index_of(u) < next_index_[static_cast<std::size_t>(u.tile)];
}

bool TileMerger::received(const WorkUnit& u) const {
  return merged(u) || waiting_[static_cast<std::size_t>(u.tile)].count(index_of(u)) > 0;
}

bool TileMerger::add(const WorkUnit& u, FilmTile film) {
  const auto t = static_cast<std::size_t>(u.tile);
  if (received(u)) return false;
  // The whole geometry: a result of the right origin but another size would
  // wait here for ever (merge_ready cannot add it), its unit never merged.
  int x0 = 0, y0 = 0, w = 0, h = 0;
  plan_.tile_rect(u.tile, &x0, &y0, &w, &h);
  if (film.x0() != x0 || film.y0() != y0 || film.width() != w || film.height() != h || film.batches() != plan_.batches)
    throw FilmTileDecodeError("result tile does not match tile " + std::to_string(u.tile) + " of the plan");
  waiting_[t].emplace(index_of(u), std::move(film));
  merge_ready(u.tile);
  return true;
}

// Merges the tile's waiting results that are next in canonical order and
// within the pass limit; writes the tile if it advanced.
void TileMerger::merge_ready(int tile_index) {
  const auto t = static_cast<std::size_t>(tile_index);
  auto it = waiting_[t].find(next_index_[t]);
  if (it == waiting_[t].end() || next_index_[t] / plan_.batches >= pass_limit_) return;
  FilmTile& target = tile(tile_index);
  for (; it != waiting_[t].end() && next_index_[t] / plan_.batches < pass_limit_;
       it = waiting_[t].find(next_index_[t])) {
    target.merge(it->second);
    waiting_[t].erase(it);
    ++next_index_[t];
    ++merged_units_;
  }
  mark_dirty(tile_index);
  if (std::chrono::steady_clock::now() - persisted_at_[t] >= persist_interval_) persist(tile_index, target);
}

void TileMerger::set_pass_limit(int passes) {
  if (files_removed_) return;
  const int previous = pass_limit_;
  pass_limit_ = passes;
  if (passes <= previous) return;
  for (int t = 0; t < plan_.tile_count(); ++t) merge_ready(t);
}

void TileMerger::drop_waiting() {
  for (auto& w : waiting_) w.clear();
}

void TileMerger::remove_files() {
  drop_waiting();
  for (int t = 0; t < plan_.tile_count(); ++t) {
    const auto i = static_cast<std::size_t>(t);
    cache_[i].reset();
    if (file_bytes_[i] == 0) continue;
    std::error_code ec;
    std::filesystem::remove(tile_path(t), ec);
    file_bytes_[i] = 0;
  }
  lru_.clear();
  cached_bytes_ = 0;
  bytes_on_disk_ = 0;
  dirty_.clear();  // merged but unwritten tiles are dropped with the rest
  std::fill(is_dirty_.begin(), is_dirty_.end(), 0);
  files_removed_ = true;
  pass_limit_ = 0;  // nothing merges any more
}

int TileMerger::complete_passes() const {
  int passes = plan_.passes;
  for (int n : next_index_) passes = std::min(passes, n / plan_.batches);
  return passes;
}

// The pooled ground pixels' sums over every tile, in tile order (ground_pool.h).
GroundPool TileMerger::ground_pool() const {
  GroundPool pool(plan_.pooled_ground_row, plan_.batches);
  if (pool.active())
    for (int t = 0; t < plan_.tile_count(); ++t) pool.add(tile(t));
  return pool;
}

void TileMerger::resolve(Image* image) const {
  const GroundPool pool = ground_pool();
  std::optional<FilmTile> scratch;
  for (int t = 0; t < plan_.tile_count(); ++t) image->resolve(pool.shown(tile(t), &scratch));
  if (plan_.mirrored) mirror_left_half(image);
}

ErrorSums TileMerger::error_sums(const std::vector<std::uint32_t>& excluded) const {
  const GroundPool pool = ground_pool();
  ErrorSums sums;
  std::optional<FilmTile> scratch;
  for (int t = 0; t < plan_.tile_count(); ++t)
    sums.add(skyfarm::error_sums(pool.shown(tile(t), &scratch), excluded, plan_.width));
  return sums;
}

std::optional<double> TileMerger::estimated_relative_rms(const std::vector<std::uint32_t>& excluded) const {
  return error_sums(excluded).relative_rms();
}

// File: magic, version, units merged (little-endian uint32 each), then the
// FilmTile's own serialisation (which carries a CRC).
std::filesystem::path TileMerger::tile_path(int t) const { return dir_ / ("tile_" + std::to_string(t) + ".bin"); }

void TileMerger::persist(int t, const FilmTile& film) const {
  if (files_removed_) return;  // a reclaimed job's tiles are never written again
  const auto bytes = film.serialize();
  const std::uint32_t header[2] = {kVersion, static_cast<std::uint32_t>(next_index_[static_cast<std::size_t>(t)])};
  try {
    AtomicFile file(tile_path(t));
    file.write(kMagic, sizeof kMagic);
    file.write(header, sizeof header);
    file.write(bytes.data(), bytes.size());
    // No fsync per merge: the file is CRC-checked when read back and a lost
    // or damaged tile is merely rendered again (deterministically the same).
    file.commit(AtomicFile::Durability::kRenamed);
  } catch (const FileWriteError& e) {
    throw StorageError(e.what());
  }
  const std::int64_t size = static_cast<std::int64_t>(sizeof kMagic + sizeof header + bytes.size());
  auto& known = file_bytes_[static_cast<std::size_t>(t)];
  bytes_on_disk_ += size - known;
  known = size;
  persisted_at_[static_cast<std::size_t>(t)] = std::chrono::steady_clock::now();
  if (is_dirty_[static_cast<std::size_t>(t)]) {
    is_dirty_[static_cast<std::size_t>(t)] = 0;
    dirty_.erase(std::prev(std::find(dirty_.rbegin(), dirty_.rend(), t).base()));  // flush() takes the last
  }
}

// The tile file, validated against the plan; nullopt when absent or damaged
// (a damaged tile is rendered again from scratch).
std::optional<FilmTile> TileMerger::read_tile(int t, int* units) const {
  std::ifstream in(tile_path(t), std::ios::binary);
  if (!in) return std::nullopt;
  const std::vector<char> data((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::uint32_t header[2] = {0, 0};
  if (data.size() < sizeof kMagic + sizeof header || std::memcmp(data.data(), kMagic, sizeof kMagic) != 0)
    return std::nullopt;
  std::memcpy(header, data.data() + sizeof kMagic, sizeof header);
  if (header[0] != kVersion || header[1] > static_cast<std::uint32_t>(plan_.batches * plan_.passes)) return std::nullopt;
  try {
    const std::size_t off = sizeof kMagic + sizeof header;
    FilmTile tile = FilmTile::deserialize(reinterpret_cast<const std::uint8_t*>(data.data()) + off, data.size() - off);
    const FilmTile expect = empty_tile(plan_, t);
    if (tile.x0() != expect.x0() || tile.y0() != expect.y0() || tile.width() != expect.width() ||
        tile.height() != expect.height() || tile.batches() != expect.batches())
      return std::nullopt;
    *units = static_cast<int>(header[1]);
    return tile;
  } catch (const FilmTileDecodeError&) {
    return std::nullopt;
  }
}

// At start: how far every tile got (files are validated now, read again
// when their tile is next needed).
void TileMerger::load() {
  for (int t = 0; t < plan_.tile_count(); ++t) {
    std::error_code ec;
    const auto size = std::filesystem::file_size(tile_path(t), ec);
    if (!ec) {
      file_bytes_[static_cast<std::size_t>(t)] = static_cast<std::int64_t>(size);
      bytes_on_disk_ += static_cast<std::int64_t>(size);
    }
    int units = 0;
    if (!read_tile(t, &units)) continue;
    next_index_[static_cast<std::size_t>(t)] = units;
    merged_units_ += units;
  }
}

FilmTile& TileMerger::tile(int t) const {
  auto& slot = cache_[static_cast<std::size_t>(t)];
  if (slot) {
    lru_.splice(lru_.begin(), lru_, lru_pos_[static_cast<std::size_t>(t)]);
    return *slot;
  }
  int units = 0;
  std::optional<FilmTile> loaded;
  if (next_index_[static_cast<std::size_t>(t)] > 0) loaded = read_tile(t, &units);
  slot = std::make_unique<FilmTile>(loaded ? std::move(*loaded) : empty_tile(plan_, t));
  const std::size_t bytes = static_cast<std::size_t>(slot->width()) * static_cast<std::size_t>(slot->height()) *
                            static_cast<std::size_t>(plan_.batches) * 6 * sizeof(double);
  cached_bytes_ += bytes;
  lru_.push_front(t);
  lru_pos_[static_cast<std::size_t>(t)] = lru_.begin();
  // Evict the least recently used tiles beyond the budget, written first if
  // they have merges not on disk yet (one that cannot be written stays).
  while (cached_bytes_ > budget_ && lru_.size() > 1) {
    const int victim = lru_.back();
    if (is_dirty_[static_cast<std::size_t>(victim)]) {
      try {
        persist(victim, *cache_[static_cast<std::size_t>(victim)]);
      } catch (const StorageError&) {
        break;
      }
    }
    lru_.pop_back();
    auto& v = cache_[static_cast<std::size_t>(victim)];
    cached_bytes_ -= static_cast<std::size_t>(v->width()) * static_cast<std::size_t>(v->height()) *
                     static_cast<std::size_t>(plan_.batches) * 6 * sizeof(double);
    v.reset();
  }
  return *slot;
}

}  // namespace skyfarm::server
