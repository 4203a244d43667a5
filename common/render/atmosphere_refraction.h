// What the renderers need to bend rays ("atmosphere.refraction"): the
// refractive shells of US76 through Ciddor's index (refractive_shells.h) at
// wavelength nodes, and the apparent <-> true elevation of a source seen from
// any altitude (RefractionTable at altitude nodes).
//
// The index is US76's whatever the scattering atmosphere (a custom preset,
// aerosols, clouds): refraction depends on the air's density alone, and the
// presets' air is US76 (as `skyfarm-worker info`'s apparent sun).
//
// Wavelength.  A path carries kWavelengthsPerPath wavelengths but one
// geometry: it is bent at its hero wavelength (lambda[0]), and the others
// ride along the hero's path.  The hero is uniformly distributed over the
// range (rotated strata), so over the image every wavelength bends as its
// own: the dispersion (coloured rims, the upper rim bluer) is in the
// expectation; per path, the companions' geometry is wrong by the dispersion
// (< 0.6' between 400 and 700 nm at the horizon), and their spectral-MIS
// weights use the hero's path.  Shells are built every kShellStep_nm and a
// path takes the nearest node: the refraction's error from it is below the
// dispersion across 2.5 nm (< 0.01' at the horizon).
//
// Accuracy for rendering.  The shells are coarser than the tests' reference
// (|d(n - 1)| <= 2e-6 per shell, at most 5 km thick: ~180 shells to 100 km,
// against ~1 400 at 3e-7): the power-law shells stay exact on their own
// model, and the horizon refraction changes by < 1" (measured in
// tests/common/render/atmosphere_refraction_test.cpp) while a ray costs ~8x
// less.  Chords per ray are bounded by the tracer's own cap (4 x shells + 16
// steps, one lap of the planet for a trapped ray).
//
// Elevations seen from altitude h (the sun's next-event estimation):
// RefractionTable at altitude nodes (dense near the ground, where the dip of
// the horizon grows fastest), 6 wavelength nodes (interpolated in 1/lambda^2),
// linear in h between nodes.  true_elevation(h, e) is that interpolation;
// apparent_elevation is its inverse (safeguarded Newton), so the two are exact
// inverses of each other, which the MIS between the sun's samples and the
// phase function's needs (the pdfs of both techniques share
// solid_angle_ratio).  A source is hidden where either node hides it.
//
// Built once per (planet radius, top altitude) and process (~0.3 s), shared.
#pragma once

#include <memory>
#include <optional>
#include <vector>

#include <glm/vec3.hpp>

#include "common/atmosphere/refraction_table.h"
#include "common/atmosphere/refractive_shells.h"
#include "common/render/bent_path.h"

namespace skyfarm {

class AtmosphereRefraction {
 public:
  static constexpr double kShellStep_nm = 5.0;
  static constexpr double kMaxRefractivityStep = 2e-6;
  static constexpr double kMaxThickness_m = 5000.0;

  AtmosphereRefraction(double planet_radius_m, double top_altitude_m);
  // One model per (planet radius, top altitude), built on first use.
  static std::shared_ptr<const AtmosphereRefraction> shared(double planet_radius_m, double top_altitude_m);

  const RefractiveShells& shells(double lambda_nm) const;
  void trace(const glm::dvec3& o, const glm::dvec3& d, double lambda_nm, BentPath* out) const {
    trace_bent_path(shells(lambda_nm), o, d, out);
  }

  // Elevations in degrees, seen from altitude h (clamped to the nodes).
  std::optional<double> true_elevation_deg(double altitude_m, double apparent_deg, double lambda_nm) const;
  std::optional<double> apparent_elevation_deg(double altitude_m, double true_deg, double lambda_nm) const;
  // dw_apparent / dw_true at apparent elevation e seen from h: the apparent
  // solid angle of a small source over its true one, cos(e_a) de_a over
  // cos(e_t) de_t (azimuth is unchanged by refraction).  < 1 near the
  // horizon: the flattening.  0 where the elevation is out of the tables.
  double solid_angle_ratio(double altitude_m, double apparent_deg, double lambda_nm) const;

  // The apparent direction at p of a source in the true direction s (unit),
  // and dw_apparent / dw_true there; nullopt where the planet hides it.
  struct Apparent {
    glm::dvec3 direction;
    double solid_angle_ratio = 1.0;
  };
  std::optional<Apparent> apparent_direction(const glm::dvec3& p, const glm::dvec3& s, double lambda_nm) const;
  // dw_apparent / dw_true of the direction d seen at p (for the MIS of a
  // sampled direction that meets the sun).
  double solid_angle_ratio_at(const glm::dvec3& p, const glm::dvec3& d, double lambda_nm) const;

  double planet_radius_m() const { return planet_radius_m_; }

 private:
  void bracket(double altitude_m, int* i0, double* w) const;
  double planet_radius_m_, top_altitude_m_;
  double first_shell_nm_ = 0.0;
  std::vector<RefractiveShells> shells_;
  std::vector<double> altitudes_m_;
  std::vector<RefractionTable> tables_;
};

}  // namespace skyfarm
