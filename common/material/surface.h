// A surface made of a material: the request's SurfaceSpec resolved to the
// material's spectral constants, and the BSDF it has at each wavelength.
//
//   kind        roughness 0                    roughness > 0
//   conductor   SmoothReflector (complex n)    RoughConductor / MultipleBounceBsdf(conductor facets)
//   dielectric  SmoothReflector (Fresnel)      RoughDielectric / MultipleBounceBsdf(dielectric facets)
//     in a solid SmoothDielectric               the same, with their own proposal (both sides)
//   diffuse     Lambertian (albedo)            RoughDiffuse / MultipleBounceBsdf(diffuse facets)
//
// The single-bounce form is used when spec.multiple_bounce is false.  A
// dielectric's relative index is its n at the wavelength (the air above
// counts as 1, its 3e-4 excess is far below the tables' accuracy); its k is
// not used at the interface (water's k < 1e-8 in the visible).  What a
// dielectric transmits depends on the body behind the surface (Body):
//   kOpaque  absorbed (the ground: deep water); only reflected directions
//            are proposed (SurfaceBsdf::reflection_only).
//   kSolid   the surface bounds a closed, non-absorbing body of the material
//            (a glass object): light crosses it, the BSDF is the full one,
//            its macro normal the OUTWARD one (+z outside, the inside below),
//            and wo may be on either side.  A crossing carries no
//            (n_wo / n_wi)^2 radiance factor: a path enters and leaves a
//            body through its surface, so the factors cancel, and a
//            throughput that dipped by n^2 inside would make the path
//            tracer's roulette kill paths there for nothing.  (The rough
//            forms, evaluated f(wi, wo) as the path tracer does, have none
//            either: their transposed radiance form is the flux form.)
// Conductors and diffuse materials are the same for both bodies.
//
// white_sky_albedo(lambda) is the surface's bihemispherical reflectance: the
// directional albedo A(mu) = integral f cos dwi averaged over incident
// directions with weight 2 mu dmu (uniform diffuse illumination).  It is the
// Lambertian stand-in that methods which know only an albedo (the LUT sky,
// the roulette control) use for this surface.  Computed by Gauss-Legendre
// quadrature in mu (16 nodes) and Monte Carlo over sample() (64 per node)
// with fixed seeds, so it is a deterministic function of the spec.
#pragma once

#include <memory>
#include <string>

#include "common/core/spectral_table.h"
#include "common/material/material_library.h"
#include "common/material/surface_bsdf.h"
#include "common/material/surface_spec.h"

namespace skyfarm::material {

enum class Body { kOpaque, kSolid };

class Surface {
 public:
  // Throws std::invalid_argument naming what is wrong (an unknown name, a
  // bad table entry, a roughness out of range).
  explicit Surface(SurfaceSpec spec);

  const SurfaceSpec& spec() const { return spec_; }
  const Material& material() const { return *material_; }
  MaterialKind kind() const { return material_->kind(); }
  // A smooth diffuse surface: a Lambertian reflector, all an albedo says.
  bool lambertian() const { return kind() == MaterialKind::kDiffuse && spec_.smooth(); }
  // A smooth conductor or dielectric: a delta lobe.
  bool specular() const { return kind() != MaterialKind::kDiffuse && spec_.smooth(); }

  SurfaceBsdf bsdf(double lambda_nm, Body body = Body::kOpaque) const;
  // Whether light crosses this surface around a body: a dielectric solid.
  bool transmits(Body body) const { return body == Body::kSolid && kind() == MaterialKind::kDielectric; }
  // The model the table above picks: "lambertian", "smooth_conductor",
  // "rough_conductor", "multiple_bounce_conductor", ... (dielectric, diffuse).
  std::string model_name() const;

  double white_sky_albedo(double lambda_nm) const;
  // white_sky_albedo every step_nm over [lo_nm, hi_nm] (ends included).
  SpectralTable white_sky_albedo_table(double lo_nm = 360.0, double hi_nm = 830.0, double step_nm = 10.0) const;

 private:
  SurfaceSpec spec_;
  std::shared_ptr<const Material> material_;
};

}  // namespace skyfarm::material
