// The project's own binary form of an imported mesh ("skyfarm mesh", the
// files assets/<sha256>.mesh of the server's data directory, and what the
// import child hands its parent).  Little-endian, no padding:
//
//   bytes 0-7    magic "SKYMESH1"
//   bytes 8-11   vertex count V (uint32)
//   bytes 12-15  triangle count T (uint32)
//   then         V x 3 positions (IEEE 754 binary64: x, y, z)
//   then         T x 3 vertex indices (uint32)
//
// decode_mesh_file() is strict, because the bytes may come from a process
// that parsed hostile input: the size must be exactly 16 + 24 V + 12 T,
// V and T within the limits, T >= 1, every position finite and within
// kMaxCoordinate metres, every index < V, no triangle with a repeated index.
// encode_mesh_file() of a canonical mesh (triangle_mesh.h) is the canonical
// file whose SHA-256 names the asset.
#pragma once
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "common/assets/triangle_mesh.h"

namespace skyfarm::assets {

inline constexpr std::string_view kMeshFileMagic = "SKYMESH1";
inline constexpr std::size_t kMeshFileHeaderBytes = 16;
// Larger than any object placed around an observer (the planet is 6.4e6 m).
inline constexpr double kMaxCoordinate = 1.0e7;

struct MeshLimits {
  std::size_t max_triangles = 2'000'000;
  std::size_t max_vertices = 6'000'000;  // 3 per triangle at most once joined
};

std::string encode_mesh_file(const TriangleMesh& mesh);

// The mesh, or false with `error` (one sentence for a client) set.
bool decode_mesh_file(std::string_view bytes, const MeshLimits& limits, TriangleMesh* mesh, std::string* error);

}  // namespace skyfarm::assets
