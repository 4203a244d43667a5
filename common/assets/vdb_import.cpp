#include "common/assets/vdb_import.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <exception>
#include <mutex>
#include <sstream>

#include <openvdb/io/Stream.h>
#include <openvdb/openvdb.h>

#include "common/assets/mesh_file.h"

namespace skyfarm::assets {

namespace {

// OpenVDB's registries of grid, map and metadata types are filled once per process.
void initialize_openvdb() {
  static std::once_flag once;
  std::call_once(once, [] { openvdb::initialize(); });
}

// An OpenVDB map's 4x4 matrix (row vectors: world = [i j k 1] M) when it is
// linear, axis-aligned and positively scaled; false with *why otherwise.
bool axis_aligned_scale(const openvdb::math::Transform& transform, std::string* why) {
  if (!transform.isLinear()) {
    *why = "the grid's transform is not linear (a frustum); only scale-and-translate transforms are supported";
    return false;
  }
  const openvdb::math::Mat4d m = transform.baseMap()->getAffineMap()->getMat4();
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      const double a = m(i, j);
      if (!std::isfinite(a) || (i != j && a != 0.0) || (i == j && !(a > 0.0))) {
        *why = "the grid's transform rotates, shears or mirrors the voxels; only axis-aligned scale-and-translate "
               "transforms with positive scales are supported";
        return false;
      }
    }
  return true;
}

}  // namespace

bool looks_like_vdb(std::string_view bytes) {
  // OpenVDB writes the int32 0x56444220 in the machine's (little-endian) order.
  static constexpr char kMagic[4] = {0x20, 0x42, 0x44, 0x56};
  return bytes.size() >= 4 && std::memcmp(bytes.data(), kMagic, 4) == 0;
}

bool import_vdb(std::string_view bytes, std::string_view grid_name, const VolumeLimits& limits, VolumeGrid* grid,
                std::string* error) {
  auto fail = [&](std::string message) {
    *error = std::move(message);
    return false;
  };
  if (!looks_like_vdb(bytes)) return fail("not an OpenVDB file (bad magic)");
  initialize_openvdb();
  try {
    std::istringstream in(std::string(bytes), std::ios::binary);
    openvdb::io::Stream stream(in, /*delayLoad=*/false);
    const openvdb::GridPtrVecPtr grids = stream.getGrids();
    if (!grids || grids->empty()) return fail("the OpenVDB file holds no grids");

    // The named float grid; without a name "density", else the only float grid.
    openvdb::FloatGrid::ConstPtr named, density, only;
    std::string names;
    int float_grids = 0;
    for (const openvdb::GridBase::Ptr& g : *grids) {
      if (!g) continue;
      names += (names.empty() ? "" : ", ") + ("\"" + g->getName() + "\" (" + g->valueType() + ")");
      auto f = openvdb::gridConstPtrCast<openvdb::FloatGrid>(g);
      if (!f) continue;
      if (++float_grids == 1) only = f;
      if (!named && g->getName() == grid_name) named = f;
      if (!density && g->getName() == "density") density = f;
    }
    openvdb::FloatGrid::ConstPtr chosen = named;
    if (grid_name.empty()) {
      chosen = density ? density : float_grids == 1 ? only : nullptr;
      if (!chosen)
        return fail("no grid named, no float grid \"density\", and the file holds " + std::to_string(float_grids) +
                    " float grids: " + names);
    }
    if (!chosen)
      return fail("the OpenVDB file has no float grid named \"" + std::string(grid_name) + "\"; it holds " + names);

    std::string why;
    if (!axis_aligned_scale(chosen->transform(), &why)) return fail(why);

    const openvdb::CoordBBox box = chosen->evalActiveVoxelBoundingBox();
    if (box.empty()) return fail("the grid \"" + chosen->getName() + "\" has no active voxels");
    const std::int64_t n[3] = {std::int64_t{box.max().x()} - box.min().x() + 1,
                               std::int64_t{box.max().y()} - box.min().y() + 1,
                               std::int64_t{box.max().z()} - box.min().z() + 1};
    if (n[0] > UINT32_MAX || n[1] > UINT32_MAX || n[2] > UINT32_MAX)
      return fail("the grid's active voxels span more than 2^32 voxels along an axis");
    if (std::string size_error =
            volume_size_error(static_cast<std::uint64_t>(n[0]), static_cast<std::uint64_t>(n[1]),
                              static_cast<std::uint64_t>(n[2]), limits);
        !size_error.empty())
      return fail(size_error + " (the dense box of the grid's active voxels)");

    VolumeGrid g;
    g.size = glm::ivec3(static_cast<int>(n[0]), static_cast<int>(n[1]), static_cast<int>(n[2]));
    const openvdb::Vec3d voxel = chosen->transform().voxelSize();
    const openvdb::Vec3d origin = chosen->transform().indexToWorld(box.min());
    for (int a = 0; a < 3; ++a) {
      g.voxel_size_m[a] = voxel[a];
      g.origin_m[a] = origin[a];
      if (!(std::isfinite(voxel[a]) && voxel[a] > 0.0 && voxel[a] <= kMaxCoordinate))
        return fail("the grid's voxel size is not finite and > 0 (at most 1e7 m)");
      if (!(std::isfinite(origin[a]) && std::abs(origin[a]) <= kMaxCoordinate))
        return fail("the grid's active voxels lie farther than 1e7 m from its origin");
    }
    g.values.resize(static_cast<std::size_t>(n[0] * n[1] * n[2]));
    auto accessor = chosen->getConstAccessor();
    std::size_t i = 0;
    float max_value = 0.0f;
    for (int z = box.min().z(); z <= box.max().z(); ++z)
      for (int y = box.min().y(); y <= box.max().y(); ++y)
        for (int x = box.min().x(); x <= box.max().x(); ++x) {
          const float v = accessor.getValue(openvdb::Coord(x, y, z));
          const float clamped = std::isfinite(v) && v > 0.0f ? v : 0.0f;
          g.values[i++] = clamped;
          max_value = std::max(max_value, clamped);
        }
    g.max_value = max_value;
    *grid = std::move(g);
    return true;
  } catch (const openvdb::Exception& e) {
    return fail(std::string("not a readable OpenVDB file: ") + e.what());
  } catch (const std::bad_alloc&) {
    return fail("not a readable OpenVDB file: it asks for more memory than there is");
  } catch (const std::exception& e) {
    return fail(std::string("not a readable OpenVDB file: ") + e.what());
  }
}

}  // namespace skyfarm::assets
