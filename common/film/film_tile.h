// FilmTile: the per-pixel sums of one rectangular tile of an image, for B
// wavelength batches, as a unit of work returns them and the server merges
// them (sums are merged, never averages of averages).
//
// Parameters
//   x0, y0     the tile's top-left pixel in image coordinates (≥ 0; x to the
//              right, y DOWN, as the camera's film and the EXR scan lines)
//   width      tile width in pixels (≥ 1)
//   height     tile height in pixels (≥ 1)
//   batches    B, the number of equal wavelength batches the spectral range
//              is cut into (wavelength_sampling.h, batch_range; ≥ 1)
//
// Per pixel and batch b the tile holds nine doubles (PixelBatchSums):
//   n       the number of samples added,
//   sum_x, sum_y, sum_z
//           ΣX, ΣY, ΣZ of the per-sample absolute tristimulus estimates
//           (cd/m², as spectral_sample_to_xyz returns them for wavelengths
//           drawn inside batch b with the batch's own pdf),
//   sum_y2  ΣY², for the sample variance of the luminance,
//   sum_l   ΣL, the per-sample estimates of the band's mean spectral radiance
//           (1/Δλ_b) ∫_{batch b} L(λ) dλ, W m⁻² sr⁻¹ nm⁻¹ (spectral channels),
//   sum_r2, sum_g2, sum_b2
//           ΣR², ΣG², ΣB² of the per-sample linear sRGB (Rec. 709) values
//           xyz_to_linear_srgb(X, Y, Z), for the per-channel variances (ΣR
//           itself is the same linear map of ΣX, ΣY, ΣZ, so it is not stored).
//
// Statistics (per pixel; batches are independent estimates of disjoint parts
// of ∫ over the whole range, so the whole-range estimate is their SUM):
//   mean XYZ            X̄ = Σ_b ΣX_b / n_b                        (needs n_b ≥ 1 ∀b)
//   variance of Ȳ       Var[Ȳ] = Σ_b s²_b / n_b,
//                       s²_b = (ΣY²_b − (ΣY_b)²/n_b) / (n_b − 1)   (unbiased; needs n_b ≥ 2 ∀b)
//   relative std error  sqrt(Var[Ȳ]) / Ȳ
//   variance of R̄ (G, B) Σ_b s²_R,b / n_b likewise, from ΣR² and ΣR = M ΣXYZ
// A pixel without enough samples in some batch has NO estimate: the accessors
// return std::nullopt ("unknown"), never a silent 0 or a NaN.  s²_b is
// computed from the raw sums (the form that merges by addition); rounding can
// make it slightly negative when all samples are (nearly) equal, so it is
// clamped at 0.
//
// Non-finite samples (a NaN or Inf in X, Y, Z or L) are not accumulated: they
// are counted in rejected_samples() instead, so one bad path cannot poison a
// pixel for good.  The renderer's tests require that count to be zero.
//
// Merging is elementwise addition (a.sum += b.sum for every double, in
// storage order).  Floating-point addition is not associative, so the result
// is bit-identical only when the caller merges the same tiles in the same
// order; the server fixes that order.
//
// Wire format (serialize / deserialize; all integers and doubles little-endian,
// independent of the host):
//   offset 0   4 bytes   magic "SKFT"
//          4   u32       format version (kFormatVersion = 2)
//          8   i32 x0,  12 i32 y0,  16 u32 width,  20 u32 height
//         24   u32       batches B
//         28   u32       P, the number of batches present (see below)
//         32   u64       rejected (non-finite) sample count
//         40   u8 × B    presence flags: 1 = the batch's sums follow,
//                        0 = the batch is all zeros and omitted (a unit of
//                        work fills one batch only, so its frame carries one)
//       then   for each present batch in order: width × height records of
//              9 f64 (n, ΣX, ΣY, ΣZ, ΣY², ΣL, ΣR², ΣG², ΣB²), row by row
//       last   u32       CRC-32 (IEEE 802.3, as zlib's crc32) of all bytes before it
// deserialize rejects anything else (wrong size, magic, version, flags, CRC,
// negative counts, non-finite sums) with FilmTileDecodeError.
//
// Not thread-safe: one tile per thread, then merge.
#pragma once
#include <cstddef>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "common/spectrum/color.h"

namespace skyfarm {

// The nine running sums of one pixel in one batch (see the file comment).
struct PixelBatchSums {
  double n = 0.0;
  double sum_x = 0.0;
  double sum_y = 0.0;
  double sum_z = 0.0;
  double sum_y2 = 0.0;
  double sum_l = 0.0;
  double sum_r2 = 0.0;
  double sum_g2 = 0.0;
  double sum_b2 = 0.0;
};

// A serialized tile that cannot be decoded (truncated, corrupt, wrong version).
class FilmTileDecodeError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class FilmTile {
 public:
  static constexpr std::uint32_t kFormatVersion = 2;
  // Limits on a tile's geometry (a tile is a part of an image, and a frame
  // that claims more is corrupt).
  static constexpr int kMaxDimension = 1 << 16;
  static constexpr int kMaxBatches = 4096;

