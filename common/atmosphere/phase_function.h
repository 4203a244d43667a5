// Phase functions of the atmosphere's scatterers: how much of the light that a
// volume element scatters goes into each direction.
//
// One value type, PhaseFunction (a std::variant of the models below, no virtual
// calls), built by a factory or from the request's PhaseSpec
// (common/atmosphere/atmosphere_spec.h).
//
// Convention
//   cos_theta (mu)  cosine of the scattering angle between the incident
//                   PROPAGATION direction and the scattered propagation
//                   direction: mu = 1 is straight forward (no deflection),
//                   mu = -1 is back towards the source.
//   eval(mu)        p(mu) in 1/sr, normalised so that the integral over the
//                   sphere, 2 pi * int_{-1}^{1} p(mu) dmu, is 1.
//   sample_cos_theta(u)  draws mu exactly from p (its pdf in 1/sr is eval(mu));
//                   one uniform number u in [0, 1); monotone in u (to
//                   rounding), deterministic, always in [-1, 1].
//   sample_direction(propagation, u1, u2)  the scattered propagation
//                   direction: mu from u1, azimuth phi = 2 pi u2 about
//                   `propagation` (a unit vector).
//   mean_cosine()   the asymmetry parameter g = <mu> = 2 pi int mu p(mu) dmu.
//
// Models and their parameters
//   rayleigh(depolarization)   rho_n in [0, 1]: depolarisation factor of the
//                   air molecules (Bucholtz 1995: ~0.0279 at 550 nm; 0 gives
//                   the textbook 3/(16 pi) (1 + mu^2)).
//   henyey_greenstein(g)       g in (-1, 1): asymmetry parameter; 0 is
//                   isotropic, g > 0 forward scattering.
//   cornette_shanks(g)         g in (-1, 1): Cornette & Shanks (1992)
//                   parameter (note: its mean cosine is not g but
//                   3g(4+g^2)/(5(2+g^2))); g = 0 is Rayleigh with rho_n = 0.
//   tabulated(angles_deg, values)  scattering angles in degrees, strictly
//                   increasing from exactly 0 to exactly 180, and the phase
//                   function at those angles in any positive scale (e.g. the
//                   4 pi-normalised P of a Mie code).  The table is interpolated
//                   LINEARLY IN mu = cos(theta) between its knots, and that
//                   piecewise-linear function is normalised exactly and sampled
//                   exactly.  Throws std::invalid_argument on a bad table.
//
// Every factory throws std::invalid_argument, with the offending value in the
// message, for parameters outside the ranges above.
#pragma once

#include <memory>
#include <span>
#include <string_view>
#include <utility>
#include <variant>
#include <vector>

#include <glm/vec3.hpp>

#include "common/atmosphere/atmosphere_spec.h"

namespace skyfarm {

// --- The models (usable on their own; PhaseFunction dispatches to them). ---

struct RayleighPhase {
  double depolarization = 0.0;  // rho_n
  double gamma = 0.0;           // rho_n / (2 - rho_n)

  double eval(double mu) const;
  double sample_cos_theta(double u) const;
  double mean_cosine() const { return 0.0; }
};

struct HenyeyGreensteinPhase {
  double g = 0.0;

  double eval(double mu) const;
  double sample_cos_theta(double u) const;
  double mean_cosine() const { return g; }
};

struct CornetteShanksPhase {
  double g = 0.0;

  double eval(double mu) const;
  // The exact cumulative distribution F(mu) = 2 pi int_{-1}^{mu} p, in [0, 1].
  double cdf(double mu) const;
  double sample_cos_theta(double u) const;
  double mean_cosine() const;
};

struct TabulatedPhase {
  // Knots in increasing mu (from -1 to 1), the normalised density p (1/sr)
  // at the knots, the cumulative probability at the knots (0 ... 1) and the
  // mean cosine, all computed once when built.
  struct Table {
    std::vector<double> mu;
    std::vector<double> p;
    std::vector<double> cdf;
    double mean_cosine = 0.0;
  };
  std::shared_ptr<const Table> table;  // immutable, shared between copies

  double eval(double mu) const;
  double sample_cos_theta(double u) const;
  double mean_cosine() const { return table->mean_cosine; }
};

// --- The value type. ---

class PhaseFunction {
 public:
  using Model = std::variant<RayleighPhase, HenyeyGreensteinPhase, CornetteShanksPhase, TabulatedPhase>;

  // Isotropic (Henyey-Greenstein with g = 0).
  PhaseFunction() = default;
  explicit PhaseFunction(Model model) : model_(std::move(model)) {}

  static PhaseFunction isotropic() { return PhaseFunction(); }
  static PhaseFunction rayleigh(double depolarization);
  static PhaseFunction henyey_greenstein(double g);
  static PhaseFunction cornette_shanks(double g);
  static PhaseFunction tabulated(std::span<const double> angles_deg, std::span<const double> values);
  static PhaseFunction from_spec(const PhaseSpec& spec);

  double eval(double cos_theta) const;
  double sample_cos_theta(double u) const;
  glm::dvec3 sample_direction(const glm::dvec3& propagation, double u1, double u2) const;
  double mean_cosine() const;

  // "rayleigh", "henyey_greenstein", "cornette_shanks" or "table" (the
  // request's names, for scene-plan reports and messages).
  std::string_view name() const;
  const Model& model() const { return model_; }

 private:
  Model model_{HenyeyGreensteinPhase{0.0}};
};

}  // namespace skyfarm
