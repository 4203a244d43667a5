// Astronomical refraction of the U.S. Standard Atmosphere 1976 (Ciddor's
// index, air_refractive_index.h) tabulated for one observer altitude: for each
// wavelength node, the refraction R = true zenith - apparent zenith of the
// ray-traced path (refracted_ray.h) on a grid of apparent elevations, with
// look-ups apparent -> true and true -> apparent elevation.
//
// Parameters (RefractionTable::Options):
//   wavelengths_nm         wavelength nodes, increasing (default 380, 400, ..., 780);
//                          between nodes R is interpolated linearly in
//                          1 / lambda^2 (n - 1 is nearly linear in it), outside
//                          them it is held (error figures below)
//   elevation_nodes        nodes per wavelength and segment (default 256)
//   max_refractivity_step  the shells' accuracy (refractive_shells.h)
//   planet_radius_m, top_altitude_m   the sphere and the top of the air
// Grid, two segments per wavelength, each interpolated with a cubic
// (Catmull-Rom) in its uniform parameter:
//   below the horizon (rays with a tangent point, from the one grazing the
//   ground at apparent elevation e_min to the horizontal ray, or for an
//   observer above the top to the ray grazing the top): uniform in e (not in
//   Bouguer's invariant k = n0 r0 cos(e): R is smooth in e at the horizontal
//   ray, where k has a square-root turn);
//   above it: e = e_0 + (90 deg - e_0) u^2, u uniform on [0, 1], crowding the
//   nodes near the horizon where R changes fastest.
// e_min follows in closed form from k = n(ground) r(ground).  Interpolation
// error against direct tracing at the mid-points, and of the wavelength
// interpolation at 20 nm spacing, are measured in the tests and listed in
// docs/physics.md, "Refraction".
// Look-ups below e_min (the ray meets the ground) or below the true elevation
// of the grazing ray (the source is hidden by the planet) return nullopt.
#pragma once

#include <optional>
#include <vector>

namespace skyfarm {

class RefractionTable {
 public:
  struct Options {
    std::vector<double> wavelengths_nm = default_wavelengths_nm();
    int elevation_nodes = 256;
    double max_refractivity_step = 3e-7;
    double planet_radius_m = 6371000.0;
    double top_altitude_m = 100000.0;
  };
  static std::vector<double> default_wavelengths_nm();

  RefractionTable(double observer_altitude_m, const Options& options);
  RefractionTable(double observer_altitude_m) : RefractionTable(observer_altitude_m, Options{}) {}

  double observer_altitude_m() const { return observer_altitude_m_; }
  const std::vector<double>& wavelengths_nm() const { return wavelengths_; }
  // Lowest apparent elevation whose ray does not meet the ground, degrees.
  double lowest_apparent_elevation_deg(double lambda_nm) const;

  // Refraction R (degrees, > 0) of a ray seen at this apparent elevation.
  std::optional<double> refraction_deg(double apparent_elevation_deg, double lambda_nm) const;
  std::optional<double> true_elevation_deg(double apparent_elevation_deg, double lambda_nm) const;
  // Inverse: where a source at this true (geometric) elevation appears.
  std::optional<double> apparent_elevation_deg(double true_elevation_deg, double lambda_nm) const;

 private:
  struct Column {  // one wavelength
    double lowest_elevation_deg = 0.0;    // e_min
    double horizon_elevation_deg = 0.0;   // e_0: 0, or the top's grazing ray from above
    double k_min = 0.0, k_max = 0.0;      // invariant at e_min and e_0
    double observer_s = 0.0;              // n0 r0
    std::vector<double> below_deg;        // R at e uniform on [e_min, e_0]
    std::vector<double> above_deg;        // R at u uniform on [0, 1]
  };
  double refraction_in_column(const Column& c, double apparent_deg) const;
  // Weights between wavelength nodes.
  void bracket(double lambda_nm, int& i0, int& i1, double& w) const;
  std::optional<double> refraction_interpolated(double apparent_deg, double lambda_nm) const;

  double observer_altitude_m_;
  std::vector<double> wavelengths_;
  std::vector<Column> columns_;
};

}  // namespace skyfarm
