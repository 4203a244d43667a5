// Placements against explicitly built matrices: the yaw / pitch / roll
// convention (yaw clockwise from north like the sun's azimuth, pitch nose
// up, roll right side down), the header's worked example, inverse round
// trips, normals staying perpendicular under non-uniform scale.
#include "common/geometry/placement.h"

#include <gtest/gtest.h>

#include <cmath>
#include <glm/geometric.hpp>
#include <random>
#include <stdexcept>

#include "common/core/constants.h"
#include "common/geometry/enu_frame.h"
#include "common/geometry/unit_disc.h"
#include "common/geometry/unit_sphere.h"

namespace skyfarm {
namespace {

void expect_vec_near(const glm::dvec3& a, const glm::dvec3& b, double tol, const char* what = "") {
  EXPECT_NEAR(a.x, b.x, tol) << what;
  EXPECT_NEAR(a.y, b.y, tol) << what;
  EXPECT_NEAR(a.z, b.z, tol) << what;
}

const glm::dvec3 kEast{1, 0, 0}, kNorth{0, 1, 0}, kUp{0, 0, 1};

TEST(Placement, YawNinetyTurnsNorthToEastExactly) {
  const glm::dmat3 r = rotation_from_yaw_pitch_roll(90.0, 0.0, 0.0);
  EXPECT_EQ(r * kNorth, kEast);
  EXPECT_EQ(r * kEast, -kNorth);  // clockwise seen from above: east -> south
  EXPECT_EQ(r * kUp, kUp);
}

TEST(Placement, PitchRaisesTheNoseAndRollLowersTheRightSide) {
  EXPECT_EQ(rotation_from_yaw_pitch_roll(0.0, 90.0, 0.0) * kNorth, kUp);
  EXPECT_EQ(rotation_from_yaw_pitch_roll(0.0, 90.0, 0.0) * kUp, -kNorth);
  EXPECT_EQ(rotation_from_yaw_pitch_roll(0.0, 0.0, 90.0) * kEast, -kUp);
  EXPECT_EQ(rotation_from_yaw_pitch_roll(0.0, 0.0, 90.0) * kUp, kEast);
  EXPECT_EQ(rotation_from_yaw_pitch_roll(0.0, 0.0, 90.0) * kNorth, kNorth);
}

TEST(Placement, ForwardAxisFollowsTheSunsAzimuthAndElevation) {
  for (double yaw : {0.0, 17.0, 135.0, 250.0, -30.0})
    for (double pitch : {-60.0, 0.0, 23.5, 80.0})
      for (double roll : {0.0, 45.0, -120.0}) {
        const glm::dvec3 forward = rotation_from_yaw_pitch_roll(yaw, pitch, roll) * kNorth;
        expect_vec_near(forward, direction_from_zenith_azimuth((90.0 - pitch) * kDegToRad, yaw * kDegToRad), 1e-15);
      }
}

// R built independently from axis-angle (Rodrigues) rotations in the same
// intrinsic order: roll about forward, then pitch about the rolled right
// axis, then yaw about up.
glm::dmat3 axis_angle(const glm::dvec3& axis, double angle_rad) {
  const double c = std::cos(angle_rad), s = std::sin(angle_rad);
  const glm::dvec3 a = glm::normalize(axis);
  glm::dmat3 m;
  for (int col = 0; col < 3; ++col) {
    glm::dvec3 e(0.0);
    e[col] = 1.0;
    m[col] = e * c + glm::cross(a, e) * s + a * glm::dot(a, e) * (1.0 - c);
  }
  return m;
}

TEST(Placement, MatchesComposedAxisAngleRotations) {
  const double yaw = 33.0, pitch = -12.0, roll = 71.0;
  // Counter-clockwise angles about +z, +x, +y: yaw is clockwise, roll lowers +x.
  const glm::dmat3 expected = axis_angle(kUp, -yaw * kDegToRad) * axis_angle(kEast, pitch * kDegToRad) *
                              axis_angle(kNorth, roll * kDegToRad);
  const glm::dmat3 r = rotation_from_yaw_pitch_roll(yaw, pitch, roll);
  for (int c = 0; c < 3; ++c) expect_vec_near(r[c], expected[c], 1e-15);
  EXPECT_NEAR(glm::determinant(r), 1.0, 1e-15);
}

TEST(Placement, TransformIsTranslateRotateScaleAsAnExplicitMatrix) {
  Placement pl;
  pl.translate_m = {3.0, -4.0, 5.0};
  pl.rotate_deg = {90.0, 0.0, 0.0};
  pl.scale = {2.0, 3.0, 4.0};
  const Transform t = transform_from_placement(pl);
  // Columns: object x (scaled 2) -> south, object y (scaled 3) -> east, z up.
  glm::dmat4 expected(0.0);
  expected[0] = {0.0, -2.0, 0.0, 0.0};
  expected[1] = {3.0, 0.0, 0.0, 0.0};
  expected[2] = {0.0, 0.0, 4.0, 0.0};
  expected[3] = {3.0, -4.0, 5.0, 1.0};
  EXPECT_EQ(t.matrix(), expected);
  EXPECT_EQ(t.point({1.0, 1.0, 1.0}), glm::dvec3(6.0, -6.0, 9.0));
  EXPECT_EQ(t.direction({0.0, 1.0, 0.0}), glm::dvec3(3.0, 0.0, 0.0));
}

TEST(Placement, HeadersWorkedExamplePanelFacesSouthEast) {
  Placement pl;
  pl.translate_m = {0.0, 10.0, 1.0};
  pl.rotate_deg = {-45.0, 90.0, 0.0};
  pl.scale = {2.0, 1.0, 1.0};
  const Transform t = transform_from_placement(pl);
  expect_vec_near(t.normal({0, 0, 1}), direction_from_zenith_azimuth(90.0 * kDegToRad, 135.0 * kDegToRad), 1e-15);
  expect_vec_near(t.direction({0, 1, 0}), kUp, 1e-15);  // top edge direction
  const glm::dvec3 width = t.direction({1, 0, 0});
  EXPECT_NEAR(glm::length(width), 2.0, 1e-15);
  expect_vec_near(width / 2.0, direction_from_zenith_azimuth(90.0 * kDegToRad, 45.0 * kDegToRad), 1e-15);
  expect_vec_near(t.point({0, 0, 0}), {0.0, 10.0, 1.0}, 0.0);
}

TEST(Placement, InverseRoundTripsPointsDirectionsAndRays) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int k = 0; k < 200; ++k) {
    Placement pl;
    pl.translate_m = {1000.0 * u(rng), 1000.0 * u(rng), 100.0 * u(rng)};
    pl.rotate_deg = {180.0 * u(rng), 90.0 * u(rng), 180.0 * u(rng)};
    pl.scale = {0.1 + 5.0 * std::abs(u(rng)), 0.1 + 5.0 * std::abs(u(rng)), (u(rng) < 0 ? -1.0 : 1.0) * (0.1 + 5.0 * std::abs(u(rng)))};
    const Transform t = transform_from_placement(pl);
    const Transform inv = t.inverse();
    const glm::dvec3 p{u(rng), u(rng), u(rng)};
    expect_vec_near(inv.point(t.point(p)), p, 1e-11);
    expect_vec_near(inv.direction(t.direction(p)), p, 1e-13);
    const Transform id = inv * t;
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r) EXPECT_NEAR(id.matrix()[c][r], c == r ? 1.0 : 0.0, 1e-12);
    // The error bound covers the actual rounding of a point (checked
    // against long double).
    const glm::dvec3 q = t.point(p);
    const glm::dvec3 bound = t.point_error(p, glm::dvec3(0.0));
    for (int i = 0; i < 3; ++i) {
      long double exact = t.matrix()[3][i];
      for (int j = 0; j < 3; ++j) exact += static_cast<long double>(t.matrix()[j][i]) * p[j];
      EXPECT_LE(std::abs(static_cast<double>(q[i] - exact)), bound[i]);
    }
  }
}

