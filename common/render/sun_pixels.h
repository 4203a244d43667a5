// The pixels that see the sun disk.  A few pixels 1e6 times brighter than
// the sky, whose samples hit or miss the 0.27-degree disk by chance, would
// otherwise make up the whole luminance-weighted error estimate of an image:
// the image-level estimate leaves them out (their own per-pixel
// error is still in the EXR's error layer).
#pragma once
#include <cstdint>
#include <vector>

#include "common/camera/camera.h"
#include "common/render/atmosphere_refraction.h"
#include "common/sun/sun.h"

namespace skyfarm {

// Sorted pixel indices y * width + x whose centre direction lies within the
// disk's angular radius plus two pixel widths of the sun's centre (empty when
// the sun is a point or out of view).
std::vector<std::uint32_t> sun_pixels(const Camera& camera, const Sun& sun);
// The same for the sun seen through refraction (null: straight) from the
// planet-centred observer: around its apparent centre at 550 nm (empty when
// hidden), widened by the rims' dispersion.  The server and the worker both
// call this one, so their sample allocations agree.
std::vector<std::uint32_t> sun_pixels(const Camera& camera, const Sun& sun, const AtmosphereRefraction* refraction,
                                      const glm::dvec3& observer);

}  // namespace skyfarm
