#include "common/geometry/triangle.h"

#include <algorithm>
#include <cmath>
#include <glm/common.hpp>
#include <utility>

#include "common/geometry/rounding_error.h"

namespace skyfarm {
namespace {

struct V2 {
  double x, y;
};

bool before(const V2& a, const V2& b) { return a.x < b.x || (a.x == b.x && a.y < b.y); }

// The edge function of a -> b, e = a_x b_y - a_y b_x (twice the signed area
// of the ray's point and the edge), computed for the vertices in a canonical
// order and negated for the other: e(a, b) == -e(b, a) in every bit, whatever
// the compiler contracts or reorders.  0 is recomputed in long double.
double edge_function(V2 a, V2 b) {
  const bool swap = before(b, a);
  if (swap) std::swap(a, b);
  double e = a.x * b.y - a.y * b.x;
  if (e == 0.0) {
    const long double el = static_cast<long double>(a.x) * b.y - static_cast<long double>(a.y) * b.x;
    e = static_cast<double>(el);
    if (e == 0.0 && el != 0.0L) e = el > 0.0L ? 1e-300 : -1e-300;
  }
  return swap ? -e : e;
}

}  // namespace

std::optional<TriangleHit> intersect_triangle(const Ray& ray, const glm::dvec3& p0, const glm::dvec3& p1,
                                              const glm::dvec3& p2, double t_max) {
  // Permute so the ray's largest direction component is z.
  const glm::dvec3 ad = glm::abs(ray.d);
  const int kz = ad.x > ad.y ? (ad.x > ad.z ? 0 : 2) : (ad.y > ad.z ? 1 : 2);
  if (ray.d[kz] == 0.0) return std::nullopt;
  const int kx = (kz + 1) % 3, ky = (kx + 1) % 3;
  const glm::dvec3 d{ray.d[kx], ray.d[ky], ray.d[kz]};
  const double sx = -d.x / d.z, sy = -d.y / d.z, sz = 1.0 / d.z;
  // Each vertex is translated and sheared by itself, so a vertex shared by
  // two triangles lands on the same bits in both.
  auto carry = [&](const glm::dvec3& p, double* z) {
    const glm::dvec3 q = p - ray.o;
    *z = q[kz];
    return V2{q[kx] + sx * q[kz], q[ky] + sy * q[kz]};
  };
  double z0, z1, z2;
  const V2 a0 = carry(p0, &z0), a1 = carry(p1, &z1), a2 = carry(p2, &z2);
  // e0 is opposite vertex 0 (edge 1 -> 2), and so on.
  const double e0 = edge_function(a1, a2);
  const double e1 = edge_function(a2, a0);
  const double e2 = edge_function(a0, a1);
  if ((e0 < 0.0 || e1 < 0.0 || e2 < 0.0) && (e0 > 0.0 || e1 > 0.0 || e2 > 0.0)) return std::nullopt;
  const double det = e0 + e1 + e2;
  if (det == 0.0) return std::nullopt;
  z0 *= sz;
  z1 *= sz;
  z2 *= sz;
  const double t_scaled = e0 * z0 + e1 * z1 + e2 * z2;
  if (det < 0.0 && (t_scaled >= 0.0 || t_scaled < t_max * det)) return std::nullopt;
  if (det > 0.0 && (t_scaled <= 0.0 || t_scaled > t_max * det)) return std::nullopt;
  const double inv_det = 1.0 / det;
  const double t = t_scaled * inv_det;
  if (!(t < t_max)) return std::nullopt;

  // t > 0 conservatively: its rounding bound from those of the sheared
  // coordinates and of the edge functions.
  const double max_z = std::max({std::abs(z0), std::abs(z1), std::abs(z2)});
  const double delta_z = rounding_gamma(3) * max_z;
  const double max_x = std::max({std::abs(a0.x), std::abs(a1.x), std::abs(a2.x)});
  const double max_y = std::max({std::abs(a0.y), std::abs(a1.y), std::abs(a2.y)});
  const double delta_x = rounding_gamma(5) * (max_x + max_z);
  const double delta_y = rounding_gamma(5) * (max_y + max_z);
  const double delta_e = 2.0 * (rounding_gamma(2) * max_x * max_y + delta_y * max_x + delta_x * max_y);
  const double max_e = std::max({std::abs(e0), std::abs(e1), std::abs(e2)});
  const double delta_t =
      3.0 * (rounding_gamma(3) * max_e * max_z + delta_e * max_z + delta_z * max_e) * std::abs(inv_det);
  if (t <= delta_t) return std::nullopt;

  TriangleHit hit;
  hit.t = t;
  hit.b0 = e0 * inv_det;
  hit.b1 = e1 * inv_det;
  hit.b2 = e2 * inv_det;
  return hit;
}

}  // namespace skyfarm
