#include "worker/bruneton_evaluation.h"

#include <cmath>
#include <cstdio>
#include <numbers>
#include <stdexcept>

namespace skyfarm {
namespace {

// Shirley and Chiu's concentric map of the square [0, 1]^2 to the unit disk
// ("A Low Distortion Map Between Disk and Square", J. Graphics Tools 1997),
// in the polar form Bruneton uses (hemispherical_function.h, ToUnitDisk):
// radius r and angle phi, radians, from the square's first axis towards its
// second.
void concentric_map(double x, double y, double* r, double* phi) {
  const double quarter = std::numbers::pi / 4.0;
  const double a = 2.0 * x - 1.0, b = 2.0 * y - 1.0;
  if (a > -b) {
    if (a > b) {
      *r = a;
      *phi = quarter * (b / a);
    } else {
      *r = b;
      *phi = quarter * (2.0 - a / b);
    }
  } else if (a < b) {
    *r = -a;
    *phi = quarter * (4.0 + b / a);
  } else {
    *r = -b;
    *phi = b != 0.0 ? quarter * (6.0 - a / b) : 0.0;
  }
}

}  // namespace

Location bruneton_location() { return Location{42.44337, -76.48163, 0.0}; }

std::vector<BrunetonCase> bruneton_cases() {
  // 2013-05-27T00:00:00Z; every case is that day, 13:30-17:30 UTC.
  const std::int64_t midnight_utc = days_from_civil(2013, 5, 27) * 86400;
  std::vector<BrunetonCase> cases;
  for (int i = 0; i < kBrunetonCaseCount; ++i) {
    const int minutes = 9 * 60 + 30 + 15 * i;  // EDT
    char text[8];
    std::snprintf(text, sizeof text, "%02d:%02d", minutes / 60, minutes % 60);
    cases.push_back(BrunetonCase{i, text, UtcInstant{midnight_utc + (minutes + 4 * 60) * 60, 0.0}});
  }
  return cases;
}

std::vector<BrunetonDirection> bruneton_directions() {
  std::vector<BrunetonDirection> out;
  for (int i = 0; i < 9; ++i)
    for (int j = 0; j < 9; ++j) {
      double r = 0.0, phi = 0.0;
      concentric_map((i + 0.5) / 9.0, (j + 0.5) / 9.0, &r, &phi);
      // Uniform in the disk -> uniform in solid angle: cos(zenith) = 1 - r^2.
      const double zenith = std::acos(1.0 - r * r) * 180.0 / std::numbers::pi;
      double azimuth = std::fmod(phi * 180.0 / std::numbers::pi, 360.0);
      if (azimuth < 0.0) azimuth += 360.0;
      out.push_back(BrunetonDirection{zenith, azimuth});
    }
  return out;
}

std::vector<double> bruneton_wavelengths_nm() {
  std::vector<double> out;
  for (int k = 0; k < kBrunetonWavelengthCount; ++k) out.push_back(360.0 + 11.75 * k);
  return out;
}

double bruneton_case_rmse(const std::vector<std::vector<double>>& model,
                          const std::vector<std::vector<double>>& reference) {
  if (model.empty() || model.size() != reference.size())
    throw std::invalid_argument("bruneton_case_rmse: model and reference need the same, non-zero, direction count");
  double sum = 0.0;
  std::size_t count = 0;
  for (std::size_t d = 0; d < model.size(); ++d) {
    if (model[d].empty() || model[d].size() != reference[d].size())
      throw std::invalid_argument("bruneton_case_rmse: model and reference need the same wavelengths");
    for (std::size_t w = 0; w < model[d].size(); ++w) {
      const double e = model[d][w] - reference[d][w];
      sum += e * e;
      ++count;
    }
  }
  return std::sqrt(sum / static_cast<double>(count));
}

double bruneton_total_rmse(const std::vector<double>& case_rmse) {
  if (case_rmse.empty()) throw std::invalid_argument("bruneton_total_rmse: no cases");
  double sum = 0.0;
  for (const double e : case_rmse) sum += e * e;
  return std::sqrt(sum / static_cast<double>(case_rmse.size()));
}

}  // namespace skyfarm
