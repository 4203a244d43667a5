// One cloud as the path tracer and the LUT renderer see it: a grey
// extinction field in planet-centred coordinates, with piecewise-constant
// bounds (majorants) along any ray, and its particles' optics.
//
// A cloud layer (cloud_layer.h) and a placed cloud volume (cloud_volume.h)
// are CloudFields; SceneClouds (scene_clouds.h) tracks paths through all of
// a scene's fields at once.
//
// Contract of for_each_majorant(ray, t_begin, t_end, visit): calls
// visit(t0, t1, sigma_maj) for pieces [t0, t1] with t_begin <= t0 < t1 <=
// t_end, in increasing t, not overlapping, covering every part of
// [t_begin, t_end] where sigma_t may be > 0 (gaps are cloud-free), with
// sigma_t(ray.at(t)) <= sigma_maj for every t in the piece.  It stops as
// soon as visit returns false.  The bounds are what makes tracking unbiased:
// tests check them against dense point samples.
#pragma once
#include <type_traits>
#include <utility>

#include <glm/vec3.hpp>

#include "common/clouds/cloud_optics.h"
#include "common/geometry/ray.h"

namespace skyfarm {

// A non-owning reference to a callable (no allocation, one indirect call).
template <class Signature>
class FunctionRef;
template <class R, class... Args>
class FunctionRef<R(Args...)> {
 public:
  template <class F, class = std::enable_if_t<!std::is_same_v<std::decay_t<F>, FunctionRef>>>
  FunctionRef(F&& f)  // NOLINT: implicit, as std::function
      : object_(const_cast<void*>(static_cast<const void*>(&f))),
        call_([](void* o, Args... a) -> R { return (*static_cast<std::remove_reference_t<F>*>(o))(std::forward<Args>(a)...); }) {}
  R operator()(Args... a) const { return call_(object_, std::forward<Args>(a)...); }

 private:
  void* object_;
  R (*call_)(void*, Args...);
};

using MajorantVisitor = FunctionRef<bool(double t0, double t1, double sigma_maj)>;

class CloudField {
 public:
  virtual ~CloudField() = default;
  // Extinction coefficient at a planet-centred point, m^-1 (>= 0, finite).
  virtual double sigma_t(const glm::dvec3& p) const = 0;
  virtual void for_each_majorant(const Ray& ray, double t_begin, double t_end, MajorantVisitor visit) const = 0;
  virtual const CloudOptics& optics() const = 0;
  // The altitude range (above the planet's radius) outside which sigma_t is 0.
  virtual double bottom_altitude_m() const = 0;
  virtual double top_altitude_m() const = 0;
};

}  // namespace skyfarm