TEST(Placement, NormalsStayPerpendicularUnderNonUniformScale) {
  Placement pl;
  pl.rotate_deg = {30.0, 20.0, -50.0};
  pl.scale = {0.2, 3.0, 7.0};
  pl.translate_m = {5.0, 6.0, 7.0};
  const Transform t = transform_from_placement(pl);
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int k = 0; k < 1000; ++k) {
    const glm::dvec3 n = glm::normalize(glm::dvec3(u(rng), u(rng), u(rng)));
    // Two tangents of the plane with normal n, carried as directions.
    const glm::dvec3 a = glm::normalize(glm::cross(n, glm::dvec3(u(rng), u(rng), u(rng))));
    const glm::dvec3 b = glm::cross(n, a);
    const glm::dvec3 nn = t.normal(n);
    EXPECT_NEAR(glm::length(nn), 1.0, 1e-14);
    EXPECT_NEAR(glm::dot(nn, glm::normalize(t.direction(a))), 0.0, 1e-13);
    EXPECT_NEAR(glm::dot(nn, glm::normalize(t.direction(b))), 0.0, 1e-13);
    // Outward stays outward: the side n points to maps to the side n' does.
    EXPECT_GT(glm::dot(nn, t.direction(n)), 0.0);
  }
  // A plain direction carried as a normal would not be perpendicular.
  const glm::dvec3 n{0.0, 0.6, 0.8}, a{0.0, 0.8, -0.6};
  EXPECT_GT(std::abs(glm::dot(glm::normalize(t.direction(n)), glm::normalize(t.direction(a)))), 0.1);
}

