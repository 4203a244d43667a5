// Tests of the camera (common/camera/camera.h): orientation, the three
// projections, their inverses and per-pixel solid angles.
//
// Oracles: named directions of the world frame (north +y, east +x, zenith +z)
// for the documented image layouts; independent closed forms for the solid
// angles (4 pi for the sphere, 2 pi (1 - cos(fov/2)) for the fisheye cap, the
// pyramid formula 4 asin(sin a sin b) for the pinhole's rectangle, the exact
// area of a square clipped by a circle for fisheye edge pixels); round trips
// film -> direction -> film and direction -> film -> direction.
// Fixed seeds (std::mt19937_64); the whole file runs in well under a second.
#include "common/camera/camera.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <glm/geometric.hpp>
#include <limits>
#include <random>
#include <stdexcept>
#include <vector>

#include "common/core/constants.h"

namespace skyfarm {
namespace {

const glm::dvec3 kPosition(0.0, 0.0, kEarthRadius_m + 10.0);
const glm::dvec3 kNorth(0, 1, 0), kSouth(0, -1, 0), kEast(1, 0, 0), kWest(-1, 0, 0), kZenith(0, 0, 1),
    kNadir(0, 0, -1);
const double kOneMinus = 1.0 - 0x1.0p-53;  // the largest jitter below 1

Camera make_camera(Projection p, int w, int h, double yaw = 0, double pitch = 0, double roll = 0, double fov = 60) {
  CameraSpec spec;
  spec.projection = p;
  spec.width = w;
  spec.height = h;
  spec.yaw_deg = yaw;
  spec.pitch_deg = pitch;
  spec.roll_deg = roll;
  spec.fov_deg = fov;
  return Camera(spec, kPosition);
}

double uniform(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

glm::dvec3 random_direction(std::mt19937_64& rng) {
  const double z = 1.0 - 2.0 * uniform(rng), phi = 2.0 * kPi * uniform(rng);
  const double s = std::sqrt(std::max(0.0, 1.0 - z * z));
  return {s * std::cos(phi), s * std::sin(phi), z};
}

// Direction through a continuous film point, split into pixel + jitter (a
// point on the right or bottom edge of the film goes to the last pixel with
// jitter 1, which the camera accepts as the film's closed edge).
bool film_ray(const Camera& cam, double fx, double fy, glm::dvec3* d) {
  const int x = std::clamp(static_cast<int>(std::floor(fx)), 0, cam.width() - 1);
  const int y = std::clamp(static_cast<int>(std::floor(fy)), 0, cam.height() - 1);
  Ray ray;
  if (!cam.generate_ray(x, y, fx - x, fy - y, &ray)) return false;
  *d = ray.d;
  return true;
}

glm::dvec3 film_dir(const Camera& cam, double fx, double fy) {
  glm::dvec3 d(0.0);
  EXPECT_TRUE(film_ray(cam, fx, fy, &d)) << "film point (" << fx << ", " << fy << ") has no direction";
  return d;
}

double angle_between(const glm::dvec3& a, const glm::dvec3& b) {
  return std::atan2(glm::length(glm::cross(a, b)), glm::dot(a, b));
}

#define EXPECT_DIR_NEAR(actual, expected, tol) EXPECT_LT(angle_between((actual), (expected)), (tol))

// --- Orientation ------------------------------------------------------------

// yaw = pitch = roll = 0: the view centre is the northern horizon, right is
// east and up is the zenith (camera.h).
TEST(CameraBasis, DefaultLooksNorthWithEastRightAndZenithUp) {
  const Camera cam = make_camera(Projection::kPerspective, 16, 16);
  EXPECT_DIR_NEAR(cam.forward(), kNorth, 1e-15);
  EXPECT_DIR_NEAR(cam.right(), kEast, 1e-15);
  EXPECT_DIR_NEAR(cam.up(), kZenith, 1e-15);
}

// Each rotation of camera.h by 90 deg: yaw 90 looks east with south to the
// right; pitch 90 looks at the zenith with (for yaw 0) south at the top of the
// image; roll 90 (clockwise from behind) puts the camera's up to the east and
// its right to the nadir.
TEST(CameraBasis, YawPitchRollFollowTheDocumentedRotations) {
  const Camera yaw = make_camera(Projection::kPerspective, 16, 16, 90, 0, 0);
  EXPECT_DIR_NEAR(yaw.forward(), kEast, 1e-15);
  EXPECT_DIR_NEAR(yaw.right(), kSouth, 1e-15);
  EXPECT_DIR_NEAR(yaw.up(), kZenith, 1e-15);
  const Camera pitch = make_camera(Projection::kPerspective, 16, 16, 0, 90, 0);
  EXPECT_DIR_NEAR(pitch.forward(), kZenith, 1e-15);
  EXPECT_DIR_NEAR(pitch.right(), kEast, 1e-15);
  EXPECT_DIR_NEAR(pitch.up(), kSouth, 1e-15);
  const Camera roll = make_camera(Projection::kPerspective, 16, 16, 0, 0, 90);
  EXPECT_DIR_NEAR(roll.forward(), kNorth, 1e-15);
  EXPECT_DIR_NEAR(roll.right(), kNadir, 1e-15);
  EXPECT_DIR_NEAR(roll.up(), kEast, 1e-15);
  // Pitch 30 at yaw 0: the view centre 30 deg above the northern horizon.
  const Camera p30 = make_camera(Projection::kPerspective, 16, 16, 0, 30, 0);
  EXPECT_DIR_NEAR(p30.forward(), glm::dvec3(0.0, std::sqrt(3.0) / 2.0, 0.5), 1e-15);
}

// (right, forward, up) is right-handed like (east, north, up) = (x, y, z):
// right x forward = up and right x up = -forward, for any orientation.
TEST(CameraBasis, OrthonormalAndRightHanded) {
  std::mt19937_64 rng(11);
  for (int i = 0; i < 500; ++i) {
    const double yaw = 720 * uniform(rng) - 360, pitch = 360 * uniform(rng) - 180, roll = 720 * uniform(rng) - 360;
    const Camera cam = make_camera(Projection::kEquirectangular, 8, 4, yaw, pitch, roll);
    const glm::dvec3 &f = cam.forward(), &r = cam.right(), &u = cam.up();
    EXPECT_NEAR(glm::length(f), 1.0, 1e-15);
    EXPECT_NEAR(glm::length(r), 1.0, 1e-15);
    EXPECT_NEAR(glm::length(u), 1.0, 1e-15);
    EXPECT_NEAR(glm::dot(f, r), 0.0, 1e-15);
    EXPECT_NEAR(glm::dot(f, u), 0.0, 1e-15);
    EXPECT_NEAR(glm::dot(r, u), 0.0, 1e-15);
    EXPECT_LT(glm::length(glm::cross(r, f) - u), 1e-15);
    EXPECT_LT(glm::length(glm::cross(r, u) + f), 1e-15);
  }
}

// --- Equirectangular --------------------------------------------------------

// The image centre is the view azimuth on the horizon: north for yaw 0, east
// for yaw 90.
TEST(CameraEquirect, CentreIsTheViewAzimuthOnTheHorizon) {
  const Camera north = make_camera(Projection::kEquirectangular, 64, 32, 0);
  EXPECT_DIR_NEAR(film_dir(north, 32, 16), kNorth, 1e-15);
  const Camera east = make_camera(Projection::kEquirectangular, 64, 32, 90);
  EXPECT_DIR_NEAR(film_dir(east, 32, 16), kEast, 1e-15);
}

// Elevation (0.5 - v) 180 deg: the top edge of the film is the zenith (for
// every column, exactly), the bottom edge the nadir.
TEST(CameraEquirect, TopRowIsTheZenithAndBottomRowTheNadir) {
  const Camera cam = make_camera(Projection::kEquirectangular, 64, 32, 37);
  for (int x = 0; x < cam.width(); ++x) {
    Ray ray;
    ASSERT_TRUE(cam.generate_ray(x, 0, 0.3, 0.0, &ray));
    EXPECT_EQ(ray.d, kZenith) << x;
    ASSERT_TRUE(cam.generate_ray(x, cam.height() - 1, 0.3, kOneMinus, &ray));
    EXPECT_DIR_NEAR(ray.d, kNadir, 1e-14) << x;
  }
}

// Clockwise azimuth with the view azimuth in the centre: column W/4 looks
// west, 3W/4 east and both edges south (yaw 0, the horizon row H/2).
TEST(CameraEquirect, QuarterColumnsLookWestAndEast) {
  const Camera cam = make_camera(Projection::kEquirectangular, 64, 32);
  EXPECT_DIR_NEAR(film_dir(cam, 16, 16), kWest, 1e-15);
  EXPECT_DIR_NEAR(film_dir(cam, 48, 16), kEast, 1e-15);
  EXPECT_DIR_NEAR(film_dir(cam, 0, 16), kSouth, 1e-15);
  EXPECT_DIR_NEAR(film_dir(cam, 64, 16), kSouth, 1e-15);
  // Row H/4 is 45 deg above the horizon.
  EXPECT_DIR_NEAR(film_dir(cam, 48, 8), glm::normalize(glm::dvec3(1, 0, 1)), 1e-15);
}

// Pitch rotates the whole sphere: pitch 90 puts the zenith in the image
// centre and the southern horizon (the camera's up) on the top row.
TEST(CameraEquirect, PitchRotatesTheWholeSphere) {
  const Camera cam = make_camera(Projection::kEquirectangular, 64, 32, 0, 90);
  EXPECT_DIR_NEAR(film_dir(cam, 32, 16), kZenith, 1e-15);
  EXPECT_DIR_NEAR(film_dir(cam, 10, 0), kSouth, 1e-15);
  EXPECT_DIR_NEAR(film_dir(cam, 48, 16), kEast, 1e-15);
}

// Sum over the lat-long cells = 4 pi (the rows telescope); each cell equals
// the direct form dphi (sin e_top - sin e_bottom).
TEST(CameraEquirect, SolidAnglesSumTo4Pi) {
  for (auto [w, h] : {std::pair{360, 180}, std::pair{7, 5}, std::pair{1, 1}, std::pair{1000, 3}}) {
    const Camera cam = make_camera(Projection::kEquirectangular, w, h, 12, 34, 56);
    double sum = 0.0;
    for (int y = 0; y < h; ++y) {
      const double e_top = (0.5 - static_cast<double>(y) / h) * kPi, e_bot = (0.5 - (y + 1.0) / h) * kPi;
      const double direct = (2.0 * kPi / w) * (std::sin(e_top) - std::sin(e_bot));
      for (int x = 0; x < w; ++x) {
        const double omega = cam.pixel_solid_angle(x, y);
        EXPECT_NEAR(omega, direct, 1e-12 * direct + 1e-300);
        sum += omega;
      }
    }
    EXPECT_NEAR(sum, 4.0 * kPi, 1e-9 * 4.0 * kPi) << w << "x" << h;
  }
}

// --- Fisheye ----------------------------------------------------------------

// Pitch 90: the centre of the circle is the zenith (odd size: the centre of
// the middle pixel; even: the corner shared by the four middle pixels).
TEST(CameraFisheye, CentreIsTheZenithForPitch90) {
  for (int n : {101, 100}) {
    const Camera cam = make_camera(Projection::kFisheye, n, n, 0, 90, 0, 180);
    Ray ray;
    if (n % 2) {
      ASSERT_TRUE(cam.generate_ray(n / 2, n / 2, 0.5, 0.5, &ray));
    } else {
      ASSERT_TRUE(cam.generate_ray(n / 2, n / 2, 0.0, 0.0, &ray));
    }
    EXPECT_DIR_NEAR(ray.d, kZenith, 1e-15);
    EXPECT_TRUE(std::isfinite(ray.d.x) && std::isfinite(ray.d.y) && std::isfinite(ray.d.z));
  }
}

// fov 180 looking up: theta = rho 90 deg, so the circle's edge is the horizon,
// every horizontal direction lands on the edge (rho = 1) and a direction 1 deg
// below the horizon is not seen.
TEST(CameraFisheye, Fov180CircleEdgeIsTheHorizon) {
  const Camera cam = make_camera(Projection::kFisheye, 200, 200, 0, 90, 0, 180);
  const double cx = 100, cy = 100, r = 100;
  for (int i = 0; i < 64; ++i) {
    const double psi = 2.0 * kPi * i / 64;
    const glm::dvec3 d = film_dir(cam, cx + r * (1 - 1e-12) * std::cos(psi), cy - r * (1 - 1e-12) * std::sin(psi));
    EXPECT_NEAR(std::asin(d.z), 0.0, 1e-9) << psi;

    const glm::dvec3 horizontal(std::sin(psi), std::cos(psi), 0.0);
    double fx, fy;
    ASSERT_TRUE(cam.direction_to_film(horizontal, &fx, &fy));
    EXPECT_NEAR(std::hypot(fx - cx, fy - cy), r, 1e-9);
    const double dip = 1.0 * kDegToRad;
    const glm::dvec3 below(std::cos(dip) * std::sin(psi), std::cos(dip) * std::cos(psi), -std::sin(dip));
    EXPECT_FALSE(cam.direction_to_film(below, &fx, &fy));
  }
}

// The conventional all-sky image, yaw 180 and pitch 90: zenith in the centre,
// north at the top, east on the LEFT, west on the right, south at the bottom.
TEST(CameraFisheye, AllSkyConventionIsYaw180Pitch90) {
  const Camera cam = make_camera(Projection::kFisheye, 200, 200, 180, 90, 0, 180);
  EXPECT_DIR_NEAR(film_dir(cam, 100, 0), kNorth, 1e-14);
  EXPECT_DIR_NEAR(film_dir(cam, 0, 100), kEast, 1e-14);
  EXPECT_DIR_NEAR(film_dir(cam, 200, 100), kWest, 1e-14);
  EXPECT_DIR_NEAR(film_dir(cam, 100, 200), kSouth, 1e-14);
  // Halfway to the edge: 45 deg elevation.
  EXPECT_DIR_NEAR(film_dir(cam, 50, 100), glm::normalize(glm::dvec3(1, 0, 1)), 1e-14);
}

// Pixels exist iff their centre is in the circle: the corners do not, and the
// count of existing pixels is the circle's area pi R^2 to within its
// perimeter 2 pi R (the Gauss circle problem).  In a wide image the circle is
// inscribed in the height; the side bands do not exist.  Film points outside
// the circle have no ray even inside an existing pixel.
TEST(CameraFisheye, CornersDoNotExistAndTheCountMatchesTheCircle) {
  for (auto [w, h] : {std::pair{200, 200}, std::pair{301, 201}, std::pair{64, 128}}) {
    const Camera cam = make_camera(Projection::kFisheye, w, h, 0, 90, 0, 180);
    for (auto [x, y] : {std::pair{0, 0}, std::pair{w - 1, 0}, std::pair{0, h - 1}, std::pair{w - 1, h - 1}}) {
      EXPECT_FALSE(cam.pixel_exists(x, y));
      Ray ray;
      EXPECT_FALSE(cam.generate_ray(x, y, 0.5, 0.5, &ray));
      EXPECT_EQ(cam.pixel_solid_angle(x, y), 0.0);
    }
    EXPECT_TRUE(cam.pixel_exists(w / 2, h / 2));
    const double r = 0.5 * std::min(w, h);
    long count = 0;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) count += cam.pixel_exists(x, y);
    EXPECT_LE(std::abs(count - kPi * r * r), 2.0 * kPi * r) << w << "x" << h << ": " << count;
  }
  const Camera wide = make_camera(Projection::kFisheye, 301, 201, 0, 90, 0, 180);
  // Circle centre (150.5, 100.5), radius 100.5: on the middle row the circle
  // spans film x in [50, 251].
  EXPECT_FALSE(wide.pixel_exists(49, 100));  // centre 49.5
  EXPECT_TRUE(wide.pixel_exists(50, 100));   // centre 50.5
  EXPECT_TRUE(wide.pixel_exists(250, 100));  // centre 250.5
  EXPECT_FALSE(wide.pixel_exists(251, 100)); // centre 251.5
  // Pixel (150, 0) exists (its top edge's midpoint touches the circle), but
  // its top-left corner is outside.
  Ray ray;
  EXPECT_TRUE(wide.pixel_exists(150, 0));
  EXPECT_TRUE(wide.generate_ray(150, 0, 0.5, 0.0, &ray));
  EXPECT_DIR_NEAR(ray.d, wide.up(), 1e-14);  // rho = 1, fov 180: 90 deg off axis
  EXPECT_FALSE(wide.generate_ray(150, 0, 0.0, 0.0, &ray));
  // Out-of-range pixels never exist.
  EXPECT_FALSE(wide.pixel_exists(-1, 0));
  EXPECT_FALSE(wide.pixel_exists(0, 201));
}

// Exact area of [a0, a1] x [b0, b1] inside the unit disk: integral over a of
// the clipped chord, piecewise one of b1 - b0, c - b0, b1 + c, 2c, 0 with
// c = sqrt(1 - a^2), and int c da = (a c + asin a) / 2.
double square_disk_area(double a0, double a1, double b0, double b1) {
  const double lo = std::max(a0, -1.0), hi = std::min(a1, 1.0);
  if (!(hi > lo)) return 0.0;
  std::vector<double> br = {lo, hi};
  for (double b : {b0, b1})
    if (std::abs(b) < 1)
      for (double a : {-std::sqrt(1 - b * b), std::sqrt(1 - b * b)})
        if (a > lo && a < hi) br.push_back(a);
  std::sort(br.begin(), br.end());
  auto s = [](double a) { return 0.5 * (a * std::sqrt(std::max(0.0, 1 - a * a)) + std::asin(std::clamp(a, -1.0, 1.0))); };
  double area = 0.0;
  for (std::size_t i = 0; i + 1 < br.size(); ++i) {
    const double p = br[i], q = br[i + 1], m = 0.5 * (p + q), c = std::sqrt(1 - m * m);
    // (Equality at the midpoint is a tangency, c's maximum: c <= b1 on the piece.)
    const bool top_clipped = c <= b1, bottom_clipped = -c >= b0;
    if (std::min(b1, c) <= std::max(b0, -c)) continue;
    const double c_part = s(q) - s(p);
    area += (top_clipped ? c_part : b1 * (q - p)) - (bottom_clipped ? -c_part : b0 * (q - p));
  }
  return area;
}

// Edge pixels: for a tiny fov the Jacobian k^2 sinc(k rho) is k^2 to 1e-20,
// so a pixel's solid angle / k^2 is the exact area of its part inside the
// circle (normalised units).  Checked for every existing pixel against the
// closed form above; and the existing pixels plus the slivers of the missing
// ones add up to the disk, pi.
TEST(CameraFisheye, EdgePixelsIntegrateTheirPartInsideTheCircle) {
  for (auto [w, h] : {std::pair{40, 40}, std::pair{31, 23}}) {
    const double fov_deg = 1e-4, k = 0.5 * fov_deg * kDegToRad;
    const Camera cam = make_camera(Projection::kFisheye, w, h, 0, 90, 0, fov_deg);
    const double r = 0.5 * std::min(w, h), cx = 0.5 * w, cy = 0.5 * h;
    double total = 0.0;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const double exact = square_disk_area((x - cx) / r, (x + 1 - cx) / r, (cy - y - 1) / r, (cy - y) / r);
        if (cam.pixel_exists(x, y)) {
          const double area = cam.pixel_solid_angle(x, y) / (k * k);
          // 2e-5 of a pixel: the sqrt endpoint of the pixels holding the
          // circle's points on the axes (a or b = +-1) limits the 8-point rule
          // there to ~6e-6; elsewhere the error is ~1e-13.
          EXPECT_NEAR(area, exact, 2e-5 / (r * r)) << x << "," << y;
          total += area;
        } else {
          total += exact;
        }
      }
    EXPECT_NEAR(total, kPi, 1e-6) << w << "x" << h;
  }
}

// The sum over existing pixels is the cap 2 pi (1 - cos(fov/2)) less the
// slivers of the pixels whose centre is outside the circle.  Tolerance: each
// such pixel that the circle crosses loses at most its full area 1/R^2 times
// the Jacobian's maximum there; the pixel lies beyond rho = 1 - sqrt(2)/R and
// k^2 sinc(k rho) decreases with rho (k <= pi), so
//   cap - n_crossing k^2 sinc(k (1 - sqrt(2)/R)) / R^2 <= sum <= cap (1 + 1e-12).
// (The actual shortfall is about a tenth of that bound.)  The centre pixel's
// solid angle is k^2 / R^2 to O((k/R)^2).
TEST(CameraFisheye, SolidAnglesSumToTheCapUpToEdgePixels) {
  for (double fov : {90.0, 180.0, 270.0, 360.0}) {
    for (auto [w, h] : {std::pair{200, 200}, std::pair{301, 201}}) {
      const Camera cam = make_camera(Projection::kFisheye, w, h, 10, 20, 30, fov);
      const double k = 0.5 * fov * kDegToRad, r = 0.5 * std::min(w, h), cx = 0.5 * w, cy = 0.5 * h;
      const double cap = 2.0 * kPi * (1.0 - std::cos(k));
      double sum = 0.0;
      int missing_crossing = 0;
      for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
          sum += cam.pixel_solid_angle(x, y);
          if (!cam.pixel_exists(x, y)) {
            // Nearest point of the pixel to the centre inside the circle?
            const double na = std::clamp(cx, double(x), x + 1.0) - cx, nb = std::clamp(cy, double(y), y + 1.0) - cy;
            missing_crossing += (na * na + nb * nb < r * r);
          }
        }
      const double rho_min = std::max(0.0, 1.0 - std::sqrt(2.0) / r), theta_min = k * rho_min;
      const double j_max = k * k * (theta_min > 0 ? std::sin(theta_min) / theta_min : 1.0);
      const double tol = missing_crossing * j_max / (r * r);
      std::printf("fov %5.1f %dx%d: (cap - sum) / cap = %.3e, bound %.3e\n", fov, w, h, (cap - sum) / cap, tol / cap);
      EXPECT_LE(sum, cap * (1 + 1e-12)) << fov << " " << w << "x" << h;
      EXPECT_GE(sum, cap - tol) << fov << " " << w << "x" << h;
      EXPECT_LT(tol / cap, 0.03);  // the bound itself is small: ~ perimeter / area
      if (w % 2 && h % 2) {
        EXPECT_NEAR(cam.pixel_solid_angle(w / 2, h / 2), k * k / (r * r), 1e-3 * k * k / (r * r));
      }
    }
  }
}

