#include "common/film/film_tile.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>

namespace skyfarm {

namespace {

static_assert(sizeof(PixelBatchSums) == 9 * sizeof(double), "PixelBatchSums must be nine packed doubles");
constexpr std::size_t kDoublesPerRecord = 9;
constexpr std::size_t kHeaderBytes = 40;  // up to the presence flags
constexpr std::size_t kCrcBytes = 4;
constexpr char kMagic[4] = {'S', 'K', 'F', 'T'};

// CRC-32 (IEEE 802.3, reflected polynomial 0xEDB88320, initial and final
// XOR 0xFFFFFFFF; the CRC of zlib's crc32 and of PNG chunks, ISO 3309).
constexpr std::array<std::uint32_t, 256> make_crc_table() {
  std::array<std::uint32_t, 256> t{};
  for (std::uint32_t i = 0; i < 256; ++i) {
    std::uint32_t c = i;
    for (int k = 0; k < 8; ++k) c = (c & 1u) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
    t[i] = c;
  }
  return t;
}
constexpr std::array<std::uint32_t, 256> kCrcTable = make_crc_table();

std::uint32_t crc32(const std::uint8_t* p, std::size_t n) {
  std::uint32_t c = 0xFFFFFFFFu;
  for (std::size_t i = 0; i < n; ++i) c = kCrcTable[(c ^ p[i]) & 0xFFu] ^ (c >> 8);
  return c ^ 0xFFFFFFFFu;
}

void store_u32(std::uint8_t* p, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) p[i] = static_cast<std::uint8_t>(v >> (8 * i));
}
void store_u64(std::uint8_t* p, std::uint64_t v) {
  for (int i = 0; i < 8; ++i) p[i] = static_cast<std::uint8_t>(v >> (8 * i));
}
std::uint32_t get_u32(const std::uint8_t* p) {
  std::uint32_t v = 0;
  for (int i = 0; i < 4; ++i) v |= static_cast<std::uint32_t>(p[i]) << (8 * i);
  return v;
}
std::uint64_t get_u64(const std::uint8_t* p) {
  std::uint64_t v = 0;
  for (int i = 0; i < 8; ++i) v |= static_cast<std::uint64_t>(p[i]) << (8 * i);
  return v;
}

bool is_finite_sample(const Xyz& c, double l) {
  return std::isfinite(c.x) && std::isfinite(c.y) && std::isfinite(c.z) && std::isfinite(l) &&
         std::isfinite(c.y * c.y);
}

// s² = (ΣY² − (ΣY)²/n) / (n − 1), the unbiased sample variance from raw sums
// (clamped at 0 against rounding); n ≥ 2.
double sample_variance(double n, double sum, double sum_sq) {
  const double m2 = sum_sq - sum * sum / n;
  return std::max(0.0, m2 / (n - 1.0));
}
double sample_variance(const PixelBatchSums& s) { return sample_variance(s.n, s.sum_y, s.sum_y2); }

[[noreturn]] void decode_error(const std::string& what) {
  throw FilmTileDecodeError("FilmTile::deserialize: " + what);
}

}  // namespace

FilmTile::FilmTile(int x0, int y0, int width, int height, int batches)
    : x0_(x0), y0_(y0), width_(width), height_(height), batches_(batches) {
  if (x0 < 0 || y0 < 0)
    throw std::invalid_argument("FilmTile: origin (" + std::to_string(x0) + ", " + std::to_string(y0) +
                                ") must be non-negative");
  if (width < 1 || height < 1 || width > kMaxDimension || height > kMaxDimension)
    throw std::invalid_argument("FilmTile: size " + std::to_string(width) + " x " + std::to_string(height) +
                                " must be in [1, " + std::to_string(kMaxDimension) + "]");
  if (batches < 1 || batches > kMaxBatches)
    throw std::invalid_argument("FilmTile: batches = " + std::to_string(batches) + " must be in [1, " +
                                std::to_string(kMaxBatches) + "]");
  if (x0 > std::numeric_limits<int>::max() - width || y0 > std::numeric_limits<int>::max() - height)
    throw std::invalid_argument("FilmTile: tile extends past the largest pixel coordinate");
  data_.assign(static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * static_cast<std::size_t>(batches),
               PixelBatchSums{});
}

