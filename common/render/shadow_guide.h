// A direction guide for path vertices where the sun is below the local
// horizontal (twilight): a tabulated approximation of the radiance arriving
// there, sampled as a piecewise-constant distribution over directions.
//
// At twilight the light a vertex in the dark air scatters on comes from a
// small part of its sphere of directions: the lit air low towards the sun's
// azimuth and, from vertices high up and far towards the sun, the aureole of
// lit air around the sun itself.  The phase function rarely sends a path
// there, and those rare paths were the heavy tail of the image.  This guide
// is a sampling pdf only (mixed with the phase function's by the
// integrator, one-sample MIS), so its errors cost variance, never bias.
//
// Table: per node (altitude h, sun zenith angle theta_s at the vertex), a
// grid over the local direction (mu = cos of the zenith angle, phi = azimuth
// from the sun's, folded to [0, pi]: the sky is mirror-symmetric about the
// sun's vertical plane); cell values L~ = LutSky::raymarch_radiance summed
// over the LUT's bins at the cell's centre direction.  The vertex uses its
// nearest node (no interpolation: the pdf is then exactly what was sampled).
//   altitude   nodes uniform in sqrt(h / top) (dense low)
//   sun        theta_s from 90 deg (where the sun sets at the vertex) to the
//              observer's plus sun_window_deg and the angle out to its horizon
//              (paths stay near the camera; beyond, the last node is used)
//   mu         cell edges mu = x |x|, x uniform in [-1, 1] (dense at the horizon)
//   phi        cell edges phi = pi v^2, v uniform in [0, 1] (dense towards the sun)
// Within a cell, mu and phi are uniform (the cell's solid angle is
// d(mu) d(phi)); the side of the sun's vertical plane is a coin.
// Built per job for path-traced renders with the sun below the observer's
// horizon (RenderPlan::shadow_guide); 8 x 12 nodes of 32 x 24 cells march
// 73 728 rays through coarse LUT tables (~0.14 s on one core, 1.2 MB; 12
// altitudes of 48 x 32 cells cost 0.5 s for no gain).  Measured in
// docs/experiments/2026-12-02-twilight.md.
#pragma once
#include <vector>

#include <glm/vec3.hpp>

#include "common/render/scene.h"
#include "common/render/sun_angle_nodes.h"

namespace skyfarm {

struct ShadowGuideResolution {
  int altitudes = 8, sun_angles = 12, mu_cells = 32, phi_cells = 24;
  int bins = 4, steps = 8;
  double sun_window_deg = 12.0;
};

class ShadowGuide {
 public:
  explicit ShadowGuide(const Scene& scene, const ShadowGuideResolution& resolution = {});

  // Whether the guide applies at p (planet-centred): the sun below p's
  // local horizontal and p's node has light to guide towards.
  bool covers(const glm::dvec3& p) const;
  // A direction from p's node's distribution (u in [0,1)^3); p must be
  // covered.  Its pdf per steradian is pdf(p, wi).
  glm::dvec3 sample(const glm::dvec3& p, double u1, double u2, double u3) const;
  double pdf(const glm::dvec3& p, const glm::dvec3& wi) const;

  std::size_t memory_bytes() const { return (cdf_rows_.size() + cdf_cols_.size() + density_.size()) * sizeof(double); }

 private:
  bool local_frame(const glm::dvec3& p, SunNodeFrame* f) const;
  int node_of(const glm::dvec3& p) const;
  double mu_edge(int j) const;
  double phi_edge(int k) const;
  std::size_t cell(int node, int j, int k) const {
    return (static_cast<std::size_t>(node) * res_.mu_cells + static_cast<std::size_t>(j)) * res_.phi_cells +
           static_cast<std::size_t>(k);
  }

  ShadowGuideResolution res_;
  double R_ = 0.0, top_ = 0.0;
  glm::dvec3 sun_{0.0, 0.0, 1.0};
  double sun_zenith_lo_ = 0.0, sun_zenith_step_ = 0.0;
  std::vector<char> usable_;       // per node: any light at all
  std::vector<double> density_;    // per cell: pdf per steradian over the half sphere (phi in [0, pi])
  std::vector<double> cdf_rows_;   // per node: mu_cells + 1 entries
  std::vector<double> cdf_cols_;   // per node and row: phi_cells + 1 entries
};

}  // namespace skyfarm
