// The NREL Solar Position Algorithm (SPA):
//   I. Reda and A. Andreas, "Solar position algorithm for solar radiation
//   applications", Solar Energy 76(5), 577-589 (2004); NREL/TP-560-34302,
//   revised January 2008.  Equation numbers below are those of the report.
// Its stated uncertainty is +/-0.0003 degrees for the years -2000 to 6000.  The
// Earth's heliocentric position comes from the VSOP87 periodic terms of the
// report's Table A4.2 and the nutation from Table A4.3, both read as data from
// data/spa_periodic_terms.csv and data/spa_nutation_terms.csv (see data/README.md).
//
// The position returned is GEOMETRIC: no atmospheric refraction is applied,
// because the renderer traces straight rays through its own atmosphere.  Callers
// wanting the apparent (refracted) elevation add refraction_correction_deg().
#include "common/sun/solar_position.h"

#include <array>
#include <cmath>
#include <cstdint>
#include <initializer_list>
#include <iterator>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

#include "common/data/csv_table.h"

namespace skyfarm {
namespace {

constexpr double kDegToRad = std::numbers::pi / 180.0;
constexpr double kRadToDeg = 180.0 / std::numbers::pi;
constexpr double kJ2000 = 2451545.0;                   // JD of J2000.0
constexpr std::int64_t kJ2000UnixSeconds = 946728000;  // 2000-01-01T12:00:00Z
constexpr double kSecondsPerDay = 86400.0;

// Trigonometry on angles in degrees (the SPA works in degrees throughout).
double sind(double deg) { return std::sin(deg * kDegToRad); }
double cosd(double deg) { return std::cos(deg * kDegToRad); }
double tand(double deg) { return std::tan(deg * kDegToRad); }

// An angle reduced to [0, 360) (SPA's "limit to the range 0 to 360").
double wrap_360(double deg) {
  double r = std::fmod(deg, 360.0);
  if (r < 0.0) r += 360.0;
  return r >= 360.0 ? 0.0 : r;  // -1e-17 + 360 rounds to 360
}

// c0 + c1 x + c2 x^2 + ... by Horner's rule.
double polynomial(double x, std::initializer_list<double> c) {
  double sum = 0.0;
  for (auto it = std::rbegin(c); it != std::rend(c); ++it) sum = sum * x + *it;
  return sum;
}

// --- Periodic-term tables (Reda & Andreas, Tables A4.2 and A4.3) -------------

struct PeriodicTerm {
  double A, B, C;  // A cos(B + C JME)
};

// Table A4.2: L0..L5, B0..B1, R0..R4; the CSV's `series` column codes them as
// 0..5, 10..11, 20..24.
struct EarthTerms {
  std::array<std::vector<PeriodicTerm>, 6> L;
  std::array<std::vector<PeriodicTerm>, 2> B;
  std::array<std::vector<PeriodicTerm>, 5> R;
};

// Reads data/spa_periodic_terms.csv into the 13 series, in the table's order.
EarthTerms load_earth_terms() {
  const CsvTable t = CsvTable::embedded("spa_periodic_terms.csv");
  const auto& series = t.column("series");
  const auto& A = t.column("A");
  const auto& B = t.column("B");
  const auto& C = t.column("C");
  EarthTerms terms;
  for (std::size_t i = 0; i < t.rows(); ++i) {
    const int code = static_cast<int>(series[i]);
    const PeriodicTerm term{A[i], B[i], C[i]};
    if (code >= 0 && code < 6) terms.L[static_cast<std::size_t>(code)].push_back(term);
    else if (code >= 10 && code < 12) terms.B[static_cast<std::size_t>(code - 10)].push_back(term);
    else if (code >= 20 && code < 25) terms.R[static_cast<std::size_t>(code - 20)].push_back(term);
    else throw std::runtime_error("spa_periodic_terms.csv: unknown series code " + std::to_string(code));
  }
  // Row counts of Table A4.2, so that a truncated table cannot pass silently.
  const std::array<std::size_t, 6> nL{64, 34, 20, 7, 3, 1};
  const std::array<std::size_t, 2> nB{5, 2};
  const std::array<std::size_t, 5> nR{40, 10, 6, 2, 1};
  for (std::size_t i = 0; i < 6; ++i)
    if (terms.L[i].size() != nL[i]) throw std::runtime_error("spa_periodic_terms.csv: wrong L" + std::to_string(i) + " row count");
  for (std::size_t i = 0; i < 2; ++i)
    if (terms.B[i].size() != nB[i]) throw std::runtime_error("spa_periodic_terms.csv: wrong B" + std::to_string(i) + " row count");
  for (std::size_t i = 0; i < 5; ++i)
    if (terms.R[i].size() != nR[i]) throw std::runtime_error("spa_periodic_terms.csv: wrong R" + std::to_string(i) + " row count");
  return terms;
}

// Parsed once, on first use (thread-safe static initialisation).
const EarthTerms& earth_terms() {
  static const EarthTerms terms = load_earth_terms();
  return terms;
}

// Table A4.3: multipliers Y0..Y4 of X0..X4, and coefficients a, b (longitude,
// units of 0.0001") and c, d (obliquity).
struct NutationTerm {
  std::array<double, 5> Y;
  double a, b, c, d;
};

// Reads data/spa_nutation_terms.csv (63 rows, in the table's order).
std::vector<NutationTerm> load_nutation_terms() {
  const CsvTable t = CsvTable::embedded("spa_nutation_terms.csv");
  const std::array<const std::vector<double>*, 5> Y{&t.column("Y0"), &t.column("Y1"), &t.column("Y2"),
                                                     &t.column("Y3"), &t.column("Y4")};
  std::vector<NutationTerm> terms(t.rows());
  for (std::size_t i = 0; i < t.rows(); ++i) {
    for (std::size_t j = 0; j < 5; ++j) terms[i].Y[j] = (*Y[j])[i];
    terms[i].a = t.column("a")[i];
    terms[i].b = t.column("b")[i];
    terms[i].c = t.column("c")[i];
    terms[i].d = t.column("d")[i];
  }
  if (terms.size() != 63) throw std::runtime_error("spa_nutation_terms.csv: expected the 63 rows of Table A4.3");
  return terms;
}

// Parsed once, on first use.
const std::vector<NutationTerm>& nutation_terms() {
  static const std::vector<NutationTerm> terms = load_nutation_terms();
  return terms;
}

// --- 3.2 Earth heliocentric longitude, latitude and radius vector -------------

// Eqs. 9-10: L0 = sum_i A_i cos(B_i + C_i JME) for one series.
double sum_series(const std::vector<PeriodicTerm>& series, double jme) {
  double sum = 0.0;
  for (const auto& t : series) sum += t.A * std::cos(t.B + t.C * jme);
  return sum;
}

// Eq. 11: X = (X0 + X1 JME + X2 JME^2 + ...) / 10^8, in radians (or AU for R).
template <std::size_t N>
double evaluate_series(const std::array<std::vector<PeriodicTerm>, N>& series, double jme) {
  double sum = 0.0;
  for (std::size_t i = N; i-- > 0;) sum = sum * jme + sum_series(series[i], jme);
  return sum / 1e8;
}

// Eqs. 9-12, 3.2.5: L in degrees, limited to [0, 360).
double heliocentric_longitude_deg(double jme) { return wrap_360(evaluate_series(earth_terms().L, jme) * kRadToDeg); }

// 3.2.7: B in degrees (same summation with the B terms).
double heliocentric_latitude_deg(double jme) { return evaluate_series(earth_terms().B, jme) * kRadToDeg; }

// 3.2.8: R in astronomical units (same summation with the R terms).
double earth_sun_distance_au(double jme) { return evaluate_series(earth_terms().R, jme); }

// --- 3.4 Nutation in longitude and obliquity ----------------------------------

struct Nutation {
  double delta_psi_deg;
  double delta_epsilon_deg;
};

// Eqs. 15-19 (fundamental arguments, degrees; Meeus 1998 ch. 22), then
// eqs. 20-23: Δψ = Σ (a_i + b_i JCE) sin(Σ_j X_j Y_ij) / 36 000 000,
//             Δε = Σ (c_i + d_i JCE) cos(Σ_j X_j Y_ij) / 36 000 000.
Nutation nutation(double jce) {
  const std::array<double, 5> X{
      polynomial(jce, {297.85036, 445267.111480, -0.0019142, 1.0 / 189474.0}),  // X0: Moon-Sun mean elongation
      polynomial(jce, {357.52772, 35999.050340, -0.0001603, -1.0 / 300000.0}),  // X1: Sun mean anomaly
      polynomial(jce, {134.96298, 477198.867398, 0.0086972, 1.0 / 56250.0}),    // X2: Moon mean anomaly
      polynomial(jce, {93.27191, 483202.017538, -0.0036825, 1.0 / 327270.0}),   // X3: Moon argument of latitude
      polynomial(jce, {125.04452, -1934.136261, 0.0020708, 1.0 / 450000.0}),    // X4: Moon ascending node
  };
  double sum_psi = 0.0;
  double sum_epsilon = 0.0;
  for (const auto& t : nutation_terms()) {
    double arg = 0.0;
    for (std::size_t j = 0; j < 5; ++j) arg += X[j] * t.Y[j];
    sum_psi += (t.a + t.b * jce) * sind(arg);
    sum_epsilon += (t.c + t.d * jce) * cosd(arg);
  }
  return {sum_psi / 36000000.0, sum_epsilon / 36000000.0};
}

// --- 3.5 Obliquity of the ecliptic -------------------------------------------

// Eq. 24 (Laskar 1986, via Meeus 1998 eq. 22.3): mean obliquity in arc seconds,
// U = JME / 10.
double mean_obliquity_arcsec(double jme) {
  return polynomial(jme / 10.0, {84381.448, -4680.93, -1.55, 1999.25, -51.38, -249.67, -39.05, 7.12, 27.87,
                                 5.79, 2.45});
}

// --- 3.8 Apparent sidereal time at Greenwich ----------------------------------

// Eq. 28 (Meeus 1998 eq. 12.4), from the UT days since J2000.0 (= JD - 2451545)
// to keep precision: ν0 = 280.46061837 + 360.98564736629 d + 0.000387933 JC^2 - JC^3/38710000.
double greenwich_mean_sidereal_deg(double days_ut, double jc) {
  return wrap_360(280.46061837 + 360.98564736629 * days_ut + 0.000387933 * jc * jc - jc * jc * jc / 38710000.0);
}

// --- 3.9-3.10 Geocentric equatorial coordinates -------------------------------

// Eq. 30: α = atan2(sin λ cos ε - tan β sin ε, cos λ), limited to [0, 360).
double right_ascension_deg(double lambda, double epsilon, double beta) {
  return wrap_360(
      std::atan2(sind(lambda) * cosd(epsilon) - tand(beta) * sind(epsilon), cosd(lambda)) * kRadToDeg);
}

// Eq. 31: δ = asin(sin β cos ε + cos β sin ε sin λ).
double declination_deg(double lambda, double epsilon, double beta) {
  return std::asin(sind(beta) * cosd(epsilon) + cosd(beta) * sind(epsilon) * sind(lambda)) * kRadToDeg;
}

// --- 3.12-3.13 Topocentric correction (parallax) ------------------------------

struct Topocentric {
  double xi_deg;           // ξ, equatorial horizontal parallax of the sun
  double delta_alpha_deg;  // Δα, parallax in right ascension
  double delta_prime_deg;  // δ', topocentric declination
};

// Eqs. 33-39.  ξ = 8.794" / R (eq. 33); the observer's geocentric position on the
// reference ellipsoid of flattening 1/298.257... (0.99664719 = 1 - f) from
// u = atan(0.99664719 tan φ) (eq. 34), x = cos u + E/a cos φ (eq. 35),
// y = 0.99664719 sin u + E/a sin φ (eq. 36), with a = 6378140 m; then
// Δα = atan2(-x sin ξ sin H, cos δ - x sin ξ cos H) (eq. 37) and
// δ' = atan2((sin δ - y sin ξ) cos Δα, cos δ - x sin ξ cos H) (eq. 39).
Topocentric topocentric(double R, double latitude, double altitude_m, double H, double delta) {
  constexpr double kOneMinusFlattening = 0.99664719;
  constexpr double kEquatorialRadiusM = 6378140.0;
  const double xi = 8.794 / (3600.0 * R);
  const double u = std::atan(kOneMinusFlattening * tand(latitude));
  const double x = std::cos(u) + altitude_m / kEquatorialRadiusM * cosd(latitude);
  const double y = kOneMinusFlattening * std::sin(u) + altitude_m / kEquatorialRadiusM * sind(latitude);
  const double denominator = cosd(delta) - x * sind(xi) * cosd(H);
  const double delta_alpha = std::atan2(-x * sind(xi) * sind(H), denominator) * kRadToDeg;
  const double delta_prime =
      std::atan2((sind(delta) - y * sind(xi)) * cosd(delta_alpha), denominator) * kRadToDeg;
  return {xi, delta_alpha, delta_prime};
}

// --- 3.14-3.15 Topocentric horizontal coordinates -----------------------------

// Eq. 41: e0 = asin(sin φ sin δ' + cos φ cos δ' cos H'), geometric elevation.
double elevation_deg(double latitude, double delta_prime, double H_prime) {
  const double s = sind(latitude) * sind(delta_prime) + cosd(latitude) * cosd(delta_prime) * cosd(H_prime);
  return std::asin(std::fmax(-1.0, std::fmin(1.0, s))) * kRadToDeg;
}

// Eqs. 45-46: astronomers' azimuth Γ = atan2(sin H', cos H' sin φ - tan δ' cos φ)
// (westward from south); Φ = Γ + 180, eastward from north, in [0, 360).
double azimuth_deg(double latitude, double delta_prime, double H_prime) {
  const double gamma =
      std::atan2(sind(H_prime), cosd(H_prime) * sind(latitude) - tand(delta_prime) * cosd(latitude)) * kRadToDeg;
  return wrap_360(gamma + 180.0);
}

}  // namespace

// Espenak & Meeus, "Five Millennium Canon of Solar Eclipses: -1999 to +3000",
// NASA/TP-2006-214141, and F. Espenak, "Polynomial Expressions for Delta T",
// NASA eclipse web site (eclipse.gsfc.nasa.gov/SEhelp/deltatpoly2004.html).
// Piecewise polynomials in the decimal year y fitted to the observed ΔT
// (Morrison & Stephenson 2004 before 1955, IERS after), extrapolated after 2005
// and joined to the long-term parabola ΔT = -20 + 32 u^2, u = (y - 1820)/100,
// outside -500..2150.  The source defines y = year + (month - 0.5)/12; any
// decimal year is accepted here.
double delta_t_seconds(double y) {
  if (y < -500.0) return polynomial((y - 1820.0) / 100.0, {-20.0, 0.0, 32.0});
  if (y < 500.0)
    return polynomial(y / 100.0, {10583.6, -1014.41, 33.78311, -5.952053, -0.1798452, 0.022174192, 0.0090316521});
  if (y < 1600.0)
    return polynomial((y - 1000.0) / 100.0,
                      {1574.2, -556.01, 71.23472, 0.319781, -0.8503463, -0.005050998, 0.0083572073});
  if (y < 1700.0) return polynomial(y - 1600.0, {120.0, -0.9808, -0.01532, 1.0 / 7129.0});
  if (y < 1800.0) return polynomial(y - 1700.0, {8.83, 0.1603, -0.0059285, 0.00013336, -1.0 / 1174000.0});
  if (y < 1860.0)
    return polynomial(y - 1800.0, {13.72, -0.332447, 0.0068612, 0.0041116, -0.00037436, 0.0000121272,
                                   -0.0000001699, 0.000000000875});
  if (y < 1900.0)
    return polynomial(y - 1860.0, {7.62, 0.5737, -0.251754, 0.01680668, -0.0004473624, 1.0 / 233174.0});
  if (y < 1920.0) return polynomial(y - 1900.0, {-2.79, 1.494119, -0.0598939, 0.0061966, -0.000197});
  if (y < 1941.0) return polynomial(y - 1920.0, {21.20, 0.84493, -0.076100, 0.0020936});
  if (y < 1961.0) return polynomial(y - 1950.0, {29.07, 0.407, -1.0 / 233.0, 1.0 / 2547.0});
  if (y < 1986.0) return polynomial(y - 1975.0, {45.45, 1.067, -1.0 / 260.0, -1.0 / 718.0});
  if (y < 2005.0)
    return polynomial(y - 2000.0, {63.86, 0.3345, -0.060374, 0.0017275, 0.000651814, 0.00002373599});
  if (y < 2050.0) return polynomial(y - 2000.0, {62.92, 0.32217, 0.005589});
  const double u = (y - 1820.0) / 100.0;
  if (y < 2150.0) return -20.0 + 32.0 * u * u - 0.5628 * (2150.0 - y);
  return -20.0 + 32.0 * u * u;
}

// SPA eq. 42 (after Bennett 1982 / Saemundsson, scaled for pressure and
// temperature): Δe = (P/1010)(283/(273 + T)) 1.02 / (60 tan(e0 + 10.3/(e0 + 5.11))),
// degrees.  As in spa.c, no correction once the sun is below the apparent horizon:
// e0 < -(0.26667 + 0.5667), the solar radius plus the refraction at the horizon.
double refraction_correction_deg(double elevation_deg, double pressure_hPa, double temperature_C) {
  constexpr double kSunRadiusDeg = 0.26667;
  constexpr double kHorizonRefractionDeg = 0.5667;
  if (!(elevation_deg >= -(kSunRadiusDeg + kHorizonRefractionDeg))) return 0.0;
  return (pressure_hPa / 1010.0) * (283.0 / (273.0 + temperature_C)) * 1.02 /
         (60.0 * tand(elevation_deg + 10.3 / (elevation_deg + 5.11)));
}

// The SPA step by step (Reda & Andreas 2008, section 3).
SolarPositionDetails solar_position_details(const Location& where, const UtcInstant& when,
                                            std::optional<double> delta_t_s) {
  SolarPositionDetails s;
  // 3.1 Julian day, ephemeris day, centuries and millennium (eqs. 4-8).  Days
  // since J2000.0 are formed from integer seconds first, so JD - 2451545 keeps
  // sub-microsecond precision instead of JD's ~20 microseconds.
  s.delta_t_s = delta_t_s ? *delta_t_s : delta_t_seconds(utc_decimal_year(when));
  const double days_ut =
      (static_cast<double>(when.unix_seconds - kJ2000UnixSeconds) + when.fraction) / kSecondsPerDay;
  const double days_tt = days_ut + s.delta_t_s / kSecondsPerDay;
  s.julian_day = kJ2000 + days_ut;                // eq. 4
  s.julian_ephemeris_day = kJ2000 + days_tt;      // eq. 5
  s.julian_century = days_ut / 36525.0;           // eq. 6
  s.julian_ephemeris_century = days_tt / 36525.0; // eq. 7
  s.julian_ephemeris_millennium = s.julian_ephemeris_century / 10.0;  // eq. 8
  const double jce = s.julian_ephemeris_century;
  const double jme = s.julian_ephemeris_millennium;

  // 3.2 Earth heliocentric coordinates (eqs. 9-12).
  s.heliocentric_longitude_deg = heliocentric_longitude_deg(jme);
  s.heliocentric_latitude_deg = heliocentric_latitude_deg(jme);
  s.earth_sun_distance_au = earth_sun_distance_au(jme);

  // 3.3 Geocentric coordinates: Θ = L + 180 (eq. 13), β = -B (eq. 14).
  s.geocentric_longitude_deg = wrap_360(s.heliocentric_longitude_deg + 180.0);
  s.geocentric_latitude_deg = -s.heliocentric_latitude_deg;

  // 3.4 Nutation (eqs. 15-23).
  const Nutation n = nutation(jce);
  s.nutation_longitude_deg = n.delta_psi_deg;
  s.nutation_obliquity_deg = n.delta_epsilon_deg;

  // 3.5 True obliquity: ε = ε0/3600 + Δε (eqs. 24-25).
  s.mean_obliquity_arcsec = mean_obliquity_arcsec(jme);
  s.true_obliquity_deg = s.mean_obliquity_arcsec / 3600.0 + s.nutation_obliquity_deg;

  // 3.6 Aberration: Δτ = -20.4898" / R (eq. 26).
  s.aberration_deg = -20.4898 / (3600.0 * s.earth_sun_distance_au);

  // 3.7 Apparent sun longitude: λ = Θ + Δψ + Δτ (eq. 27).
  s.apparent_longitude_deg = s.geocentric_longitude_deg + s.nutation_longitude_deg + s.aberration_deg;

  // 3.8 Apparent sidereal time at Greenwich: ν = ν0 + Δψ cos ε (eqs. 28-29).
  s.greenwich_mean_sidereal_deg = greenwich_mean_sidereal_deg(days_ut, s.julian_century);
  s.greenwich_apparent_sidereal_deg =
      s.greenwich_mean_sidereal_deg + s.nutation_longitude_deg * cosd(s.true_obliquity_deg);

  // 3.9-3.10 Geocentric right ascension and declination (eqs. 30-31).
  s.right_ascension_deg =
      right_ascension_deg(s.apparent_longitude_deg, s.true_obliquity_deg, s.geocentric_latitude_deg);
  s.declination_deg = declination_deg(s.apparent_longitude_deg, s.true_obliquity_deg, s.geocentric_latitude_deg);

  // 3.11 Observer local hour angle: H = ν + σ - α, σ east-positive (eq. 32).
  s.hour_angle_deg = wrap_360(s.greenwich_apparent_sidereal_deg + where.longitude_deg - s.right_ascension_deg);

  // 3.12-3.13 Topocentric right ascension, declination and hour angle (eqs. 33-40).
  const Topocentric t = topocentric(s.earth_sun_distance_au, where.latitude_deg, where.altitude_m,
                                    s.hour_angle_deg, s.declination_deg);
  s.horizontal_parallax_deg = t.xi_deg;
  s.parallax_right_ascension_deg = t.delta_alpha_deg;
  s.topocentric_right_ascension_deg = s.right_ascension_deg + t.delta_alpha_deg;  // eq. 38
  s.topocentric_declination_deg = t.delta_prime_deg;
  s.topocentric_hour_angle_deg = s.hour_angle_deg - t.delta_alpha_deg;            // eq. 40

  // 3.14-3.15 Topocentric elevation (no refraction), zenith and azimuth (eqs. 41, 44-46).
  s.elevation_deg = elevation_deg(where.latitude_deg, s.topocentric_declination_deg, s.topocentric_hour_angle_deg);
  s.zenith_deg = 90.0 - s.elevation_deg;
  s.azimuth_deg = azimuth_deg(where.latitude_deg, s.topocentric_declination_deg, s.topocentric_hour_angle_deg);
  return s;
}

// The SPA's geometric topocentric position (solar_position_details, without
// refraction), reduced to what the renderer uses.
SolarPosition solar_position(const Location& where, const UtcInstant& when, std::optional<double> delta_t_s) {
  const SolarPositionDetails d = solar_position_details(where, when, delta_t_s);
  SolarPosition p;
  p.zenith_deg = d.zenith_deg;
  p.azimuth_deg = d.azimuth_deg;
  p.earth_sun_distance_au = d.earth_sun_distance_au;
  p.declination_deg = d.declination_deg;
  p.right_ascension_deg = d.right_ascension_deg;
  p.hour_angle_deg = d.hour_angle_deg;
  return p;
}

}  // namespace skyfarm
