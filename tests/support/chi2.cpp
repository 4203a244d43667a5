// Chi-square goodness-of-fit harness (see chi2.h).
#include "tests/support/chi2.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <sstream>
#include <utility>

namespace skyfarm::testing {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kMinExpected = 5.0;     // pool cells expected below this
constexpr double kZeroExpected = 1e-6;   // a cell this unlikely must stay empty
constexpr double kMaxPdfIntegral = 1.1;  // Mitsuba's sanity bound
constexpr int kSimpsonMinDepth = 3;      // 8 panels before adapting
constexpr int kSimpsonMaxDepth = 30;

std::string number(double x) {
  std::ostringstream out;
  out.precision(6);
  out << x;
  return out.str();
}

Chi2Result failure(const std::string& why) { return {std::numeric_limits<double>::quiet_NaN(), 0, 0.0, why}; }

// Adaptive Simpson quadrature of f over [a, b] with absolute tolerance eps,
// halved per level (Lyness 1969 refinement, Richardson correction delta/15),
// forced to kSimpsonMinDepth levels so that narrow features are not skipped.
// Records whether f was ever negative or not finite.
class Simpson {
 public:
  explicit Simpson(std::function<double(double)> f) : f_(std::move(f)) {}

  double integrate(double a, double b, double eps) {
    const double fa = eval(a), fm = eval(0.5 * (a + b)), fb = eval(b);
    return refine(a, b, fa, fm, fb, (b - a) / 6.0 * (fa + 4.0 * fm + fb), eps, 0);
  }
  bool negative() const { return negative_; }
  bool non_finite() const { return non_finite_; }
  double first_bad_x() const { return bad_x_; }

 private:
  double eval(double x) {
    const double v = f_(x);
    if (!std::isfinite(v)) {
      if (!non_finite_ && !negative_) bad_x_ = x;
      non_finite_ = true;
      return 0.0;
    }
    if (v < 0.0) {
      if (!non_finite_ && !negative_) bad_x_ = x;
      negative_ = true;
    }
    return v;
  }

  double refine(double a, double b, double fa, double fm, double fb, double whole, double eps, int depth) {
    const double m = 0.5 * (a + b);
    const double flm = eval(0.5 * (a + m)), frm = eval(0.5 * (m + b));
    const double left = (m - a) / 6.0 * (fa + 4.0 * flm + fm);
    const double right = (b - m) / 6.0 * (fm + 4.0 * frm + fb);
    const double delta = left + right - whole;
    if (depth >= kSimpsonMaxDepth || (depth >= kSimpsonMinDepth && std::abs(delta) <= 15.0 * eps)) {
      return left + right + delta / 15.0;
    }
    return refine(a, m, fa, flm, fm, left, 0.5 * eps, depth + 1) +
           refine(m, b, fm, frm, fb, right, 0.5 * eps, depth + 1);
  }

