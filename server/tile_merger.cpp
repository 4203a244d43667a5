#include "server/tile_merger.h"

#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>

#include "common/film/error_estimate.h"
#include "common/image/atomic_file.h"
#include "server/job_service.h"

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

TileMerger::TileMerger(const RenderPlan& plan, std::filesystem::path dir) : plan_(plan), dir_(std::move(dir)) {
  std::error_code ec;
  std::filesystem::create_directories(dir_, ec);
  if (ec) throw StorageError("cannot create " + dir_.string() + ": " + ec.message());
  for (int t = 0; t < plan_.tile_count(); ++t) tiles_.push_back(empty_tile(plan_, t));
  next_index_.assign(static_cast<std::size_t>(plan_.tile_count()), 0);
  waiting_.resize(static_cast<std::size_t>(plan_.tile_count()));
  load();
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
  const FilmTile& target = tiles_[t];
  if (film.x0() != target.x0() || film.y0() != target.y0() || film.width() != target.width() ||
      film.height() != target.height() || film.batches() != target.batches())
    throw FilmTileDecodeError("result tile does not match tile " + std::to_string(u.tile) + " of the plan");
  waiting_[t].emplace(index_of(u), std::move(film));
  // Merge every waiting result that is next in canonical order.
  bool advanced = false;
  for (auto it = waiting_[t].find(next_index_[t]); it != waiting_[t].end(); it = waiting_[t].find(next_index_[t])) {
    tiles_[t].merge(it->second);
    waiting_[t].erase(it);
    ++next_index_[t];
    ++merged_units_;
    advanced = true;
  }
  if (advanced) persist(u.tile);
  return true;
}

int TileMerger::complete_passes() const {
  int passes = plan_.passes;
  for (int n : next_index_) passes = std::min(passes, n / plan_.batches);
  return passes;
}

void TileMerger::resolve(Image* image) const {
  for (const auto& tile : tiles_) image->resolve(tile);
}

std::optional<double> TileMerger::estimated_relative_rms() const {
  ErrorSums sums;
  for (const auto& tile : tiles_) sums.add(error_sums(tile));
  return sums.relative_rms();
}

// File: magic, version, units merged (little-endian uint32 each), then the
// FilmTile's own serialisation (which carries a CRC).
void TileMerger::persist(int t) const {
  const auto bytes = tiles_[static_cast<std::size_t>(t)].serialize();
  const std::uint32_t header[2] = {kVersion, static_cast<std::uint32_t>(next_index_[static_cast<std::size_t>(t)])};
  try {
    AtomicFile file(dir_ / ("tile_" + std::to_string(t) + ".bin"));
    file.write(kMagic, sizeof kMagic);
    file.write(header, sizeof header);
    file.write(bytes.data(), bytes.size());
    file.commit();
  } catch (const FileWriteError& e) {
    throw StorageError(e.what());
  }
}

void TileMerger::load() {
  for (int t = 0; t < plan_.tile_count(); ++t) {
    std::ifstream in(dir_ / ("tile_" + std::to_string(t) + ".bin"), std::ios::binary);
    if (!in) continue;
    const std::vector<char> data((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::uint32_t header[2] = {0, 0};
    if (data.size() < sizeof kMagic + sizeof header || std::memcmp(data.data(), kMagic, sizeof kMagic) != 0) continue;
    std::memcpy(header, data.data() + sizeof kMagic, sizeof header);
    if (header[0] != kVersion || header[1] > static_cast<std::uint32_t>(plan_.batches * plan_.passes)) continue;
    try {
      const std::size_t off = sizeof kMagic + sizeof header;
      FilmTile tile = FilmTile::deserialize(reinterpret_cast<const std::uint8_t*>(data.data()) + off,
                                            data.size() - off);
      const FilmTile& expect = tiles_[static_cast<std::size_t>(t)];
      if (tile.x0() != expect.x0() || tile.y0() != expect.y0() || tile.width() != expect.width() ||
          tile.height() != expect.height() || tile.batches() != expect.batches())
        continue;
      tiles_[static_cast<std::size_t>(t)] = std::move(tile);
      next_index_[static_cast<std::size_t>(t)] = static_cast<int>(header[1]);
      merged_units_ += static_cast<int>(header[1]);
    } catch (const FilmTileDecodeError&) {
      // A damaged tile is rendered again from scratch.
    }
  }
}

}  // namespace skyfarm::server
