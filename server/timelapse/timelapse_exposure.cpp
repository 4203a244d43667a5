#include "server/timelapse/timelapse_exposure.h"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace skyfarm::server {

std::vector<double> smoothed_exposure(const std::vector<double>& auto_ev100, int window) {
  if (window < 1 || window % 2 == 0)
    throw std::invalid_argument("smoothed_exposure: window " + std::to_string(window) + " must be odd and >= 1");
  const long long n = static_cast<long long>(auto_ev100.size()), k = (window - 1) / 2;
  std::vector<double> out(auto_ev100.size());
  for (long long i = 0; i < n; ++i) {
    const long long r = std::min({k, i, n - 1 - i});
    const long long lo = i - r, hi = i + r;
    double sum = 0.0;
    for (long long j = lo; j <= hi; ++j) sum += auto_ev100[static_cast<std::size_t>(j)];
    out[static_cast<std::size_t>(i)] = sum / static_cast<double>(hi - lo + 1);
  }
  return out;
}

}  // namespace skyfarm::server
