// A ray of the path tracer bent by refraction: the exact curved path of
// refracted_ray.h (its points at the refractive-shell boundaries and turning
// points) as a polyline of straight chords, in planet-centred coordinates,
// with the arc-length-like parameter t running along the chords.  Each
// chord joins two points of the exact path; consecutive pieces are merged
// into one chord while the path strays from it by less than 1 m (length x
// turning angle / 4; the ray's radius of curvature is >= ~30 000 km in
// air): a steep ray is a few chords, a grazing one ~15 km chords near the
// ground and longer ones above.
//
// BentShellWalk walks the chords through the majorant shells
// (shell_traversal.h per chord, chord after chord), so free-flight sampling
// and ratio tracking (free_flight.h) run along the bent path unchanged: delta
// tracking is memoryless, so a walk split at the chords' ends samples the
// same collisions as one straight walk would through the same shells.  It
// also serves as the flight's "line": at(t) on the chord being walked.
#pragma once

#include <cstddef>
#include <span>
#include <vector>

#include <glm/vec3.hpp>

#include "common/atmosphere/refracted_ray.h"
#include "common/geometry/ray.h"
#include "common/render/shell_traversal.h"

namespace skyfarm {

struct Chord {
  glm::dvec3 o{0.0}, d{0.0, 0.0, 1.0};  // start, unit direction
  double t0 = 0.0;                      // the path's t at o
  double length = 0.0;
  Ray ray() const { return Ray{o, d}; }
};

struct BentPath {
  RefractedRay::Outcome outcome = RefractedRay::Outcome::kEscaped;
  // From the start to the end: the ground, the exit through the top, or, for
  // a start above the top, first the straight stretch down to the top.
  std::vector<Chord> chords;
  bool in_atmosphere = false;
  double t_enter = 0.0;  // where the path enters the atmosphere (0 from inside)
  double t_end = 0.0;    // where it reaches the ground or leaves the top
  // The direction beyond the atmosphere when it escapes (the true direction
  // of what it sees); the start direction when it never entered.
  glm::dvec3 exit_direction{0.0, 0.0, 1.0};
  glm::dvec3 start{0.0};

  // The chord holding t (the last one for t past the end; the path has chords).
  std::size_t chord_at(double t) const;
  // The straight ray that carries the path at its parameter t and the
  // distance along it to that point (for finish_segment's ends).
  Ray ray_at(double t, double* local_t) const;
};

// Traces the path from o (planet-centred, m) along the unit direction d
// through `shells` (refracted_ray.h, exact for them) into *out (its storage
// is reused).  A vertical ray (d along o) bends in no plane: any plane does.
void trace_bent_path(const RefractiveShells& shells, const glm::dvec3& o, const glm::dvec3& d, BentPath* out);

class BentShellWalk {
 public:
  // The shell segments of [t_begin, t_end] of `path` (a walk of nothing if empty).
  BentShellWalk(const BentPath& path, double planet_radius_m, std::span<const double> shell_bottoms, double t_begin,
                double t_end);
  bool next(ShellSegment* segment);
  // The point at t on the chord walked now (t within the last segment).
  glm::dvec3 at(double t) const { return chord_->o + (t - chord_->t0) * chord_->d; }
  // The direction of the chord walked now.
  const glm::dvec3& direction() const { return chord_->d; }

 private:
  bool open_next_chord();
  const BentPath* path_;
  double R_;
  std::span<const double> bottoms_;
  double t_begin_, t_end_;
  std::size_t next_chord_ = 0;
  const Chord* chord_ = nullptr;
  ShellTraversal walk_;
};

}  // namespace skyfarm
