#include "common/material/position_free_walk.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include <glm/geometric.hpp>

#include "common/material/direction_sampling.h"
#include "common/material/fresnel.h"
#include "common/material/smith_full_sphere.h"

namespace skyfarm::material {

PositionFreeWalk::PositionFreeWalk(const MicrofacetDistribution& distribution, Facet facet,
                                   HeightCorrelation correlation, int max_bounces)
    : distribution_(distribution), facet_(facet), correlation_(correlation), max_bounces_(max_bounces) {
  if (max_bounces < 1) throw std::invalid_argument("PositionFreeWalk: max_bounces < 1");
  if (facet.kind == FacetKind::dielectric && (!(facet.eta > 0.0) || !std::isfinite(facet.eta) || facet.eta == 1.0)) {
    throw std::invalid_argument("PositionFreeWalk: dielectric eta must be finite, > 0 and != 1");
  }
  if (facet.kind == FacetKind::diffuse && !(facet.albedo >= 0.0 && facet.albedo <= 1.0)) {
    throw std::invalid_argument("PositionFreeWalk: albedo outside [0, 1]");
  }
}

// Uncorrelated: the distant masking of the leaving direction, supplement
// eq. 3 (the complement is e = 1 - G1^dist of eq. 22).  Correlated: the
// last-bounce term over the arrival term, eq. 13 / eq. 3; its complement is
// eq. 17 over eq. 3.  Below the macro surface nothing leaves.
double PositionFreeWalk::leave_probability(const glm::dvec3& v, const glm::dvec3& w) const {
  if (w.z <= 0.0) return 0.0;
  double p = 0.0;
  if (correlation_ == HeightCorrelation::uncorrelated) {
    p = g1_full_sphere(distribution_, w);
  } else {
    const double arrival = g1_full_sphere(distribution_, v);
    p = std::isfinite(arrival) ? g2_full_sphere(distribution_, v, w) / arrival : 1.0;
  }
  return std::isfinite(p) ? std::clamp(p, 0.0, 1.0) : 0.0;
}

// The vertex term of the last bounce, as a density over the leaving
// direction.  Mirror facets: the visible normal wh that maps v to target has
// density D_v(wh), and the reflection Jacobian is 1 / (4 v . wh) (Walter et
// al. 2007, eq. 14).  Dielectric facets: F times that for reflection;
// (1 - F) D_v(wh) eta^2 |w . wh| / (v . wh + eta w . wh)^2 for refraction
// (eq. 16 for wh and eq. 17 for the Jacobian, in the flux form: the walk
// carries energy from the light).  Lambertian facets: (albedo / pi)
// <target . wm>+ at the facet wm already drawn from D_v (one-sample estimate
// of the integral over the visible normals; Heitz and Dupuy 2015).
double PositionFreeWalk::scatter_density(const glm::dvec3& v, const glm::dvec3& wm, bool same_side,
                                         const glm::dvec3& target, double eta) const {
  if (facet_.kind == FacetKind::diffuse) {
    if (!same_side) return 0.0;
    return facet_.albedo / kBsdfPi * std::max(glm::dot(target, wm), 0.0);
  }
  if (same_side) {
    const glm::dvec3 sum = v + target;
    const double length = glm::length(sum);
    if (!(length > 0.0)) return 0.0;
    const glm::dvec3 wh = sum / length;
    const double cos_vh = glm::dot(v, wh);
    if (wh.z <= 0.0 || cos_vh <= 0.0) return 0.0;
    const double reflectance = facet_.kind == FacetKind::conductor ? facet_.fresnel.reflectance(cos_vh)
                                                                   : fresnel_dielectric(cos_vh, eta);
    const double d = reflectance * distribution_.visible_normal_pdf(v, wh) / (4.0 * cos_vh);
    return std::isfinite(d) ? d : 0.0;
  }
  if (facet_.kind != FacetKind::dielectric) return 0.0;
  // The target seen from v's side is -target (the other side's frame is the
  // point mirror of this one).
  const glm::dvec3 w = -target;
  const glm::dvec3 sum = v + eta * w;
  const double length = glm::length(sum);
  if (!(length > 0.0)) return 0.0;
  glm::dvec3 wh = sum / length;
  if (wh.z < 0.0) wh = -wh;
  const double cos_vh = glm::dot(v, wh);
  const double cos_wh = glm::dot(w, wh);
  if (wh.z <= 0.0 || cos_vh <= 0.0 || cos_wh >= 0.0) return 0.0;
  const double transmittance = 1.0 - fresnel_dielectric(cos_vh, eta);
  const double denom = cos_vh + eta * cos_wh;
  const double d = transmittance * distribution_.visible_normal_pdf(v, wh) * eta * eta * std::abs(cos_wh) /
                   (denom * denom);
  return std::isfinite(d) ? d : 0.0;
}

std::optional<PositionFreeWalk::Scatter> PositionFreeWalk::scatter(const glm::dvec3& v, const glm::dvec3& wm,
                                                                    double eta, RandomSequence& rng) const {
  const double cos_vm = glm::dot(v, wm);
  if (!(cos_vm > 0.0)) return std::nullopt;
  switch (facet_.kind) {
    case FacetKind::conductor:
      return Scatter{reflect_about(v, wm), false, facet_.fresnel.reflectance(cos_vm)};
    case FacetKind::diffuse: {
      const double u0 = rng.next();
      const double u1 = rng.next();
      return Scatter{sample_cosine_around(wm, {u0, u1}), false, facet_.albedo};
    }
    case FacetKind::dielectric: {
      const double reflectance = fresnel_dielectric(cos_vm, eta);
      if (rng.next() < reflectance) return Scatter{reflect_about(v, wm), false, 1.0};
      // Snell's law in vector form (pbrt-v4's Refract); the refracted ray
      // travels on the other side, whose frame is the point mirror.
      const double sin2_t = (1.0 - cos_vm * cos_vm) / (eta * eta);
      if (sin2_t >= 1.0) return Scatter{reflect_about(v, wm), false, 1.0};
      const double cos_t = std::sqrt(1.0 - sin2_t);
      const glm::dvec3 refracted = glm::normalize(-v / eta + (cos_vm / eta - cos_t) * wm);
      return Scatter{-refracted, true, 1.0};
    }
  }
  return std::nullopt;
}

// The unidirectional estimator: f(wo, wi) |wo.z| = sum over orders k of the
// expected throughput of the first k - 1 bounces times the k-th vertex's
// connection to wo (its scattering density times its leaving probability).
double PositionFreeWalk::estimate(const glm::dvec3& wi, const glm::dvec3& wo, RandomSequence& rng, int min_order,
                                  int max_order) const {
  const bool two_sided = facet_.kind == FacetKind::dielectric;
  if (wi.z == 0.0 || wo.z == 0.0) return 0.0;
  if (!two_sided && (wi.z < 0.0 || wo.z < 0.0)) return 0.0;
  bool outside = wi.z > 0.0;
  glm::dvec3 v = outside ? wi : -wi;
  const bool target_outside = wo.z > 0.0;
  const glm::dvec3 target = target_outside ? wo : -wo;
  double throughput = 1.0;
  double total = 0.0;
  for (int order = 1; order <= max_bounces_ && order <= max_order; ++order) {
    const double u0 = rng.next();
    const double u1 = rng.next();
    const glm::dvec3 wm = distribution_.sample_visible_normal(v, {u0, u1});
    const double eta = outside ? facet_.eta : 1.0 / facet_.eta;
    if (order >= min_order) {
      const double density = scatter_density(v, wm, outside == target_outside, target, eta);
      if (density > 0.0) total += throughput * density * leave_probability(v, target);
    }
    const std::optional<Scatter> s = scatter(v, wm, eta, rng);
    if (!s) break;
    throughput *= s->weight;
    if (!(throughput > 0.0)) break;
    if (s->crossed) outside = !outside;
    const double leave = leave_probability(v, s->w);
    if (leave > 0.0 && rng.next() < leave) break;
    v = -s->w;
  }
  return std::isfinite(total) ? total : 0.0;
}

std::optional<PositionFreeWalk::Exit> PositionFreeWalk::trace(const glm::dvec3& wi, RandomSequence& rng) const {
  const bool two_sided = facet_.kind == FacetKind::dielectric;
  if (wi.z == 0.0 || (!two_sided && wi.z < 0.0)) return std::nullopt;
  bool outside = wi.z > 0.0;
  glm::dvec3 v = outside ? wi : -wi;
  double throughput = 1.0;
  for (int order = 1; order <= max_bounces_; ++order) {
    const double u0 = rng.next();
    const double u1 = rng.next();
    const glm::dvec3 wm = distribution_.sample_visible_normal(v, {u0, u1});
    const double eta = outside ? facet_.eta : 1.0 / facet_.eta;
    const std::optional<Scatter> s = scatter(v, wm, eta, rng);
    if (!s) return std::nullopt;
    throughput *= s->weight;
    if (s->crossed) outside = !outside;
    const double leave = leave_probability(v, s->w);
    if (leave > 0.0 && rng.next() < leave) {
      return Exit{outside ? s->w : -s->w, throughput, order};
    }
    v = -s->w;
  }
  return std::nullopt;
}

}  // namespace skyfarm::material

