// Geometry shared by the per-job tables indexed by the sun's zenith angle at
// a path vertex (RadianceControl, ShadowGuide): the window of angles the
// vertices of a job span, and the frame at a table node.
#pragma once
#include <glm/vec3.hpp>

#include "common/render/scene.h"

namespace skyfarm {

// The sun's zenith angles (rad) at the vertices of a job's paths: the
// observer's +- window_deg plus the angle (from the planet's centre) out to
// the observer's horizon, within [0, pi].  Paths stay near the camera; a
// vertex outside the window uses the table's edge.
struct SunZenithWindow {
  double lo = 0.0, hi = 0.0;
};
SunZenithWindow vertex_sun_zenith_window(const Scene& scene, double window_deg);

// A node's frame: `up` the zenith of a point where the sun (unit) is theta_s
// from the zenith, `towards_sun` the sun's azimuth on that point's
// horizontal, `side` = up x towards_sun.  The same for every table, so
// nodes of equal theta_s are the same points.
struct SunNodeFrame {
  glm::dvec3 up, towards_sun, side;
};
SunNodeFrame sun_node_frame(const glm::dvec3& sun, double theta_s);

}  // namespace skyfarm
