#include "common/accel/triangle_bvh.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include <embree3/rtcore.h>
#include <glm/mat4x4.hpp>
#include <glm/matrix.hpp>

#include "common/accel/ray_triangle.h"

namespace skyfarm::accel {
namespace {

// The smallest float not below x: Embree's float bounds must never cut a
// candidate the double test would keep.
float float_up(double x) {
  if (x >= static_cast<double>(std::numeric_limits<float>::max())) return std::numeric_limits<float>::infinity();
  float f = static_cast<float>(x);
  if (static_cast<double>(f) < x) f = std::nextafter(f, std::numeric_limits<float>::infinity());
  return f;
}

// The largest float not above x.
float float_down(double x) {
  if (x <= -static_cast<double>(std::numeric_limits<float>::max())) return -std::numeric_limits<float>::infinity();
  float f = static_cast<float>(x);
  if (static_cast<double>(f) > x) f = std::nextafter(f, -std::numeric_limits<float>::infinity());
  return f;
}

// The half-width of the closest hit's window, as a fraction of (t + extent):
// Embree's float t was measured within 8.3e-7 of that from the double t (a
// 20 km scene, all four x86 ISAs), so 1e-5 leaves a twelvefold margin while
// the window stays narrow (0.2 m for a scene reaching 20 km).
constexpr double kRelativeSlack = 1e-5;

bool key_less(const BvhHit& a, const BvhHit& b) {
  if (a.t != b.t) return a.t < b.t;
  if (a.instance != b.instance) return a.instance < b.instance;
  return a.primitive < b.primitive;
}

// The scene behind a TriangleBvh.
struct Scene {
  std::vector<MeshArrays> meshes;
  std::vector<Instance> instances;
  std::vector<glm::dmat4> world_to_object;
  double extent = 0.0;  // the largest |coordinate| of the scene's world bounds
  RTCDevice device = nullptr;
  std::vector<RTCScene> mesh_scenes;  // one per mesh; null for a mesh without triangles
  RTCScene top = nullptr;

  Scene() = default;
  Scene(const Scene&) = delete;
  Scene& operator=(const Scene&) = delete;
  ~Scene() {
    if (top) rtcReleaseScene(top);
    for (RTCScene s : mesh_scenes)
      if (s) rtcReleaseScene(s);
    if (device) rtcReleaseDevice(device);
  }

  double slack(double t) const { return kRelativeSlack * (std::abs(t) + extent); }

  // The double-precision test of one candidate, in the instance's frame.
  std::optional<BvhHit> refine(std::uint32_t instance, std::uint32_t primitive, const glm::dvec3& origin,
                               const glm::dvec3& dir, double tmax) const {
    const Instance& inst = instances[instance];
    const MeshArrays& mesh = meshes[inst.mesh];
    const glm::dmat4& m = world_to_object[instance];
    const glm::dvec3 o = glm::dvec3(m * glm::dvec4(origin, 1.0));
    const glm::dvec3 d = glm::dvec3(m * glm::dvec4(dir, 0.0));
    const std::uint32_t* idx = &mesh.indices[3 * static_cast<std::size_t>(primitive)];
    const auto h = intersect_triangle(o, d, mesh.positions[idx[0]], mesh.positions[idx[1]], mesh.positions[idx[2]]);
    if (!h || !(h->t > 0.0) || h->t > tmax) return std::nullopt;
    BvhHit hit;
    hit.t = h->t;
    hit.instance = instance;
    hit.mesh = inst.mesh;
    hit.primitive = primitive;
    hit.u = h->u;
    hit.v = h->v;
    hit.point = origin + h->t * dir;
    return hit;
  }
};

// Embree's context, extended with the query (Embree passes the pointer it was
// given back to the filters).
struct Query {
  RTCIntersectContext context;
  const Scene* impl;
  glm::dvec3 origin;
  glm::dvec3 dir;
  double tmax;
  bool collect = false;  // closest hit's second pass: reject all, keep the best
  std::optional<BvhHit> best;
};

// Closest hit, in two passes over the same filter.  The first (collect
// false) lets Embree commit every candidate the double test confirms, so its
// float tfar shrinks as usual and the traversal ends at the float-closest
// confirmed hit (a filter that rejects everything and lowers tfar itself does
// not prune: Embree 3 does not re-read tfar after a rejected hit).  The true
// closest in doubles lies within the float error of that hit, so the second
// pass (collect true) walks only the window t_found +- slack, rejects every
// candidate for Embree and keeps the smallest (t, instance, primitive) here.
void closest_filter(const RTCFilterFunctionNArguments* args) {
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] == 0) continue;
    auto* q = reinterpret_cast<Query*>(args->context);
    const std::uint32_t instance = args->context->instID[0];
    const std::uint32_t primitive = RTCHitN_primID(args->hit, args->N, i);
    const auto hit = q->impl->refine(instance, primitive, q->origin, q->dir, q->tmax);
    if (!hit || q->collect) args->valid[i] = 0;
    if (hit && (!q->best || key_less(*hit, *q->best))) q->best = hit;
  }
}

