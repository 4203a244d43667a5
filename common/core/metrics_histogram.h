// MetricsHistogram: a thread-safe histogram of observations over fixed upper
// bounds, as a Prometheus histogram exposes it (cumulative `_bucket{le}`
// counts, `_sum`, `_count`; text format 0.0.4).
//
// Parameters
//   upper_bounds  the buckets' inclusive upper bounds, finite and strictly
//                 increasing (at least one); the +Inf bucket is implicit.
//                 An observation v lands in the first bucket with v <= bound
//                 (Prometheus' `le`), NaN in +Inf only.
//
// A mutex rather than atomics: a snapshot is then consistent (the +Inf
// bucket equals the count, the buckets never decrease in `le`), which a
// scrape that races an observation would otherwise break; observations are
// a few per work unit or HTTP request, so the lock is never contended long.
#pragma once
#include <cstdint>
#include <mutex>
#include <span>
#include <vector>

namespace skyfarm {

class MetricsHistogram {
 public:
  struct Snapshot {
    std::vector<double> upper_bounds;        // finite bounds, increasing
    std::vector<std::uint64_t> cumulative;   // observations <= bound; one more entry: +Inf (== count)
    double sum = 0.0;
    std::uint64_t count = 0;
  };

  // Throws std::invalid_argument for bounds that are empty, not finite or not
  // strictly increasing.
  explicit MetricsHistogram(std::span<const double> upper_bounds);
  MetricsHistogram(const MetricsHistogram& other);
  MetricsHistogram& operator=(const MetricsHistogram&) = delete;

  void observe(double value);
  Snapshot snapshot() const;

 private:
  const std::vector<double> bounds_;
  mutable std::mutex mu_;
  std::vector<std::uint64_t> counts_;  // per bucket, not cumulative; last: above every bound
  double sum_ = 0.0;
  std::uint64_t count_ = 0;
};

// Bucket bounds in seconds for the server's durations.
// A work unit: a few ms (LUT tiles) to minutes (the unit timeout is 120 s).
inline constexpr double kUnitDurationBucketsS[] = {0.005, 0.01, 0.025, 0.05, 0.1, 0.25, 0.5, 1,
                                                   2.5,   5,    10,    30,   60,  120,  300};
// A job, submit to finish: a tiny LUT render (ms) to hours.
inline constexpr double kJobDurationBucketsS[] = {0.1, 0.25, 0.5, 1,   2.5,  5,    10,   30,
                                                  60,  120,  300, 600, 1800, 3600, 7200, 21600};
// An HTTP request: Prometheus' client default buckets (5 ms to 10 s), then
// 30 s and 60 s for image downloads and event streams.
inline constexpr double kHttpDurationBucketsS[] = {0.005, 0.01, 0.025, 0.05, 0.1, 0.25, 0.5,
                                                   1,     2.5,  5,     10,   30,  60};

}  // namespace skyfarm
