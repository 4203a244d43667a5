// Benchmarks of the LUT renderer (common/lut/): building the tables, one
// radiance look-up, and how many spectral bins colour needs.
//
//   BM_LutBuildAll/N/bands    all tables for one sun position, N bins, one
//                             core, with multiple-scattering bands up to
//                             `bands` (0: Hillaire's isotropic term alone)
//   BM_LutBuildPerSun/N       the sun-dependent tables only (sky view + aerial
//                             perspective; LutSky::with_sun reuses the rest)
//   BM_LutBuildStage/S/N      one stage: 0 medium, 1 transmittance, 2 multiple
//                             scattering, 3 ground irradiance, 4 sky view,
//                             5 aerial perspective, 6 multiple-scattering
//                             bands, 7 sky view with the bands
//   BM_LutRadiance/N          LutSky::radiance from warm tables
//   BM_LutBinCountColourError/N   colour of the sky-view radiance with N bins
//                             against N = 94 (5 nm): counters max_rel_dY
//                             (relative luminance) and max_dxy (CIE 1931 xy
//                             distance), per sun position and overall
//
// Scene: Earth preset (air, ozone 300 DU, aerosols), AM0 sun, observer on the
// ground, 360-830 nm.  The figures quoted for the LUT sky are BM_LutBuildAll/bins:32/bands:2,
// BM_LutBuildPerSun/32 and BM_LutRadiance/32 (docs/experiments/*-lut-build-time.md).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <vector>

#include "common/atmosphere/atmosphere_builder.h"
#include "common/core/constants.h"
#include "common/lut/aerial_perspective_lut.h"
#include "common/lut/ground_irradiance_lut.h"
#include "common/lut/lut_sky.h"
#include "common/lut/multiple_scattering_bands.h"
#include "common/lut/sky_view_lut.h"

