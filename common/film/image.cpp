#include "common/film/image.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include "common/spectrum/wavelength_sampling.h"

#ifndef SKYFARM_VERSION
#define SKYFARM_VERSION "unknown"
#endif

namespace skyfarm {

Image::Image(int width, int height, ImageLayers layers)
    : width_(width), height_(height), spectral_layout_(layers.spectral) {
  if (width < 1 || height < 1 || width > kMaxDimension || height > kMaxDimension)
    throw std::invalid_argument("Image: size " + std::to_string(width) + " x " + std::to_string(height) +
                                " must be in [1, " + std::to_string(kMaxDimension) + "]");
  if (spectral_layout_) {
    const SpectralLayout& s = *spectral_layout_;
    if (!(std::isfinite(s.min_nm) && std::isfinite(s.max_nm) && s.min_nm < s.max_nm && s.min_nm > 0.0))
      throw std::invalid_argument("Image: spectral range [" + std::to_string(s.min_nm) + ", " +
                                  std::to_string(s.max_nm) + "] nm must satisfy 0 < min < max");
    if (s.batches < 1 || s.batches > FilmTile::kMaxBatches)
      throw std::invalid_argument("Image: spectral batches = " + std::to_string(s.batches) + " must be in [1, " +
                                  std::to_string(FilmTile::kMaxBatches) + "]");
    spectral_.assign(pixel_count() * static_cast<std::size_t>(s.batches), 0.0f);
  }
  rgb_.assign(pixel_count() * 3, 0.0f);
  if (layers.relative_error) error_.assign(pixel_count(), kUnknownError);
  metadata_[metadata_key::kSoftwareVersion] = software_version_text();
}

std::string software_version_text() { return std::string("skyfarm ") + SKYFARM_VERSION; }

std::size_t Image::offset(int x, int y) const {
  if (x < 0 || y < 0 || x >= width_ || y >= height_)
    throw std::out_of_range("Image: pixel (" + std::to_string(x) + ", " + std::to_string(y) + ") is outside " +
                            std::to_string(width_) + " x " + std::to_string(height_));
  return static_cast<std::size_t>(y) * static_cast<std::size_t>(width_) + static_cast<std::size_t>(x);
}

std::array<float, 3> Image::rgb(int x, int y) const {
  const std::size_t i = 3 * offset(x, y);
  return {rgb_[i], rgb_[i + 1], rgb_[i + 2]};
}

void Image::set_rgb(int x, int y, const Rgb& c) {
  const std::size_t i = 3 * offset(x, y);
  rgb_[i] = static_cast<float>(c.r);
  rgb_[i + 1] = static_cast<float>(c.g);
  rgb_[i + 2] = static_cast<float>(c.b);
}

void Image::set_xyz(int x, int y, const Xyz& xyz) { set_rgb(x, y, xyz_to_linear_srgb(xyz)); }

double Image::luminance(int x, int y) const {
  const auto c = rgb(x, y);
  return kLinearSrgbToXyz[1][0] * c[0] + kLinearSrgbToXyz[1][1] * c[1] + kLinearSrgbToXyz[1][2] * c[2];
}

WavelengthRange Image::band_range(int b) const {
  if (!spectral_layout_) throw std::logic_error("Image: no spectral channels");
  const SpectralLayout& s = *spectral_layout_;
  if (b < 0 || b >= s.batches)
    throw std::out_of_range("Image: band " + std::to_string(b) + " is outside [0, " + std::to_string(s.batches) +
                            ")");
  return batch_range(s.min_nm, s.max_nm, b, s.batches);
}

double Image::band_center_nm(int b) const {
  const WavelengthRange r = band_range(b);
  return 0.5 * (r.min_nm + r.max_nm);
}

const float* Image::spectral_channel(int b) const {
  (void)band_range(b);  // checks
  return spectral_.data() + static_cast<std::size_t>(b) * pixel_count();
}

void Image::set_spectral(int x, int y, int b, float band_mean_radiance) {
  (void)band_range(b);
  spectral_[static_cast<std::size_t>(b) * pixel_count() + offset(x, y)] = band_mean_radiance;
}

std::optional<float> Image::relative_error(int x, int y) const {
  const std::size_t i = offset(x, y);
  if (error_.empty() || error_[i] == kUnknownError) return std::nullopt;
  return error_[i];
}

void Image::set_relative_error(int x, int y, std::optional<double> e) {
  if (error_.empty()) throw std::logic_error("Image: no relative-error layer");
  error_[offset(x, y)] = e ? static_cast<float>(*e) : kUnknownError;
}

void Image::resolve(const FilmTile& tile) {
  if (static_cast<long long>(tile.x0()) + tile.width() > width_ ||
      static_cast<long long>(tile.y0()) + tile.height() > height_)
    throw std::invalid_argument("Image::resolve: tile at (" + std::to_string(tile.x0()) + ", " +
                                std::to_string(tile.y0()) + ") of size " + std::to_string(tile.width()) + " x " +
                                std::to_string(tile.height()) + " does not fit in the " + std::to_string(width_) +
                                " x " + std::to_string(height_) + " image");
  if (spectral_layout_ && tile.batches() != spectral_layout_->batches)
    throw std::invalid_argument("Image::resolve: tile has " + std::to_string(tile.batches()) +
                                " batches, the image's spectral layout " +
                                std::to_string(spectral_layout_->batches));
  const int nb = spectral_batches();
  for (int y = tile.y0(); y < tile.y0() + tile.height(); ++y) {
    for (int x = tile.x0(); x < tile.x0() + tile.width(); ++x) {
      const std::optional<Xyz> mean = tile.mean_xyz(x, y);
      set_rgb(x, y, mean ? xyz_to_linear_srgb(*mean) : Rgb{0.0, 0.0, 0.0});
      for (int b = 0; b < nb; ++b)
        set_spectral(x, y, b, static_cast<float>(tile.band_radiance(x, y, b).value_or(0.0)));
      if (has_error_layer()) set_relative_error(x, y, tile.relative_standard_error(x, y));
    }
  }
}

}  // namespace skyfarm
