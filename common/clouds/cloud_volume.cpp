#include "common/clouds/cloud_volume.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include <glm/geometric.hpp>
#include <glm/mat4x4.hpp>

namespace skyfarm {

namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

// A brick's voxels along one axis: those whose trilinear support meets the
// brick's index range [8k - 1, 8k + 7), plus one spare each side.
void brick_voxel_range(int brick, int voxels, int* lo, int* hi) {
  *lo = std::max(0, CloudVolume::kBrickVoxels * brick - 2);
  *hi = std::min(voxels - 1, CloudVolume::kBrickVoxels * brick + CloudVolume::kBrickVoxels);
}

}  // namespace

CloudVolume::CloudVolume(std::shared_ptr<const assets::VolumeGrid> grid, const Placement& placement,
                         double density_scale, CloudOptics optics, double ground_radius_m)
    : grid_(std::move(grid)), density_scale_(density_scale), optics_(std::move(optics)), enu_(ground_radius_m) {
  if (!grid_ || grid_->size.x < 1 || grid_->size.y < 1 || grid_->size.z < 1 ||
      grid_->values.size() != static_cast<std::size_t>(grid_->size.x) * static_cast<std::size_t>(grid_->size.y) *
                                  static_cast<std::size_t>(grid_->size.z))
    throw std::invalid_argument("cloud volume: the grid is empty or its values do not match its size");
  if (!(std::isfinite(density_scale) && density_scale >= 0.0))
    throw std::invalid_argument("cloud volume: density_scale must be finite and >= 0, got " +
                                std::to_string(density_scale));
  // index -> grid frame (metres) -> local ENU.
  glm::dmat4 index_to_grid(1.0);
  for (int a = 0; a < 3; ++a) {
    index_to_grid[a][a] = grid_->voxel_size_m[a];
    index_to_grid[3][a] = grid_->origin_m[a];
  }
  enu_to_index_ = (transform_from_placement(placement) * Transform(index_to_grid)).inverse();

  // Brick w = (u + 1) / 8 covers u in [8k - 1, 8k + 7); the field lives in u in [-1, n].
  const glm::ivec3 n = grid_->size;
  for (int a = 0; a < 3; ++a) bricks_[a] = (n[a] + 1 + kBrickVoxels - 1) / kBrickVoxels;
  majorants_.assign(static_cast<std::size_t>(bricks_.x) * static_cast<std::size_t>(bricks_.y) *
                        static_cast<std::size_t>(bricks_.z),
                    0.0);
  std::size_t b = 0;
  for (int bz = 0; bz < bricks_.z; ++bz)
    for (int by = 0; by < bricks_.y; ++by)
      for (int bx = 0; bx < bricks_.x; ++bx, ++b) {
        int x0, x1, y0, y1, z0, z1;
        brick_voxel_range(bx, n.x, &x0, &x1);
        brick_voxel_range(by, n.y, &y0, &y1);
        brick_voxel_range(bz, n.z, &z0, &z1);
        float m = 0.0f;
        for (int z = z0; z <= z1; ++z)
          for (int y = y0; y <= y1; ++y)
            for (int x = x0; x <= x1; ++x) m = std::max(m, grid_->at(x, y, z));
        majorants_[b] = density_scale_ * static_cast<double>(m);
      }

  // The altitude range: the bounding sphere of the support box [-1, n]^3.
  const Transform index_to_enu = enu_to_index_.inverse();
  glm::dvec3 corners[8], centre(0.0);
  for (int c = 0; c < 8; ++c) {
    const glm::dvec3 u((c & 1) ? n.x : -1, (c & 2) ? n.y : -1, (c & 4) ? n.z : -1);
    corners[c] = index_to_enu.point(u);
    centre += corners[c] / 8.0;
  }
  double radius = 0.0;
  for (const glm::dvec3& c : corners) radius = std::max(radius, glm::length(c - centre));
  const double altitude = glm::length(enu_.to_world(centre)) - ground_radius_m;
  bottom_m_ = std::max(0.0, altitude - radius);
  top_m_ = std::max(bottom_m_, altitude + radius);
}

