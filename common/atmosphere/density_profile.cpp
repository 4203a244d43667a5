#include "common/atmosphere/density_profile.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "common/atmosphere/us76.h"
#include "common/core/overloaded.h"
#include "common/core/integrate.h"

namespace skyfarm {
namespace {

// --- Bruneton layers (Bruneton 2017, functions.glsl GetLayerDensity /
// GetProfileDensity): layer i spans [bottom_i, bottom_i + width_i); the last
// layer extends to infinity.  The value is clamped to [0, 1].
double layer_raw(const DensityLayer& l, double h) {
  return l.exp_term * std::exp(l.exp_scale_per_m * h) + l.linear_term_per_m * h + l.constant_term;
}

std::size_t layer_index(const std::vector<DensityLayer>& layers, double h, double* bottom) {
  double b = 0.0;
  for (std::size_t i = 0; i + 1 < layers.size(); ++i) {
    if (h < b + layers[i].width_m) {
      *bottom = b;
      return i;
    }
    b += layers[i].width_m;
  }
  *bottom = b;
  return layers.size() - 1;
}

// Bruneton evaluates each layer at the altitude itself (not relative to the
// layer bottom); we do the same so custom atmospheres match his model exactly.
double layers_eval(const std::vector<DensityLayer>& layers, double h) {
  double bottom = 0.0;
  const auto& l = layers[layer_index(layers, h, &bottom)];
  return std::clamp(layer_raw(l, h), 0.0, 1.0);
}

// Max of clamp(a e^{s h} + l h + c, 0, 1) over [h0, h1]: the unclamped
// function's extremes are at the ends or where its derivative
// a s e^{s h} + l vanishes, h* = ln(-l / (a s)) / s; clamping is monotone.
double layer_max(const DensityLayer& l, double h0, double h1) {
  double m = std::max(layer_raw(l, h0), layer_raw(l, h1));
  const double as = l.exp_term * l.exp_scale_per_m;
  if (as != 0.0 && l.exp_scale_per_m != 0.0 && -l.linear_term_per_m / as > 0.0) {
    const double h_star = std::log(-l.linear_term_per_m / as) / l.exp_scale_per_m;
    if (h_star > h0 && h_star < h1) m = std::max(m, layer_raw(l, h_star));
  }
  return std::clamp(m, 0.0, 1.0);
}

double layers_max(const std::vector<DensityLayer>& layers, double h0, double h1) {
  double m = 0.0, bottom = 0.0;
  for (std::size_t i = 0; i < layers.size(); ++i) {
    const bool last = (i + 1 == layers.size());
    const double top = last ? h1 : bottom + layers[i].width_m;
    const double a = std::max(h0, bottom), b = std::min(h1, top);
    if (a <= b) m = std::max(m, layer_max(layers[i], a, b));
    if (!last) bottom += layers[i].width_m;
    if (bottom > h1) break;
  }
  return m;
}

// Break points where a profile is not smooth, for piecewise quadrature.
std::vector<double> layer_breaks(const std::vector<DensityLayer>& layers) {
  std::vector<double> breaks;
  double b = 0.0;
  for (std::size_t i = 0; i + 1 < layers.size(); ++i) breaks.push_back(b += layers[i].width_m);
  return breaks;
}

// Integral over [h0, h1] split at `breaks`, adaptive Simpson on each piece.
double integrate_split(const std::function<double(double)>& f, double h0, double h1, std::vector<double> breaks) {
  breaks.push_back(h0);
  breaks.push_back(h1);
  std::sort(breaks.begin(), breaks.end());
  double sum = 0.0;
  for (std::size_t i = 1; i < breaks.size(); ++i) {
    const double a = std::max(h0, breaks[i - 1]), b = std::min(h1, breaks[i]);
    if (b > a) sum += integrate_adaptive_simpson(f, a, b, 1e-11);
  }
  return sum;
}

}  // namespace

DensityProfile DensityProfile::exponential(double scale_height_m) {
  if (!(scale_height_m > 0.0) || !std::isfinite(scale_height_m))
    throw std::invalid_argument("exponential density: scale height must be positive and finite");
  return DensityProfile(Exponential{scale_height_m});
}

DensityProfile DensityProfile::table(PiecewiseLinear rho_of_h) {
  std::vector<double> x(rho_of_h.x().begin(), rho_of_h.x().end());
  std::vector<double> y(rho_of_h.y().begin(), rho_of_h.y().end());
  for (double v : y)
    if (v < 0.0) throw std::invalid_argument("table density: values must be >= 0");
  return DensityProfile(Table{PiecewiseLinear(std::move(x), std::move(y), PiecewiseLinear::Outside::kZero,
                                              "table density")});
}

DensityProfile DensityProfile::layers(std::vector<DensityLayer> layers) {
  if (layers.empty()) throw std::invalid_argument("layers density: needs at least one layer");
  return DensityProfile(Layers{std::move(layers)});
}

DensityProfile DensityProfile::us76_air() { return DensityProfile(Us76Air{}); }

DensityProfile DensityProfile::from_spec(const DensitySpec& spec) {
  return std::visit(Overloaded{
                        [](const ExponentialDensity& s) { return exponential(s.scale_height_m); },
                        [](const TableDensity& s) {
                          return table(PiecewiseLinear(s.altitude_m, s.values, PiecewiseLinear::Outside::kZero,
                                                       "density table"));
                        },
                        [](const LayersDensity& s) { return layers(s.layers); },
                    },
                    spec);
}

double DensityProfile::eval(double altitude_m) const {
  const double h = std::max(altitude_m, 0.0);
  return std::visit(Overloaded{
                        [h](const Exponential& e) { return std::exp(-h / e.H); },
                        [h](const Table& t) { return t.rho(h); },
                        [h](const Layers& l) { return layers_eval(l.layers, h); },
                        [h](const Us76Air&) { return us76::number_density_per_m3(h); },
                    },
                    kind_);
}

double DensityProfile::max_on(double h0_m, double h1_m) const {
  const double h0 = std::max(h0_m, 0.0), h1 = std::max(h1_m, h0);
  return std::visit(Overloaded{
                        // exp(-h/H) and the US76 density fall monotonically with h.
                        [h0](const Exponential& e) { return std::exp(-h0 / e.H); },
                        [h0, h1](const Table& t) { return t.rho.max_on(h0, h1); },
                        [h0, h1](const Layers& l) { return layers_max(l.layers, h0, h1); },
                        [h0](const Us76Air&) { return us76::number_density_per_m3(h0); },
                    },
                    kind_);
}

double DensityProfile::column(double h0_m, double h1_m) const {
  const double h0 = std::max(h0_m, 0.0), h1 = std::max(h1_m, h0);
  return std::visit(Overloaded{
                        // H (e^{-h0/H} - e^{-h1/H}), written with expm1 for thin slabs.
                        [h0, h1](const Exponential& e) {
                          return -e.H * std::exp(-h0 / e.H) * std::expm1(-(h1 - h0) / e.H);
                        },
                        [h0, h1](const Table& t) { return t.rho.integral(h0, h1); },
                        [h0, h1](const Layers& l) {
                          return integrate_split([&l](double h) { return layers_eval(l.layers, h); }, h0, h1,
                                                 layer_breaks(l.layers));
                        },
                        [h0, h1](const Us76Air&) {
                          // Split at the US76 layer bases, where the profile has kinks.
                          return integrate_split(us76::number_density_per_m3, h0, h1,
                                                 {11019.1, 20063.1, 32161.9, 47350.1, 51412.5, 71802.0, 80000.0,
                                                  86000.0, 90000.0, 95000.0, 100000.0, 105000.0, 110000.0,
                                                  115000.0, 120000.0});
                        },
                    },
                    kind_);
}

}  // namespace skyfarm
