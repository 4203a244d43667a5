// The interface every surface BSDF implements.
//
// Local shading frame: +z is the macro-surface normal.  Directions are unit
// glm::dvec3 pointing AWAY from the surface: wo towards the viewer (the
// direction the path arrived from), wi towards the light (the direction the
// path continues along).  A direction below the macro surface (w.z < 0) is
// on the transmission side.
//
// Spectral: a BSDF holds its optical constants at ONE wavelength (a complex
// index, an albedo) and returns plain doubles.  The path tracer carries
// several wavelengths per path (a hero wavelength and its companions); it
// builds one BSDF per wavelength from the material's spectral tables (cheap:
// a few doubles), samples the direction with the hero's and evaluates f and
// pdf with every companion's.  Seeding the RandomSequence of each companion
// with the same seed makes the stochastic evaluations of one path
// correlated across wavelengths, as for the volume.
//
// Members
//   f(wo, wi, rng)   the BSDF value in 1/sr.  For the exact forms (Lambertian,
//                    single-bounce conductor and dielectric) it is a
//                    function and rng is untouched.  For the stochastic forms
//                    (stochastic() true: rough diffuse, every multiple-bounce
//                    BSDF) it is ONE unbiased Monte Carlo estimate: E[f] is
//                    the BSDF, each call draws from rng, values are >= 0.
//   sample(wo, uc, u, rng)
//                    proposes wi with density pdf(wo, wi) (uc, u uniform in
//                    [0, 1)) and returns value = f(wo, wi) |wi.z| / pdf, with
//                    f an estimate for the stochastic forms (so value is an
//                    unbiased estimate of the exact weight).  nullopt when
//                    the proposal fails (a direction on the wrong side).
//   pdf(wo, wi)      the density of sample()'s proposal over solid angle,
//                    ALWAYS a deterministic function of (wo, wi) and ALWAYS
//                    exactly the density sample() draws from, also for the
//                    stochastic forms (they propose from a mixture of known
//                    densities and put all the randomness in f).
//
// Why multiple importance sampling stays unbiased with a stochastic f: the
// MIS weights (balance or power heuristic) are built from pdf() and the light
// sampling density only, both deterministic, so the weights of the two
// strategies still sum to one for every path; each strategy's contribution
// is (weight) x (unbiased estimate of f |cos| / density), whose expectation is
// the exact one.  What must NOT be done is to build a weight from a value of
// f (e.g. f-proportional heuristics): that would correlate weight and
// estimate.
#pragma once

#include <cstdint>
#include <optional>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "common/material/random_sequence.h"

namespace skyfarm::material {

// Kinds of lobe a BSDF has or a sample came from.
enum BsdfFlags : std::uint32_t {
  kBsdfReflection = 1u << 0,
  kBsdfTransmission = 1u << 1,
  kBsdfDiffuse = 1u << 2,
  kBsdfGlossy = 1u << 3,
  kBsdfSpecular = 1u << 4,  // a delta lobe: f and pdf are not functions
};

struct BsdfSample {
  glm::dvec3 wi{0.0, 0.0, 1.0};
  double value = 0.0;  // f(wo, wi) |wi.z| / pdf (an unbiased estimate for stochastic forms)
  double pdf = 0.0;    // pdf(wo, wi), 1/sr
  std::uint32_t flags = 0;
};

class Bsdf {
 public:
  virtual ~Bsdf() = default;

  virtual std::uint32_t flags() const = 0;
  virtual bool stochastic() const = 0;

  virtual double f(const glm::dvec3& wo, const glm::dvec3& wi, RandomSequence& rng) const = 0;
  virtual std::optional<BsdfSample> sample(const glm::dvec3& wo, double uc, const glm::dvec2& u,
                                           RandomSequence& rng) const = 0;
  virtual double pdf(const glm::dvec3& wo, const glm::dvec3& wi) const = 0;
};

}  // namespace skyfarm::material