// Trilinear interpolation of the voxel values, 0 beyond the grid.
double CloudVolume::sigma_t_at_index(const glm::dvec3& u) const {
  const glm::ivec3 n = grid_->size;
  if (!(u.x > -1.0 && u.y > -1.0 && u.z > -1.0 && u.x < n.x && u.y < n.y && u.z < n.z)) return 0.0;
  const glm::dvec3 fl = glm::floor(u);
  const glm::ivec3 i0(fl);
  const glm::dvec3 f = u - fl;
  double sum = 0.0;
  for (int c = 0; c < 8; ++c) {
    const glm::ivec3 i = i0 + glm::ivec3(c & 1, (c >> 1) & 1, (c >> 2) & 1);
    if (i.x < 0 || i.y < 0 || i.z < 0 || i.x >= n.x || i.y >= n.y || i.z >= n.z) continue;
    const double w = ((c & 1) ? f.x : 1.0 - f.x) * ((c & 2) ? f.y : 1.0 - f.y) * ((c & 4) ? f.z : 1.0 - f.z);
    sum += w * static_cast<double>(grid_->at(i.x, i.y, i.z));
  }
  return density_scale_ * sum;
}

double CloudVolume::sigma_t(const glm::dvec3& p) const {
  return sigma_t_at_index(enu_to_index_.point(enu_.to_enu(p)));
}

void CloudVolume::for_each_majorant(const Ray& ray, double t_begin, double t_end, MajorantVisitor visit) const {
  if (!(t_end > t_begin)) return;
  // The ray in brick coordinates w = (u + 1) / 8, same t.
  constexpr double kBrick = kBrickVoxels;
  const glm::dvec3 o = (enu_to_index_.point(enu_.to_enu(ray.o)) + 1.0) / kBrick;
  const glm::dvec3 d = enu_to_index_.direction(ray.d) / kBrick;

  // Clip to the brick box, half a voxel wider each side: rounding may put a
  // point the box excludes just inside the field, whose edge bricks bound it.
  constexpr double kPad = 0.5 / kBrick;
  double t0 = t_begin, t1 = t_end;
  for (int a = 0; a < 3; ++a) {
    const double lo = -kPad, hi = bricks_[a] + kPad;
    if (d[a] == 0.0) {
      if (!(o[a] >= lo && o[a] <= hi)) return;
      continue;
    }
    double ta = (lo - o[a]) / d[a], tb = (hi - o[a]) / d[a];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
  }
  if (!(t0 < t1)) return;

  // Amanatides-Woo: the brick at t0, then one boundary crossing at a time.
  const glm::dvec3 p = o + t0 * d;
  glm::ivec3 cell, step;
  glm::dvec3 t_next, t_delta;
  for (int a = 0; a < 3; ++a) {
    cell[a] = std::clamp(static_cast<int>(std::floor(p[a])), 0, bricks_[a] - 1);
    if (d[a] > 0.0) {
      step[a] = 1;
      t_next[a] = (cell[a] + 1 - o[a]) / d[a];
      t_delta[a] = 1.0 / d[a];
    } else if (d[a] < 0.0) {
      step[a] = -1;
      t_next[a] = (cell[a] - o[a]) / d[a];
      t_delta[a] = -1.0 / d[a];
    } else {
      step[a] = 0;
      t_next[a] = kInfinity;
      t_delta[a] = kInfinity;
    }
  }

  // Neighbouring bricks of equal bound go out as one piece; empty ones as none.
  double pending_t0 = 0.0, pending_t1 = 0.0, pending_maj = 0.0;
  bool pending = false, stopped = false;
  auto flush = [&] {
    if (pending && !visit(pending_t0, pending_t1, pending_maj)) stopped = true;
    pending = false;
  };
  auto emit = [&](double a, double b, double maj) {
    if (!(b > a)) return;
    if (maj <= 0.0) return flush();
    if (pending && maj == pending_maj && a == pending_t1) {
      pending_t1 = b;
      return;
    }
    flush();
    pending_t0 = a, pending_t1 = b, pending_maj = maj, pending = true;
  };

  double t = t0;
  while (t < t1 && !stopped) {
    const int axis = t_next.x <= t_next.y ? (t_next.x <= t_next.z ? 0 : 2) : (t_next.y <= t_next.z ? 1 : 2);
    const double maj = brick_majorant(cell.x, cell.y, cell.z);
    const double t_exit = std::min(t_next[axis], t1);
    cell[axis] += step[axis];
    // Leaving the bricks before t1 means running in the pad: the edge brick covers it.
    const bool outside = cell[axis] < 0 || cell[axis] >= bricks_[axis];
    emit(t, outside ? t1 : t_exit, maj);
    if (outside) break;
    t = std::max(t, t_exit);
    t_next[axis] += t_delta[axis];
  }
  if (!stopped) flush();
}

}  // namespace skyfarm
