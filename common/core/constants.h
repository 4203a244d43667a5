// Physical and mathematical constants, SI units, each with its source.
#pragma once

namespace skyfarm {

inline constexpr double kPi = 3.14159265358979323846;
inline constexpr double kInvPi = 1.0 / kPi;
inline constexpr double kInv4Pi = 1.0 / (4.0 * kPi);
inline constexpr double kDegToRad = kPi / 180.0;
inline constexpr double kRadToDeg = 180.0 / kPi;

// Luminous efficacy of monochromatic 555 nm (540 THz) radiation, lm/W (SI definition of the candela).
inline constexpr double kMaxLuminousEfficacy = 683.0;
// Boltzmann constant, J/K (SI 2019 exact).
inline constexpr double kBoltzmann = 1.380649e-23;
// One Dobson unit: 2.6867e20 molecules per m^2 (0.01 mm of ozone at STP; WMO).
inline constexpr double kDobsonUnit_per_m2 = 2.6867e20;
// Astronomical unit, m (IAU 2012 exact).
inline constexpr double kAstronomicalUnit_m = 1.495978707e11;
// Mean Earth radius, m.
inline constexpr double kEarthRadius_m = 6371000.0;
// Default top of the atmosphere above the ground, m.
inline constexpr double kDefaultTopAltitude_m = 100000.0;

}  // namespace skyfarm
