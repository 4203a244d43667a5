// SKYFARM_LUT_SIMD_CLONES before a function definition: its loops are
// compiled three times on x86-64 Linux GCC, for AVX-512 (x86-64-v4: 8
// doubles per instruction), AVX2 and the baseline (SSE2), and the loader
// picks one per CPU (function multi-versioning, an ifunc).  Only inline
// code is compiled into the clones, so hot loops call header-inline helpers
// (lut::Bilinear, lut::exp_inline, TransmittanceLut::mu_position).
//
// All clones give the same bits: the loops are element-wise (GCC does not
// reorder a floating-point sum without -ffast-math), and contraction to FMA
// is switched off here (GCC's default for C++ is -ffp-contract=fast, and
// x86-64-v4 has FMA, which rounds once where a * b + c rounds twice).
// Building with -DSKYFARM_LUT_SIMD_CLONES= (empty) leaves the baseline only,
// to compare.
#pragma once

#ifndef SKYFARM_LUT_SIMD_CLONES
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && defined(__linux__)
#define SKYFARM_LUT_SIMD_CLONES \
  __attribute__((optimize("fp-contract=off"), target_clones("arch=x86-64-v4", "avx2", "default")))
#else
#define SKYFARM_LUT_SIMD_CLONES
#endif
#endif
