#include "common/assets/mesh_import.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <exception>
#include <vector>

#include <assimp/BaseImporter.h>
#include <assimp/Importer.hpp>
#include <assimp/importerdesc.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

namespace skyfarm::assets {

namespace {

bool starts_with_ci(std::string_view text, std::string_view prefix) {
  if (text.size() < prefix.size()) return false;
  for (std::size_t i = 0; i < prefix.size(); ++i)
    if (std::tolower(static_cast<unsigned char>(text[i])) != prefix[i]) return false;
  return true;
}

std::string_view trim_front(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t' || s.front() == '\r' || s.front() == '\n' ||
                        s.front() == '\xEF' || s.front() == '\xBB' || s.front() == '\xBF'))
    s.remove_prefix(1);
  return s;
}

// assimp's extension for a format: the glTF 2 loader claims both.
const char* extension_of(std::string_view format) {
  if (format == "obj") return "obj";
  if (format == "ply") return "ply";
  if (format == "stl") return "stl";
  if (format == "gltf") return "gltf";
  if (format == "glb") return "glb";
  return nullptr;
}

// Keeps only the loaders that claim `extension` (glTF has two: 1.0 and 2.0;
// the 2.0 one reads only version 2 files).
void keep_one_loader(Assimp::Importer& importer, const char* extension) {
  std::vector<Assimp::BaseImporter*> others;
  for (std::size_t i = 0; i < importer.GetImporterCount(); ++i) {
    Assimp::BaseImporter* loader = importer.GetImporter(i);
    const aiImporterDesc* info = importer.GetImporterInfo(i);
    bool claims = false;
    if (info && info->mFileExtensions) {
      std::string_view list = info->mFileExtensions;
      while (!list.empty()) {
        const std::size_t space = list.find(' ');
        if (list.substr(0, space) == extension) claims = true;
        list = space == std::string_view::npos ? std::string_view() : list.substr(space + 1);
      }
    }
    if (!claims) others.push_back(loader);
  }
  for (Assimp::BaseImporter* loader : others) importer.UnregisterLoader(loader);
}

// assimp walks every element a PLY header declares, present or not (a
// 10-byte header saying 1e9 vertices costs a minute of CPU): each element
// takes at least one byte in a binary file and two ("0\n") in an ASCII one.
bool ply_counts_fit(std::string_view bytes, std::string* error) {
  const std::size_t end = bytes.find("end_header");
  if (end == std::string_view::npos) return true;  // assimp refuses it itself
  const bool ascii = bytes.substr(0, end).find("format ascii") != std::string_view::npos;
  const std::uint64_t body = bytes.size() - end;
  std::uint64_t elements = 0;
  for (std::size_t at = bytes.find("element"); at != std::string_view::npos && at < end;
       at = bytes.find("element", at + 7)) {
    const std::size_t eol = bytes.find('\n', at);
    const std::string_view line = bytes.substr(at, eol == std::string_view::npos ? std::string_view::npos : eol - at);
    const std::size_t last = line.find_last_of(' ');
    if (last == std::string_view::npos) continue;
    std::uint64_t count = 0;
    for (char c : line.substr(last + 1)) {
      if (c < '0' || c > '9') break;
      count = std::min<std::uint64_t>(count * 10 + static_cast<std::uint64_t>(c - '0'), std::uint64_t{1} << 40);
    }
    elements += count;
  }
  if (elements * (ascii ? 2 : 1) > body) {
    *error = "the PLY header declares " + std::to_string(elements) + " elements, more than the file holds";
    return false;
  }
  return true;
}

}  // namespace

bool is_mesh_format(std::string_view format) {
  return std::find(std::begin(kMeshFormats), std::end(kMeshFormats), format) != std::end(kMeshFormats);
}

std::optional<std::string> detect_mesh_format(std::string_view bytes) {
  if (bytes.substr(0, 4) == "glTF") return "glb";
  if (bytes.substr(0, 4) == "ply\n" || bytes.substr(0, 5) == "ply\r\n") return "ply";
  if (bytes.size() >= 84) {
    std::uint32_t count;
    std::memcpy(&count, bytes.data() + 80, 4);
    if (bytes.size() == 84 + 50 * static_cast<std::uint64_t>(count)) return "stl";
  }
  const std::string_view text = trim_front(bytes);
  if (starts_with_ci(text, "solid")) return "stl";
  if (text.substr(0, 1) == "{" && bytes.find("\"asset\"") != std::string_view::npos) return "gltf";
  if (text.substr(0, 2) == "v " || bytes.find("\nv ") != std::string_view::npos) return "obj";
  return std::nullopt;
}

