#include "common/assets/mesh_file.h"

#include <cmath>
#include <cstring>

#include "common/assets/binary_io.h"

namespace skyfarm::assets {

using binary_io::append;
using binary_io::read_at;

std::string encode_mesh_file(const TriangleMesh& mesh) {
  std::string out;
  out.reserve(kMeshFileHeaderBytes + 8 * mesh.positions.size() + 4 * mesh.indices.size());
  out.append(kMeshFileMagic);
  append(out, static_cast<std::uint32_t>(mesh.vertex_count()));
  append(out, static_cast<std::uint32_t>(mesh.triangle_count()));
  for (std::size_t i = 0; i < 3 * mesh.vertex_count(); ++i) append(out, mesh.positions[i]);
  for (std::size_t i = 0; i < 3 * mesh.triangle_count(); ++i) append(out, mesh.indices[i]);
  return out;
}

bool decode_mesh_file(std::string_view bytes, const MeshLimits& limits, TriangleMesh* mesh, std::string* error) {
  auto fail = [&](std::string message) {
    *error = std::move(message);
    return false;
  };
  if (bytes.size() < kMeshFileHeaderBytes || bytes.substr(0, kMeshFileMagic.size()) != kMeshFileMagic)
    return fail("not a skyfarm mesh file (bad magic)");
  const std::uint64_t v = read_at<std::uint32_t>(bytes, 8);
  const std::uint64_t t = read_at<std::uint32_t>(bytes, 12);
  if (t == 0) return fail("the mesh has no triangles");
  if (t > limits.max_triangles)
    return fail("the mesh has " + std::to_string(t) + " triangles, more than the limit of " +
                std::to_string(limits.max_triangles));
  if (v > limits.max_vertices)
    return fail("the mesh has " + std::to_string(v) + " vertices, more than the limit of " +
                std::to_string(limits.max_vertices));
  if (bytes.size() != kMeshFileHeaderBytes + 24 * v + 12 * t) return fail("mesh file size does not match its counts");

  TriangleMesh m;
  m.positions.resize(3 * v);
  m.indices.resize(3 * t);
  std::memcpy(m.positions.data(), bytes.data() + kMeshFileHeaderBytes, 24 * v);
  std::memcpy(m.indices.data(), bytes.data() + kMeshFileHeaderBytes + 24 * v, 12 * t);
  for (double p : m.positions)
    if (!std::isfinite(p) || std::abs(p) > kMaxCoordinate)
      return fail("a vertex position is not finite or farther than 1e7 m from the origin");
  for (std::size_t i = 0; i < t; ++i) {
    const std::uint32_t* tri = &m.indices[3 * i];
    if (tri[0] >= v || tri[1] >= v || tri[2] >= v) return fail("a triangle refers to a vertex that does not exist");
    if (tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2]) return fail("a triangle repeats a vertex");
  }
  *mesh = std::move(m);
  return true;
}

}  // namespace skyfarm::assets