  std::function<double(double)> f_;
  bool negative_ = false, non_finite_ = false;
  double bad_x_ = 0.0;
};

// The statistic from per-cell probabilities and observed counts (steps 1c-4).
Chi2Result evaluate(const std::vector<double>& probability, const std::vector<double>& observed, double n,
                    const std::function<std::string(std::size_t)>& describe) {
  const std::size_t cells = probability.size();
  const double pdf_integral = std::accumulate(probability.begin(), probability.end(), 0.0);
  std::ostringstream summary;
  summary << "N = " << number(n) << ", " << cells << " cells, pdf integral = " << number(pdf_integral);
  if (pdf_integral > kMaxPdfIntegral) {
    return failure("pdf integrates to " + number(pdf_integral) + " > " + number(kMaxPdfIntegral) +
                   " over the domain; " + summary.str());
  }

  std::vector<double> expected(cells);
  for (std::size_t i = 0; i < cells; ++i) expected[i] = n * probability[i];

  // Samples where the pdf says (almost) none can be.
  for (std::size_t i = 0; i < cells; ++i) {
    if (expected[i] < kZeroExpected && observed[i] > 0.0) {
      return failure(number(observed[i]) + " sample(s) in cell " + describe(i) + " whose expected count is " +
                     number(expected[i]) + " (the pdf is ~0 there); " + summary.str());
    }
  }

  // Pool the cells expecting < kMinExpected, smallest first, into groups that
  // each expect >= kMinExpected (a remainder joins the last group, or the
  // smallest regular cell).  The grouping depends on the expected counts
  // only, so the statistic keeps its chi-square distribution.
  std::vector<std::size_t> order(cells);
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::sort(order.begin(), order.end(), [&](std::size_t i, std::size_t j) { return expected[i] < expected[j]; });
  struct Group {
    double expected = 0.0, observed = 0.0;
    std::size_t members = 0, first = 0;  // first: the cell described when members == 1
  };
  std::vector<Group> groups;
  Group open;
  std::size_t pooled_cells = 0;
  for (const std::size_t i : order) {
    if (expected[i] < kMinExpected) {
      open.expected += expected[i];
      open.observed += observed[i];
      if (open.members++ == 0) open.first = i;
      ++pooled_cells;
      if (open.expected >= kMinExpected) {
        groups.push_back(open);
        open = Group{};
      }
    } else {
      groups.push_back({expected[i], observed[i], 1, i});
    }
  }
  if (open.expected > 0.0) {
    // Remainder below kMinExpected: merge into the last pooled group, else
    // into the smallest regular cell.
    Group* target = nullptr;
    for (Group& g : groups) {
      if (g.members > 1 || expected[g.first] < kMinExpected) target = &g;
    }
    if (target == nullptr && !groups.empty()) target = &groups.front();
    if (target != nullptr) {
      target->expected += open.expected;
      target->observed += open.observed;
      target->members += open.members;
    } else {
      groups.push_back(open);
    }
  }

  struct Contribution {
    double chi2;
    std::size_t group;
  };
  std::vector<Contribution> contributions;
  double statistic = 0.0;
  for (std::size_t j = 0; j < groups.size(); ++j) {
    const Group& g = groups[j];
    const double c = (g.observed - g.expected) * (g.observed - g.expected) / g.expected;
    statistic += c;
    contributions.push_back({c, j});
  }
  const int dof = static_cast<int>(groups.size()) - 1;
  summary << ", " << pooled_cells << " cells expecting < " << number(kMinExpected) << " pooled";
  if (dof < 1) {
    return failure("too few cells with enough expected samples for a chi-square test (dof = " + std::to_string(dof) +
                   "); use more samples or fewer bins; " + summary.str());
  }

  const double p_value = chi2_survival(statistic, dof);
  std::ostringstream detail;
  detail << "chi2 = " << number(statistic) << ", dof = " << dof << ", p = " << number(p_value) << "; " << summary.str()
         << "; worst cells:";
  std::sort(contributions.begin(), contributions.end(),
            [](const Contribution& x, const Contribution& y) { return x.chi2 > y.chi2; });
  for (std::size_t j = 0; j < std::min<std::size_t>(5, contributions.size()); ++j) {
    const Contribution& c = contributions[j];
    const Group& g = groups[c.group];
    detail << "\n  ";
    if (g.members == 1) {
      detail << describe(g.first);
    } else {
      detail << "pool of " << g.members << " cells";
    }
    detail << ": observed " << number(g.observed) << ", expected " << number(g.expected) << " (contributes "
           << number(c.chi2) << ")";
  }
  return {statistic, dof, p_value, detail.str()};
}

// Series for the regularised lower incomplete gamma function, x < a + 1:
//   P(a, x) = e^{-x} x^a / Gamma(a + 1) * sum_{n>=0} x^n / ((a + 1)...(a + n)).
double gamma_p_series(double a, double x) {
  double term = 1.0 / a, sum = term;
  for (int n = 1; n < 100000; ++n) {
    term *= x / (a + n);
    sum += term;
    if (std::abs(term) < std::abs(sum) * 1e-16) break;
  }
  return sum * std::exp(-x + a * std::log(x) - std::lgamma(a));
}

// Continued fraction for the regularised upper incomplete gamma function,
// x >= a + 1 (Legendre's fraction in its even form, evaluated by the modified
// Lentz method):
//   Q(a, x) = e^{-x} x^a / Gamma(a) * 1/(x+1-a- 1(1-a)/(x+3-a- 2(2-a)/(x+5-a- ...))).
double gamma_q_continued_fraction(double a, double x) {
  constexpr double kTiny = 1e-300;
  double b = x + 1.0 - a;
  double c = 1.0 / kTiny;
  double d = 1.0 / b;
  double h = d;
  for (int i = 1; i < 100000; ++i) {
    const double an = -i * (i - a);
    b += 2.0;
    d = an * d + b;
    if (std::abs(d) < kTiny) d = kTiny;
    c = b + an / c;
    if (std::abs(c) < kTiny) c = kTiny;
    d = 1.0 / d;
    const double ratio = d * c;
    h *= ratio;
    if (std::abs(ratio - 1.0) < 1e-16) break;
  }
  return std::exp(-x + a * std::log(x) - std::lgamma(a)) * h;
}

}  // namespace