// Any hit: the first candidate the double test confirms ends the query.
void occluded_filter(const RTCFilterFunctionNArguments* args) {
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] == 0) continue;
    auto* q = reinterpret_cast<Query*>(args->context);
    const std::uint32_t instance = args->context->instID[0];
    const std::uint32_t primitive = RTCHitN_primID(args->hit, args->N, i);
    if (!q->impl->refine(instance, primitive, q->origin, q->dir, q->tmax)) args->valid[i] = 0;
  }
}

void check(RTCDevice device, const char* what) {
  const RTCError e = rtcGetDeviceError(device);
  if (e != RTC_ERROR_NONE) throw std::runtime_error(std::string("TriangleBvh: Embree failed to ") + what + " (error " + std::to_string(static_cast<int>(e)) + ")");
}

}  // namespace

struct TriangleBvh::Impl : Scene {};

TriangleBvh::TriangleBvh(std::vector<MeshArrays> meshes, std::vector<Instance> instances, BvhBuildOptions options)
    : impl_(std::make_unique<Impl>()) {
  Impl& s = *impl_;
  s.meshes = std::move(meshes);
  s.instances = std::move(instances);
  for (std::size_t m = 0; m < s.meshes.size(); ++m) {
    const MeshArrays& mesh = s.meshes[m];
    if (mesh.indices.size() % 3 != 0) throw std::invalid_argument("TriangleBvh: mesh " + std::to_string(m) + ": indices not a multiple of 3");
    for (std::uint32_t i : mesh.indices)
      if (i >= mesh.positions.size()) throw std::invalid_argument("TriangleBvh: mesh " + std::to_string(m) + ": index out of range");
  }
  bool any = false;
  for (std::size_t i = 0; i < s.instances.size(); ++i) {
    const Instance& inst = s.instances[i];
    if (inst.mesh >= s.meshes.size()) throw std::invalid_argument("TriangleBvh: instance " + std::to_string(i) + ": no mesh " + std::to_string(inst.mesh));
    s.world_to_object.push_back(glm::inverse(inst.object_to_world));
    const MeshArrays& mesh = s.meshes[inst.mesh];
    if (mesh.indices.empty()) continue;
    any = true;
    for (const glm::dvec3& p : mesh.positions) {
      const glm::dvec3 w = glm::dvec3(inst.object_to_world * glm::dvec4(p, 1.0));
      s.extent = std::max({s.extent, std::abs(w.x), std::abs(w.y), std::abs(w.z)});
    }
  }
  if (!any) return;  // an empty scene: no device

  const std::string config = options.build_threads > 0 ? "threads=" + std::to_string(options.build_threads) : "";
  s.device = rtcNewDevice(config.c_str());
  if (!s.device) throw std::runtime_error("TriangleBvh: cannot create an Embree device");

  s.mesh_scenes.assign(s.meshes.size(), nullptr);
  std::vector<bool> used(s.meshes.size(), false);
  for (const Instance& inst : s.instances) used[inst.mesh] = true;
  for (std::size_t m = 0; m < s.meshes.size(); ++m) {
    const MeshArrays& mesh = s.meshes[m];
    if (!used[m] || mesh.indices.empty()) continue;
    RTCScene scene = rtcNewScene(s.device);
    s.mesh_scenes[m] = scene;
    rtcSetSceneFlags(scene, RTC_SCENE_FLAG_ROBUST);
    RTCGeometry g = rtcNewGeometry(s.device, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                          3 * sizeof(float), mesh.positions.size()));
    for (std::size_t i = 0; i < mesh.positions.size(); ++i)
      for (int c = 0; c < 3; ++c) v[3 * i + c] = static_cast<float>(mesh.positions[i][c]);
    auto* ix = static_cast<std::uint32_t*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                                   3 * sizeof(std::uint32_t), mesh.indices.size() / 3));
    std::copy(mesh.indices.begin(), mesh.indices.end(), ix);
    rtcSetGeometryIntersectFilterFunction(g, closest_filter);
    rtcSetGeometryOccludedFilterFunction(g, occluded_filter);
    rtcCommitGeometry(g);
    rtcAttachGeometryByID(scene, g, 0);
    rtcReleaseGeometry(g);
    rtcCommitScene(scene);
    check(s.device, "build a mesh's BVH");
  }

  s.top = rtcNewScene(s.device);
  rtcSetSceneFlags(s.top, RTC_SCENE_FLAG_ROBUST);
  for (std::size_t i = 0; i < s.instances.size(); ++i) {
    const Instance& inst = s.instances[i];
    if (!s.mesh_scenes[inst.mesh]) continue;
    RTCGeometry g = rtcNewGeometry(s.device, RTC_GEOMETRY_TYPE_INSTANCE);
    rtcSetGeometryInstancedScene(g, s.mesh_scenes[inst.mesh]);
    float xf[16];
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r) xf[4 * c + r] = static_cast<float>(inst.object_to_world[c][r]);
    rtcSetGeometryTransform(g, 0, RTC_FORMAT_FLOAT4X4_COLUMN_MAJOR, xf);
    rtcCommitGeometry(g);
    rtcAttachGeometryByID(s.top, g, static_cast<unsigned>(i));
    rtcReleaseGeometry(g);
  }
  rtcCommitScene(s.top);
  check(s.device, "build the instances' BVH");
}

