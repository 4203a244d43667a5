#include "common/render/atmosphere_medium.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <stdexcept>

#include "common/atmosphere/ozone.h"
#include "common/atmosphere/rayleigh.h"
#include "common/atmosphere/us76.h"
#include "common/sun/sun.h"

namespace skyfarm {
namespace {

// The altitude grid: top / N with N = ceil(top / 25 m), at most 40000 steps.
double altitude_step_for(double top) {
  const double n = std::min(40000.0, std::ceil(top / 25.0));
  return top / n;
}

// Sub-steps of a majorant bin in the wavelength tables.
constexpr int kWavelengthStepsPerBin = 16;

}  // namespace

double PathPhases::sample_cos_theta(int scatterer, double u) const {
  const auto s = static_cast<std::size_t>(scatterer);
  return shared_[s] ? shared_[s]->sample_cos_theta(u) : rayleigh(s, 0).sample_cos_theta(u);
}

AtmosphereMedium::AtmosphereMedium(const Atmosphere& atmosphere, double lambda_min_nm, double lambda_max_nm)
    : atmosphere_(atmosphere),
      altitude_step_(altitude_step_for(atmosphere.top_altitude_m())),
      majorants_(atmosphere, lambda_min_nm, lambda_max_nm, 1.0, altitude_step_) {
  build_shells();
  const auto& cs = atmosphere_.constituents();
  if (cs.size() > static_cast<std::size_t>(kMaxConstituents))
    throw std::invalid_argument("atmosphere: at most 16 constituents");
  const double top = atmosphere_.top_altitude_m();
  const int n_h = static_cast<int>(std::lround(top / altitude_step_)) + 1;
  const double l0 = majorants_.lambda_min_nm(), l1 = majorants_.lambda_max_nm();
  const int n_l = static_cast<int>(majorants_.bin_count()) * kWavelengthStepsPerBin + 1;
  std::vector<std::function<double(double)>> of_altitude, of_wavelength;
  bool any_ozone = false;
  for (std::size_t c = 0; c < cs.size(); ++c) {
    const Constituent& con = cs[c];
    Columns col;
    col.rho = of_altitude.size();
    of_altitude.push_back([&con](double h) { return con.density.eval(h); });
    col.k_s = of_wavelength.size();
    of_wavelength.push_back([&con](double l) { return con.k_scattering.eval(l, 0.0); });
    col.ozone = con.k_absorption.is_ozone();
    col.k_a = of_wavelength.size();
    if (col.ozone) {
      any_ozone = true;
      for (std::size_t k = 0; k < 5; ++k)
        of_wavelength.push_back([k](double l) { return ozone::column_cross_section_m2(l, k); });
    } else {
      of_wavelength.push_back([&con](double l) { return con.k_absorption.eval(l, 0.0); });
    }
    columns_.push_back(col);
    if (con.scatters()) scatterers_.push_back(static_cast<int>(c));
    if (con.absorbs()) absorbers_.push_back(static_cast<int>(c));
  }
  temperature_column_ = of_altitude.size();
  if (any_ozone) of_altitude.push_back(us76::temperature_K);
  altitude_tables_ = UniformTableSet(0.0, top, n_h, of_altitude);
  wavelength_tables_ = UniformTableSet(l0, l1, n_l, of_wavelength);
  build_control_shells();
}

// The control extinction of residual ratio tracking on the fine shells:
//   sigma_c(shell, bin) = sum_c min_shell rho_c * (min_bin k_s,c + min_bin,columns k_a,c),
// a lower bound of the tabulated sigma_t in the shell and bin (every factor
// is >= 0 and linear between knots, so its minimum is at a knot or an end),
// shaved by 1e-9 relative against round-off; the residual majorant is then
// sigma_maj - sigma_c >= sigma_t - sigma_c >= 0.
void AtmosphereMedium::build_control_shells() {
  const std::size_t bins = fine_.bins, shells = fine_.shell_count();
  control_.bins = residual_.bins = bins;
  control_.bottoms = residual_.bottoms = fine_.bottoms;
  control_.table.assign(shells * bins, 0.0);
  std::vector<double> k_min(bins);
  for (const Columns& col : columns_) {
    // The smallest coefficient in each bin does not depend on the shell: once per bin.
    for (std::size_t j = 0; j < bins; ++j) {
      const double l0 = majorants_.lambda_min_nm() + majorants_.bin_width_nm() * static_cast<double>(j);
      const double l1 = l0 + majorants_.bin_width_nm();
      k_min[j] = wavelength_tables_.min_on(col.k_s, l0, l1);
      if (col.ozone) {
        double k_a_min = wavelength_tables_.min_on(col.k_a, l0, l1);
        for (std::size_t k = 0; k < 5; ++k) k_a_min = std::min(k_a_min, wavelength_tables_.min_on(col.k_a + k, l0, l1));
        k_min[j] += k_a_min;
      } else {
        k_min[j] += wavelength_tables_.min_on(col.k_a, l0, l1);
      }
    }
    for (std::size_t i = 0; i < shells; ++i) {
      const double rho_min = altitude_tables_.min_on(col.rho, fine_.bottoms[i], fine_.bottoms[i + 1]);
      if (!(rho_min > 0.0)) continue;
      for (std::size_t j = 0; j < bins; ++j) control_.at(i, j) += rho_min * k_min[j];
    }
  }
  residual_.table.resize(control_.table.size());
  for (std::size_t n = 0; n < control_.table.size(); ++n) {
    control_.table[n] = std::max(0.0, control_.table[n] * (1.0 - 1e-9));
    residual_.table[n] = std::max(0.0, fine_.table[n] - control_.table[n]);
  }
}

const std::string& AtmosphereMedium::scatterer_name(int s) const {
  return atmosphere_.constituents()[static_cast<std::size_t>(scatterers_[static_cast<std::size_t>(s)])].name;
}

std::array<std::size_t, kWavelengthsPerPath> AtmosphereMedium::bins(const SampledWavelengths& lambda) const {
  std::array<std::size_t, kWavelengthsPerPath> b{};
  for (int i = 0; i < kWavelengthsPerPath; ++i) b[i] = majorants_.bin_of(lambda.lambda_nm[i]);
  return b;
}

// Fine shells: the MajorantGrid's.  Coarse shells: the fine boundaries
// nearest 0, 1, 2, 5, 10, 20, 40, 70 km and the top, each bound the max of
// the fine bounds inside it.
void AtmosphereMedium::build_shells() {
  const std::size_t bins = majorants_.bin_count();
  fine_.bins = coarse_.bins = bins;
  for (std::size_t i = 0; i <= majorants_.shell_count(); ++i) fine_.bottoms.push_back(majorants_.shell_bottom(i));
  fine_.table.assign(fine_.shell_count() * bins, 0.0);
  for (std::size_t i = 0; i < majorants_.shell_count(); ++i)
    for (std::size_t j = 0; j < bins; ++j) fine_.at(i, j) = majorants_.sigma_maj(i, j) * (1.0 + 1e-9);

  std::vector<std::size_t> cuts{0};
  for (double target : {1000.0, 2000.0, 5000.0, 10000.0, 20000.0, 40000.0, 70000.0}) {
    std::size_t best = cuts.back();
    for (std::size_t i = cuts.back() + 1; i < fine_.shell_count(); ++i)
      if (std::abs(fine_.bottoms[i] - target) < std::abs(fine_.bottoms[best] - target) || best == cuts.back())
        best = i;
    if (best > cuts.back() && best < fine_.shell_count()) cuts.push_back(best);
  }
  cuts.push_back(fine_.shell_count());
  for (std::size_t c = 0; c + 1 < cuts.size(); ++c) coarse_.bottoms.push_back(fine_.bottoms[cuts[c]]);
  coarse_.bottoms.push_back(fine_.bottoms.back());
  coarse_.table.assign(coarse_.shell_count() * bins, 0.0);
  for (std::size_t c = 0; c + 1 < cuts.size(); ++c) {
    for (std::size_t j = 0; j < bins; ++j) {
      double m = 0.0;
      for (std::size_t i = cuts[c]; i < cuts[c + 1]; ++i) m = std::max(m, fine_.at(i, j));
      coarse_.at(c, j) = m;
    }
  }
}

PathCoefficients AtmosphereMedium::path_coefficients(const SampledWavelengths& lambda, const Sun* sun) const {
  PathCoefficients pc;
  pc.bins = bins(lambda);
  for (int i = 0; i < kWavelengthsPerPath; ++i) {
    const double l = lambda.lambda_nm[static_cast<std::size_t>(i)];
    pc.sun_radiance[i] = sun ? sun->radiance(l) : 0.0;
    pc.ground_albedo[i] = atmosphere_.ground().albedo(l);
  }
  const std::size_t columns = wavelength_tables_.columns();
  for (int i = 0; i < kWavelengthsPerPath; ++i) {
    const auto w = static_cast<std::size_t>(i);
    const UniformTableSet::Position at = wavelength_tables_.locate(lambda.lambda_nm[w]);
    for (std::size_t col = 0; col < columns; ++col) pc.k[col][w] = wavelength_tables_.eval(at, col);
  }
  return pc;
}

void AtmosphereMedium::point(double h, const PathCoefficients& pc, MediumPoint* out) const {
  out->sigma_a = SampledSpectrum(0.0);
  out->sigma_s = SampledSpectrum(0.0);
  if (h > atmosphere_.top_altitude_m()) {
    for (std::size_t s = 0; s < scatterers_.size(); ++s) out->sigma_s_c[s] = SampledSpectrum(0.0).v;
    return;
  }
  h = std::max(h, 0.0);
  const UniformTableSet::Position at = altitude_tables_.locate(h);
  for (std::size_t s = 0; s < scatterers_.size(); ++s) {
    const Columns& col = columns_[static_cast<std::size_t>(scatterers_[s])];
    const SampledSpectrum sigma_s_c = pc.k_of(col.k_s) * altitude_tables_.eval(at, col.rho);
    out->sigma_s_c[s] = sigma_s_c.v;
    out->sigma_s += sigma_s_c;
  }
  for (int a : absorbers_) {
    const Columns& col = columns_[static_cast<std::size_t>(a)];
    const double rho = altitude_tables_.eval(at, col.rho);
    if (col.ozone) {
      std::size_t k = 0;
      double t = 0.0;
      ozone::temperature_bracket(altitude_tables_.eval(at, temperature_column_), &k, &t);
      out->sigma_a += (pc.k_of(col.k_a + k) * (1.0 - t) + pc.k_of(col.k_a + k + 1) * t) * rho;
    } else {
      out->sigma_a += pc.k_of(col.k_a) * rho;
    }
  }
}

PathPhases AtmosphereMedium::phases(const SampledWavelengths& lambda) const {
  PathPhases p;
  p.count_ = static_cast<int>(scatterers_.size());
  const auto& cs = atmosphere_.constituents();
  for (std::size_t s = 0; s < scatterers_.size(); ++s) {
    const Constituent& c = cs[static_cast<std::size_t>(scatterers_[s])];
    if (c.rayleigh_depolarization_from_bucholtz) {
      p.shared_[s] = nullptr;
      for (std::size_t i = 0; i < kWavelengthsPerPath; ++i) {
        const double rho_n = rayleigh::depolarization(lambda.lambda_nm[i]);
        p.depolarization_[s][i] = rho_n;
        p.gamma_[s][i] = rho_n / (2.0 - rho_n);
      }
    } else {
      p.shared_[s] = &c.phase;
    }
  }
  return p;
}

}  // namespace skyfarm
