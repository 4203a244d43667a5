// The roulette's control variate table (radiance_control.h): its nodes are
// the LUT sky's marches, a look-up at a node's own point and direction
// returns the node, values between nodes stay within their corners, and
// narrow spectral ranges get one bin.
#include "common/render/radiance_control.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include <glm/geometric.hpp>

#include "common/core/constants.h"
#include "common/lut/lut_sky.h"
#include "tests/support/sun_specs.h"

namespace skyfarm {
namespace {

Scene noon_scene(double lambda_min_nm = 400.0, double lambda_max_nm = 700.0) {
  return Scene::from_specs(AtmosphereSpec{}, testing::sun_spec(30.0, 0.0), Location{}, std::nullopt, lambda_min_nm,
                           lambda_max_nm);
}

TEST(RadianceControl, NodesAreTheLutSkysMarches) {
  const Scene scene = noon_scene();
  const RadianceControlResolution res;
  const RadianceControl control(scene, res);
  ASSERT_EQ(control.bins(), 8);  // 300 nm at most one bin per 20 nm, capped at 8
  const LutResolution lut = RadianceControl::lut_resolution(control.bins());
  const LutSky sky = LutSky::build(scene.atmosphere(), scene.sun(), scene.observer_altitude_m(), 400.0, 700.0, lut);
  std::vector<double> L(8);
  int checked = 0;
  for (int a : {0, 3, 7})
    for (int m : {0, 7, 8, 15})
      for (int s : {0, 2, 4})
        for (int k : {0, 5}) {
          glm::dvec3 p, wi;
          control.node_geometry(a, m, s, k, &p, &wi);
          sky.raymarch_radiance(p, wi, L, false, res.steps);
          for (int b = 0; b < 8; ++b) {
            EXPECT_EQ(control.node(a, m, s, k, b), static_cast<float>(L[static_cast<std::size_t>(b)]))
                << a << " " << m << " " << s << " " << k << " bin " << b;
            ++checked;
          }
        }
  EXPECT_EQ(checked, 3 * 4 * 3 * 2 * 8);
}

// At a node's own point and direction, at the bin centres, the look-up is
// the node (the coordinates invert the node geometry; 1e-4 allows the
// round trip through acos and the horizon mapping).
TEST(RadianceControl, LookUpAtANodeIsTheNode) {
  const Scene scene = noon_scene();
  const RadianceControl control(scene);
  SampledWavelengths wl;
  for (int i = 0; i < 4; ++i) wl.lambda_nm[static_cast<std::size_t>(i)] = 400.0 + 37.5 * (2 * i + 0.5);  // centres of bins 0, 2, 4, 6
  wl.pdf.fill(1.0);
  for (int a : {1, 4, 6})
    for (int m : {2, 11, 14})
      for (int s : {1, 3})
        for (int k : {1, 3, 6}) {
          glm::dvec3 p, wi;
          control.node_geometry(a, m, s, k, &p, &wi);
          const SampledSpectrum c = control.radiance(p, wi, wl);
          for (int i = 0; i < 4; ++i) {
            const double node = control.node(a, m, s, k, 2 * i);
            EXPECT_NEAR(c[i], node, 1e-4 * node + 1e-12) << a << " " << m << " " << s << " " << k << " bin " << 2 * i;
          }
        }
}

// Anywhere (points from the ground to above the top, every direction, sun
// angles inside and outside the table's window): finite, >= 0, and within
// the range of the table (multilinear weights are convex).
TEST(RadianceControl, EveryLookUpIsFiniteNonNegativeAndWithinTheTable) {
  const Scene scene = noon_scene();
  const RadianceControl control(scene);
  float lo = 1e30f, hi = 0.0f;
  for (int a = 0; a < 8; ++a)
    for (int m = 0; m < 16; ++m)
      for (int s = 0; s < 5; ++s)
        for (int k = 0; k < 8; ++k)
          for (int b = 0; b < 8; ++b) {
            lo = std::min(lo, control.node(a, m, s, k, b));
            hi = std::max(hi, control.node(a, m, s, k, b));
          }
  EXPECT_GT(hi, 0.0f);
  const double R = scene.atmosphere().planet_radius_m();
  SampledWavelengths wl;
  wl.lambda_nm = {380.0, 455.5, 612.0, 720.0};  // two outside the range: the edge bins
  wl.pdf.fill(1.0);
  for (int i = 0; i < 2000; ++i) {
    const double u = (i * 0.618034) - std::floor(i * 0.618034), v = (i * 0.754878) - std::floor(i * 0.754878);
    const double w = (i * 0.569840) - std::floor(i * 0.569840), x = (i * 0.414214) - std::floor(i * 0.414214);
    const double theta = std::acos(1.0 - 2.0 * u), phi = 2.0 * kPi * v;  // where on the planet
    const glm::dvec3 up{std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)};
    const glm::dvec3 p = up * (R + 120000.0 * w);
    const double t2 = std::acos(1.0 - 2.0 * x), p2 = 2.0 * kPi * u * v;
    const glm::dvec3 wi{std::sin(t2) * std::cos(p2), std::sin(t2) * std::sin(p2), std::cos(t2)};
    const SampledSpectrum c = control.radiance(p, glm::normalize(wi), wl);
    for (int j = 0; j < 4; ++j) {
      ASSERT_TRUE(std::isfinite(c[j])) << i;
      EXPECT_GE(c[j], 0.0) << i;
      EXPECT_GE(c[j], static_cast<double>(lo) * (1.0 - 1e-9)) << i;
      EXPECT_LE(c[j], static_cast<double>(hi) * (1.0 + 1e-9)) << i;
    }
  }
}

TEST(RadianceControl, ANarrowRangeHasOneBin) {
  const RadianceControl control(noon_scene(550.0, 551.0));
  EXPECT_EQ(control.bins(), 1);
  SampledWavelengths wl;
  wl.lambda_nm = {550.1, 550.4, 550.6, 550.9};
  wl.pdf.fill(1.0);
  const SampledSpectrum c = control.radiance(noon_scene().observer(), glm::dvec3(0.0, 0.0, 1.0), wl);
  for (int j = 0; j < 4; ++j) {
    EXPECT_GT(c[j], 0.0);
    EXPECT_EQ(c[j], c[0]);
  }
}

TEST(RadianceControl, ResolutionsWithoutTwoNodesAreRejected) {
  RadianceControlResolution res;
  res.sun_angles = 1;
  EXPECT_THROW(RadianceControl(noon_scene(), res), std::invalid_argument);
}

}  // namespace
}  // namespace skyfarm
