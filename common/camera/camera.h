// The camera: pixels -> primary rays, and back.
//
// Parameters (CameraSpec, all angles in degrees)
//   projection  equirectangular | fisheye | perspective
//   width       image width in pixels, >= 1
//   height      image height in pixels, >= 1
//   yaw_deg     azimuth of the view centre, clockwise from north (finite)
//   pitch_deg   elevation of the view centre above the horizon (finite)
//   roll_deg    rotation about the view axis; positive = the camera turns
//               clockwise as seen from behind it, so the image content turns
//               counter-clockwise (finite)
//   fov_deg     perspective: horizontal field of view, 0 < fov < 180;
//               fisheye: full angle of the image circle, 0 < fov <= 360;
//               equirectangular: ignored
//   position    planet-centred observer position, m (the ray origin)
//
// World frame (common/geometry/ray.h): planet-centred, +z local up, +y local
// north, +x local east, azimuth clockwise from north.  The camera takes these
// axes as its local horizon frame (the observer is on +z).
//
// Camera basis (forward f, right r, up u), built in three steps:
//   level at yaw   f0 = (sin yaw, cos yaw, 0)     azimuth yaw
//                  r0 = (cos yaw, -sin yaw, 0)    azimuth yaw + 90 deg
//                  u0 = (0, 0, 1)                 zenith
//   pitch p        f = cos p f0 + sin p u0,  u = -sin p f0 + cos p u0,  r = r0
//   roll q         r' = cos q r - sin q u,   u' = sin q r + cos q u
//                  (a right-handed rotation by q about f)
// (r, f, u) is right-handed like (east, north, up) = (x, y, z):
//   r x f = u,  f x u = r,  u x r = f,  and so r x u = -f.
// yaw = pitch = roll = 0: f = north (+y), r = east (+x), u = zenith (+z).
//
// Film coordinates: (fx, fy) in [0, W] x [0, H], fx to the right, fy DOWN
// from the top edge; pixel (x, y) covers [x, x+1] x [y, y+1] and a primary
// ray goes through (x + jx, y + jy), jx, jy in [0, 1) (box filter).
//
// Projections
//   equirectangular  the full sphere, lat-long environment-map layout:
//                    u = fx / W -> relative azimuth phi = (u - 1/2) 360 deg
//                    (clockwise: centre = view azimuth, right = +90 deg),
//                    v = fy / H -> elevation (1/2 - v) 180 deg (top = +u pole).
//                    Pitch and roll rotate the whole sphere; fov ignored.
//   fisheye          angular (equidistant): image circle of radius
//                    R = min(W, H) / 2 px centred in the image; normalised
//                    radius rho in [0, 1] -> angle from the axis
//                    theta = rho fov / 2; in-image angle psi (x right, y up)
//                    -> d = cos theta f + sin theta (cos psi r + sin psi u).
//                    A conventional all-sky image (zenith at the centre, north
//                    up, east LEFT) is yaw 180, pitch 90.
//   perspective      pinhole, horizontal fov, square pixels:
//                    d = normalize(f + x_ndc t r + y_ndc t (H/W) u),
//                    t = tan(fov/2), x_ndc, y_ndc in [-1, 1] (y up).
//
// Pixels: for the fisheye a pixel exists iff its centre lies in the closed
// image circle; other pixels are never traced and stay zero.  Every direction
// returned is a unit vector, finite at the equirect poles and fisheye centre.
//
// All arithmetic in double precision, no fast-math: the same bits on every
// worker, and rays that stay exact at planetary scale.
#pragma once

#include <glm/vec3.hpp>

#include "common/camera/camera_spec.h"
#include "common/geometry/ray.h"

namespace skyfarm {

class Camera {
 public:
  // position: planet-centred observer position (m).  Throws
  // std::invalid_argument on a spec that cannot be built (size < 1, a
  // non-finite angle or position, fov outside the range of its projection).
  Camera(const CameraSpec& spec, const glm::dvec3& position);

  int width() const { return width_; }
  int height() const { return height_; }
  Projection projection() const { return projection_; }

  // False for pixels never traced: outside [0, W) x [0, H), and for the
  // fisheye the pixels whose CENTRE lies outside the image circle.
  bool pixel_exists(int x, int y) const;

  // Primary ray through the film point (x + jx, y + jy), jx, jy in [0, 1)
  // (box-filter jitter; x to the right, y down from the top row).  Returns
  // false (and leaves *ray alone) for a pixel outside the image or a film
  // point with no direction (outside the fisheye circle).
  bool generate_ray(int x, int y, double jx, double jy, Ray* ray) const;

  // Inverse: continuous film coordinates of a unit direction d.  False if d
  // is not seen (behind a pinhole or off its film, outside the fisheye fov).
  // The equirect returns fx in [0, W) (the seam at fx = W wraps to 0).
  bool direction_to_film(const glm::dvec3& d, double* fx, double* fy) const;

  // Solid angle (sr) of the directions the pixel's film square maps to; 0 for
  // pixels that do not exist.  Equirect and perspective in closed form; the
  // fisheye by Gauss-Legendre quadrature of its Jacobian over the part of the
  // pixel inside the image circle.
  double pixel_solid_angle(int x, int y) const;

  const glm::dvec3& forward() const { return forward_; }
  const glm::dvec3& right() const { return right_; }
  const glm::dvec3& up() const { return up_; }
  const glm::dvec3& position() const { return position_; }

 private:
  // Unit direction of a film point (no range checks); false outside the
  // fisheye circle.
  bool film_to_direction(double fx, double fy, glm::dvec3* d) const;
  double fisheye_pixel_solid_angle(int x, int y) const;

  Projection projection_;
  int width_, height_;
  glm::dvec3 position_;
  glm::dvec3 forward_, right_, up_;
  // Perspective: tan of the half-extents of the film at unit distance.
  double tan_half_x_ = 0.0, tan_half_y_ = 0.0;
  // Fisheye: circle centre and radius in pixels, half the fov in radians.
  double centre_x_ = 0.0, centre_y_ = 0.0, radius_px_ = 0.0, half_fov_ = 0.0;
};

}  // namespace skyfarm
