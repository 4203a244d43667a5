// Import of a mesh file (OBJ, PLY, glTF 2.0 / GLB, STL) with assimp into the
// canonical TriangleMesh (triangle_mesh.h).
//
//   format   "obj", "ply", "stl", "gltf" (JSON, buffers as data: URIs; a
//            file beside it is never read), "glb"; detect_mesh_format()
//            guesses one from the bytes
//   limits   MeshLimits (mesh_file.h): more triangles than max_triangles, in
//            the file or once imported, is an error
//
// Node transforms are applied (aiProcess_PreTransformVertices), polygons
// triangulated, points and lines dropped; the result is canonicalized
// (identical vertices joined, degenerate triangles dropped).  Only the
// loader of the named format is registered, so a file cannot reach another
// parser.  assimp is a large parser of hostile input: the server runs this
// in a child process (server/assets/mesh_import_process.h), never in its own.
#pragma once
#include <optional>
#include <string>
#include <string_view>

#include "common/assets/mesh_file.h"
#include "common/assets/triangle_mesh.h"

namespace skyfarm::assets {

// The known format names, in the order above.
inline constexpr std::string_view kMeshFormats[] = {"obj", "ply", "stl", "gltf", "glb"};

bool is_mesh_format(std::string_view format);

// "glb" (magic glTF), "ply" (magic ply), "stl" (solid ... or a binary STL of
// the exact size its count says), "gltf" (a JSON object with "asset"), "obj"
// (text with a "v " line); nullopt otherwise.
std::optional<std::string> detect_mesh_format(std::string_view bytes);

// The mesh, or false with `error` (one sentence for a client) set.
bool import_mesh(std::string_view bytes, std::string_view format, const MeshLimits& limits, TriangleMesh* mesh,
                 std::string* error);

}  // namespace skyfarm::assets