TriangleBvh::~TriangleBvh() = default;
TriangleBvh::TriangleBvh(TriangleBvh&&) noexcept = default;
TriangleBvh& TriangleBvh::operator=(TriangleBvh&&) noexcept = default;

bool TriangleBvh::empty() const { return impl_->top == nullptr; }

namespace {

void set_ray(RTCRay& ray, const glm::dvec3& origin, const glm::dvec3& dir, float tfar) {
  ray.org_x = static_cast<float>(origin.x);
  ray.org_y = static_cast<float>(origin.y);
  ray.org_z = static_cast<float>(origin.z);
  ray.dir_x = static_cast<float>(dir.x);
  ray.dir_y = static_cast<float>(dir.y);
  ray.dir_z = static_cast<float>(dir.z);
  ray.tnear = 0.0f;
  ray.tfar = tfar;
  ray.time = 0.0f;
  ray.mask = 0xffffffffu;
  ray.id = 0;
  ray.flags = 0;
}

}  // namespace

std::optional<BvhHit> TriangleBvh::closest_hit(const glm::dvec3& origin, const glm::dvec3& dir, double tmax) const {
  const Impl& s = *impl_;
  if (!s.top || !(tmax > 0.0)) return std::nullopt;
  Query q;
  rtcInitIntersectContext(&q.context);
  q.impl = &s;
  q.origin = origin;
  q.dir = dir;
  q.tmax = tmax;
  RTCRayHit rh;
  set_ray(rh.ray, origin, dir, float_up(tmax + s.slack(tmax)));
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(s.top, &q.context, &rh);
  if (!q.best) return std::nullopt;
  // The window pass.  Its bounds come from the found hit's double t; every
  // triangle whose double t is within the float error of it has its float t
  // inside the window.
  const double t = q.best->t, slack = s.slack(t);
  set_ray(rh.ray, origin, dir, float_up(std::min(t + slack, tmax + slack)));
  rh.ray.tnear = std::max(0.0f, float_down(t - slack));
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  rtcInitIntersectContext(&q.context);
  q.collect = true;
  rtcIntersect1(s.top, &q.context, &rh);
  return q.best;
}

bool TriangleBvh::occluded(const glm::dvec3& origin, const glm::dvec3& dir, double tmax) const {
  const Impl& s = *impl_;
  if (!s.top || !(tmax > 0.0)) return false;
  Query q;
  rtcInitIntersectContext(&q.context);
  q.impl = &s;
  q.origin = origin;
  q.dir = dir;
  q.tmax = tmax;
  RTCRay ray;
  set_ray(ray, origin, dir, float_up(tmax + s.slack(tmax)));
  rtcOccluded1(s.top, &q.context, &ray);
  return ray.tfar == -std::numeric_limits<float>::infinity();
}

}  // namespace skyfarm::accel
