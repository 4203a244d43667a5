// A radiance probe (radiance_probe.h) cut into units of work for the farm,
// and the one canonical way their sums are combined, so
// that the answer's bits depend on the request alone: `skyfarm-worker probe`
// (every unit on local threads) and the farm (units on any number of
// workers, results arriving in any order) trace the same units and reduce
// them in the same order.
//
// Pairs: (direction d, wavelength w) is pair p = d * W + w (W wavelengths).
//   Sample s of pair p draws its random numbers from Sampler(seed, p, s), a
//   pure function of (seed, direction, wavelength, sample index, dimension)
//   whatever the cut.
// The cut (ProbePlan::make, a pure function of pairs, samples, max_units):
//   target = max(min_unit_paths, ceil(pairs x samples / max_units)) paths
//            (min_unit_paths: kProbeMinUnitPaths = 65536, ~0.15 s on one core)
//   samples >= target: one pair per unit, its samples in chunks of `target`
//                      (the last one shorter);
//   otherwise:         one chunk of all the samples, floor(target / samples)
//                      pairs per unit.
//   Unit i is group g = i % groups (pairs [g ppu, min(pairs, (g+1) ppu)))
//   and chunk c = i / groups, so the first chunk of every pair goes first.
//   At most 2 max_units + 1 units whatever the request.
// A cell (chunk c, pair p) is the sum of L and L^2 over the chunk's samples
// in increasing sample order; a pair's total is 0.0 + cell 0 + cell 1 + ...
// in chunk order (ProbeReduction); mean = total / n, standard error =
// sample standard deviation / sqrt(n).
//
// Wire format of a unit's sums (ProbeUnitSums::serialize; little-endian):
//   offset 0  4 bytes "SKPU" (magic)     4  u32 version (1)
//          8  u64 unit index            16  u64 first pair     24  u64 pairs n
//         32  u64 first sample          40  u64 samples        48  u64 paths
//         56  u64 non-finite paths      64  n x (f64 sum L, f64 sum L^2)
// deserialize rejects anything else (size, magic, version, a sum that is
// negative or not finite) with ProbeUnitDecodeError.
#pragma once
#include <cstddef>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <vector>

#include <glm/vec3.hpp>

#include "common/render/radiance_probe.h"
#include "common/render/scene.h"

namespace skyfarm {

inline constexpr std::uint64_t kProbeMinUnitPaths = 65536;  // ~0.15 s on one core
inline constexpr std::size_t kProbeDefaultMaxUnits = 4096;

struct ProbeUnit {
  std::size_t index = 0;
  std::size_t group = 0, chunk = 0;
  std::size_t pair_begin = 0, pair_end = 0;          // [begin, end)
  std::uint64_t sample_begin = 0, sample_end = 0;    // [begin, end)
  bool operator==(const ProbeUnit&) const = default;
};

struct ProbePlan {
  std::size_t pairs = 0;
  std::uint64_t samples = 0;         // per pair
  std::uint64_t chunk_samples = 0;   // samples per chunk (the last chunk may hold fewer)
  std::size_t chunks = 0;            // per pair
  std::size_t pairs_per_unit = 0;
  std::size_t groups = 0;            // ceil(pairs / pairs_per_unit)

  // Throws std::invalid_argument for pairs, samples, max_units or
  // min_unit_paths of 0.  (Tests cut small probes finer with min_unit_paths.)
  static ProbePlan make(std::size_t pairs, std::uint64_t samples, std::size_t max_units = kProbeDefaultMaxUnits,
                        std::uint64_t min_unit_paths = kProbeMinUnitPaths);
  std::size_t unit_count() const { return groups * chunks; }
  // Throws std::out_of_range past unit_count().
  ProbeUnit unit(std::size_t index) const;
  bool operator==(const ProbePlan&) const = default;
};

class ProbeUnitDecodeError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// What a unit sends back: per pair of the unit, sum L and sum L^2 over its samples.
struct ProbeUnitSums {
  ProbeUnit unit;
  std::vector<double> sum, sum_sq;  // one per pair in [unit.pair_begin, unit.pair_end)
  PathCounters counters;

  std::vector<std::uint8_t> serialize() const;
  // Needs the plan to rebuild the unit; throws ProbeUnitDecodeError when the
  // bytes are malformed or do not describe plan.unit(index).
  static ProbeUnitSums deserialize(const std::vector<std::uint8_t>& bytes, const ProbePlan& plan);
};

// Traces one unit on the calling thread.  directions: unit vectors in the
// observer frame; wavelengths: as in the request (pair p = d * W + w);
// control: the roulette's control variate (IntegratorOptions), or none.
ProbeUnitSums trace_probe_unit(const Scene& scene, const std::vector<glm::dvec3>& directions,
                               const std::vector<double>& wavelengths_nm, std::uint64_t seed, const ProbeUnit& unit,
                               std::shared_ptr<const RadianceControl> control = nullptr);

// Collects the units' sums and combines them in canonical order.  Not thread-safe.
class ProbeReduction {
 public:
  explicit ProbeReduction(const ProbePlan& plan);

  // Keeps the sums of a unit not seen before (true); a repeat is ignored
  // (false).  Throws std::invalid_argument when `sums` is not a unit of the plan.
  bool add(const ProbeUnitSums& sums);
  bool has(std::size_t unit) const { return have_.at(unit); }
  std::size_t received() const { return received_; }
  bool complete() const { return received_ == plan_.unit_count(); }
  const ProbePlan& plan() const { return plan_; }

  // Radiance and standard error as [direction][wavelength]; needs complete()
  // (else std::logic_error).
  ProbeResult result(std::size_t wavelengths) const;

 private:
  ProbePlan plan_;
  std::vector<double> sum_, sum_sq_;  // [chunk * pairs + pair]
  std::vector<bool> have_;
  std::size_t received_ = 0;
  PathCounters counters_;
};

}  // namespace skyfarm
