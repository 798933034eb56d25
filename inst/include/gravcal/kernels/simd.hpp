// gravcal: which vector instructions the kernels may be compiled with.
//
// The only place that says so. GRAVCAL_SSE2: the platform's baseline has
// SSE2 (x86-64), so SSE2 kernels are compiled in and may run anywhere.
// GRAVCAL_AVX2: AVX2 kernels are compiled function by function
// (GRAVCAL_TARGET_AVX2), to be run only where the processor has AVX2; the
// choice is made once, in the kernel table (kernels.hpp), never inside a
// kernel.
//
// GRAVCAL_NO_SIMD defined when compiling: no vector kernel at all (the
// scalar references only; the results are the same bits). GRAVCAL_NO_AVX2:
// no AVX2 kernel. AVX2 needs GCC or clang on x86.
//
// Header-only, standard headers only (and the compiler's intrinsics
// headers on x86).
#ifndef GRAVCAL_SIMD_HPP
#define GRAVCAL_SIMD_HPP

#include "gravcal/mcu/fp_contract.hpp"

#include <cstdlib>

#if defined(__SSE2__) && !defined(GRAVCAL_NO_SIMD)
#define GRAVCAL_SSE2 1
#include <emmintrin.h>
#endif

#if defined(GRAVCAL_SSE2) && defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__)) && \
    !defined(GRAVCAL_NO_AVX2)
#define GRAVCAL_AVX2 1
#define GRAVCAL_TARGET_AVX2 __attribute__((target("avx2")))
#include <immintrin.h>
#endif

namespace gravcal {
namespace simd_detail {

// Whether the processor has AVX2 (false where no AVX2 kernel is compiled).
inline bool cpu_has_avx2() {
#if defined(GRAVCAL_AVX2)
  __builtin_cpu_init();
  return __builtin_cpu_supports("avx2") != 0;
#else
  return false;
#endif
}

}  // namespace simd_detail

namespace kernels {

// The instruction sets a kernel can be had in.
enum Level : int { scalar = 0, sse2 = 1, avx2 = 2 };

// One kernel's variants, all with the same signature and the same results
// to the bit: the scalar reference and the vector code standing in for it
// (null where there is none, or it is not compiled).
template <class F>
struct Variants {
  F scalar;
  F sse2;
  F avx2;
  constexpr F at(int level) const {
    return level == Level::avx2 ? avx2 : level == Level::sse2 ? sse2 : scalar;
  }
};

}  // namespace kernels
}  // namespace gravcal

// A variant's name where it is compiled, else null (for Variants).
#if defined(GRAVCAL_SSE2)
#define GRAVCAL_IF_SSE2(f) f
#else
#define GRAVCAL_IF_SSE2(f) nullptr
#endif
#if defined(GRAVCAL_AVX2)
#define GRAVCAL_IF_AVX2(f) f
#else
#define GRAVCAL_IF_AVX2(f) nullptr
#endif

#endif  // GRAVCAL_SIMD_HPP
