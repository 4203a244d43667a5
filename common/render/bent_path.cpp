#include "common/render/bent_path.h"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

#include "common/core/constants.h"

namespace skyfarm {
namespace {

// How far a chord may stray from the curved path it stands for, m.
constexpr double kMaxSagitta_m = 1.0;

}  // namespace

std::size_t BentPath::chord_at(double t) const {
  // The first chord whose end lies beyond t.
  const auto it = std::upper_bound(chords.begin(), chords.end(), t,
                                   [](double x, const Chord& c) { return x < c.t0 + c.length; });
  return it == chords.end() ? chords.size() - 1 : static_cast<std::size_t>(it - chords.begin());
}

Ray BentPath::ray_at(double t, double* local_t) const {
  const Chord& c = chords[chord_at(t)];
  *local_t = t - c.t0;
  return c.ray();
}

void trace_bent_path(const RefractiveShells& shells, const glm::dvec3& o, const glm::dvec3& d, BentPath* out) {
  out->chords.clear();
  out->start = o;
  const double r = glm::length(o);
  const glm::dvec3 up = o / r;
  const double cos_z = std::clamp(glm::dot(up, d), -1.0, 1.0);
  glm::dvec3 forward = d - cos_z * up;
  const double horizontal = glm::length(forward);
  if (horizontal > 1e-15) {
    forward /= horizontal;
  } else {  // vertical: any horizontal will do
    forward = glm::normalize(glm::cross(up, std::abs(up.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0)));
  }
  // The zenith angle from the sine and cosine, exact near 0 and 180 degrees.
  const double zenith_deg = std::atan2(horizontal, cos_z) * kRadToDeg;
  thread_local RefractedRay ray;  // its path's storage reused
  trace_refracted_ray(shells, r, zenith_deg, true, &ray);
  out->outcome = ray.outcome;
  // Consecutive pieces merge into one chord while the arc they replace stays
  // within kMaxSagitta_m of it: the chord's length times the angle its pieces
  // turn through, over 4, bounds how far the path strays from it.  A steep
  // ray (turning < 1e-7 rad per shell) becomes a few chords, a grazing one
  // keeps ~15 km chords near the ground; every chord's ends are still points
  // of the exact path.  The entry from space is always a vertex (t_enter).
  const bool from_space = r >= shells.top_radius_m();
  glm::dvec3 start = o, previous = o, first_direction(0.0);
  double t = 0.0;
  bool open = false;  // a chord from `start` to `previous` waits to be closed
  auto close = [&] {
    const glm::dvec3 step = previous - start;
    const double length = glm::length(step);
    out->chords.push_back(Chord{start, step / length, t, length});
    t += length;
    start = previous;
    open = false;
  };
  for (std::size_t i = 1; i < ray.path.size(); ++i) {
    const glm::dvec3 p = path_point(ray.path[i], up, forward);
    const glm::dvec3 piece = p - previous;
    const double piece_length = glm::length(piece);
    if (!(piece_length > 0.0)) continue;  // a turning point on a boundary
    const glm::dvec3 direction = piece / piece_length;
    if (open) {
      const double turn = glm::length(glm::cross(direction, first_direction));  // sin, exact when small
      const double length = glm::length(p - start);
      if (length * turn > 4.0 * kMaxSagitta_m) close();
    }
    if (!open) {
      first_direction = direction;
      open = true;
    }
    previous = p;
    if (from_space && i == 1) close();  // the straight stretch down to the top
  }
  if (open) close();
  // A start on the ground looking down meets it at once: one empty chord, so
  // that the path still ends there (not in space).
  if (out->chords.empty() && ray.outcome == RefractedRay::Outcome::kHitGround) out->chords.push_back(Chord{o, d, 0.0, 0.0});
  out->in_atmosphere = !out->chords.empty();
  out->t_enter = r >= shells.top_radius_m() && out->in_atmosphere ? out->chords.front().length : 0.0;
  out->t_end = t;
  out->exit_direction = out->in_atmosphere && ray.outcome == RefractedRay::Outcome::kEscaped
                            ? glm::normalize(plane_direction(ray.exit_direction_rad, up, forward))
                            : d;
  // A ray from above that enters and leaves again at once has one vacuum
  // chord only: it never was in the air.
  if (out->in_atmosphere && r >= shells.top_radius_m() && out->t_enter >= out->t_end) out->in_atmosphere = false;
}

BentShellWalk::BentShellWalk(const BentPath& path, double planet_radius_m, std::span<const double> shell_bottoms,
                             double t_begin, double t_end)
    : path_(&path), R_(planet_radius_m), bottoms_(shell_bottoms), t_begin_(t_begin), t_end_(t_end) {}

bool BentShellWalk::open_next_chord() {
  while (next_chord_ < path_->chords.size()) {
    const Chord& c = path_->chords[next_chord_++];
    const double a = std::max(0.0, t_begin_ - c.t0), b = std::min(c.length, t_end_ - c.t0);
    if (!(b > a)) {
      if (c.t0 >= t_end_) return false;
      continue;
    }
    chord_ = &c;
    walk_ = ShellTraversal(c.ray(), R_, bottoms_, a, b);
    return true;
  }
  return false;
}

bool BentShellWalk::next(ShellSegment* segment) {
  for (;;) {
    if (chord_ && walk_.next(segment)) {
      segment->t0 += chord_->t0;
      segment->t1 += chord_->t0;
      return true;
    }
    if (!open_next_chord()) return false;
  }
}

}  // namespace skyfarm