// --- Perspective ------------------------------------------------------------

// Pinhole at yaw = pitch = 0, t = tan(fov/2), t_y = t H/W: the right edge's
// centre is fov/2 east of north on the horizon; the top edge's centre
// atan(t_y) above north; the top-left corner lies atan(hypot(t, t_y)) from the
// axis, at azimuth -atan(t) and elevation atan(t_y / sqrt(1 + t^2)).
TEST(CameraPerspective, EdgesAndCornersSubtendTheExpectedAngles) {
  for (double fov : {90.0, 60.0, 150.0}) {
    const int w = 160, h = 90;
    const Camera cam = make_camera(Projection::kPerspective, w, h, 0, 0, 0, fov);
    const double half = 0.5 * fov * kDegToRad, t = std::tan(half), ty = t * h / w;
    EXPECT_DIR_NEAR(film_dir(cam, w, 0.5 * h), glm::dvec3(std::sin(half), std::cos(half), 0.0), 1e-14);
    EXPECT_DIR_NEAR(film_dir(cam, 0, 0.5 * h), glm::dvec3(-std::sin(half), std::cos(half), 0.0), 1e-14);
    const double top = std::atan(ty);
    EXPECT_DIR_NEAR(film_dir(cam, 0.5 * w, 0), glm::dvec3(0.0, std::cos(top), std::sin(top)), 1e-14);
    const glm::dvec3 corner = film_dir(cam, 0, 0);
    EXPECT_NEAR(angle_between(corner, kNorth), std::atan(std::hypot(t, ty)), 1e-14);
    EXPECT_NEAR(std::atan2(corner.x, corner.y), -std::atan(t), 1e-14);
    EXPECT_NEAR(std::asin(corner.z), std::atan(ty / std::sqrt(1 + t * t)), 1e-14);
    const glm::dvec3 bottom_right = film_dir(cam, w, h);
    EXPECT_NEAR(std::atan2(bottom_right.x, bottom_right.y), std::atan(t), 1e-14);
    EXPECT_NEAR(std::asin(bottom_right.z), -std::atan(ty / std::sqrt(1 + t * t)), 1e-14);
  }
}

