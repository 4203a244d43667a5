#include "common/render/probe_units.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <string>

#include "common/geometry/ray.h"
#include "common/sampling/sampler.h"

namespace skyfarm {
namespace {

constexpr char kMagic[4] = {'S', 'K', 'P', 'U'};
constexpr std::uint32_t kVersion = 1;
constexpr std::size_t kHeaderBytes = 64;

std::uint64_t ceil_div(std::uint64_t a, std::uint64_t b) { return a / b + (a % b != 0); }

void put_u64(std::uint8_t* p, std::uint64_t v) {
  for (int i = 0; i < 8; ++i) p[i] = static_cast<std::uint8_t>(v >> (8 * i));
}
std::uint64_t get_u64(const std::uint8_t* p) {
  std::uint64_t v = 0;
  for (int i = 0; i < 8; ++i) v |= static_cast<std::uint64_t>(p[i]) << (8 * i);
  return v;
}
std::uint32_t get_u32(const std::uint8_t* p) {
  std::uint32_t v = 0;
  for (int i = 0; i < 4; ++i) v |= static_cast<std::uint32_t>(p[i]) << (8 * i);
  return v;
}

[[noreturn]] void decode_error(const std::string& what) {
  throw ProbeUnitDecodeError("probe unit sums: " + what);
}

}  // namespace

// --- ProbePlan ------------------------------------------------------------------

ProbePlan ProbePlan::make(std::size_t pairs, std::uint64_t samples, std::size_t max_units,
                          std::uint64_t min_unit_paths) {
  if (pairs == 0 || samples == 0 || max_units == 0 || min_unit_paths == 0)
    throw std::invalid_argument("ProbePlan: pairs, samples, max_units and min_unit_paths must be positive");
  // pairs x samples in long double: 1e8 pairs x 1e9 samples does not fit 64 bits.
  const long double total = static_cast<long double>(pairs) * static_cast<long double>(samples);
  const auto spread = static_cast<std::uint64_t>(std::ceil(total / static_cast<long double>(max_units)));
  const std::uint64_t target = std::max(min_unit_paths, spread);
  ProbePlan plan;
  plan.pairs = pairs;
  plan.samples = samples;
  if (samples >= target) {
    plan.chunk_samples = target;
    plan.chunks = static_cast<std::size_t>(ceil_div(samples, target));
    plan.pairs_per_unit = 1;
  } else {
    plan.chunk_samples = samples;
    plan.chunks = 1;
    plan.pairs_per_unit = static_cast<std::size_t>(std::min<std::uint64_t>(target / samples, pairs));
  }
  plan.groups = static_cast<std::size_t>(ceil_div(pairs, plan.pairs_per_unit));
  return plan;
}

ProbeUnit ProbePlan::unit(std::size_t index) const {
  if (index >= unit_count())
    throw std::out_of_range("probe unit " + std::to_string(index) + " of " + std::to_string(unit_count()));
  ProbeUnit u;
  u.index = index;
  u.group = index % groups;
  u.chunk = index / groups;
  u.pair_begin = u.group * pairs_per_unit;
  u.pair_end = std::min(pairs, u.pair_begin + pairs_per_unit);
  u.sample_begin = static_cast<std::uint64_t>(u.chunk) * chunk_samples;
  u.sample_end = std::min(samples, u.sample_begin + chunk_samples);
  return u;
}

// --- ProbeUnitSums ----------------------------------------------------------------

std::vector<std::uint8_t> ProbeUnitSums::serialize() const {
  const std::size_t n = sum.size();
  std::vector<std::uint8_t> out(kHeaderBytes + 16 * n);
  std::uint8_t* p = out.data();
  std::memcpy(p, kMagic, 4);
  for (int i = 0; i < 4; ++i) p[4 + i] = static_cast<std::uint8_t>(kVersion >> (8 * i));
  put_u64(p + 8, unit.index);
  put_u64(p + 16, unit.pair_begin);
  put_u64(p + 24, n);
  put_u64(p + 32, unit.sample_begin);
  put_u64(p + 40, unit.sample_end - unit.sample_begin);
  put_u64(p + 48, counters.paths);
  put_u64(p + 56, counters.nonfinite);
  for (std::size_t i = 0; i < n; ++i) {
    put_u64(p + kHeaderBytes + 16 * i, std::bit_cast<std::uint64_t>(sum[i]));
    put_u64(p + kHeaderBytes + 16 * i + 8, std::bit_cast<std::uint64_t>(sum_sq[i]));
  }
  return out;
}

ProbeUnitSums ProbeUnitSums::deserialize(const std::vector<std::uint8_t>& bytes, const ProbePlan& plan) {
  if (bytes.size() < kHeaderBytes) decode_error("truncated (" + std::to_string(bytes.size()) + " bytes)");
  const std::uint8_t* p = bytes.data();
  if (std::memcmp(p, kMagic, 4) != 0) decode_error("bad magic");
  const std::uint32_t version = get_u32(p + 4);
  if (version != kVersion) decode_error("version " + std::to_string(version) + " (expected 1)");
  const std::uint64_t index = get_u64(p + 8);
  if (index >= plan.unit_count()) decode_error("unit " + std::to_string(index) + " is not in the plan");
  ProbeUnitSums s;
  s.unit = plan.unit(static_cast<std::size_t>(index));
  const std::uint64_t n = get_u64(p + 24);
  if (get_u64(p + 16) != s.unit.pair_begin || n != s.unit.pair_end - s.unit.pair_begin ||
      get_u64(p + 32) != s.unit.sample_begin || get_u64(p + 40) != s.unit.sample_end - s.unit.sample_begin)
    decode_error("the pairs or samples do not match unit " + std::to_string(index));
  if (bytes.size() != kHeaderBytes + 16 * n) decode_error("size does not match its pair count");
  s.counters.paths = get_u64(p + 48);
  s.counters.nonfinite = get_u64(p + 56);
  s.sum.resize(static_cast<std::size_t>(n));
  s.sum_sq.resize(static_cast<std::size_t>(n));
  for (std::size_t i = 0; i < n; ++i) {
    s.sum[i] = std::bit_cast<double>(get_u64(p + kHeaderBytes + 16 * i));
    s.sum_sq[i] = std::bit_cast<double>(get_u64(p + kHeaderBytes + 16 * i + 8));
    if (!std::isfinite(s.sum[i]) || !std::isfinite(s.sum_sq[i]) || s.sum[i] < 0.0 || s.sum_sq[i] < 0.0)
      decode_error("a sum is negative or not finite");
  }
  return s;
}

// --- Tracing ------------------------------------------------------------------------

ProbeUnitSums trace_probe_unit(const Scene& scene, const std::vector<glm::dvec3>& directions,
                               const std::vector<double>& wavelengths_nm, std::uint64_t seed, const ProbeUnit& unit,
                               std::shared_ptr<const RadianceControl> control) {
  IntegratorOptions options;
  options.roulette_control = std::move(control);
  const VolumePathIntegrator integrator(scene, options);
  const std::size_t W = wavelengths_nm.size();
  if (W == 0 || unit.pair_end > directions.size() * W)
    throw std::invalid_argument("probe unit: pairs outside the request's directions x wavelengths");
  ProbeUnitSums out;
  out.unit = unit;
  for (std::size_t pair = unit.pair_begin; pair < unit.pair_end; ++pair) {
    const Ray ray{scene.observer(), directions[pair / W]};
    // Monochromatic: every wavelength slot is the asked wavelength (pdf 1).
    SampledWavelengths wl;
    wl.lambda_nm.fill(wavelengths_nm[pair % W]);
    wl.pdf.fill(1.0);
    double sum = 0.0, sum_sq = 0.0;
    for (std::uint64_t s = unit.sample_begin; s < unit.sample_end; ++s) {
      Sampler sampler(seed, pair, s);
      const double L = integrator.radiance(ray, wl, sampler, &out.counters)[0];
      sum += L;
      sum_sq += L * L;
    }
    out.sum.push_back(sum);
    out.sum_sq.push_back(sum_sq);
  }
  return out;
}

// --- ProbeReduction -------------------------------------------------------------------

ProbeReduction::ProbeReduction(const ProbePlan& plan)
    : plan_(plan),
      sum_(plan.chunks * plan.pairs, 0.0),
      sum_sq_(plan.chunks * plan.pairs, 0.0),
      have_(plan.unit_count(), false) {}

bool ProbeReduction::add(const ProbeUnitSums& s) {
  if (s.unit.index >= plan_.unit_count() || !(s.unit == plan_.unit(s.unit.index)) ||
      s.sum.size() != s.unit.pair_end - s.unit.pair_begin || s.sum_sq.size() != s.sum.size())
    throw std::invalid_argument("ProbeReduction: the sums are not a unit of this probe");
  if (have_[s.unit.index]) return false;
  have_[s.unit.index] = true;
  ++received_;
  const std::size_t row = s.unit.chunk * plan_.pairs;
  for (std::size_t i = 0; i < s.sum.size(); ++i) {
    sum_[row + s.unit.pair_begin + i] = s.sum[i];
    sum_sq_[row + s.unit.pair_begin + i] = s.sum_sq[i];
  }
  counters_.add(s.counters);
  return true;
}

ProbeResult ProbeReduction::result(std::size_t wavelengths) const {
  if (!complete()) throw std::logic_error("ProbeReduction::result before every unit arrived");
  if (wavelengths == 0 || plan_.pairs % wavelengths != 0)
    throw std::invalid_argument("ProbeReduction::result: pairs are not directions x wavelengths");
  ProbeResult r;
  r.radiance.assign(plan_.pairs / wavelengths, std::vector<double>(wavelengths, 0.0));
  r.standard_error = r.radiance;
  r.counters = counters_;
  const double n = static_cast<double>(plan_.samples);
  for (std::size_t pair = 0; pair < plan_.pairs; ++pair) {
    double sum = 0.0, sum_sq = 0.0;
    for (std::size_t c = 0; c < plan_.chunks; ++c) {  // canonical order: chunk 0, 1, ...
      sum += sum_[c * plan_.pairs + pair];
      sum_sq += sum_sq_[c * plan_.pairs + pair];
    }
    const double mean = sum / n;
    const double var = n > 1 ? std::max(0.0, (sum_sq - n * mean * mean) / (n - 1.0)) : 0.0;
    r.radiance[pair / wavelengths][pair % wavelengths] = mean;
    r.standard_error[pair / wavelengths][pair % wavelengths] = std::sqrt(var / n);
  }
  return r;
}

}  // namespace skyfarm
