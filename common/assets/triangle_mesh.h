// A plain triangle mesh: what an uploaded mesh asset becomes once imported.
//
//   positions  x, y, z of each vertex, metres, doubles (3 per vertex)
//   indices    vertex indices, uint32, 3 per triangle (counter-clockwise as the
//              file gave them)
//
// canonicalize_mesh() makes the form every importer hands out: identical
// positions joined into one vertex (exact bit equality), triangles with a
// repeated index or zero area dropped, unreferenced vertices removed and the
// vertices numbered in order of first use.  Two files with the same triangles
// in the same order so give the same mesh, byte for byte (mesh_file.h).
#pragma once
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace skyfarm::assets {

struct MeshBounds {
  std::array<double, 3> min{0, 0, 0};
  std::array<double, 3> max{0, 0, 0};
};

struct TriangleMesh {
  std::vector<double> positions;       // 3 per vertex
  std::vector<std::uint32_t> indices;  // 3 per triangle

  std::size_t vertex_count() const { return positions.size() / 3; }
  std::size_t triangle_count() const { return indices.size() / 3; }
};

// The axis-aligned box around every vertex (all zeros for an empty mesh).
MeshBounds mesh_bounds(const TriangleMesh& mesh);

// The canonical form described above.  Indices out of range are dropped with
// their triangle.
TriangleMesh canonicalize_mesh(const TriangleMesh& mesh);

}  // namespace skyfarm::assets
