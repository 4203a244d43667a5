// A unit-sphere triangle mesh: the regular icosahedron, each triangle split
// into four `subdivisions` times with the new vertices pushed out to |p| = 1.
// Shared vertices are shared indices (a closed, watertight mesh), triangles
// wind counter-clockwise seen from outside, normals are the positions.
//
//   subdivisions  0..8: 20 * 4^s triangles, 10 * 4^s + 2 vertices
//                 (s = 4: 5120 triangles, edges ~0.07, the mesh within 1.14e-3
//                 of the sphere)
// Throws std::invalid_argument outside 0..8.
#pragma once
#include "common/geometry/triangle_mesh.h"

namespace skyfarm {

TriangleMesh icosphere(int subdivisions);

}  // namespace skyfarm