double regularized_gamma_q(double a, double x) {
  if (!(a > 0.0) || std::isnan(x)) return std::numeric_limits<double>::quiet_NaN();
  if (x <= 0.0) return 1.0;
  if (std::isinf(x)) return 0.0;
  if (x < a + 1.0) return 1.0 - gamma_p_series(a, x);
  return gamma_q_continued_fraction(a, x);
}

double chi2_survival(double statistic, int dof) { return regularized_gamma_q(0.5 * dof, 0.5 * statistic); }

double sidak_significance(double alpha, int num_tests) { return -std::expm1(std::log1p(-alpha) / num_tests); }

Chi2Result chi2_test_1d(const std::function<double(double)>& pdf, const std::vector<double>& samples, double a,
                        double b, int bins) {
  if (!(a < b) || bins < 1) return failure("bad domain [" + number(a) + ", " + number(b) + "] or bins");
  if (samples.empty()) return failure("no samples");
  const double width = (b - a) / bins;
  std::vector<double> observed(static_cast<std::size_t>(bins), 0.0);
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const double x = samples[i];
    if (!std::isfinite(x)) return failure("sample " + std::to_string(i) + " is not finite (" + number(x) + ")");
    if (x < a || x > b) {
      return failure("sample " + std::to_string(i) + " = " + number(x) + " lies outside the domain [" + number(a) +
                     ", " + number(b) + "]");
    }
    const int bin = std::clamp(static_cast<int>((x - a) / width), 0, bins - 1);
    observed[static_cast<std::size_t>(bin)] += 1.0;
  }

  Simpson simpson(pdf);
  std::vector<double> probability(static_cast<std::size_t>(bins));
  for (int i = 0; i < bins; ++i) {
    const double lo = a + width * i, hi = (i + 1 == bins) ? b : a + width * (i + 1);
    probability[static_cast<std::size_t>(i)] = simpson.integrate(lo, hi, 1e-12);
  }
  if (simpson.non_finite() || simpson.negative()) {
    return failure(std::string("pdf is ") + (simpson.non_finite() ? "not finite" : "negative") +
                   " at x = " + number(simpson.first_bad_x()));
  }
  auto describe = [&](std::size_t i) {
    const double lo = a + width * static_cast<double>(i);
    std::ostringstream out;  // (not "[" + std::string: GCC 12 -Wrestrict false positive, PR 105329)
    out << "[" << number(lo) << ", " << number(lo + width) << ")";
    return out.str();
  };
  return evaluate(probability, observed, static_cast<double>(samples.size()), describe);
}

