// Merges the results of a job's units into its tiles in canonical order and
// keeps them on disk.
//
// Within a tile, unit (batch b, pass p) has index p * batches + b; results
// are merged strictly in index order (merge = addition of sums), so the
// tile's sums are bit-identical to a local render of the tile however many
// workers ran it and in whatever order the results came back.  A result that
// arrives early waits in memory until its predecessors are merged.  After
// an advance the tile (its sums and how many units it holds) is written
// atomically to <dir>/tile_<t>.bin; a restarted server reloads these files
// and resumes after the last merged unit of each tile.
//
// Persistence interval: with `persist_interval` 0 every advance is written
// at once.  Above 0 a tile is written at most once per interval (tiny units
// merge thousands of times a second into few tiles, and each write is a file
// created and renamed); flush_due() writes the tiles whose interval has
// passed, flush() all of them, and so does the destructor.  Crash safety
// does not depend on it: a file records exactly the units it holds, so units
// merged after its last write are simply not merged after a restart, and the
// job service hands them out again (the same bytes, deterministically).
//
// Memory: only the most recently used tiles stay in memory, up to
// `memory_budget_bytes` (the others are on disk already and are read back
// when their next unit arrives), so a 4096x2048 job does not need its whole
// film in the server's memory.
#pragma once
#include <chrono>
#include <filesystem>
#include <list>
#include <map>
#include <memory>
#include <optional>
#include <vector>

#include "common/film/error_estimate.h"
#include "common/film/film_tile.h"
#include "common/film/ground_pool.h"
#include "common/film/image.h"
#include "common/render/render_plan.h"

namespace skyfarm::server {

class TileMerger {
 public:
  // Creates `dir` if needed (unless create_dir is false: a finished job whose
  // directory expired) and reloads the tiles found there.  Throws
  // StorageError when the directory cannot be created.
  TileMerger(const RenderPlan& plan, std::filesystem::path dir, std::size_t memory_budget_bytes = 64u << 20,
             bool create_dir = true,
             std::chrono::milliseconds persist_interval = std::chrono::milliseconds(0));
  ~TileMerger();  // flush(), errors ignored
  TileMerger(const TileMerger&) = delete;
  TileMerger& operator=(const TileMerger&) = delete;

  // A unit's result.  Returns false (and ignores it) when that unit is already
  // merged or waiting.  Throws FilmTileDecodeError on a tile of the wrong
  // geometry, StorageError when the tile cannot be written.
  bool add(const WorkUnit& unit, FilmTile film);
  // Merged into its tile (on disk within the persistence interval).
  bool merged(const WorkUnit& unit) const;
  // Write every tile with merges not yet on disk / those of them written
  // longer than the interval ago.  Throw StorageError when one cannot be written.
  void flush();
  void flush_due(std::chrono::steady_clock::time_point now);
  // Tiles with merges not yet on disk.
  std::size_t dirty_tiles() const { return dirty_.size(); }
  // Merged or waiting in memory.
  bool received(const WorkUnit& unit) const;

  // Only the first `passes` passes merge; units of later passes wait in
  // memory (default: no limit).  Raising the limit merges what became eligible.
  // The job service keeps it at (passes complete everywhere) + 1, so that at
  // the moment a pass completes every tile holds exactly that many passes:
  // stopping there (target error reached) gives the same image as a local
  // render stopped after the same pass, whatever the timing.
  void set_pass_limit(int passes);
  int pass_limit() const { return pass_limit_; }
  // Forgets results waiting in memory (a job stopped early).
  void drop_waiting();
  // Deletes the tile files and forgets the sums (a finished, cancelled or
  // failed job): the counts of merged units stay, nothing merges any more,
  // and resolve / sums_of / error_sums must not be called after it.
  void remove_files();
  bool files_removed() const { return files_removed_; }
  // The bytes of the tile files on disk.
  std::int64_t bytes_on_disk() const { return bytes_on_disk_; }

  std::int64_t merged_units() const { return merged_units_; }
  std::int64_t total_units() const { return plan_.unit_count(); }
  bool complete() const { return merged_units_ == total_units(); }
  // Passes merged in every tile (all batches).
  int complete_passes() const;
  bool first_pass_complete() const { return complete_passes() >= 1; }

  // Resolves every tile into `image` (sizes must match).
  void resolve(Image* image) const;
  // Units merged into tile t, and its sums (read back from disk if needed).
  int merged_units_of(int t) const { return next_index_[static_cast<std::size_t>(t)]; }
  const FilmTile& sums_of(int t) const { return tile(t); }
  // ErrorSums::relative_rms: sqrt(sum_i var(Y_i) / sum_i Y_i^2) with the true
  // sum Y^2 estimated from the noisy means, over pixels with an estimate, or
  // nullopt; `excluded` are the sun disk's pixels (render/sun_pixels.h).
  std::optional<double> estimated_relative_rms(const std::vector<std::uint32_t>& excluded = {}) const;
  // The sums behind it, with the count of traced pixels that have too few
  // samples for an estimate (said, not counted as zero error).
  ErrorSums error_sums(const std::vector<std::uint32_t>& excluded = {}) const;

 private:
  int index_of(const WorkUnit& u) const { return u.pass * plan_.batches + u.batch; }
  void merge_ready(int tile);
  std::filesystem::path tile_path(int tile) const;
  void persist(int tile, const FilmTile& film) const;
  void mark_dirty(int tile);
  void load();
  // The tile's sums, from memory or disk; keeps the cache within its budget.
  FilmTile& tile(int t) const;
  GroundPool ground_pool() const;
  std::optional<FilmTile> read_tile(int t, int* units) const;

  RenderPlan plan_;
  std::filesystem::path dir_;
  std::size_t budget_;
  mutable std::vector<std::unique_ptr<FilmTile>> cache_;  // nullptr: on disk (or empty)
  mutable std::list<int> lru_;                            // most recent first
  mutable std::vector<std::list<int>::iterator> lru_pos_; // each cached tile's place in lru_
  mutable std::size_t cached_bytes_ = 0;
  std::vector<int> next_index_;                   // per tile: units merged
  std::vector<std::map<int, FilmTile>> waiting_;  // per tile: early results by index
  std::int64_t merged_units_ = 0;
  int pass_limit_ = 1 << 30;
  mutable std::vector<std::int64_t> file_bytes_;  // per tile: its file's size (0: none)
  mutable std::int64_t bytes_on_disk_ = 0;
  bool files_removed_ = false;
  std::chrono::steady_clock::duration persist_interval_{};
  mutable std::vector<std::chrono::steady_clock::time_point> persisted_at_;  // per tile: last write
  mutable std::vector<int> dirty_;                                          // tiles not written since a merge
  mutable std::vector<char> is_dirty_;
};

}  // namespace skyfarm::server
