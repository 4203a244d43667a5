// The project's own binary form of a cloud volume ("skyfarm volume", the
// files assets/<sha256>.vol of the server's data directory, what the import
// child hands its parent and what workers fetch).  Little-endian, no padding:
//
//   bytes 0-7    magic "SKYVOL1\0"
//   bytes 8-19   voxel counts nx, ny, nz (uint32 each)
//   bytes 20-43  voxel edge lengths along x, y, z, metres (binary64)
//   bytes 44-67  centre of voxel (0, 0, 0) in the grid's frame, metres (binary64)
//   then         nx ny nz values (IEEE 754 binary32), x fastest, then y, then z
//
// decode_volume_file() is strict, because the bytes may come from a process
// that parsed hostile input: the size must be exactly 68 + 4 nx ny nz, every
// count >= 1, their product and the values' bytes within the VolumeLimits,
// voxel sizes finite and > 0, the origin finite and within kMaxCoordinate
// metres, every value finite and >= 0.  The SHA-256 of encode_volume_file()
// names the asset.
#pragma once
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "common/assets/volume_grid.h"

namespace skyfarm::assets {

inline constexpr std::string_view kVolumeFileMagic{"SKYVOL1\0", 8};
inline constexpr std::size_t kVolumeFileHeaderBytes = 68;

struct VolumeLimits {
  std::uint64_t max_voxels = std::uint64_t{512} * 512 * 512;
  std::uint64_t max_bytes = std::uint64_t{1} << 30;  // of the values, 4 per voxel
};

// A sentence for a client when the counts break the limits ("" when they do not).
std::string volume_size_error(std::uint64_t nx, std::uint64_t ny, std::uint64_t nz, const VolumeLimits& limits);

// True when the bytes start with the SKYVOL1 magic.
bool is_volume_file(std::string_view bytes);

std::string encode_volume_file(const VolumeGrid& grid);

// The grid (max_value computed), or false with `error` (one sentence for a client) set.
bool decode_volume_file(std::string_view bytes, const VolumeLimits& limits, VolumeGrid* grid, std::string* error);

}  // namespace skyfarm::assets
