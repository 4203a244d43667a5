// A spherically stratified refractive atmosphere as concentric shells, the
// medium the refracted-ray tracer (refracted_ray.h) crosses exactly.  The index
// is given at the shell boundaries (nodes) and follows a power law of the
// radius inside each shell, n(r) = n_i (r / r_i)^(-alpha_i), fitted to both
// nodes: n is continuous (no spurious reflections) and the ray's path inside a
// shell has a closed form (refracted_ray.cpp).  Constant-index shells with
// straight chords were tried first: a grazing ray then runs unbent along a
// whole shell and the horizon refraction converges only as sqrt(thickness).
//
// Parameters of RefractiveShells::from_profile:
//   profile.refractivity     (n - 1) as a function of geometric altitude, m
//   profile.planet_radius_m  radius of the ground sphere, m
//   profile.top_altitude_m   altitude above which n = 1 exactly, m
//   max_refractivity_step    largest change of (n - 1) across one shell
//                            (default 3e-7; error figures in docs/physics.md,
//                            "Refraction")
//   max_thickness_m          thickest shell, m (default 2000)
// The top node is n = 1 exactly, so the ray leaves into vacuum without a jump.
#pragma once

#include <functional>
#include <vector>

namespace skyfarm {

struct RefractivityProfile {
  std::function<double(double altitude_m)> refractivity;
  double planet_radius_m = 6371000.0;
  double top_altitude_m = 100000.0;
};

// The U.S. Standard Atmosphere 1976 through Ciddor's equation (air_refractive_index.h).
RefractivityProfile us76_refractivity_profile(double lambda_nm, double planet_radius_m = 6371000.0,
                                              double top_altitude_m = 100000.0);

class RefractiveShells {
 public:
  // radii: N + 1 increasing boundaries (ground first, top last); index: n at each.
  RefractiveShells(std::vector<double> radii_m, std::vector<double> refractive_index);
  static RefractiveShells from_profile(const RefractivityProfile& profile, double max_refractivity_step = 3e-7,
                                       double max_thickness_m = 2000.0);

  int shell_count() const { return static_cast<int>(radii_.size()) - 1; }
  double radius_m(int boundary) const { return radii_[boundary]; }
  double index(int boundary) const { return index_[boundary]; }
  // Exponent beta_i = 1 - alpha_i of n r = n_i r_i (r / r_i)^beta in shell i.
  double beta(int shell) const { return beta_[shell]; }
  // n at radius r inside shell i (the power law).
  double index_at(int shell, double radius_m) const;
  double ground_radius_m() const { return radii_.front(); }
  double top_radius_m() const { return radii_.back(); }
  // Shell holding radius r (r clamped into [ground, top)).
  int shell_at(double radius_m) const;

 private:
  std::vector<double> radii_;
  std::vector<double> index_;
  std::vector<double> beta_;
};

}  // namespace skyfarm
