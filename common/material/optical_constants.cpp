#include "common/material/optical_constants.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <map>
#include <stdexcept>
#include <utility>

namespace skyfarm::material {
namespace {

std::string number(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.10g", x);
  return buf;
}

std::string at_index(std::string_view field, std::size_t i, double x) {
  return std::string(field) + "[" + std::to_string(i) + "] = " + number(x);
}

void check_wavelengths(const std::vector<double>& wl, const std::string& what) {
  if (wl.empty()) throw std::invalid_argument(what + ": wavelengths_nm is empty; a table needs at least one point");
  for (std::size_t i = 0; i < wl.size(); ++i) {
    if (!std::isfinite(wl[i]))
      throw std::invalid_argument(what + ": " + at_index("wavelengths_nm", i, wl[i]) + " is not finite");
    if (!(wl[i] > 0.0))
      throw std::invalid_argument(what + ": " + at_index("wavelengths_nm", i, wl[i]) + " must be > 0");
    if (i > 0 && !(wl[i] > wl[i - 1]))
      throw std::invalid_argument(what + ": wavelengths_nm must increase strictly, but " +
                                  at_index("wavelengths_nm", i, wl[i]) + " follows " +
                                  at_index("wavelengths_nm", i - 1, wl[i - 1]));
  }
}

// `values` has one finite entry per wavelength, each satisfying `ok` (whose
// rule `rule` reads like "must be > 0").
template <class Ok>
void check_values(const std::vector<double>& wl, const std::vector<double>& values, std::string_view field,
                  Ok ok, std::string_view rule, const std::string& what) {
  if (values.size() != wl.size())
    throw std::invalid_argument(what + ": " + std::string(field) + " has " + std::to_string(values.size()) +
                                " values for " + std::to_string(wl.size()) +
                                " wavelengths; the lengths must be the same");
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (!std::isfinite(values[i]))
      throw std::invalid_argument(what + ": " + at_index(field, i, values[i]) + " is not finite");
    if (!ok(values[i]))
      throw std::invalid_argument(what + ": " + at_index(field, i, values[i]) + " " + std::string(rule));
  }
}

// A one-point table is a constant: it holds at every wavelength.
bool table_covers(const PiecewiseLinear& t, double lo_nm, double hi_nm) {
  return t.x().size() == 1 || (t.x_min() <= lo_nm && hi_nm <= t.x_max());
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  return s;
}

}  // namespace

double normal_incidence_reflectance(ComplexIor ior) {
  const double k2 = ior.k * ior.k;
  return ((ior.n - 1.0) * (ior.n - 1.0) + k2) / ((ior.n + 1.0) * (ior.n + 1.0) + k2);
}

// --- Sellmeier ---------------------------------------------------------------

SellmeierDispersion::SellmeierDispersion(std::vector<SellmeierTerm> terms, double min_wavelength_nm,
                                         double max_wavelength_nm, const std::string& what)
    : terms_(std::move(terms)), min_nm_(min_wavelength_nm), max_nm_(max_wavelength_nm) {
  if (terms_.empty()) throw std::invalid_argument(what + ": a Sellmeier formula needs at least one term");
  for (std::size_t i = 0; i < terms_.size(); ++i) {
    if (!std::isfinite(terms_[i].b) || !std::isfinite(terms_[i].c_um2))
      throw std::invalid_argument(what + ": Sellmeier term " + std::to_string(i + 1) + " is not finite");
  }
  if (!std::isfinite(min_nm_) || !std::isfinite(max_nm_) || !(min_nm_ > 0.0) || !(max_nm_ > min_nm_))
    throw std::invalid_argument(what + ": the Sellmeier range [" + number(min_nm_) + ", " + number(max_nm_) +
                                "] nm must satisfy 0 < min < max");
  // A pole (λ² = Cᵢ) inside the range makes n infinite there.
  for (std::size_t i = 0; i < terms_.size(); ++i) {
    if (terms_[i].c_um2 <= 0.0) continue;
    const double pole_nm = 1000.0 * std::sqrt(terms_[i].c_um2);
    if (pole_nm >= min_nm_ && pole_nm <= max_nm_)
      throw std::invalid_argument(what + ": Sellmeier term " + std::to_string(i + 1) + " has a pole at " +
                                  number(pole_nm) + " nm, inside its range");
  }
  // Between the poles n² is continuous; sample it for n² <= 0 (no real index).
  constexpr int kSamples = 256;
  for (int s = 0; s <= kSamples; ++s) {
    const double lambda = min_nm_ + (max_nm_ - min_nm_) * s / kSamples;
    const double n = n_unclamped(lambda);
    if (!(n > 0.0))
      throw std::invalid_argument(what + ": the Sellmeier formula gives n² <= 0 at " + number(lambda) + " nm");
  }
}

double SellmeierDispersion::n_unclamped(double lambda_nm) const {
  const double l2 = (lambda_nm * 1e-3) * (lambda_nm * 1e-3);
  double n2 = 1.0;
  for (const SellmeierTerm& t : terms_) n2 += t.b * l2 / (l2 - t.c_um2);
  return n2 > 0.0 ? std::sqrt(n2) : std::nan("");
}

double SellmeierDispersion::n(double lambda_nm) const {
  return n_unclamped(std::clamp(lambda_nm, min_nm_, max_nm_));
}