Chi2Result chi2_test_sphere(const std::function<double(const glm::dvec3&)>& pdf, const std::vector<glm::dvec3>& samples,
                            int cos_theta_bins, int phi_bins) {
  if (cos_theta_bins < 1 || phi_bins < 1) return failure("bad bin counts");
  if (samples.empty()) return failure("no samples");
  const double d_mu = 2.0 / cos_theta_bins, d_phi = 2.0 * kPi / phi_bins;
  const auto cell_index = [phi_bins](int i_mu, int i_phi) {
    return static_cast<std::size_t>(i_mu) * static_cast<std::size_t>(phi_bins) + static_cast<std::size_t>(i_phi);
  };
  std::vector<double> observed(static_cast<std::size_t>(cos_theta_bins) * static_cast<std::size_t>(phi_bins), 0.0);
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const glm::dvec3& w = samples[i];
    if (!(std::isfinite(w.x) && std::isfinite(w.y) && std::isfinite(w.z))) {
      return failure("sample " + std::to_string(i) + " is not finite");
    }
    const double length = std::sqrt(w.x * w.x + w.y * w.y + w.z * w.z);
    if (std::abs(length - 1.0) > 1e-6) {
      return failure("sample " + std::to_string(i) + " = (" + number(w.x) + ", " + number(w.y) + ", " + number(w.z) +
                     ") is not a unit vector (length " + number(length) + ")");
    }
    const double mu = std::clamp(w.z / length, -1.0, 1.0);
    double phi = std::atan2(w.y, w.x);
    if (phi < 0.0) phi += 2.0 * kPi;
    const int i_mu = std::clamp(static_cast<int>((mu + 1.0) / d_mu), 0, cos_theta_bins - 1);
    const int i_phi = std::clamp(static_cast<int>(phi / d_phi), 0, phi_bins - 1);
    observed[cell_index(i_mu, i_phi)] += 1.0;
  }

  // Nested Simpson: inner over phi at fixed mu, outer over mu (d omega = d mu d phi).
  std::vector<double> probability(observed.size());
  bool negative = false, non_finite = false;
  glm::dvec3 bad{0.0};
  for (int i_mu = 0; i_mu < cos_theta_bins; ++i_mu) {
    const double mu0 = -1.0 + d_mu * i_mu, mu1 = (i_mu + 1 == cos_theta_bins) ? 1.0 : -1.0 + d_mu * (i_mu + 1);
    for (int i_phi = 0; i_phi < phi_bins; ++i_phi) {
      const double phi0 = d_phi * i_phi, phi1 = (i_phi + 1 == phi_bins) ? 2.0 * kPi : d_phi * (i_phi + 1);
      Simpson outer([&](double mu) {
        const double sin_theta = std::sqrt(std::max(0.0, (1.0 - mu) * (1.0 + mu)));
        Simpson inner([&](double phi) {
          const glm::dvec3 w{sin_theta * std::cos(phi), sin_theta * std::sin(phi), mu};
          const double v = pdf(w);
          if (!(std::isfinite(v) && v >= 0.0) && !negative && !non_finite) bad = w;
          return v;
        });
        const double v = inner.integrate(phi0, phi1, 1e-13);
        negative = negative || inner.negative();
        non_finite = non_finite || inner.non_finite();
        return v;
      });
      probability[cell_index(i_mu, i_phi)] = outer.integrate(mu0, mu1, 1e-11);
      if (negative || non_finite) {
        return failure(std::string("pdf is ") + (non_finite ? "not finite" : "negative") + " at (" + number(bad.x) +
                       ", " + number(bad.y) + ", " + number(bad.z) + ")");
      }
    }
  }
  auto describe = [&](std::size_t cell) {
    const std::size_t i_mu = cell / static_cast<std::size_t>(phi_bins),
                      i_phi = cell % static_cast<std::size_t>(phi_bins);
    const double mu0 = -1.0 + d_mu * static_cast<double>(i_mu), phi0 = d_phi * static_cast<double>(i_phi);
    std::ostringstream out;
    out << "cos_theta [" << number(mu0) << ", " << number(mu0 + d_mu) << ") x phi [" << number(phi0) << ", "
        << number(phi0 + d_phi) << ")";
    return out.str();
  };
  return evaluate(probability, observed, static_cast<double>(samples.size()), describe);
}

}  // namespace skyfarm::testing
