// Little-endian reads and writes of plain values in the asset files
// (mesh_file.h, volume_file.h): the host's bytes as they are, so the files
// are little-endian only on a little-endian host, which the static_assert
// below demands.
#pragma once
#include <bit>
#include <cstddef>
#include <cstring>
#include <string>
#include <string_view>

namespace skyfarm::assets::binary_io {

static_assert(std::endian::native == std::endian::little, "the asset files are little-endian; add byte swaps here");

template <class T>
void append(std::string& out, const T& value) {
  out.append(reinterpret_cast<const char*>(&value), sizeof value);
}

// The T at `offset`; the caller has checked that sizeof(T) bytes lie there.
template <class T>
T read_at(std::string_view bytes, std::size_t offset) {
  T value;
  std::memcpy(&value, bytes.data() + offset, sizeof value);
  return value;
}

}  // namespace skyfarm::assets::binary_io
