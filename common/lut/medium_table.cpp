#include "common/lut/medium_table.h"

#include <algorithm>
#include <cmath>

#include "common/atmosphere/ozone.h"
#include "common/atmosphere/us76.h"
#include "common/lut/invalid_argument.h"

namespace skyfarm {

namespace {

// One coefficient k(lambda, h) of a constituent at the bin centres: a single
// spectrum when it does not depend on altitude, else (ozone, the only kind
// that does) the spectra of the temperature columns, mixed per altitude node
// by its bracket.
struct BinnedCoefficient {
  enum class Kind { kZero, kSpectrum, kOzone } kind = Kind::kZero;
  std::vector<double> spectrum;              // [bin]
  std::vector<std::vector<double>> columns;  // [column][bin]

  BinnedCoefficient(const SpectralCoefficient& k, const SpectralGrid& grid) {
    const std::size_t B = static_cast<std::size_t>(grid.size());
    if (k.is_zero()) return;
    if (k.altitude_independent()) {
      kind = Kind::kSpectrum;
      spectrum.resize(B);
      for (std::size_t b = 0; b < B; ++b) spectrum[b] = k.eval(grid.centre_nm(static_cast<int>(b)), 0.0);
      return;
    }
    kind = Kind::kOzone;
    columns.assign(ozone::kTableTemperatures_K.size(), std::vector<double>(B));
    for (std::size_t j = 0; j < columns.size(); ++j)
      for (std::size_t b = 0; b < B; ++b)
        columns[j][b] = ozone::column_cross_section_m2(grid.centre_nm(static_cast<int>(b)), j);
  }
  bool zero() const { return kind == Kind::kZero; }
};

// The temperature bracket of the ozone columns at an altitude node.
struct Bracket {
  std::size_t k = 0;
  double t = 0.0;
};

// k at a node (its bracket) and bin b; for ozone the same expression as
// ozone::cross_section_m2, so the tables keep its bits.
double value(const BinnedCoefficient& c, const Bracket& br, std::size_t b) {
  if (c.kind == BinnedCoefficient::Kind::kSpectrum) return c.spectrum[b];
  if (c.kind == BinnedCoefficient::Kind::kZero) return 0.0;
  return (1.0 - br.t) * c.columns[br.k][b] + br.t * c.columns[br.k + 1][b];
}

// Weight of ozone column j at a node.
double column_weight(const Bracket& br, std::size_t j) {
  if (j == br.k) return 1.0 - br.t;
  return j == br.k + 1 ? br.t : 0.0;
}


// The extinction terms (medium_table.h): per constituent its altitude-
// independent spectra (scattering plus absorption) as one term with its
// density as profile, and one term per ozone column that some node uses.
struct Terms {
  std::vector<std::vector<double>> profiles, spectra;  // [term][node], [term][bin]
};

Terms extinction_terms(const std::vector<std::vector<double>>& density, const std::vector<BinnedCoefficient>& k_s,
                       const std::vector<BinnedCoefficient>& k_a, const std::vector<Bracket>& bracket,
                       std::size_t bins) {
  Terms terms;
  const std::size_t H = bracket.size();
  for (std::size_t c = 0; c < density.size(); ++c) {
    std::vector<double> flat(bins, 0.0);
    bool any_flat = false;
    for (const BinnedCoefficient* k : {&k_s[c], &k_a[c]}) {
      if (k->kind == BinnedCoefficient::Kind::kSpectrum) {
        any_flat = true;
        for (std::size_t b = 0; b < bins; ++b) flat[b] += k->spectrum[b];
      }
      if (k->kind != BinnedCoefficient::Kind::kOzone) continue;
      for (std::size_t j = 0; j < k->columns.size(); ++j) {
        std::vector<double> profile(H);
        for (std::size_t i = 0; i < H; ++i) profile[i] = density[c][i] * column_weight(bracket[i], j);
        if (std::all_of(profile.begin(), profile.end(), [](double p) { return p == 0.0; })) continue;
        terms.profiles.push_back(std::move(profile));
        terms.spectra.push_back(k->columns[j]);
      }
    }
    if (any_flat) {
      terms.profiles.push_back(density[c]);
      terms.spectra.push_back(std::move(flat));
    }
  }
  return terms;
}

}  // namespace

MediumTable MediumTable::build(const Atmosphere& atmosphere, const SpectralGrid& grid, int altitude_samples,
                               int phase_samples) {
  if (altitude_samples < 2 || phase_samples < 2)
    throw lut::invalid_argument("medium table: need >= 2 altitude and phase samples, got ", altitude_samples, " and ",
                                phase_samples);
  MediumTable m;
  m.bins_ = grid.size();
  m.altitude_samples_ = altitude_samples;
  m.phase_samples_ = phase_samples;
  m.R_ = atmosphere.planet_radius_m();
  m.R_top_ = atmosphere.top_radius_m();
  m.dh_ = atmosphere.top_altitude_m() / (altitude_samples - 1);
  m.inv_dh_ = 1.0 / m.dh_;
  m.build_coefficients(atmosphere, grid);
  m.build_phase(atmosphere, grid);
  m.albedo_.resize(static_cast<std::size_t>(m.bins_));
  for (int b = 0; b < m.bins_; ++b)
    m.albedo_[static_cast<std::size_t>(b)] = atmosphere.ground().albedo(grid.centre_nm(b));
  return m;
}

// Densities once per node and constituent, spectra once per bin (instead of
// both per node and bin): the products are those of Constituent::sigma_s and
// sigma_a, summed in the order of Atmosphere::sigma_t, so the values are the
// same bits as evaluating the constituents at every node and bin.
void MediumTable::build_coefficients(const Atmosphere& atmosphere, const SpectralGrid& grid) {
  const std::vector<Constituent>& constituents = atmosphere.constituents();
  const std::size_t B = static_cast<std::size_t>(bins_), H = static_cast<std::size_t>(altitude_samples_);
  const std::size_t N = constituents.size();
  std::vector<std::vector<double>> density(N, std::vector<double>(H));
  std::vector<Bracket> bracket(H);
  for (std::size_t i = 0; i < H; ++i) {
    // The last node sits exactly on the top (the coefficients' own cut-off
    // is "above the top", so the top itself still has its values).
    const double h = std::min(static_cast<double>(i) * dh_, atmosphere.top_altitude_m());
    ozone::temperature_bracket(us76::temperature_K(h), &bracket[i].k, &bracket[i].t);
    for (std::size_t c = 0; c < N; ++c) density[c][i] = constituents[c].density.eval(h);
  }
  std::vector<BinnedCoefficient> k_s, k_a;
  std::vector<std::size_t> scatterer;  // constituent index of each scatterer
  for (std::size_t c = 0; c < N; ++c) {
    k_s.emplace_back(constituents[c].k_scattering, grid);
    k_a.emplace_back(constituents[c].k_absorption, grid);
    if (constituents[c].scatters()) scatterer.push_back(c);
  }
  scatterers_ = static_cast<int>(scatterer.size());
  const std::size_t C = scatterer.size();
  const std::size_t W = node_width();
  coefficients_.assign(H * W, 0.0);
  std::vector<double> s(N);
  for (std::size_t i = 0; i < H; ++i)
    for (std::size_t b = 0; b < B; ++b) {
      double s_t = 0.0, s_s = 0.0;
      for (std::size_t c = 0; c < N; ++c) {
        s[c] = k_s[c].zero() ? 0.0 : density[c][i] * value(k_s[c], bracket[i], b);
        const double a = k_a[c].zero() ? 0.0 : density[c][i] * value(k_a[c], bracket[i], b);
        s_t += s[c] + a;
        s_s += s[c];
      }
      double* node = coefficients_.data() + i * W;
      node[b] = s_t;
      node[B + b] = s_s;
      for (std::size_t c = 0; c < C; ++c) node[(2 + c) * B + b] = s[scatterer[c]];
    }

  const Terms terms = extinction_terms(density, k_s, k_a, bracket, B);
  terms_ = static_cast<int>(terms.profiles.size());
  padded_terms_ = std::max(8, (terms_ + 7) / 8 * 8);
  const std::size_t K = static_cast<std::size_t>(padded_terms_);
  term_profiles_.assign(H * K / 8, EightTerms{});
  term_spectra_.assign(K * B, 0.0);
  for (std::size_t k = 0; k < terms.profiles.size(); ++k) {
    for (std::size_t i = 0; i < H; ++i) term_profiles_[i * K / 8 + k / 8].value[k % 8] = terms.profiles[k][i];
    std::copy(terms.spectra[k].begin(), terms.spectra[k].end(), term_spectra_.begin() + static_cast<std::ptrdiff_t>(k * B));
  }
}

void MediumTable::build_phase(const Atmosphere& atmosphere, const SpectralGrid& grid) {
  const std::size_t B = static_cast<std::size_t>(bins_), C = static_cast<std::size_t>(scatterers_);
  phase_functions_.reserve(C * B);
  for (const Constituent& c : atmosphere.constituents())
    if (c.scatters())
      for (std::size_t b = 0; b < B; ++b) phase_functions_.push_back(c.phase_at(grid.centre_nm(static_cast<int>(b))));
  const std::size_t P = static_cast<std::size_t>(phase_samples_);
  phase_table_.assign(P * C * B, 0.0);
  for (std::size_t k = 0; k < P; ++k) {
    const double x = static_cast<double>(k) / static_cast<double>(P - 1);  // sin(theta/2)
    const double nu = 1.0 - 2.0 * x * x;
    for (std::size_t j = 0; j < C * B; ++j) phase_table_[k * C * B + j] = phase_functions_[j].eval(nu);
  }
}


// Linear in x = sin(theta/2) = sqrt((1 - nu)/2) between the table's nodes.
// Where nu falls on the phase table's nodes (x = sqrt((1 - nu) / 2)).
MediumTable::Node MediumTable::phase_node(double nu) const {
  const double x = std::sqrt(std::clamp(0.5 * (1.0 - nu), 0.0, 1.0));
  const double u = x * (phase_samples_ - 1);
  const std::size_t i = std::min(static_cast<std::size_t>(u), static_cast<std::size_t>(phase_samples_ - 2));
  return Node{i, u - static_cast<double>(i)};
}

void MediumTable::phase(double nu, double* out) const {
  interpolate(phase_table_.data(), static_cast<std::size_t>(scatterers_ * bins_), phase_node(nu), scatterers_ * bins_,
              out);
}

void MediumTable::phase(double nu, float* out) const {
  interpolate(phase_table_.data(), static_cast<std::size_t>(scatterers_ * bins_), phase_node(nu), scatterers_ * bins_,
              out);
}

void MediumTable::phase_exact(double nu, double* out) const {
  for (std::size_t j = 0; j < phase_functions_.size(); ++j) out[j] = phase_functions_[j].eval(nu);
}

std::size_t MediumTable::memory_bytes() const {
  return table_memory_bytes(coefficients_) + table_memory_bytes(phase_table_) + table_memory_bytes(term_profiles_) +
         sizeof(double) * (albedo_.size() + term_spectra_.size()) + sizeof(PhaseFunction) * phase_functions_.size();
}

}  // namespace skyfarm