namespace skyfarm {
namespace {

const Atmosphere& atmosphere() {
  static const Atmosphere atm = build_atmosphere(AtmosphereSpec{});
  return atm;
}

Sun am0_sun(double zenith_deg, double azimuth_deg = 0.0) {
  SunSpec s;
  s.zenith_deg = zenith_deg;
  s.azimuth_deg = azimuth_deg;
  return Sun::from_spec(s, Location{}, std::nullopt);
}

LutResolution bins(int n) {
  LutResolution r;
  r.spectral_bins = n;
  return r;
}

const LutSky& warm_sky(int n) {
  static std::map<int, LutSky> skies;
  auto it = skies.find(n);
  if (it == skies.end())
    it = skies.emplace(n, LutSky::build(atmosphere(), am0_sun(30.0), 0.0, 360.0, 830.0, bins(n))).first;
  return it->second;
}

void BM_LutBuildAll(benchmark::State& state) {
  LutResolution res = bins(static_cast<int>(state.range(0)));
  res.bands = static_cast<int>(state.range(1));
  const Sun sun = am0_sun(40.0, 120.0);
  for (auto _ : state) benchmark::DoNotOptimize(LutSky::build(atmosphere(), sun, 0.0, 360.0, 830.0, res));
}
BENCHMARK(BM_LutBuildAll)
    ->ArgsProduct({{8, 16, 32}, {0, 2}})
    ->ArgNames({"bins", "bands"})
    ->Unit(benchmark::kMillisecond);

void BM_LutBuildPerSun(benchmark::State& state) {
  const LutSky& base = warm_sky(static_cast<int>(state.range(0)));
  const Sun sun = am0_sun(40.0, 120.0);
  for (auto _ : state) benchmark::DoNotOptimize(base.with_sun(sun));
}
BENCHMARK(BM_LutBuildPerSun)->Arg(8)->Arg(16)->Arg(32)->Unit(benchmark::kMillisecond);

void BM_LutBuildStage(benchmark::State& state) {
  const int stage = static_cast<int>(state.range(0)), n = static_cast<int>(state.range(1));
  const SpectralGrid grid(360.0, 830.0, n);
  const MediumTable medium = MediumTable::build(atmosphere(), grid);
  const TransmittanceLut T = TransmittanceLut::build(medium);
  const MultipleScatteringLut ms = MultipleScatteringLut::build(medium, T);
  const GroundIrradianceLut gi = GroundIrradianceLut::build(medium, T, ms);
  const MultipleScatteringBands bands = MultipleScatteringBands::build(medium, T, gi);
  const std::vector<double> E(static_cast<std::size_t>(n), 1.5);
  const double R = atmosphere().planet_radius_m(), mu_s = std::cos(40.0 * kDegToRad);
  for (auto _ : state) {
    switch (stage) {
      case 0:
        benchmark::DoNotOptimize(MediumTable::build(atmosphere(), grid));
        break;
      case 1:
        benchmark::DoNotOptimize(TransmittanceLut::build(medium));
        break;
      case 2:
        benchmark::DoNotOptimize(MultipleScatteringLut::build(medium, T));
        break;
      case 3:
        benchmark::DoNotOptimize(GroundIrradianceLut::build(medium, T, ms));
        break;
      case 4:
        benchmark::DoNotOptimize(SkyViewLut::build(medium, T, ms, gi, R, mu_s, E));
        break;
      case 5:
        benchmark::DoNotOptimize(AerialPerspectiveLut::build(medium, T, ms, R, mu_s, E));
        break;
      case 6:
        benchmark::DoNotOptimize(MultipleScatteringBands::build(medium, T, gi));
        break;
      default:
        benchmark::DoNotOptimize(SkyViewLut::build(medium, T, ms, gi, R, mu_s, E, 192, 108, 30, &bands));
        break;
    }
  }
}
BENCHMARK(BM_LutBuildStage)
    ->ArgsProduct({{0, 1, 2, 3, 4, 5, 6, 7}, {8, 16, 32}})
    ->ArgNames({"stage", "bins"})
    ->Unit(benchmark::kMillisecond);

void BM_LutRadiance(benchmark::State& state) {
  const LutSky& sky = warm_sky(static_cast<int>(state.range(0)));
  std::vector<glm::dvec3> dirs;
  for (int i = 0; i < 64; ++i) {
    const double z = (i + 0.5) / 64.0 * kPi, a = i * 2.39996;  // zenith to nadir, golden-angle azimuths
    dirs.push_back(direction_from_zenith_azimuth(z, a));
  }
  std::vector<double> L(static_cast<std::size_t>(sky.grid().size()));
  std::size_t i = 0;
  for (auto _ : state) {
    sky.radiance(dirs[i++ & 63], L, true);
    benchmark::DoNotOptimize(L.data());
  }
}
BENCHMARK(BM_LutRadiance)->Arg(8)->Arg(16)->Arg(32);

// --- Colour against 94 bins of 5 nm. ---

struct SkyColours {
  std::vector<Xyz> xyz;  // per (sun, direction)
};

const std::vector<double>& sun_zeniths() {
  static const std::vector<double> z = {30.0, 80.0, 90.0, 96.0};
  return z;
}

// Zenith, horizon, near-horizon rows, the ground; 0-180 deg from the sun.
std::vector<glm::dvec3> colour_directions() {
  std::vector<glm::dvec3> d;
  for (double z : {0.0, 30.0, 60.0, 80.0, 88.0, 90.0, 95.0, 120.0, 180.0})
    for (double a : {10.0, 45.0, 90.0, 135.0, 180.0})
      d.push_back(direction_from_zenith_azimuth(z * kDegToRad, a * kDegToRad));
  return d;
}

SkyColours colours(int n) {
  const LutSky base = LutSky::build(atmosphere(), am0_sun(30.0), 0.0, 360.0, 830.0, bins(n));
  const BinnedSpectrumIntegral cie(base.grid(), 360.0, 830.0);
  const std::vector<glm::dvec3> dirs = colour_directions();
  std::vector<double> L(static_cast<std::size_t>(n));
  SkyColours c;
  for (double sz : sun_zeniths()) {
    const LutSky sky = base.with_sun(am0_sun(sz, 0.0));
    for (const glm::dvec3& d : dirs) {
      sky.radiance(d, L, false);
      c.xyz.push_back(cie.xyz(L));
    }
  }
  return c;
}

void BM_LutBinCountColourError(benchmark::State& state) {
  static const SkyColours reference = colours(94);
  const int n = static_cast<int>(state.range(0));
  SkyColours c;
  for (auto _ : state) c = colours(n);
  const std::size_t per_sun = colour_directions().size();
  double max_dY = 0.0, max_dxy = 0.0;
  for (std::size_t s = 0; s < sun_zeniths().size(); ++s) {
    double dY = 0.0, dxy = 0.0;
    for (std::size_t k = s * per_sun; k < (s + 1) * per_sun; ++k) {
      const Xyz& a = c.xyz[k];
      const Xyz& b = reference.xyz[k];
      dY = std::max(dY, std::abs(a.y / b.y - 1.0));
      const Chromaticity ca = chromaticity(a), cb = chromaticity(b);
      dxy = std::max(dxy, std::hypot(ca.x - cb.x, ca.y - cb.y));
    }
    const std::string sun = std::to_string(static_cast<int>(sun_zeniths()[s]));
    state.counters[std::string("rel_dY_sun").append(sun)] = dY;
    state.counters[std::string("dxy_sun").append(sun)] = dxy;
    max_dY = std::max(max_dY, dY);
    max_dxy = std::max(max_dxy, dxy);
  }
  state.counters["max_rel_dY"] = max_dY;
  state.counters["max_dxy"] = max_dxy;
}
BENCHMARK(BM_LutBinCountColourError)
    ->Arg(4)
    ->Arg(8)
    ->Arg(12)
    ->Arg(16)
    ->Arg(24)
    ->Arg(28)
    ->Arg(32)
    ->Iterations(1)
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace skyfarm