namespace skyfarm::material {

namespace {

// The longest walk of the two-way estimators: a non-absorbing walk at
// alpha = 2 leaves within a few tens of bounces.
constexpr int kTwoWayCap = 64;

}  // namespace

// The bidirectional estimator for mirror / conductor facets (Lambertian and
// dielectric facets have their own, below).  A path of k bounces has
// directions v_i (towards the previous bounce; v_1 = wi) and t_i (towards
// the next; t_k = wo, v_{i+1} = -t_i), and contribution
//   prod_{i<k} phi(v_i, t_i) c(v_i, t_i)  x  phi(v_k, wo) L(v_k, wo),
// phi(v, t) = F(v.wh) D_v(wh) / (4 v.wh) the mirror vertex term (wh the half
// vector), c and L the continue and leave probabilities (leave_probability).
// Forward sampling draws t_i with density pf_i = D_{v_i}(wh) / (4 v_i.wh)
// and continues with probability c: weight F per bounce.  Reverse sampling
// (from wo) draws v_i given t_i with density pr_i = D_{t_i}(wh) / (4 t_i.wh)
// and continues with probability r, its own leave test: weight
//   phi(v_i, t_i) / pr_i x (c or L) / r = F G1(v_i) |t_i.z| / (G1(t_i) |v_i.z|) x (c or L) / r.
// Joining a forward prefix of a draws to a reverse prefix of b draws at
// vertex j = a + 1 gives a path of k = a + b + 1 bounces; its balance
// weight is P_j / sum_l P_l with P_l = prod_{i<l} pf_i c_i prod_{i>l} pr_i r_i,
// the whole densities of the draws, continuation tests included (left out,
// a reverse draw that nearly always leaves would get a large weight 1 / r).
double PositionFreeWalk::estimate_bidirectional(const glm::dvec3& wi, const glm::dvec3& wo,
                                                RandomSequence& rng) const {
  if (facet_.kind == FacetKind::diffuse) return estimate_bidirectional_diffuse(wi, wo, rng);
  if (facet_.kind == FacetKind::dielectric) return estimate_bidirectional_dielectric(wi, wo, rng);
  if (wi.z <= 0.0 || wo.z <= 0.0) return 0.0;
  const int cap = std::min(max_bounces_, 64);

  // Forward: forward_v[a] is v_{a+1}; forward_weight[a] the throughput of a draws.
  std::vector<glm::dvec3> forward_v{wi};
  std::vector<double> forward_weight{1.0};
  while (static_cast<int>(forward_v.size()) < cap) {
    const glm::dvec3 v = forward_v.back();
    const double u0 = rng.next();
    const double u1 = rng.next();
    const glm::dvec3 wm = distribution_.sample_visible_normal(v, {u0, u1});
    const double cos_vm = glm::dot(v, wm);
    if (!(cos_vm > 0.0)) break;
    const glm::dvec3 t = reflect_about(v, wm);
    const double weight = forward_weight.back() * facet_.fresnel.reflectance(cos_vm);
    if (!(weight > 0.0)) break;
    const double leave = leave_probability(v, t);
    if (leave > 0.0 && rng.next() < leave) break;
    forward_v.push_back(-t);
    forward_weight.push_back(weight);
  }

  // Reverse: reverse_t[b] is the outgoing direction of the joining vertex
  // after b draws (reverse_t[0] = wo); reverse_weight[b] the throughput.
  std::vector<glm::dvec3> reverse_t{wo};
  std::vector<double> reverse_weight{1.0};
  while (static_cast<int>(reverse_t.size()) < cap) {
    const glm::dvec3 t = reverse_t.back();
    const double u0 = rng.next();
    const double u1 = rng.next();
    const glm::dvec3 wm = distribution_.sample_visible_normal(t, {u0, u1});
    const double cos_tm = glm::dot(t, wm);
    if (!(cos_tm > 0.0)) break;
    const glm::dvec3 v = reflect_about(t, wm);
    if (v.z == 0.0) break;
    const double segment = reverse_t.size() == 1 ? leave_probability(v, t) : 1.0 - leave_probability(v, t);
    const double carry = 1.0 - leave_probability(t, v);
    const double ratio = facet_.fresnel.reflectance(cos_tm) * g1_full_sphere(distribution_, v) * std::abs(t.z) /
                         (g1_full_sphere(distribution_, t) * std::abs(v.z));
    const double weight = reverse_weight.back() * ratio * segment / carry;
    if (!(carry > 0.0) || !(weight > 0.0) || !std::isfinite(weight)) break;
    if (rng.next() >= carry) break;
    reverse_t.push_back(-v);
    reverse_weight.push_back(weight);
  }

  // The forward and reverse densities of one bounce (v, t), each times the
  // probability that its walk goes on after it.
  auto densities = [&](const glm::dvec3& v, const glm::dvec3& t, double* pf, double* pr) {
    const glm::dvec3 sum = v + t;
    const double length = glm::length(sum);
    *pf = 0.0;
    *pr = 0.0;
    if (!(length > 0.0)) return;
    const glm::dvec3 wh = sum / length;
    const double cos_v = glm::dot(v, wh);
    const double cos_t = glm::dot(t, wh);
    if (cos_v <= 0.0 || cos_t <= 0.0) return;
    *pf = distribution_.visible_normal_pdf(v, wh) / (4.0 * cos_v) * (1.0 - leave_probability(v, t));
    *pr = distribution_.visible_normal_pdf(t, wh) / (4.0 * cos_t) * (1.0 - leave_probability(t, v));
  };

  // The densities of the drawn bounces do not depend on where the walks are
  // joined: forward bounce i is (forward_v[i], -forward_v[i + 1]), reverse
  // draw m is (-reverse_t[m], reverse_t[m - 1]).
  const std::size_t na = forward_v.size();
  const std::size_t nb = reverse_t.size();
  std::vector<double> forward_pf(na, 0.0);
  std::vector<double> forward_pr(na, 0.0);
  for (std::size_t i = 0; i + 1 < na; ++i) densities(forward_v[i], -forward_v[i + 1], &forward_pf[i], &forward_pr[i]);
  std::vector<double> reverse_pf(nb, 0.0);
  std::vector<double> reverse_pr(nb, 0.0);
  for (std::size_t m = 1; m < nb; ++m) densities(-reverse_t[m], reverse_t[m - 1], &reverse_pf[m], &reverse_pr[m]);

  std::vector<double> pf;
  std::vector<double> pr;
  double total = 0.0;
  for (std::size_t a = 0; a < na; ++a) {
    for (std::size_t b = 0; b < nb; ++b) {
      const glm::dvec3& v = forward_v[a];
      const glm::dvec3& t = reverse_t[b];
      const double phi = scatter_density(v, v, true, t, 1.0);  // mirror: wm unused
      if (!(phi > 0.0)) continue;
      const double segment = b == 0 ? leave_probability(v, t) : 1.0 - leave_probability(v, t);
      const double contribution = forward_weight[a] * phi * segment * reverse_weight[b];
      if (!(contribution > 0.0)) continue;
      // The path's bounces 0..k-1: forward draws, the joining bounce a,
      // reverse draws (bounce i is reverse draw k - i).
      const std::size_t k = a + b + 1;
      pf.assign(k, 0.0);
      pr.assign(k, 0.0);
      for (std::size_t i = 0; i < a; ++i) {
        pf[i] = forward_pf[i];
        pr[i] = forward_pr[i];
      }
      densities(v, t, &pf[a], &pr[a]);
      for (std::size_t i = a + 1; i < k; ++i) {
        pf[i] = reverse_pf[k - i];
        pr[i] = reverse_pr[k - i];
      }
      // sum_l P_l / P_j, stepping away from j = a on both sides.
      double sum = 1.0;
      double ratio = 1.0;
      for (std::size_t l = a + 1; l < k; ++l) {
        ratio *= pf[l - 1] / pr[l];
        sum += ratio;
      }
      ratio = 1.0;
      for (std::size_t l = a; l-- > 0;) {
        ratio *= pr[l + 1] / pf[l];
        sum += ratio;
      }
      const double weight = 1.0 / sum;
      if (std::isfinite(weight)) total += weight * contribution;
    }
  }
  return std::isfinite(total) ? total : 0.0;
}

// The bidirectional estimator for Lambertian facets.  The vertex term
//   phi(v, t) = albedo / pi  integral D_v(wm) <t . wm>+ dwm
// has no closed form, so each bounce's facet normal wm is part of the path:
// a bounce is (v, wm, t) with the term (albedo / pi) D_v(wm) <t . wm>+, whose
// integral over wm is phi (Heitz and Dupuy 2015, stochastic evaluation).
// The densities of one bounce over that space are then all analytic:
//   forward  wm from D_v, t cosine-weighted around wm:  D_v(wm) <t . wm> / pi
//   reverse  wm from D_t, v cosine-weighted around wm:  D_t(wm) <v . wm> / pi
// each times the probability that its walk goes on (c = 1 - L(v, t) forward,
// r = 1 - L(t, v) reverse).  A forward draw weighs albedo; a reverse draw
// weighs phi / p_reverse = albedo / kappa times its segment over r, with
//   kappa = G1(t) |v.z| / (G1(v) |t.z|) = D_t(wm) <v . wm> / (D_v(wm) <t . wm>),
// since D_v(wm) |v.z| / G1(v) = <v . wm> D(wm) is symmetric (as for mirror
// facets).  The joining bounce has both walks' directions and takes its
// normal from either walk: the one the light's walk drew at v (density
// D_v(wm)) or the one the viewer's walk drew at t (D_t(wm)), each drawn
// anyway for the walk's next step.  The two are combined with shares
// c_F = 1 / (1 + kappa) and c_R = 1 - c_F (a generalised balance
// heuristic: with one normal from each, the plain one, c = 1/2, is noisier
// than D_v alone at grazing light, where D_v is nearly proportional to the
// integrand; c_F favours the normal seen from the less grazing of v and t),
// i.e. over the joint density
// pj = c_F D_v(wm) + c_R D_t(wm).  A joining normal from walk X adds
//   (albedo / pi) c_X h x segment,  h = <t . wm> <v . wm> / (c_F <v . wm> + c_R kappa <t . wm>),
// times both walks' weights and the balance weight over the joining
// bounce.  Strategy l (the joining bounce) of a path of k bounces has the
// density P_l = prod_{i<l} pf_i x pj_l x prod_{i>l} pr_i, so with
//   A_i = pf_i / pj_i = c_i h_i / pi,   B_i = pr_i / pj_i = kappa_i r_i h_i / pi,
// the ratio of neighbours is P_{l+1} / P_l = A_l / B_{l+1}; the balance
// weight 1 / sum_l (P_l / P_j) is summed from both walks' prefix sums, so
// every join costs O(1).
double PositionFreeWalk::estimate_bidirectional_diffuse(const glm::dvec3& wi, const glm::dvec3& wo,
                                                        RandomSequence& rng) const {
  if (wi.z <= 0.0 || wo.z <= 0.0) return 0.0;
  const double albedo = facet_.albedo;
  if (!(albedo > 0.0)) return 0.0;
  const int cap = std::min(max_bounces_, kTwoWayCap);
  const bool correlated = correlation_ == HeightCorrelation::correlated;

  // Every direction's Lambda is computed once (it is even in w.z, so v and
  // -v share it); G1 and the leave probability follow from Lambdas exactly
  // as g1_full_sphere, g2_full_sphere and leave_probability compute them.
  auto g1 = [](const glm::dvec3& w, double lambda) {
    if (w.z > 0.0) return 1.0 / (1.0 + lambda);
    return lambda == 0.0 ? std::numeric_limits<double>::infinity() : 1.0 / lambda;
  };
  auto leave = [&](const glm::dvec3& v, double lambda_v, const glm::dvec3& t, double lambda_t) {
    if (t.z <= 0.0) return 0.0;
    double p = 1.0 / (1.0 + lambda_t);
    if (correlated) {
      const double arrival = g1(v, lambda_v);
      const double denominator = v.z > 0.0 ? 1.0 + lambda_v + lambda_t : lambda_v + lambda_t;
      const double g2 = denominator == 0.0 ? std::numeric_limits<double>::infinity() : 1.0 / denominator;
      p = std::isfinite(arrival) ? g2 / arrival : 1.0;
    }
    return std::isfinite(p) ? std::clamp(p, 0.0, 1.0) : 0.0;
  };
  // kappa = G1(t) |v.z| / (G1(v) |t.z|) = D_t(wm) <v.wm> / (D_v(wm) <t.wm>).
  auto kappa = [&](const glm::dvec3& v, double lambda_v, const glm::dvec3& t, double lambda_t) {
    return g1(t, lambda_t) * std::abs(v.z) / (g1(v, lambda_v) * std::abs(t.z));
  };
  // The share of the light's walk's normal, c_F = 1 / (1 + kappa).
  auto forward_share = [](double k) { return std::isfinite(k) ? 1.0 / (1.0 + k) : 0.0; };
  // h = <t.wm> <v.wm> / (c_F <v.wm> + c_R kappa <t.wm>).
  auto joint = [](double cos_vm, double cos_tm, double k, double c_f) {
    return cos_vm > 0.0 && cos_tm > 0.0 ? cos_tm * cos_vm / (c_f * cos_vm + (1.0 - c_f) * k * cos_tm) : 0.0;
  };

  // Forward: forward_v[a] is v_{a+1} (forward_lambda its Lambda),
  // forward_m[a] the normal drawn there; a draws weigh albedo^a.
  std::array<glm::dvec3, kTwoWayCap> forward_v;
  std::array<glm::dvec3, kTwoWayCap> forward_m;
  std::array<double, kTwoWayCap> forward_lambda;
  forward_v[0] = wi;
  forward_lambda[0] = distribution_.lambda(wi);
  int na = 1;
  for (;;) {
    const glm::dvec3 v = forward_v[na - 1];
    const double u0 = rng.next();
    const double u1 = rng.next();
    const glm::dvec3 wm = distribution_.sample_visible_normal(v, {u0, u1});
    forward_m[na - 1] = wm;
    if (na >= cap || !(glm::dot(v, wm) > 0.0)) break;
    const double u2 = rng.next();
    const double u3 = rng.next();
    const glm::dvec3 t = sample_cosine_around(wm, {u2, u3});
    const double lambda_t = distribution_.lambda(t);
    const double p = leave(v, forward_lambda[na - 1], t, lambda_t);
    if (p > 0.0 && rng.next() < p) break;
    forward_v[na] = -t;
    forward_lambda[na] = lambda_t;
    ++na;
  }

  // Reverse: reverse_t[b] is the outgoing direction of the joining bounce
  // after b draws (reverse_t[0] = wo), reverse_n[b] the normal drawn there
  // (so draw b has the normal reverse_n[b - 1]), reverse_weight[b] the
  // throughput.
  std::array<glm::dvec3, kTwoWayCap> reverse_t;
  std::array<glm::dvec3, kTwoWayCap> reverse_n;
  std::array<double, kTwoWayCap> reverse_lambda;
  std::array<double, kTwoWayCap> reverse_weight;
  reverse_t[0] = wo;
  reverse_lambda[0] = distribution_.lambda(wo);
  reverse_weight[0] = 1.0;
  int nb = 1;
  for (;;) {
    const glm::dvec3 t = reverse_t[nb - 1];
    const double lambda_t = reverse_lambda[nb - 1];
    const double u0 = rng.next();
    const double u1 = rng.next();
    const glm::dvec3 wm = distribution_.sample_visible_normal(t, {u0, u1});
    reverse_n[nb - 1] = wm;
    if (nb >= cap || !(glm::dot(t, wm) > 0.0)) break;
    const double u2 = rng.next();
    const double u3 = rng.next();
    const glm::dvec3 v = sample_cosine_around(wm, {u2, u3});
    if (v.z == 0.0) break;
    const double lambda_v = distribution_.lambda(v);
    const double p = leave(v, lambda_v, t, lambda_t);
    const double segment = nb == 1 ? p : 1.0 - p;
    const double carry = 1.0 - leave(t, lambda_t, v, lambda_v);
    const double weight = reverse_weight[nb - 1] * albedo * kappa(t, lambda_t, v, lambda_v) * segment / carry;
    if (!(carry > 0.0) || !(weight > 0.0) || !std::isfinite(weight)) break;
    if (rng.next() >= carry) break;
    reverse_t[nb] = -v;
    reverse_lambda[nb] = lambda_v;
    reverse_weight[nb] = weight;
    ++nb;
  }

  // A bounce's factors A = c h / pi and B = kappa r h / pi (above).
  auto factors = [&](const glm::dvec3& v, double lambda_v, const glm::dvec3& wm, const glm::dvec3& t,
                     double lambda_t, double* a, double* b) {
    const double k = kappa(v, lambda_v, t, lambda_t);
    const double h = joint(glm::dot(v, wm), glm::dot(t, wm), k, forward_share(k)) / kBsdfPi;
    *a = h * (1.0 - leave(v, lambda_v, t, lambda_t));
    *b = h * k * (1.0 - leave(t, lambda_t, v, lambda_v));
  };

  // Forward bounce i is (forward_v[i], forward_m[i], -forward_v[i + 1]).  At
  // a join on forward prefix a >= 1, sum_{l<a} P_l / P_a =
  // B_join / A_{a-1} x down[a], with down[1] = 1 and
  // down[a] = 1 + B_{a-1} / A_{a-2} x down[a - 1].
  std::array<double, kTwoWayCap> forward_a;
  std::array<double, kTwoWayCap> forward_b;
  std::array<double, kTwoWayCap> down;
  for (int i = 0; i + 1 < na; ++i) {
    factors(forward_v[i], forward_lambda[i], forward_m[i], -forward_v[i + 1], forward_lambda[i + 1], &forward_a[i],
            &forward_b[i]);
  }
  if (na > 1) down[1] = 1.0;
  for (int a = 2; a < na; ++a) down[a] = 1.0 + forward_b[a - 1] / forward_a[a - 2] * down[a - 1];

  // Reverse draw m is the bounce (-reverse_t[m], reverse_n[m - 1], reverse_t[m - 1]).
  // At a join on reverse prefix b >= 1, sum_{l>j} P_l / P_j =
  // A_join / B_{draw b} x up[b], with up[1] = 1 and
  // up[b] = 1 + A_{draw b} / B_{draw b-1} x up[b - 1].
  std::array<double, kTwoWayCap> reverse_a;
  std::array<double, kTwoWayCap> reverse_b;
  std::array<double, kTwoWayCap> up;
  for (int m = 1; m < nb; ++m) {
    factors(-reverse_t[m], reverse_lambda[m], reverse_n[m - 1], reverse_t[m - 1], reverse_lambda[m - 1],
            &reverse_a[m], &reverse_b[m]);
  }
  if (nb > 1) up[1] = 1.0;
  for (int b = 2; b < nb; ++b) up[b] = 1.0 + reverse_a[b] / reverse_b[b - 1] * up[b - 1];

  double total = 0.0;
  double forward_weight = 1.0;
  for (int a = 0; a < na; ++a, forward_weight *= albedo) {
    const glm::dvec3& v = forward_v[a];
    const double lambda_v = forward_lambda[a];
    // Paths of at most `cap` bounces, each with all its strategies.
    for (int b = 0; b < nb && a + b < cap; ++b) {
      const glm::dvec3& t = reverse_t[b];
      const double lambda_t = reverse_lambda[b];
      const double p = leave(v, lambda_v, t, lambda_t);
      const double segment = b == 0 ? p : 1.0 - p;
      const double scale = forward_weight * albedo / kBsdfPi * segment * reverse_weight[b];
      if (!(scale > 0.0)) continue;
      const double k = kappa(v, lambda_v, t, lambda_t);
      const double c_f = forward_share(k);
      // The two joining normals: the light's walk's (share c_F) and the
      // viewer's (share c_R = 1 - c_F).
      for (int x = 0; x < 2; ++x) {
        const double c_x = x == 0 ? c_f : 1.0 - c_f;
        if (!(c_x > 0.0)) continue;
        const glm::dvec3& wm = x == 0 ? forward_m[a] : reverse_n[b];
        const double h = joint(glm::dot(v, wm), glm::dot(t, wm), k, c_f);
        if (!(h > 0.0)) continue;
        double sum = 1.0;
        if (b > 0) sum += h / kBsdfPi * (1.0 - p) / reverse_b[b] * up[b];
        if (a > 0) sum += h / kBsdfPi * k * (1.0 - leave(t, lambda_t, v, lambda_v)) / forward_a[a - 1] * down[a];
        const double weight = 1.0 / sum;
        if (std::isfinite(weight)) total += weight * scale * c_x * h;
      }
    }
  }
  return std::isfinite(total) ? total : 0.0;
}


// The bidirectional estimator for dielectric facets: the mirror facets'
// estimator with two sides.  Each direction is kept in the frame of the side
// it travels on (outside: as given; inside: point-mirrored, as in
// estimate()), with the relative index seen from that side.  A forward draw
// picks reflection or refraction by F, so its density is the vertex term
// itself (weight 1): F D_v(wh) / (4 v.wh), or (1 - F) D_v(wh) times the
// refraction Jacobian (scatter_density).  The reverse walk draws the same
// way from t with the index seen from t's side, and since F is the same
// from both sides of one facet and D_v(wh) |v.z| / G1(v) = <v.wh> D(wh),
//   phi(v, t) / p_reverse(v | t) = G1(v) |t.z| / (G1(t) |v.z|)          (reflection)
//                                = eta_v^2 G1(v) |t.z| / (G1(t) |v.z|)  (refraction),
// eta_v the relative index seen from v's side: the radiance compression
// across the interface.  The balance weights are over direction densities
// (forward: scatter_density(v -> t) c, reverse: scatter_density(t -> v) r).
double PositionFreeWalk::estimate_bidirectional_dielectric(const glm::dvec3& wi, const glm::dvec3& wo,
                                                           RandomSequence& rng) const {
  if (wi.z == 0.0 || wo.z == 0.0) return 0.0;
  const int cap = std::min(max_bounces_, kTwoWayCap);
  auto eta_of = [&](bool outside) { return outside ? facet_.eta : 1.0 / facet_.eta; };

  // Forward: forward_v[a] is v_{a+1} in the frame of its side forward_out[a].
  std::array<glm::dvec3, kTwoWayCap> forward_v;
  std::array<bool, kTwoWayCap> forward_out;
  forward_out[0] = wi.z > 0.0;
  forward_v[0] = forward_out[0] ? wi : -wi;
  int na = 1;
  while (na < cap) {
    const glm::dvec3 v = forward_v[na - 1];
    const bool outside = forward_out[na - 1];
    const double u0 = rng.next();
    const double u1 = rng.next();
    const glm::dvec3 wm = distribution_.sample_visible_normal(v, {u0, u1});
    const std::optional<Scatter> s = scatter(v, wm, eta_of(outside), rng);
    if (!s || !(s->weight > 0.0)) break;
    const double leave = leave_probability(v, s->w);
    if (leave > 0.0 && rng.next() < leave) break;
    forward_v[na] = -s->w;
    forward_out[na] = s->crossed ? !outside : outside;
    ++na;
  }

  // Reverse: reverse_t[b] is the outgoing direction of the joining bounce
  // after b draws (reverse_t[0] = wo), in the frame of its side reverse_out[b].
  std::array<glm::dvec3, kTwoWayCap> reverse_t;
  std::array<bool, kTwoWayCap> reverse_out;
  std::array<double, kTwoWayCap> reverse_weight;
  reverse_out[0] = wo.z > 0.0;
  reverse_t[0] = reverse_out[0] ? wo : -wo;
  reverse_weight[0] = 1.0;
  int nb = 1;
  while (nb < cap) {
    const glm::dvec3 t = reverse_t[nb - 1];
    const bool t_outside = reverse_out[nb - 1];
    const double u0 = rng.next();
    const double u1 = rng.next();
    const glm::dvec3 wm = distribution_.sample_visible_normal(t, {u0, u1});
    const std::optional<Scatter> s = scatter(t, wm, eta_of(t_outside), rng);
    if (!s || !(s->weight > 0.0)) break;
    const glm::dvec3 v = s->w;
    if (v.z == 0.0) break;
    const bool v_outside = s->crossed ? !t_outside : t_outside;
    const double segment = nb == 1 ? leave_probability(v, t) : 1.0 - leave_probability(v, t);
    const double carry = 1.0 - leave_probability(t, v);
    const double eta_v = eta_of(v_outside);
    const double ratio = (s->crossed ? eta_v * eta_v : 1.0) * g1_full_sphere(distribution_, v) * std::abs(t.z) /
                         (g1_full_sphere(distribution_, t) * std::abs(v.z));
    const double weight = reverse_weight[nb - 1] * ratio * segment / carry;
    if (!(carry > 0.0) || !(weight > 0.0) || !std::isfinite(weight)) break;
    if (rng.next() >= carry) break;
    reverse_t[nb] = -v;
    reverse_out[nb] = v_outside;
    reverse_weight[nb] = weight;
    ++nb;
  }

  // The forward and reverse densities of one bounce (v, t), each times the
  // probability that its walk goes on after it.
  auto densities = [&](const glm::dvec3& v, bool v_outside, const glm::dvec3& t, bool t_outside, double* pf,
                       double* pr) {
    const bool same_side = v_outside == t_outside;
    *pf = scatter_density(v, v, same_side, t, eta_of(v_outside)) * (1.0 - leave_probability(v, t));
    *pr = scatter_density(t, t, same_side, v, eta_of(t_outside)) * (1.0 - leave_probability(t, v));
  };

  // Forward bounce i is (forward_v[i], -forward_v[i + 1]); reverse draw m is
  // (-reverse_t[m], reverse_t[m - 1]).  The balance weight's sum
  // sum_l P_l / P_j, with P_{l+1} / P_l = pf_l / pr_{l+1}, is summed from
  // both walks' prefix sums (as for Lambertian facets): at a join on
  // forward prefix a and reverse prefix b,
  //   sum_{l<a} = pr_join / pf_{a-1} x down[a],  down[a] = 1 + pr_{a-1} / pf_{a-2} x down[a-1],
  //   sum_{l>a} = pf_join / pr_{draw b} x up[b],  up[b] = 1 + pf_{draw b} / pr_{draw b-1} x up[b-1].
  std::array<double, kTwoWayCap> forward_pf;
  std::array<double, kTwoWayCap> forward_pr;
  std::array<double, kTwoWayCap> down;
  for (int i = 0; i + 1 < na; ++i) {
    densities(forward_v[i], forward_out[i], -forward_v[i + 1], forward_out[i + 1], &forward_pf[i], &forward_pr[i]);
  }
  if (na > 1) down[1] = 1.0;
  for (int a = 2; a < na; ++a) down[a] = 1.0 + forward_pr[a - 1] / forward_pf[a - 2] * down[a - 1];
  std::array<double, kTwoWayCap> reverse_pf;
  std::array<double, kTwoWayCap> reverse_pr;
  std::array<double, kTwoWayCap> up;
  for (int m = 1; m < nb; ++m) {
    densities(-reverse_t[m], reverse_out[m], reverse_t[m - 1], reverse_out[m - 1], &reverse_pf[m], &reverse_pr[m]);
  }
  if (nb > 1) up[1] = 1.0;
  for (int b = 2; b < nb; ++b) up[b] = 1.0 + reverse_pf[b] / reverse_pr[b - 1] * up[b - 1];

  double total = 0.0;
  for (int a = 0; a < na; ++a) {
    // Paths of at most `cap` bounces, each with all its strategies.
    for (int b = 0; b < nb && a + b < cap; ++b) {
      const glm::dvec3& v = forward_v[a];
      const glm::dvec3& t = reverse_t[b];
      const bool same_side = forward_out[a] == reverse_out[b];
      const double phi = scatter_density(v, v, same_side, t, eta_of(forward_out[a]));
      if (!(phi > 0.0)) continue;
      const double leave = leave_probability(v, t);
      const double segment = b == 0 ? leave : 1.0 - leave;
      const double contribution = phi * segment * reverse_weight[b];
      if (!(contribution > 0.0)) continue;
      // The joining bounce's densities (as densities() computes them).
      double sum = 1.0;
      if (b > 0) sum += phi * (1.0 - leave) / reverse_pr[b] * up[b];
      if (a > 0) {
        const double pr_join = scatter_density(t, t, same_side, v, eta_of(reverse_out[b])) *
                               (1.0 - leave_probability(t, v));
        sum += pr_join / forward_pf[a - 1] * down[a];
      }
      const double weight = 1.0 / sum;
      if (std::isfinite(weight)) total += weight * contribution;
    }
  }
  return std::isfinite(total) ? total : 0.0;
}

}  // namespace skyfarm::material
