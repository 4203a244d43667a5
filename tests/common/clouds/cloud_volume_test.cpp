// The placed cloud volume (common/clouds/cloud_volume.h): its field against
// the grid's values, its placement, its majorants against dense point
// samples, and the optical depth through a constant box against the
// analytic integral of the trilinear field.
#include "common/clouds/cloud_volume.h"

#include <cmath>
#include <cstdint>
#include <memory>
#include <random>
#include <vector>

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include "common/assets/volume_source.h"
#include "common/clouds/scene_clouds.h"
#include "common/render/render_setup.h"
#include "common/sampling/sampler.h"

namespace skyfarm {
namespace {

constexpr double kRadius = 6'371'000.0;

std::shared_ptr<assets::VolumeGrid> make_grid(glm::ivec3 size, glm::dvec3 voxel, glm::dvec3 origin,
                                              std::uint32_t seed, double empty_share = 0.0) {
  auto g = std::make_shared<assets::VolumeGrid>();
  g->size = size;
  g->voxel_size_m = voxel;
  g->origin_m = origin;
  g->values.resize(static_cast<std::size_t>(size.x) * size.y * size.z);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (float& v : g->values) {
    v = u(rng) < empty_share ? 0.0f : 2.0f * u(rng);
    g->max_value = std::max(g->max_value, v);
  }
  return g;
}

CloudOptics plain_optics() {
  CloudOptics o;
  o.phase = PhaseFunction::isotropic();
  return o;
}

TEST(CloudVolume, TrilinearIsExactAtVoxelCentres) {
  const auto grid = make_grid({5, 4, 3}, {20.0, 25.0, 30.0}, {-40.0, -50.0, 0.0}, 7);
  Placement place;
  place.translate_m = {100.0, 200.0, 1500.0};
  place.rotate_deg = {30.0, 10.0, -5.0};
  const double scale = 0.05;
  const CloudVolume volume(grid, place, scale, plain_optics(), kRadius);
  for (int z = 0; z < 3; ++z)
    for (int y = 0; y < 4; ++y)
      for (int x = 0; x < 5; ++x) {
        const glm::dvec3 world = volume.enu_frame().to_world(volume.enu_from_index(glm::dvec3(x, y, z)));
        // World coordinates carry ~1e-9 m of rounding: 4e-11 of a voxel, so the
        // interpolation is within ~1e-10 relative of the voxel's value.
        EXPECT_NEAR(volume.sigma_t(world), scale * grid->at(x, y, z), 1e-9 * scale * 2.0) << x << " " << y << " " << z;
      }
  // Midway between two centres: their mean (linear along one axis).
  const glm::dvec3 mid = volume.enu_frame().to_world(volume.enu_from_index({1.5, 2.0, 1.0}));
  EXPECT_NEAR(volume.sigma_t(mid), scale * 0.5 * (double(grid->at(1, 2, 1)) + double(grid->at(2, 2, 1))), 1e-11);
}

TEST(CloudVolume, PlacedOneKilometreNorthIsThere) {
  // A single voxel of value 1 at the grid frame's origin, placed 1 km north
  // and 2 km up: the field is density_scale there and 0 at the observer's zenith.
  auto grid = std::make_shared<assets::VolumeGrid>();
  grid->size = {1, 1, 1};
  grid->voxel_size_m = {100.0, 100.0, 100.0};
  grid->values = {1.0f};
  grid->max_value = 1.0f;
  Placement place;
  place.translate_m = {0.0, 1000.0, 2000.0};
  const CloudVolume volume(grid, place, 0.02, plain_optics(), kRadius);
  const EnuFrame enu(kRadius);
  EXPECT_NEAR(volume.sigma_t(enu.to_world({0.0, 1000.0, 2000.0})), 0.02, 1e-12);
  // 50 m east of the centre: half way to the (zero) neighbour voxel centre.
  EXPECT_NEAR(volume.sigma_t(enu.to_world({50.0, 1000.0, 2000.0})), 0.01, 1e-9);
  EXPECT_EQ(volume.sigma_t(enu.to_world({0.0, 0.0, 2000.0})), 0.0);
  EXPECT_EQ(volume.sigma_t(enu.to_world({0.0, 1000.0 - 101.0, 2000.0})), 0.0);
  // Altitude range: the support (+-100 m about 2 km, 1 km away) within its bounding sphere.
  EXPECT_LE(volume.bottom_altitude_m(), 1900.0);
  EXPECT_GE(volume.top_altitude_m(), 2100.0);
  EXPECT_GT(volume.bottom_altitude_m(), 1500.0);
  EXPECT_LT(volume.top_altitude_m(), 2500.0);

  // Yaw 90 turns the grid's +x (east) to south: a voxel at grid x = +100 m lands 100 m south.
  auto two = std::make_shared<assets::VolumeGrid>(*grid);
  two->size = {2, 1, 1};
  two->values = {0.0f, 1.0f};
  place.rotate_deg = {90.0, 0.0, 0.0};
  const CloudVolume turned(two, place, 0.02, plain_optics(), kRadius);
  EXPECT_NEAR(turned.sigma_t(enu.to_world({0.0, 900.0, 2000.0})), 0.02, 1e-12);
  EXPECT_NEAR(turned.sigma_t(enu.to_world({0.0, 1000.0, 2000.0})), 0.0, 1e-12);
}

// Every piece bounds the field at points densely spread over it, and the
// field is 0 in the gaps between pieces.
TEST(CloudVolume, MajorantsBoundDenseSamples) {
  const auto grid = make_grid({37, 21, 18}, {30.0, 30.0, 45.0}, {-500.0, -300.0, 0.0}, 11, 0.6);
  // Make some bricks entirely empty so that gaps occur.
  auto& v = grid->values;
  for (int z = 0; z < 18; ++z)
    for (int y = 0; y < 21; ++y)
      for (int x = 10; x < 30; ++x) v[static_cast<std::size_t>(x) + 37u * (y + 21u * z)] = 0.0f;
  Placement place;
  place.translate_m = {300.0, 2000.0, 1200.0};
  place.rotate_deg = {25.0, -12.0, 7.0};
  place.scale = {1.5, 1.0, 0.8};
  const CloudVolume volume(grid, place, 0.03, plain_optics(), kRadius);
  const EnuFrame enu(kRadius);
  const glm::dvec3 centre_enu = volume.enu_from_index({18.0, 10.0, 9.0});

  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int pieces = 0, gaps_checked = 0, samples = 0;
  for (int r = 0; r < 300; ++r) {
    // Rays from around the volume towards points near its centre.
    glm::dvec3 from = centre_enu + 1500.0 * glm::dvec3(u(rng), u(rng), u(rng));
    glm::dvec3 to = centre_enu + 400.0 * glm::dvec3(u(rng), u(rng), u(rng));
    if (r % 10 == 0) to = from + glm::dvec3(1.0, 0.0, 0.0);  // axis-aligned in ENU
    const Ray ray{enu.to_world(from), glm::normalize(to - from)};
    const double t_begin = 10.0 * (r % 3), t_end = 4000.0;
    double last = t_begin;
    volume.for_each_majorant(ray, t_begin, t_end, [&](double t0, double t1, double maj) {
      EXPECT_GE(t0, last);
      EXPECT_LT(t0, t1);
      EXPECT_LE(t1, t_end);
      for (int k = 0; k < 16 && t0 > last; ++k) {  // the gap before the piece, if any
        const double t = last + (t0 - last) * (k + 0.5) / 16.0;
        EXPECT_EQ(volume.sigma_t(ray.at(t)), 0.0) << "gap at t " << t;
        ++gaps_checked;
      }
      for (int k = 0; k <= 64; ++k) {
        const double t = t0 + (t1 - t0) * k / 64.0;
        EXPECT_LE(volume.sigma_t(ray.at(t)), maj) << "t " << t << " in [" << t0 << ", " << t1 << "]";
        ++samples;
      }
      last = t1;
      ++pieces;
      return true;
    });
    for (int k = 0; k < 16; ++k) {
      const double t = last + (t_end - last) * (k + 0.5) / 16.0;
      EXPECT_EQ(volume.sigma_t(ray.at(t)), 0.0) << "tail at t " << t;
    }
  }
  EXPECT_GT(pieces, 300);
  EXPECT_GT(samples, 20000);
  EXPECT_GT(gaps_checked, 1000);
}

TEST(CloudVolume, MajorantsStopWhenAsked) {
  const auto grid = make_grid({32, 32, 32}, {10.0, 10.0, 10.0}, {0.0, 0.0, 0.0}, 5);
  const CloudVolume volume(grid, Placement{}, 0.1, plain_optics(), kRadius);
  const EnuFrame enu(kRadius);
  const Ray ray{enu.to_world({-50.0, 3.0, 5.0}), glm::normalize(glm::dvec3(1.0, 0.9, 0.8))};
  int calls = 0;
  volume.for_each_majorant(ray, 0.0, 1e4, [&](double, double, double) { return ++calls < 2; });
  EXPECT_EQ(calls, 2);
}

// A box of constant value v, n voxels of size h along x: the trilinear field
// along a line through the interior ramps from 0 at u = -1 to v at u = 0,
// stays v to u = n - 1 and ramps down to 0 at u = n, so the optical depth is
// density_scale * v * h * ((n - 1) + 2 * 1/2) = density_scale * v * n * h.
TEST(CloudVolume, OpticalDepthThroughConstantBoxIsAnalytic) {
  auto grid = std::make_shared<assets::VolumeGrid>();
  grid->size = {20, 6, 5};
  grid->voxel_size_m = {50.0, 40.0, 30.0};
  grid->origin_m = {-475.0, -100.0, 0.0};
  grid->values.assign(20 * 6 * 5, 0.8f);
  grid->max_value = 0.8f;
  Placement place;
  place.translate_m = {0.0, 3000.0, 1000.0};
  const double scale = 0.01;
  auto volume = std::make_shared<CloudVolume>(grid, place, scale, plain_optics(), kRadius);
  const SceneClouds clouds({volume});
  const EnuFrame enu(kRadius);
  // East-west through the interior (grid y = 0 m, z = 60 m are inside [0, n-1] centres).
  const Ray ray{enu.to_world({-2000.0, 3000.0, 1060.0}), {1.0, 0.0, 0.0}};
  const double expected = scale * 0.8 * 20 * 50.0;  // 0.4
  EXPECT_NEAR(clouds.optical_depth(ray, 0.0, 4000.0, 1.0), expected, 1e-4 * expected);
  // Rotated by yaw 30 and crossed along the grid's own x axis: the same depth.
  place.rotate_deg = {30.0, 0.0, 0.0};
  auto turned = std::make_shared<CloudVolume>(grid, place, scale, plain_optics(), kRadius);
  const SceneClouds turned_clouds({turned});
  const glm::dvec3 axis = glm::normalize(turned->enu_from_index({1.0, 2.5, 2.0}) - turned->enu_from_index({0.0, 2.5, 2.0}));
  const glm::dvec3 start = turned->enu_from_index({-30.0, 2.5, 2.0});
  const Ray along{enu.to_world(start), axis};
  EXPECT_NEAR(turned_clouds.optical_depth(along, 0.0, 4000.0, 1.0), expected, 1e-4 * expected);
}

// Ratio tracking against the volume's majorants (SceneClouds) is unbiased:
// through a box of constant value, E[T] = exp(-tau) with tau analytic as
// above, here along a diagonal that also crosses the fading edges: tau from
// the midpoint rule at 0.25 m steps (the field is piecewise trilinear, the
// rule's error ~1e-6) as the independent reference.
TEST(CloudVolume, RatioTrackingMatchesBeerLambert) {
  auto grid = std::make_shared<assets::VolumeGrid>();
  grid->size = {10, 10, 10};
  grid->voxel_size_m = glm::dvec3(20.0);
  grid->values.assign(1000, 1.0f);
  grid->values[555] = 3.0f;  // one dense voxel: the majorants are not flat
  grid->max_value = 3.0f;
  Placement place;
  place.translate_m = {0.0, 500.0, 800.0};
  auto volume = std::make_shared<CloudVolume>(grid, place, 0.01, plain_optics(), kRadius);
  const SceneClouds clouds({volume});
  const EnuFrame enu(kRadius);
  const glm::dvec3 from{-200.0, 300.0, 700.0}, to = volume->enu_from_index({5.2, 5.4, 5.1});
  const Ray ray{enu.to_world(from), glm::normalize(to - from)};
  const double tau = clouds.optical_depth(ray, 0.0, 1000.0, 0.25);
  ASSERT_GT(tau, 1.0);
  const int n = 20000;
  double sum = 0.0, sum2 = 0.0;
  std::uint64_t collisions = 0;
  for (int i = 0; i < n; ++i) {
    Sampler sampler(5, 0, static_cast<std::uint64_t>(i));
    const double t = clouds.transmittance(ray, 0.0, 1000.0, sampler, &collisions);
    sum += t;
    sum2 += t * t;
  }
  const double mean = sum / n, sd = std::sqrt(std::max(0.0, sum2 / n - mean * mean) / n);
  EXPECT_NEAR(mean, std::exp(-tau), 4.0 * sd + 1e-4) << "tau " << tau << ", sd " << sd;
}

// A request's volume (RenderSpec::clouds) becomes a CloudVolume: the grid
// from the source, placed, scaled, with the particles' optics.
class OneGridSource : public assets::VolumeSource {
 public:
  explicit OneGridSource(std::shared_ptr<const assets::VolumeGrid> grid) : grid_(std::move(grid)) {}
  std::shared_ptr<const assets::VolumeGrid> volume(std::string_view id) const override {
    if (id != "sha256:" + std::string(64, 'a')) throw std::runtime_error("asset " + std::string(id) + " is unknown");
    return grid_;
  }

