// A cloud volume's density as the renderer holds it: one scalar grid,
// dense over the active voxels' bounding box, with the index-to-metres
// mapping of the file it came from (OpenVDB: the grid's linear transform;
// its units are taken as metres).  The server imports an uploaded OpenVDB
// file into this form once (common/assets/vdb_import.h) and stores it as a
// SKYVOL1 file (volume_file.h) that workers fetch like meshes.
#pragma once
#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

namespace skyfarm::assets {

struct VolumeGrid {
  glm::ivec3 size{0};            // voxels along x, y, z
  glm::dvec3 voxel_size_m{1.0};  // edge lengths of a voxel, metres
  glm::dvec3 origin_m{0.0};      // the centre of voxel (0, 0, 0), in the grid's own frame, metres
  std::vector<float> values;     // x fastest, then y, then z; finite and >= 0
  float max_value = 0.0f;

  float at(int x, int y, int z) const {
    return values[static_cast<std::size_t>(x) +
                  static_cast<std::size_t>(size.x) * (static_cast<std::size_t>(y) +
                                                      static_cast<std::size_t>(size.y) * static_cast<std::size_t>(z))];
  }
};

}  // namespace skyfarm::assets