std::size_t FilmTile::index(int x, int y, int batch) const {
  if (!contains(x, y))
    throw std::out_of_range("FilmTile: pixel (" + std::to_string(x) + ", " + std::to_string(y) +
                            ") is outside the tile at (" + std::to_string(x0_) + ", " + std::to_string(y0_) +
                            ") of size " + std::to_string(width_) + " x " + std::to_string(height_));
  if (batch < 0 || batch >= batches_)
    throw std::out_of_range("FilmTile: batch " + std::to_string(batch) + " is outside [0, " +
                            std::to_string(batches_) + ")");
  return unchecked_index(x, y, batch);
}

void FilmTile::add_sample(int x, int y, int batch, const Xyz& xyz, double band_radiance) {
  PixelBatchSums& s = data_[index(x, y, batch)];
  const Rgb rgb = xyz_to_linear_srgb(xyz);
  const double r2 = rgb.r * rgb.r, g2 = rgb.g * rgb.g, b2 = rgb.b * rgb.b, y2 = xyz.y * xyz.y;
  // A square that overflows would poison the pixel's sums just like a NaN.
  if (!is_finite_sample(xyz, band_radiance) || !std::isfinite(r2 + g2 + b2 + y2)) {
    ++rejected_;
    return;
  }
  s.n += 1.0;
  s.sum_x += xyz.x;
  s.sum_y += xyz.y;
  s.sum_z += xyz.z;
  s.sum_y2 += y2;
  s.sum_l += band_radiance;
  s.sum_r2 += r2;
  s.sum_g2 += g2;
  s.sum_b2 += b2;
}

void FilmTile::merge(const FilmTile& other) {
  if (!same_geometry(other))
    throw std::invalid_argument("FilmTile::merge: geometry differs (tile at (" + std::to_string(x0_) + ", " +
                                std::to_string(y0_) + ") " + std::to_string(width_) + " x " +
                                std::to_string(height_) + " x " + std::to_string(batches_) + " batches vs (" +
                                std::to_string(other.x0_) + ", " + std::to_string(other.y0_) + ") " +
                                std::to_string(other.width_) + " x " + std::to_string(other.height_) + " x " +
                                std::to_string(other.batches_) + ")");
  for (std::size_t i = 0; i < data_.size(); ++i) {
    PixelBatchSums& a = data_[i];
    const PixelBatchSums& b = other.data_[i];
    a.n += b.n;
    a.sum_x += b.sum_x;
    a.sum_y += b.sum_y;
    a.sum_z += b.sum_z;
    a.sum_y2 += b.sum_y2;
    a.sum_l += b.sum_l;
    a.sum_r2 += b.sum_r2;
    a.sum_g2 += b.sum_g2;
    a.sum_b2 += b.sum_b2;
  }
  rejected_ += other.rejected_;
}

void FilmTile::clear() {
  std::fill(data_.begin(), data_.end(), PixelBatchSums{});
  rejected_ = 0;
}

double FilmTile::total_samples() const {
  double n = 0.0;
  for (const PixelBatchSums& s : data_) n += s.n;
  return n;
}

double FilmTile::min_batch_samples(int x, int y) const {
  double n = sums(x, y, 0).n;
  for (int b = 1; b < batches_; ++b) n = std::min(n, data_[unchecked_index(x, y, b)].n);
  return n;
}

std::optional<Xyz> FilmTile::mean_xyz(int x, int y) const {
  (void)index(x, y, 0);  // range check
  Xyz m{0.0, 0.0, 0.0};
  for (int b = 0; b < batches_; ++b) {
    const PixelBatchSums& s = data_[unchecked_index(x, y, b)];
    if (s.n < 1.0) return std::nullopt;
    m.x += s.sum_x / s.n;
    m.y += s.sum_y / s.n;
    m.z += s.sum_z / s.n;
  }
  return m;
}

std::optional<double> FilmTile::band_radiance(int x, int y, int batch) const {
  const PixelBatchSums& s = sums(x, y, batch);
  if (s.n < 1.0) return std::nullopt;
  return s.sum_l / s.n;
}

std::optional<double> FilmTile::luminance_sample_variance(int x, int y, int batch) const {
  const PixelBatchSums& s = sums(x, y, batch);
  if (s.n < 2.0) return std::nullopt;
  return sample_variance(s);
}

std::optional<double> FilmTile::luminance_variance_of_mean(int x, int y) const {
  (void)index(x, y, 0);
  double var = 0.0;
  for (int b = 0; b < batches_; ++b) {
    const PixelBatchSums& s = data_[unchecked_index(x, y, b)];
    if (s.n < 2.0) return std::nullopt;
    var += sample_variance(s) / s.n;
  }
  return var;
}