// Behind the pinhole, or outside the film, a direction is not seen.
TEST(CameraPerspective, DirectionsBehindOrOffTheFilmAreNotSeen) {
  const Camera cam = make_camera(Projection::kPerspective, 160, 90, 0, 0, 0, 90);
  double fx, fy;
  EXPECT_FALSE(cam.direction_to_film(kSouth, &fx, &fy));
  EXPECT_FALSE(cam.direction_to_film(kEast, &fx, &fy));  // 90 deg off axis
  EXPECT_FALSE(cam.direction_to_film(glm::normalize(glm::dvec3(1.01, 1, 0)), &fx, &fy));
  EXPECT_FALSE(cam.direction_to_film(glm::normalize(glm::dvec3(0, 1, 0.6)), &fx, &fy));  // above t_y = 0.5625
  EXPECT_TRUE(cam.direction_to_film(glm::normalize(glm::dvec3(0.99, 1, 0)), &fx, &fy));
  EXPECT_TRUE(cam.direction_to_film(kNorth, &fx, &fy));
  EXPECT_NEAR(fx, 80.0, 1e-12);
  EXPECT_NEAR(fy, 45.0, 1e-12);
}

// The pixels tile the film's rectangle, which subtends 4 asin(sin a sin b)
// with tan a = t, tan b = t H/W (the right rectangular pyramid).
TEST(CameraPerspective, SolidAnglesSumToThePinholeRectangle) {
  for (double fov : {10.0, 90.0, 150.0, 179.0}) {
    for (auto [w, h] : {std::pair{160, 90}, std::pair{33, 17}, std::pair{50, 200}}) {
      const Camera cam = make_camera(Projection::kPerspective, w, h, 10, 20, 30, fov);
      const double a = 0.5 * fov * kDegToRad, b = std::atan(std::tan(a) * h / w);
      const double expected = 4.0 * std::asin(std::sin(a) * std::sin(b));
      double sum = 0.0;
      for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
          const double omega = cam.pixel_solid_angle(x, y);
          EXPECT_GT(omega, 0.0);
          sum += omega;
        }
      EXPECT_NEAR(sum, expected, 1e-9 * expected) << fov << " " << w << "x" << h;
    }
  }
  // The centre pixel of a narrow view is its area on the unit plane.
  const Camera cam = make_camera(Projection::kPerspective, 101, 51, 0, 0, 0, 1.0);
  const double t = std::tan(0.5 * kDegToRad);
  // Pixel width 2 t / W, height 2 t_y / H = 2 t / W (square pixels).
  const double side = 2 * t / 101;
  EXPECT_NEAR(cam.pixel_solid_angle(50, 25), side * side, 1e-6 * side * side);
}