SellmeierDispersion SellmeierDispersion::parse_coefficients(std::string_view text, const std::string& source) {
  std::map<std::string, double, std::less<>> values;
  std::size_t line_no = 0;
  bool header_seen = false;
  while (!text.empty()) {
    const std::size_t eol = text.find('\n');
    std::string_view line = trim(text.substr(0, eol));
    text = eol == std::string_view::npos ? std::string_view{} : text.substr(eol + 1);
    ++line_no;
    if (line.empty()) continue;
    const std::size_t comma = line.find(',');
    if (comma == std::string_view::npos)
      throw std::runtime_error(source + ":" + std::to_string(line_no) + ": expected `name,value`");
    const std::string_view key = trim(line.substr(0, comma)), cell = trim(line.substr(comma + 1));
    if (!header_seen) {
      if (key != "coefficient" || cell != "value")
        throw std::runtime_error(source + ":1: expected the header `coefficient,value`");
      header_seen = true;
      continue;
    }
    double value = 0.0;
    const auto [end, ec] = std::from_chars(cell.data(), cell.data() + cell.size(), value);
    if (ec != std::errc{} || end != cell.data() + cell.size())
      throw std::runtime_error(source + ":" + std::to_string(line_no) + ": `" + std::string(cell) +
                               "` is not a number");
    values[std::string(key)] = value;
  }
  const auto get = [&](const std::string& key) {
    const auto it = values.find(key);
    if (it == values.end()) throw std::runtime_error(source + ": missing coefficient `" + key + "`");
    return it->second;
  };
  // Coefficient names: `prefix` + the term's number + `suffix` ("C2_um2").
  const auto name = [](std::string_view prefix, int i, std::string_view suffix) {
    std::string out(prefix);
    out += std::to_string(i);
    out += suffix;
    return out;
  };
  std::vector<SellmeierTerm> terms;
  for (int i = 1; values.contains(name("B", i, "")); ++i) {
    SellmeierTerm t;
    t.b = get(name("B", i, ""));
    if (values.contains(name("C", i, "_um2"))) {
      t.c_um2 = get(name("C", i, "_um2"));
    } else {
      const double lambda_um = get(name("lambda", i, "_um"));  // Malitson's resonance wavelengths
      t.c_um2 = lambda_um * lambda_um;
    }
    terms.push_back(t);
  }
  const double min_nm = 1000.0 * get("wavelength_min_um");
  const double max_nm = 1000.0 * get("wavelength_max_um");
  return SellmeierDispersion(std::move(terms), min_nm, max_nm, source);
}

// --- Complex index -----------------------------------------------------------

SpectralIor SpectralIor::tabulated(const std::vector<double>& wavelengths_nm, const std::vector<double>& n,
                                   const std::vector<double>& k, const std::string& what) {
  check_wavelengths(wavelengths_nm, what);
  check_values(wavelengths_nm, n, "n", [](double v) { return v > 0.0; }, "must be > 0", what);
  check_values(wavelengths_nm, k, "k", [](double v) { return v >= 0.0; }, "must be >= 0", what);
  SpectralIor ior;
  ior.n_table_ = PiecewiseLinear(wavelengths_nm, n, PiecewiseLinear::Outside::kClamp, what + " n");
  ior.k_ = PiecewiseLinear(wavelengths_nm, k, PiecewiseLinear::Outside::kClamp, what + " k");
  return ior;
}

SpectralIor SpectralIor::sellmeier(SellmeierDispersion n, const std::vector<double>& k_wavelengths_nm,
                                   const std::vector<double>& k, const std::string& what) {
  check_wavelengths(k_wavelengths_nm, what);
  check_values(k_wavelengths_nm, k, "k", [](double v) { return v >= 0.0; }, "must be >= 0", what);
  SpectralIor ior;
  ior.sellmeier_ = std::move(n);
  ior.k_ = PiecewiseLinear(k_wavelengths_nm, k, PiecewiseLinear::Outside::kClamp, what + " k");
  return ior;
}

SpectralIor SpectralIor::sellmeier(SellmeierDispersion n) {
  SpectralIor ior;
  ior.sellmeier_ = std::move(n);
  ior.k_ = PiecewiseLinear::constant(0.0);
  return ior;
}

double SpectralIor::n(double lambda_nm) const {
  return sellmeier_ ? sellmeier_->n(lambda_nm) : n_table_(lambda_nm);
}

bool SpectralIor::covers(double lo_nm, double hi_nm) const {
  const bool n_ok = sellmeier_ ? sellmeier_->min_wavelength_nm() <= lo_nm && hi_nm <= sellmeier_->max_wavelength_nm()
                               : table_covers(n_table_, lo_nm, hi_nm);
  return n_ok && table_covers(k_, lo_nm, hi_nm);
}

// --- Albedo ------------------------------------------------------------------

SpectralAlbedo::SpectralAlbedo(const std::vector<double>& wavelengths_nm, const std::vector<double>& albedo,
                               const std::string& what) {
  check_wavelengths(wavelengths_nm, what);
  check_values(wavelengths_nm, albedo, "albedo", [](double v) { return v >= 0.0 && v <= 1.0; },
               "must lie in [0, 1]", what);
  table_ = PiecewiseLinear(wavelengths_nm, albedo, PiecewiseLinear::Outside::kClamp, what + " albedo");
}

bool SpectralAlbedo::covers(double lo_nm, double hi_nm) const {
  return table_covers(table_, lo_nm, hi_nm);
}

}  // namespace skyfarm::material