std::optional<double> FilmTile::relative_standard_error(int x, int y) const {
  const std::optional<double> var = luminance_variance_of_mean(x, y);
  if (!var) return std::nullopt;
  if (*var == 0.0) return 0.0;
  const double mean = mean_xyz(x, y)->y;  // known: every n_b ≥ 2
  if (!(mean > 0.0)) return std::nullopt;
  return std::sqrt(*var) / mean;
}

std::optional<Rgb> FilmTile::rgb_variance_of_mean(int x, int y) const {
  (void)index(x, y, 0);  // range check
  Rgb var{0.0, 0.0, 0.0};
  for (int b = 0; b < batches_; ++b) {
    const PixelBatchSums& s = data_[unchecked_index(x, y, b)];
    if (s.n < 2.0) return std::nullopt;
    const Rgb sum = xyz_to_linear_srgb(Xyz{s.sum_x, s.sum_y, s.sum_z});
    var.r += sample_variance(s.n, sum.r, s.sum_r2) / s.n;
    var.g += sample_variance(s.n, sum.g, s.sum_g2) / s.n;
    var.b += sample_variance(s.n, sum.b, s.sum_b2) / s.n;
  }
  return var;
}

std::vector<std::uint8_t> FilmTile::serialize() const {
  const std::size_t per_batch = static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_);
  std::vector<std::uint8_t> present(static_cast<std::size_t>(batches_), 0);
  std::uint32_t n_present = 0;
  for (int b = 0; b < batches_; ++b) {
    const PixelBatchSums* first = data_.data() + static_cast<std::size_t>(b) * per_batch;
    // "All zeros" means all bits zero, so that a −0.0 survives the round trip.
    const bool nonzero = std::any_of(first, first + per_batch, [](const PixelBatchSums& s) {
      return std::bit_cast<std::uint64_t>(s.n) | std::bit_cast<std::uint64_t>(s.sum_x) |
             std::bit_cast<std::uint64_t>(s.sum_y) | std::bit_cast<std::uint64_t>(s.sum_z) |
             std::bit_cast<std::uint64_t>(s.sum_y2) | std::bit_cast<std::uint64_t>(s.sum_l) |
             std::bit_cast<std::uint64_t>(s.sum_r2) | std::bit_cast<std::uint64_t>(s.sum_g2) |
             std::bit_cast<std::uint64_t>(s.sum_b2);
    });
    if (nonzero) {
      present[static_cast<std::size_t>(b)] = 1;
      ++n_present;
    }
  }

  const std::size_t record_bytes = kDoublesPerRecord * 8;
  std::vector<std::uint8_t> out(kHeaderBytes + present.size() + n_present * per_batch * record_bytes + kCrcBytes);
  std::uint8_t* p = out.data();
  std::memcpy(p, kMagic, 4);
  store_u32(p + 4, kFormatVersion);
  store_u32(p + 8, static_cast<std::uint32_t>(x0_));
  store_u32(p + 12, static_cast<std::uint32_t>(y0_));
  store_u32(p + 16, static_cast<std::uint32_t>(width_));
  store_u32(p + 20, static_cast<std::uint32_t>(height_));
  store_u32(p + 24, static_cast<std::uint32_t>(batches_));
  store_u32(p + 28, n_present);
  store_u64(p + 32, rejected_);
  std::memcpy(p + kHeaderBytes, present.data(), present.size());
  p += kHeaderBytes + present.size();
  for (int b = 0; b < batches_; ++b) {
    if (!present[static_cast<std::size_t>(b)]) continue;
    const PixelBatchSums* first = data_.data() + static_cast<std::size_t>(b) * per_batch;
    for (std::size_t i = 0; i < per_batch; ++i) {
      const PixelBatchSums& s = first[i];
      for (double v : {s.n, s.sum_x, s.sum_y, s.sum_z, s.sum_y2, s.sum_l, s.sum_r2, s.sum_g2, s.sum_b2}) {
        store_u64(p, std::bit_cast<std::uint64_t>(v));
        p += 8;
      }
    }
  }
  store_u32(p, crc32(out.data(), out.size() - kCrcBytes));
  return out;
}

