// SKYFARM_LUT_SIMD_CLONES before a function definition: its per-bin loops
// are compiled twice on x86-64 Linux GCC, for AVX2 and for the baseline
// (SSE2), and the loader picks one per CPU (function multi-versioning, an
// ifunc).  Only inline code is compiled into the clones, so hot loops call
// header-inline helpers (lut::Bilinear, MediumTable::add_sigma_t).  The
// loops are element-wise and without FMA (-std=c++20 compiles with
// -ffp-contract=off), so both clones give the same bits.
#pragma once

#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && defined(__linux__)
#define SKYFARM_LUT_SIMD_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define SKYFARM_LUT_SIMD_CLONES
#endif