TEST(Placement, AreaScaleOfScaledSquareAndDisc) {
  Placement pl;
  pl.rotate_deg = {10.0, 20.0, 30.0};
  pl.scale = {2.0, 3.0, 5.0};
  const Transform t = transform_from_placement(pl);
  EXPECT_NEAR(t.area_scale({0, 0, 1}), 6.0, 1e-13);   // z = 0 plane: sx sy
  EXPECT_NEAR(t.area_scale({1, 0, 0}), 15.0, 1e-13);  // x = const: sy sz
}

TEST(Placement, AreaSamplesCarryTheirPdfPerPlacedArea) {
  // A disc scaled into a 2 x 3 ellipse: pdf 1 / (6 pi) per m^2 everywhere.
  Placement pl;
  pl.rotate_deg = {40.0, 15.0, -5.0};
  pl.scale = {2.0, 3.0, 0.5};
  const Transform t = transform_from_placement(pl);
  const AreaSample s = t.to_parent(sample_unit_disc({0.3, 0.8}));
  EXPECT_NEAR(s.pdf_area, 1.0 / (6.0 * kPi), 1e-15);
  expect_vec_near(s.n, t.normal({0, 0, 1}), 0.0);
  // A sphere scaled by 2: 1 / (16 pi).
  Placement ps;
  ps.scale = glm::dvec3(2.0);
  ps.translate_m = {1.0, 2.0, 3.0};
  const AreaSample q = transform_from_placement(ps).to_parent(sample_unit_sphere({0.1, 0.7}));
  EXPECT_NEAR(q.pdf_area, 1.0 / (16.0 * kPi), 1e-15);
  EXPECT_NEAR(glm::length(q.p - glm::dvec3(1.0, 2.0, 3.0)), 2.0, 1e-15);
}

TEST(Placement, RejectsZeroOrNonFiniteScale) {
  Placement pl;
  pl.scale = {1.0, 0.0, 1.0};
  EXPECT_THROW(transform_from_placement(pl), std::invalid_argument);
  pl.scale = {1.0, 1.0, std::nan("")};
  EXPECT_THROW(transform_from_placement(pl), std::invalid_argument);
  pl.scale = {1.0, 1.0, 1.0};
  pl.rotate_deg.x = INFINITY;
  EXPECT_THROW(transform_from_placement(pl), std::invalid_argument);
  glm::dmat4 m(1.0);
  m[0][3] = 1.0;
  EXPECT_THROW(Transform{m}, std::invalid_argument);
}

TEST(EnuFrame, WorldRoundTripIsExactNearTheObserver) {
  const double r0 = 6371000.0 + 1234.5;
  const EnuFrame frame(r0);
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-5000.0, 5000.0);
  for (int k = 0; k < 1000; ++k) {
    const glm::dvec3 world = frame.to_world(glm::dvec3(u(rng), u(rng), u(rng)));
    EXPECT_EQ(frame.to_world(frame.to_enu(world)), world);  // to_enu is exact (Sterbenz)
  }
  EXPECT_EQ(frame.to_world(glm::dvec3(1.0, 2.0, 3.0)), glm::dvec3(1.0, 2.0, r0 + 3.0));
  EXPECT_THROW(EnuFrame(0.0), std::invalid_argument);
}

}  // namespace
}  // namespace skyfarm