FilmTile FilmTile::deserialize(const std::uint8_t* bytes, std::size_t size) {
  if (bytes == nullptr && size != 0) decode_error("null buffer");
  if (size < kHeaderBytes + kCrcBytes)
    decode_error("truncated: " + std::to_string(size) + " bytes, shorter than the " +
                 std::to_string(kHeaderBytes + kCrcBytes) + "-byte header");
  if (std::memcmp(bytes, kMagic, 4) != 0) decode_error("bad magic (not a FilmTile frame)");
  const std::uint32_t version = get_u32(bytes + 4);
  if (version != kFormatVersion)
    decode_error("unsupported format version " + std::to_string(version) + " (this build reads " +
                 std::to_string(kFormatVersion) + ")");
  const std::int64_t x0 = static_cast<std::int32_t>(get_u32(bytes + 8));
  const std::int64_t y0 = static_cast<std::int32_t>(get_u32(bytes + 12));
  const std::uint32_t w = get_u32(bytes + 16), h = get_u32(bytes + 20), nb = get_u32(bytes + 24);
  const std::uint32_t n_present = get_u32(bytes + 28);
  const std::uint64_t rejected = get_u64(bytes + 32);
  if (x0 < 0 || y0 < 0 || w < 1 || h < 1 || w > static_cast<std::uint32_t>(kMaxDimension) ||
      h > static_cast<std::uint32_t>(kMaxDimension) || nb < 1 || nb > static_cast<std::uint32_t>(kMaxBatches) ||
      x0 > std::numeric_limits<int>::max() - static_cast<std::int64_t>(w) ||
      y0 > std::numeric_limits<int>::max() - static_cast<std::int64_t>(h))
    decode_error("corrupt header: tile (" + std::to_string(x0) + ", " + std::to_string(y0) + ") " +
                 std::to_string(w) + " x " + std::to_string(h) + " x " + std::to_string(nb) + " batches");
  if (n_present > nb) decode_error("corrupt header: " + std::to_string(n_present) + " present batches of " +
                                   std::to_string(nb));
  // Sizes are bounded by the limits above (2^16 · 2^16 · 4096 · 72 < 2^63).
  const std::uint64_t per_batch_bytes = static_cast<std::uint64_t>(w) * h * kDoublesPerRecord * 8;
  const std::uint64_t expected = kHeaderBytes + nb + n_present * per_batch_bytes + kCrcBytes;
  if (size != expected)
    decode_error(std::string(size < expected ? "truncated" : "trailing bytes") + ": " + std::to_string(size) +
                 " bytes, the header implies " + std::to_string(expected));
  const std::uint32_t stored_crc = get_u32(bytes + size - kCrcBytes);
  if (crc32(bytes, size - kCrcBytes) != stored_crc) decode_error("checksum mismatch (corrupt frame)");

  FilmTile tile(static_cast<int>(x0), static_cast<int>(y0), static_cast<int>(w), static_cast<int>(h),
                static_cast<int>(nb));
  tile.rejected_ = rejected;
  const std::uint8_t* flags = bytes + kHeaderBytes;
  std::uint32_t seen = 0;
  for (std::uint32_t b = 0; b < nb; ++b) {
    if (flags[b] > 1) decode_error("corrupt presence flag " + std::to_string(flags[b]) + " for batch " +
                                   std::to_string(b));
    seen += flags[b];
  }
  if (seen != n_present) decode_error("presence flags name " + std::to_string(seen) + " batches, header says " +
                                      std::to_string(n_present));
  const std::size_t per_batch = static_cast<std::size_t>(w) * h;
  const std::uint8_t* p = flags + nb;
  for (std::uint32_t b = 0; b < nb; ++b) {
    if (!flags[b]) continue;
    PixelBatchSums* first = tile.data_.data() + static_cast<std::size_t>(b) * per_batch;
    for (std::size_t i = 0; i < per_batch; ++i) {
      double v[kDoublesPerRecord];
      for (std::size_t k = 0; k < kDoublesPerRecord; ++k, p += 8) v[k] = std::bit_cast<double>(get_u64(p));
      for (double d : v)
        if (!std::isfinite(d)) decode_error("non-finite sum in batch " + std::to_string(b));
      if (v[0] < 0.0 || v[4] < 0.0 || v[6] < 0.0 || v[7] < 0.0 || v[8] < 0.0)
        decode_error("negative sample count or sum of squares in batch " + std::to_string(b));
      first[i] = PixelBatchSums{v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7], v[8]};
    }
  }
  return tile;
}

}  // namespace skyfarm