// --- All projections ----------------------------------------------------------

// Roll q turns the camera clockwise as seen from behind, so the image content
// turns counter-clockwise by q about the image centre: a direction seen at
// offset (dx, dy) (y up) with roll 0 is seen at (dx cos q - dy sin q,
// dx sin q + dy cos q).  Holds for the square pinhole and the fisheye.  And
// roll 90: the top centre of the unrolled image (towards the zenith) moves to
// the left edge's centre.
TEST(CameraRoll, ImageContentTurnsCounterClockwise) {
  std::mt19937_64 rng(5);
  const double q = 25.0 * kDegToRad;
  for (Projection p : {Projection::kPerspective, Projection::kFisheye}) {
    const Camera flat = make_camera(p, 100, 100, 30, 10, 0, 90);
    const Camera rolled = make_camera(p, 100, 100, 30, 10, 25, 90);
    for (int i = 0; i < 100; ++i) {
      const double fx = 30 + 40 * uniform(rng), fy = 30 + 40 * uniform(rng);
      const glm::dvec3 d = film_dir(flat, fx, fy);
      double gx, gy;
      ASSERT_TRUE(rolled.direction_to_film(d, &gx, &gy));
      const double dx = fx - 50, dy = 50 - fy;
      EXPECT_NEAR(gx - 50, dx * std::cos(q) - dy * std::sin(q), 1e-9);
      EXPECT_NEAR(50 - gy, dx * std::sin(q) + dy * std::cos(q), 1e-9);
    }
  }
  const Camera flat = make_camera(Projection::kPerspective, 100, 100, 0, 0, 0, 90);
  const Camera roll90 = make_camera(Projection::kPerspective, 100, 100, 0, 0, 90, 90);
  double gx, gy;
  ASSERT_TRUE(roll90.direction_to_film(film_dir(flat, 50, 10), &gx, &gy));
  EXPECT_NEAR(gx, 10, 1e-9);
  EXPECT_NEAR(gy, 50, 1e-9);
  // Equirect: roll 90 turns the sphere about the view axis; the zenith is
  // then seen left of the centre (relative azimuth -90 deg) on the horizon row.
  const Camera eq = make_camera(Projection::kEquirectangular, 64, 32, 0, 0, 90);
  ASSERT_TRUE(eq.direction_to_film(kZenith, &gx, &gy));
  EXPECT_NEAR(gx, 16, 1e-12);
  EXPECT_NEAR(gy, 16, 1e-12);
}

