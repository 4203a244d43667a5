#include "common/assets/volume_file.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "common/assets/binary_io.h"
#include "common/assets/mesh_file.h"

namespace skyfarm::assets {

using binary_io::append;
using binary_io::read_at;

std::string volume_size_error(std::uint64_t nx, std::uint64_t ny, std::uint64_t nz, const VolumeLimits& limits) {
  if (nx == 0 || ny == 0 || nz == 0) return "the volume has no voxels";
  // Indices are ints (VolumeGrid::size): no axis beyond 2^31 - 1, whatever the limits.
  constexpr std::uint64_t kMaxAxis = 0x7fffffff;
  if (nx > kMaxAxis || ny > kMaxAxis || nz > kMaxAxis) return "the volume has more than 2^31 - 1 voxels along an axis";
  // Each count is < 2^32, so the product of two fits; the third is checked by division.
  const std::uint64_t nxy = nx * ny;
  const std::string dims = std::to_string(nx) + " x " + std::to_string(ny) + " x " + std::to_string(nz);
  if (nxy > limits.max_voxels || nz > limits.max_voxels / nxy)
    return "the volume has " + dims + " voxels, more than the limit of " + std::to_string(limits.max_voxels);
  if (4 * nxy * nz > limits.max_bytes)
    return "the volume's " + dims + " voxels need " + std::to_string(4 * nxy * nz) + " bytes, more than the limit of " +
           std::to_string(limits.max_bytes);
  return {};
}

bool is_volume_file(std::string_view bytes) {
  return bytes.size() >= kVolumeFileMagic.size() && bytes.substr(0, kVolumeFileMagic.size()) == kVolumeFileMagic;
}

std::string encode_volume_file(const VolumeGrid& grid) {
  std::string out;
  out.reserve(kVolumeFileHeaderBytes + 4 * grid.values.size());
  out.append(kVolumeFileMagic);
  for (int a = 0; a < 3; ++a) append(out, static_cast<std::uint32_t>(grid.size[a]));
  for (int a = 0; a < 3; ++a) append(out, grid.voxel_size_m[a]);
  for (int a = 0; a < 3; ++a) append(out, grid.origin_m[a]);
  out.append(reinterpret_cast<const char*>(grid.values.data()), 4 * grid.values.size());
  return out;
}

bool decode_volume_file(std::string_view bytes, const VolumeLimits& limits, VolumeGrid* grid, std::string* error) {
  auto fail = [&](std::string message) {
    *error = std::move(message);
    return false;
  };
  if (bytes.size() < kVolumeFileHeaderBytes || !is_volume_file(bytes))
    return fail("not a skyfarm volume file (bad magic or truncated header)");
  const std::uint64_t nx = read_at<std::uint32_t>(bytes, 8), ny = read_at<std::uint32_t>(bytes, 12),
                      nz = read_at<std::uint32_t>(bytes, 16);
  if (std::string why = volume_size_error(nx, ny, nz, limits); !why.empty()) return fail(why);
  // Each count fits an int, and their product is within the limits.
  const std::uint64_t count = nx * ny * nz;
  if (bytes.size() != kVolumeFileHeaderBytes + 4 * count) return fail("volume file size does not match its counts");
  VolumeGrid g;
  g.size = glm::ivec3(static_cast<int>(nx), static_cast<int>(ny), static_cast<int>(nz));
  for (int a = 0; a < 3; ++a) {
    g.voxel_size_m[a] = read_at<double>(bytes, 20 + 8 * static_cast<std::size_t>(a));
    g.origin_m[a] = read_at<double>(bytes, 44 + 8 * static_cast<std::size_t>(a));
    if (!(std::isfinite(g.voxel_size_m[a]) && g.voxel_size_m[a] > 0.0 && g.voxel_size_m[a] <= kMaxCoordinate))
      return fail("a voxel size is not finite and > 0 (at most 1e7 m)");
    if (!(std::isfinite(g.origin_m[a]) && std::abs(g.origin_m[a]) <= kMaxCoordinate))
      return fail("the volume's origin is not finite or farther than 1e7 m");
  }
  g.values.resize(count);
  std::memcpy(g.values.data(), bytes.data() + kVolumeFileHeaderBytes, 4 * count);
  float max_value = 0.0f;
  for (float v : g.values) {
    if (!(std::isfinite(v) && v >= 0.0f)) return fail("a voxel value is not finite and >= 0");
    max_value = std::max(max_value, v);
  }
  g.max_value = max_value;
  *grid = std::move(g);
  return true;
}

}  // namespace skyfarm::assets
