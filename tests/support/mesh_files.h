// Small mesh files the asset tests write themselves: a unit cube (OBJ, quads)
// and the tetrahedron (0,0,0) (1,0,0) (0,1,0) (0,0,1) in every format the
// import reads.  The glTF ones place it with a node translation of +10 m in x,
// so that an import that ignores node transforms shows.
#pragma once
#include <cstdint>
#include <cstring>
#include <string>

namespace skyfarm::testing {

inline const float kTetraPositions[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
inline const std::uint16_t kTetraFaces[4][3] = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};

template <class T>
void append_le(std::string& out, T value) {
  out.append(reinterpret_cast<const char*>(&value), sizeof value);
}

inline std::string cube_obj() {
  return "# unit cube\n"
         "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n"
         "f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n";
}

inline std::string tetra_obj() {
  std::string s;
  for (const auto& p : kTetraPositions)
    s += "v " + std::to_string(p[0]) + " " + std::to_string(p[1]) + " " + std::to_string(p[2]) + "\n";
  for (const auto& f : kTetraFaces)
    s += "f " + std::to_string(f[0] + 1) + " " + std::to_string(f[1] + 1) + " " + std::to_string(f[2] + 1) + "\n";
  return s;
}

inline std::string tetra_ply_ascii() {
  std::string s =
      "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 4\nproperty list uchar int vertex_indices\nend_header\n";
  for (const auto& p : kTetraPositions)
    s += std::to_string(p[0]) + " " + std::to_string(p[1]) + " " + std::to_string(p[2]) + "\n";
  for (const auto& f : kTetraFaces)
    s += "3 " + std::to_string(f[0]) + " " + std::to_string(f[1]) + " " + std::to_string(f[2]) + "\n";
  return s;
}

inline std::string tetra_ply_binary() {
  std::string s =
      "ply\nformat binary_little_endian 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
      "property float z\nelement face 4\nproperty list uchar int vertex_indices\nend_header\n";
  for (const auto& p : kTetraPositions)
    for (float c : p) append_le(s, c);
  for (const auto& f : kTetraFaces) {
    append_le(s, std::uint8_t{3});
    for (std::uint16_t i : f) append_le(s, std::int32_t{i});
  }
  return s;
}

inline std::string tetra_stl_binary() {
  std::string s(80, ' ');
  append_le(s, std::uint32_t{4});
  for (const auto& f : kTetraFaces) {
    for (int k = 0; k < 3; ++k) append_le(s, 0.0f);  // the normal: recomputed by readers
    for (std::uint16_t i : f)
      for (float c : kTetraPositions[i]) append_le(s, c);
    append_le(s, std::uint16_t{0});
  }
  return s;
}

inline std::string tetra_stl_ascii() {
  std::string s = "solid tetra\n";
  for (const auto& f : kTetraFaces) {
    s += " facet normal 0 0 0\n  outer loop\n";
    for (std::uint16_t i : f)
      s += "   vertex " + std::to_string(kTetraPositions[i][0]) + " " + std::to_string(kTetraPositions[i][1]) + " " +
           std::to_string(kTetraPositions[i][2]) + "\n";
    s += "  endloop\n endfacet\n";
  }
  return s + "endsolid tetra\n";
}

// Positions (48 bytes) then uint16 indices (24 bytes).
inline std::string tetra_buffer() {
  std::string b;
  for (const auto& p : kTetraPositions)
    for (float c : p) append_le(b, c);
  for (const auto& f : kTetraFaces)
    for (std::uint16_t i : f) append_le(b, i);
  return b;
}

inline std::string base64(const std::string& in) {
  static constexpr char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  std::size_t i = 0;
  for (; i + 2 < in.size(); i += 3) {
    const unsigned v = (static_cast<unsigned char>(in[i]) << 16) | (static_cast<unsigned char>(in[i + 1]) << 8) |
                       static_cast<unsigned char>(in[i + 2]);
    for (int s = 18; s >= 0; s -= 6) out += kAlphabet[(v >> s) & 63];
  }
  if (i < in.size()) {
    unsigned v = static_cast<unsigned char>(in[i]) << 16;
    if (i + 1 < in.size()) v |= static_cast<unsigned char>(in[i + 1]) << 8;
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += i + 1 < in.size() ? kAlphabet[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

// The glTF JSON; `uri` empty: the GLB's own BIN chunk.
inline std::string tetra_gltf_json(const std::string& uri) {
  std::string buffer = R"({"byteLength":72)";
  if (!uri.empty()) buffer += R"(,"uri":")" + uri + "\"";
  buffer += "}";
  return R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],)"
         R"("nodes":[{"mesh":0,"translation":[10,0,0]}],)"
         R"("meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1}]}],)"
         R"("buffers":[)" + buffer + R"(],)"
         R"("bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":48},{"buffer":0,"byteOffset":48,"byteLength":24}],)"
         R"("accessors":[{"bufferView":0,"componentType":5126,"count":4,"type":"VEC3","min":[0,0,0],"max":[1,1,1]},)"
         R"({"bufferView":1,"componentType":5123,"count":12,"type":"SCALAR"}]})";
}

inline std::string tetra_gltf() {
  return tetra_gltf_json("data:application/octet-stream;base64," + base64(tetra_buffer()));
}

inline std::string tetra_glb() {
  std::string json = tetra_gltf_json("");
  while (json.size() % 4) json += ' ';
  std::string bin = tetra_buffer();
  while (bin.size() % 4) bin += '\0';
  std::string s = "glTF";
  append_le(s, std::uint32_t{2});
  append_le(s, static_cast<std::uint32_t>(12 + 8 + json.size() + 8 + bin.size()));
  append_le(s, static_cast<std::uint32_t>(json.size()));
  append_le(s, std::uint32_t{0x4E4F534A});
  s += json;
  append_le(s, static_cast<std::uint32_t>(bin.size()));
  append_le(s, std::uint32_t{0x004E4942});
  s += bin;
  return s;
}

}  // namespace skyfarm::testing