// direction -> film -> direction for random directions and orientations, and
// film -> direction -> film for random film points (away from the equirect
// poles and the fov-360 fisheye's back pole, where the film point of a
// direction is not unique).
TEST(CameraRoundTrip, DirectionFilmDirectionAndBack) {
  std::mt19937_64 rng(7);
  struct Case {
    Projection p;
    int w, h;
    double fov;
  };
  for (const Case& c : {Case{Projection::kEquirectangular, 64, 32, 0}, Case{Projection::kEquirectangular, 33, 17, 0},
                        Case{Projection::kFisheye, 64, 64, 180}, Case{Projection::kFisheye, 81, 47, 360},
                        Case{Projection::kFisheye, 64, 64, 30}, Case{Projection::kPerspective, 64, 36, 90},
                        Case{Projection::kPerspective, 33, 65, 170}}) {
    const Camera cam = make_camera(c.p, c.w, c.h, 360 * uniform(rng), 180 * uniform(rng) - 90,
                                   360 * uniform(rng) - 180, c.fov);
    int seen = 0;
    for (int i = 0; i < 2000; ++i) {
      const glm::dvec3 d = random_direction(rng);
      double fx, fy;
      if (!cam.direction_to_film(d, &fx, &fy)) continue;
      ++seen;
      ASSERT_TRUE(fx >= 0 && fx <= c.w && fy >= 0 && fy <= c.h) << fx << "," << fy;
      glm::dvec3 back;
      ASSERT_TRUE(film_ray(cam, fx, fy, &back)) << fx << "," << fy;
      EXPECT_DIR_NEAR(back, d, 1e-12);
    }
    EXPECT_GT(seen, c.p == Projection::kFisheye && c.fov == 30 ? 20 : 200);
    for (int i = 0; i < 2000; ++i) {
      const double fx = c.w * uniform(rng), fy = c.h * (0.01 + 0.98 * uniform(rng));
      glm::dvec3 d;
      if (!film_ray(cam, fx, fy, &d)) continue;
      double gx, gy;
      ASSERT_TRUE(cam.direction_to_film(d, &gx, &gy));
      if (c.p == Projection::kFisheye && c.fov == 360 && std::hypot(fx - 0.5 * c.w, fy - 0.5 * c.h) > 0.999 * 23.5)
        continue;
      EXPECT_NEAR(gx, fx, 1e-8);
      EXPECT_NEAR(gy, fy, 1e-8);
    }
  }
}