 private:
  std::shared_ptr<const assets::VolumeGrid> grid_;
};

TEST(CloudVolume, MakeSceneCloudsPlacesTheRequestsVolumes) {
  auto grid = std::make_shared<assets::VolumeGrid>();
  grid->size = {4, 4, 8};
  grid->voxel_size_m = glm::dvec3(25.0);
  grid->origin_m = {-37.5, -37.5, 0.0};
  grid->values.assign(4 * 4 * 8, 0.5f);
  grid->max_value = 0.5f;
  const OneGridSource source(grid);
  RenderSpec spec;
  CloudVolumeSpec v;
  v.asset = "sha256:" + std::string(64, 'a');
  v.placement.translate_m = {0.0, 1000.0, 1500.0};
  v.density_scale = 0.02;
  v.effective_radius_um = 10.0;
  spec.clouds.volumes.push_back(v);
  const auto clouds = make_scene_clouds(spec, kRadius, &source);
  ASSERT_TRUE(clouds);
  ASSERT_EQ(clouds->fields().size(), 1u);
  EXPECT_EQ(clouds->fields()[0]->optics().albedo, cloud_optics(CloudParticle::kWater, 10.0).albedo);
  // Straight up through its middle (x = y = 0 lies between the 2nd and 3rd
  // voxel centres, where the field is still the full 0.5): tau = 0.02 * 0.5 * 8 * 25 m.
  const EnuFrame enu(kRadius);
  const Ray up{enu.to_world({0.0, 1000.0, 1000.0}), {0.0, 0.0, 1.0}};
  EXPECT_NEAR(clouds->optical_depth(up, 0.0, 2000.0, 0.5), 0.02 * 0.5 * 8 * 25.0, 1e-6);
  EXPECT_LE(clouds->bottom_altitude_m(), 1500.0 - 25.0);
  EXPECT_GE(clouds->top_altitude_m(), 1500.0 + 8 * 25.0);

  EXPECT_THROW(make_scene_clouds(spec, kRadius, nullptr), std::runtime_error);
  spec.clouds.volumes[0].asset = "sha256:" + std::string(64, 'b');
  try {
    (void)make_scene_clouds(spec, kRadius, &source);
    ADD_FAILURE() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("is unknown"), std::string::npos) << e.what();
  }
}

TEST(CloudVolume, RejectsBadArguments) {
  const auto grid = make_grid({2, 2, 2}, {1.0, 1.0, 1.0}, {0.0, 0.0, 0.0}, 1);
  EXPECT_THROW(CloudVolume(grid, Placement{}, -1.0, plain_optics(), kRadius), std::invalid_argument);
  EXPECT_THROW(CloudVolume(grid, Placement{}, std::nan(""), plain_optics(), kRadius), std::invalid_argument);
  Placement flat;
  flat.scale = {1.0, 0.0, 1.0};
  EXPECT_THROW(CloudVolume(grid, flat, 0.1, plain_optics(), kRadius), std::invalid_argument);
  EXPECT_THROW(CloudVolume(nullptr, Placement{}, 0.1, plain_optics(), kRadius), std::invalid_argument);
}

}  // namespace
}  // namespace skyfarm
