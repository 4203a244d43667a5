// exp written as plain arithmetic, so that the LUT builders' loops that call
// it vectorise.
//
// Why: GCC compiles std::exp to a call, and a loop with a call stays scalar.
// The tables' builders spend much of their time in loops over march steps
// and spectral bins that need a segment's transmittance, so exp_inline
// replaces the library call there.  It uses + - * / and integer operations
// on the bit patterns only (no FMA, no table), so a vectorised clone and the
// scalar code give the same bits (simd_clones.h), and a table built twice is
// bit-identical.  (Square roots need no such help: skyfarm_common is built
// with -fno-math-errno, so std::sqrt is one IEEE instruction, correctly
// rounded in every clone, and vectorises; an earlier sqrt_inline of Newton
// steps was slower than it.)
//
//   exp_inline(x)   e^x, x clamped to [-746, 709]; relative error < 3e-16
//                   for normal results (measured against std::exp in
//                   tests/common/lut/vector_math_test.cpp), subnormal results
//                   rounded as usual, 0 below -745.2 (and for -inf), NaN for
//                   NaN.  Cody & Waite's reduction x = n ln 2 + r,
//                   |r| <= ln(2)/2 (ln 2 split in a high part with 21
//                   trailing zero bits, so n ln2_hi is exact), e^r by its
//                   Taylor series to r^13 (remainder < 2e-16 relative), and
//                   2^n from bit patterns.
// It has no branch or select: GCC sinks the work behind a select into a
// conditional block, which it then does not vectorise.
#pragma once
#include <algorithm>
#include <bit>
#include <cstdint>
#include <limits>

namespace skyfarm::lut {

inline double exp_inline(double x) {
  constexpr double kLog2e = 1.4426950408889634074;
  constexpr double kShifter = 0x1.8p52;  // adding it rounds to an integer, kept in the low bits
  constexpr double kLn2Hi = 0x1.62e42fee00000p-1, kLn2Lo = 0x1.a39ef35793c76p-33;
  const double xc = std::max(std::min(x, 709.0), -746.0);  // NaN passes through
  const double t = xc * kLog2e + kShifter;
  const double n = t - kShifter;
  const double r = (xc - n * kLn2Hi) - n * kLn2Lo;
  double p = 1.0 / 6227020800.0;  // 1/13!
  p = p * r + 1.0 / 479001600.0;
  p = p * r + 1.0 / 39916800.0;
  p = p * r + 1.0 / 3628800.0;
  p = p * r + 1.0 / 362880.0;
  p = p * r + 1.0 / 40320.0;
  p = p * r + 1.0 / 5040.0;
  p = p * r + 1.0 / 720.0;
  p = p * r + 1.0 / 120.0;
  p = p * r + 1.0 / 24.0;
  p = p * r + 1.0 / 6.0;
  p = p * r + 0.5;
  p = p * r + 1.0;
  p = p * r + 1.0;
  // 2^n = 2^n1 2^n2 with n1 = floor(n / 2): both factors are normal doubles
  // for n in [-1076, 1023], and the second product rounds to a subnormal or
  // to 0 as e^x does (no select, which would keep the loops scalar).
  const std::int64_t k = static_cast<std::int64_t>(std::bit_cast<std::uint64_t>(t) - std::bit_cast<std::uint64_t>(kShifter));
  const std::int64_t k1 = k >> 1, k2 = k - k1;
  const double s1 = std::bit_cast<double>(static_cast<std::uint64_t>(k1 + 1023) << 52);
  const double s2 = std::bit_cast<double>(static_cast<std::uint64_t>(k2 + 1023) << 52);
  return (p * s1) * s2;
}

// The same in single precision, for results stored as floats (the
// transmittance table: 16 per AVX-512 instruction, and 7 Taylor terms
// instead of 13).
//   exp_inline_f(x)  e^x, x clamped to [-104, 88.7]; relative error
//                    < 1.5e-7 for normal results (against std::exp in double,
//                    vector_math_test.cpp), subnormal results rounded as
//                    usual, 0 below -103.9 (and for -inf), NaN for NaN.
//                    Cody & Waite with ln 2 split in a high part with 12
//                    trailing zero bits (n ln2_hi exact for |n| < 2^12),
//                    e^r to r^7 (remainder < 6e-9 relative), 2^n in two
//                    factors as above.
inline float exp_inline_f(float x) {
  constexpr float kLog2e = 1.44269504f;
  constexpr float kShifter = 0x1.8p23f;
  constexpr float kLn2Hi = 0x1.62e000p-1f, kLn2Lo = 0x1.0bfbe8p-15f;
  const float xc = std::max(std::min(x, 88.7f), -104.0f);  // NaN passes through
  const float t = xc * kLog2e + kShifter;
  const float n = t - kShifter;
  const float r = (xc - n * kLn2Hi) - n * kLn2Lo;
  float p = 1.0f / 5040.0f;
  p = p * r + 1.0f / 720.0f;
  p = p * r + 1.0f / 120.0f;
  p = p * r + 1.0f / 24.0f;
  p = p * r + 1.0f / 6.0f;
  p = p * r + 0.5f;
  p = p * r + 1.0f;
  p = p * r + 1.0f;
  const std::int32_t k = static_cast<std::int32_t>(std::bit_cast<std::uint32_t>(t) - std::bit_cast<std::uint32_t>(kShifter));
  const std::int32_t k1 = k >> 1, k2 = k - k1;
  const float s1 = std::bit_cast<float>(static_cast<std::uint32_t>(k1 + 127) << 23);
  const float s2 = std::bit_cast<float>(static_cast<std::uint32_t>(k2 + 127) << 23);
  return (p * s1) * s2;
}

}  // namespace skyfarm::lut