// Every ray starts at the camera position with a finite unit direction, for
// every pixel and the extreme jitters (the equirect poles, the fisheye
// centre and circle); every solid angle is finite and >= 0.
TEST(CameraRays, OriginsArePositionAndDirectionsFiniteUnit) {
  for (Projection p : {Projection::kEquirectangular, Projection::kFisheye, Projection::kPerspective}) {
    for (auto [w, h] : {std::pair{33, 17}, std::pair{32, 32}, std::pair{1, 1}}) {
      for (double fov : {1e-3, 90.0, 179.9, 360.0}) {
        if (p == Projection::kPerspective && fov >= 180) continue;
        const Camera cam = make_camera(p, w, h, 45, 90, -30, fov);
        int traced = 0;
        for (int y = 0; y < h; ++y)
          for (int x = 0; x < w; ++x) {
            const double omega = cam.pixel_solid_angle(x, y);
            EXPECT_TRUE(std::isfinite(omega) && omega >= 0.0);
            EXPECT_EQ(omega > 0.0, cam.pixel_exists(x, y));
            for (double jx : {0.0, 0.5, kOneMinus})
              for (double jy : {0.0, 0.5, kOneMinus}) {
                Ray ray;
                if (!cam.generate_ray(x, y, jx, jy, &ray)) continue;
                ++traced;
                EXPECT_EQ(ray.o, kPosition);
                ASSERT_TRUE(std::isfinite(ray.d.x) && std::isfinite(ray.d.y) && std::isfinite(ray.d.z));
                EXPECT_NEAR(glm::length(ray.d), 1.0, 1e-15);
              }
            Ray ray;
            if (cam.pixel_exists(x, y)) {
              EXPECT_TRUE(cam.generate_ray(x, y, 0.5, 0.5, &ray));
            }
          }
        EXPECT_GT(traced, 0);
        Ray ray;
        EXPECT_FALSE(cam.generate_ray(w, 0, 0.5, 0.5, &ray));
        EXPECT_FALSE(cam.generate_ray(0, -1, 0.5, 0.5, &ray));
        EXPECT_EQ(cam.pixel_solid_angle(-1, 0), 0.0);
      }
    }
  }
}

