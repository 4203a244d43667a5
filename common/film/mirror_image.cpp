#include "common/film/mirror_image.h"

namespace skyfarm {

void mirror_left_half(Image* image) {
  const int W = image->width();
  for (int y = 0; y < image->height(); ++y)
    for (int x = W / 2; x < W; ++x) {
      const int src = W - 1 - x;
      const auto rgb = image->rgb(src, y);
      image->set_rgb(x, y, Rgb{rgb[0], rgb[1], rgb[2]});
      if (image->has_spectral())
        for (int b = 0; b < image->spectral_batches(); ++b)
          image->set_spectral(x, y, b, image->spectral_channel(b)[static_cast<std::size_t>(y) * static_cast<std::size_t>(W) + static_cast<std::size_t>(src)]);
      if (image->has_error_layer()) {
        const auto e = image->relative_error(src, y);
        image->set_relative_error(x, y, e ? std::optional<double>(*e) : std::nullopt);
      }
    }
}

}  // namespace skyfarm