bool import_mesh(std::string_view bytes, std::string_view format, const MeshLimits& limits, TriangleMesh* mesh,
                 std::string* error) {
  const char* extension = extension_of(format);
  if (!extension) {
    *error = "unknown mesh format '" + std::string(format) + "'";
    return false;
  }
  if (bytes.empty()) {
    *error = "the mesh file is empty";
    return false;
  }
  if (format == "ply" && !ply_counts_fit(bytes, error)) return false;
  if (format == "glb" && bytes.size() >= 12) {
    std::uint32_t length;
    std::memcpy(&length, bytes.data() + 8, 4);
    if (length != bytes.size()) {
      *error = "the GLB header's length (" + std::to_string(length) + ") is not the file's (" +
               std::to_string(bytes.size()) + ")";
      return false;
    }
  }
  try {
    Assimp::Importer importer;
    keep_one_loader(importer, extension);
    importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE, aiPrimitiveType_POINT | aiPrimitiveType_LINE);
    const unsigned flags = aiProcess_Triangulate | aiProcess_JoinIdenticalVertices | aiProcess_SortByPType |
                           aiProcess_PreTransformVertices | aiProcess_ValidateDataStructure;
    const aiScene* scene = importer.ReadFileFromMemory(bytes.data(), bytes.size(), flags, extension);
    if (!scene) {
      *error = std::string("the ") + extension + " file could not be read: " + importer.GetErrorString();
      return false;
    }
    std::uint64_t triangles = 0;
    for (unsigned m = 0; m < scene->mNumMeshes; ++m)
      if (scene->mMeshes[m]->mPrimitiveTypes & aiPrimitiveType_TRIANGLE) triangles += scene->mMeshes[m]->mNumFaces;
    if (triangles > limits.max_triangles) {
      *error = "the file has " + std::to_string(triangles) + " triangles, more than the limit of " +
               std::to_string(limits.max_triangles);
      return false;
    }
    TriangleMesh raw;
    for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
      const aiMesh* in = scene->mMeshes[m];
      if (!(in->mPrimitiveTypes & aiPrimitiveType_TRIANGLE) || !in->mVertices) continue;
      const std::uint64_t base = raw.vertex_count();
      if (base + in->mNumVertices > UINT32_MAX) {
        *error = "the file has too many vertices";
        return false;
      }
      for (unsigned v = 0; v < in->mNumVertices; ++v) {
        raw.positions.push_back(in->mVertices[v].x);
        raw.positions.push_back(in->mVertices[v].y);
        raw.positions.push_back(in->mVertices[v].z);
      }
      for (unsigned f = 0; f < in->mNumFaces; ++f) {
        const aiFace& face = in->mFaces[f];
        if (face.mNumIndices != 3) continue;
        for (int k = 0; k < 3; ++k) {
          if (face.mIndices[k] >= in->mNumVertices) {
            *error = "a face refers to a vertex that does not exist";
            return false;
          }
          raw.indices.push_back(static_cast<std::uint32_t>(base + face.mIndices[k]));
        }
      }
    }
    for (double p : raw.positions)
      if (!std::isfinite(p) || std::abs(p) > kMaxCoordinate) {
        *error = "a vertex position is not finite or farther than 1e7 m from the origin";
        return false;
      }
    TriangleMesh canonical = canonicalize_mesh(raw);
    if (canonical.triangle_count() == 0) {
      *error = "the file has no triangles of non-zero area";
      return false;
    }
    if (canonical.vertex_count() > limits.max_vertices) {
      *error = "the mesh has " + std::to_string(canonical.vertex_count()) + " vertices, more than the limit of " +
               std::to_string(limits.max_vertices);
      return false;
    }
    *mesh = std::move(canonical);
    return true;
  } catch (const std::exception& e) {
    *error = std::string("the ") + extension + " file could not be read: " + e.what();
    return false;
  }
}

}  // namespace skyfarm::assets