  // All sums zero.  Throws std::invalid_argument unless x0, y0 ≥ 0,
  // 1 ≤ width, height ≤ kMaxDimension and 1 ≤ batches ≤ kMaxBatches.
  FilmTile(int x0, int y0, int width, int height, int batches);

  int x0() const { return x0_; }
  int y0() const { return y0_; }
  int width() const { return width_; }
  int height() const { return height_; }
  int batches() const { return batches_; }
  // True when (x, y), in image coordinates, lies inside the tile.
  bool contains(int x, int y) const {
    return x >= x0_ && y >= y0_ && x - x0_ < width_ && y - y0_ < height_;
  }
  bool same_geometry(const FilmTile& other) const {
    return x0_ == other.x0_ && y0_ == other.y0_ && width_ == other.width_ && height_ == other.height_ &&
           batches_ == other.batches_;
  }

  // Adds one sample to pixel (x, y) (image coordinates) of batch b: n += 1,
  // ΣX += xyz.x, …, ΣY² += xyz.y², ΣL += band_radiance, ΣR² += R², ….  A sample with a
  // non-finite value is counted in rejected_samples() and not added.
  // Throws std::out_of_range for a pixel outside the tile or a bad batch.
  void add_sample(int x, int y, int batch, const Xyz& xyz, double band_radiance);

  // Elementwise addition of another tile's sums (and rejected counts).
  // Throws std::invalid_argument unless other has the same geometry.
  void merge(const FilmTile& other);

  // Sets every sum (and the rejected count) back to zero.
  void clear();

  // The sums of pixel (x, y) (image coordinates) in batch b; throws
  // std::out_of_range outside the tile.
  const PixelBatchSums& sums(int x, int y, int batch) const { return data_[index(x, y, batch)]; }
  // Replaces them (ground_pool.h: pixels that share one pooled estimate).
  void set_sums(int x, int y, int batch, const PixelBatchSums& sums) { data_[index(x, y, batch)] = sums; }
  // All sums, batch-major: index ((b · height + (y − y0)) · width + (x − x0)).
  const std::vector<PixelBatchSums>& data() const { return data_; }
  std::uint64_t rejected_samples() const { return rejected_; }
  // Total sample count over the tile's pixels and batches (Σ n).
  double total_samples() const;

  // --- Statistics of pixel (x, y), image coordinates -------------------------
  // Samples in the batch with the fewest (the pixel's progress).
  double min_batch_samples(int x, int y) const;
  // Mean absolute XYZ over the whole range, Σ_b ΣX_b / n_b; nullopt unless
  // every batch has n_b ≥ 1.
  std::optional<Xyz> mean_xyz(int x, int y) const;
  // Mean of the band's spectral radiance estimate, ΣL_b / n_b
  // (W m⁻² sr⁻¹ nm⁻¹); nullopt when n_b = 0.
  std::optional<double> band_radiance(int x, int y, int batch) const;
  // Unbiased sample variance s²_b of the per-sample Y of batch b
  // ((cd/m²)²); nullopt when n_b < 2.
  std::optional<double> luminance_sample_variance(int x, int y, int batch) const;
  // Variance of the whole-range mean luminance, Σ_b s²_b / n_b; nullopt
  // unless every batch has n_b ≥ 2.
  std::optional<double> luminance_variance_of_mean(int x, int y) const;
  // sqrt(Var[Ȳ]) / Ȳ, dimensionless; nullopt unless every batch has n_b ≥ 2.
  // 0 when the variance is 0 (all samples equal, including an all-black
  // pixel); nullopt when Ȳ ≤ 0 with a positive variance (no meaningful
  // relative error).
  std::optional<double> relative_standard_error(int x, int y) const;
  // Variances of the whole-range mean linear sRGB channels (R̄, Ḡ, B̄),
  // Σ_b s²_b / n_b per channel; nullopt unless every batch has n_b ≥ 2.
  std::optional<Rgb> rgb_variance_of_mean(int x, int y) const;

  // --- Wire format ----------------------------------------------------------
  std::vector<std::uint8_t> serialize() const;
  // Throws FilmTileDecodeError (with what was wrong) for anything serialize
  // could not have produced.
  static FilmTile deserialize(const std::uint8_t* bytes, std::size_t size);
  static FilmTile deserialize(const std::vector<std::uint8_t>& bytes) {
    return deserialize(bytes.data(), bytes.size());
  }

 private:
  std::size_t index(int x, int y, int batch) const;
  std::size_t unchecked_index(int x, int y, int batch) const {
    return (static_cast<std::size_t>(batch) * static_cast<std::size_t>(height_) + static_cast<std::size_t>(y - y0_)) *
               static_cast<std::size_t>(width_) +
           static_cast<std::size_t>(x - x0_);
  }

  int x0_, y0_, width_, height_, batches_;
  std::uint64_t rejected_ = 0;
  std::vector<PixelBatchSums> data_;
};

}  // namespace skyfarm
