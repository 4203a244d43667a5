// Microfacet normal distributions: GGX (Trowbridge-Reitz) and Beckmann, both
// anisotropic, with their Smith masking (Lambda, G1), the distribution of
// visible normals and its sampling.
//
// Local shading frame: +z is the macro-surface normal, x and y the tangent
// directions along which the roughness is alpha_x and alpha_y.  Every
// direction (w, wo, wm) is a unit glm::dvec3 in that frame pointing AWAY from
// the surface.  Doubles throughout.
//
// Parameters
//   model     MicrofacetModel::ggx or ::beckmann.
//   alpha_x   roughness along x, > 0 (the RMS slope times sqrt(2) for
//             Beckmann; the GGX width).  Values from 1e-4 (near mirror) to 2
//             (very rough) are exercised by the tests; alpha_x == alpha_y is
//             the isotropic case.
//   alpha_y   roughness along y, > 0.  The constructor throws
//             std::invalid_argument for a zero, negative or non-finite alpha.
//   wm        microfacet normal.  D(wm) is 0 for wm.z <= 0 (the surface is a
//             height field: no normal points below the macro surface).
//   w, wo     a direction of view or light.  lambda() and g1() are Smith's
//             functions for w above the macro surface (w.z > 0); lambda()
//             depends on |w.z| only, so lambda(-w) is the value needed by the
//             full-sphere extension (smith_full_sphere.h).
//   u         glm::dvec2 in [0, 1)^2, the random numbers of one sample.
//
// sample_visible_normal(wo, u) draws wm with the density visible_normal_pdf(
// wo, wm) = D_wo(wm) in 1/sr, for wo anywhere on the sphere except exactly
// -z: below the macro surface it draws the normals facing wo (wo . wm > 0,
// wm.z > 0) weighted by their projected area, as the full-sphere Smith model
// needs.
#pragma once

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

namespace skyfarm::material {

enum class MicrofacetModel { ggx, beckmann };

class MicrofacetDistribution {
 public:
  MicrofacetDistribution(MicrofacetModel model, double alpha_x, double alpha_y);

  MicrofacetModel model() const { return model_; }
  double alpha_x() const { return alpha_x_; }
  double alpha_y() const { return alpha_y_; }

  // The normal distribution D(wm) in 1/sr; integrates to 1 against wm.z.
  double D(const glm::dvec3& wm) const;

  // Smith's Lambda(w) for w above the macro surface (depends on |w.z| only);
  // +infinity at grazing incidence (w.z == 0).
  double lambda(const glm::dvec3& w) const;

  // Smith's masking G1(w) = 1 / (1 + Lambda(w)) for w above the macro surface.
  double g1(const glm::dvec3& w) const;

  // The distribution of normals visible from wo, D_wo(wm), in 1/sr; it
  // integrates to 1 over the sphere of wm for every wo but -z.
  double visible_normal_pdf(const glm::dvec3& wo, const glm::dvec3& wm) const;

  // A normal drawn with density visible_normal_pdf(wo, .).
  glm::dvec3 sample_visible_normal(const glm::dvec3& wo, const glm::dvec2& u) const;

 private:
  // The projected area of the normals facing w, per unit macro area and per
  // unit |w.z|: integral of <w . wm>+ D(wm) dwm divided by |w.z|, i.e.
  // 1 + Lambda(w) above the macro surface and Lambda(-w) below it.
  double facing_area_over_cos(const glm::dvec3& w) const;

  glm::dvec3 sample_visible_normal_ggx(const glm::dvec3& wo, const glm::dvec2& u) const;
  glm::dvec3 sample_visible_normal_beckmann(const glm::dvec3& wo, const glm::dvec2& u) const;

  MicrofacetModel model_;
  double alpha_x_;
  double alpha_y_;
};

}  // namespace skyfarm::material