// Specs that cannot be built throw std::invalid_argument.
TEST(CameraSpec, InvalidSpecsThrow) {
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  EXPECT_THROW(make_camera(Projection::kEquirectangular, 0, 10), std::invalid_argument);
  EXPECT_THROW(make_camera(Projection::kEquirectangular, 10, -1), std::invalid_argument);
  EXPECT_THROW(make_camera(Projection::kEquirectangular, 10, 10, nan), std::invalid_argument);
  EXPECT_THROW(make_camera(Projection::kEquirectangular, 10, 10, 0, inf), std::invalid_argument);
  EXPECT_THROW(make_camera(Projection::kEquirectangular, 10, 10, 0, 0, nan), std::invalid_argument);
  EXPECT_THROW(make_camera(Projection::kPerspective, 10, 10, 0, 0, 0, 0), std::invalid_argument);
  EXPECT_THROW(make_camera(Projection::kPerspective, 10, 10, 0, 0, 0, 180), std::invalid_argument);
  EXPECT_THROW(make_camera(Projection::kPerspective, 10, 10, 0, 0, 0, nan), std::invalid_argument);
  EXPECT_THROW(make_camera(Projection::kFisheye, 10, 10, 0, 0, 0, -5), std::invalid_argument);
  EXPECT_THROW(make_camera(Projection::kFisheye, 10, 10, 0, 0, 0, 360.5), std::invalid_argument);
  EXPECT_NO_THROW(make_camera(Projection::kFisheye, 10, 10, 0, 0, 0, 360));
  EXPECT_NO_THROW(make_camera(Projection::kEquirectangular, 10, 10, 0, 0, 0, nan));  // fov ignored
  CameraSpec spec;
  EXPECT_THROW(Camera(spec, glm::dvec3(0, 0, nan)), std::invalid_argument);
}

}  // namespace
}  // namespace skyfarm
