// gravcal: optional AVX2 code paths, chosen when the program runs.
//
// The package is built for the baseline of its platform (SSE2 on x86-64),
// so code for newer instructions is compiled function by function
// (GRAVCAL_TARGET_AVX2) and called only where use_avx2() says the processor
// has them. Every such path gives the same bits as the baseline one it
// stands in for (integer work, or the same floating-point operations in the
// same order, never fused), and the tests compare the two
// (set_avx2(false) forces the baseline).
//
// GRAVCAL_NO_SIMD or GRAVCAL_NO_AVX2 defined when compiling: no AVX2 code
// at all. Only with GCC or clang on x86. The environment variable
// GRAVCAL_NO_AVX2 set to anything but "" or "0" when the process first asks
// turns the AVX2 paths off (to compare, or to rule them out).
//
// Header-only, standard headers only.
#ifndef GRAVCAL_SIMD_HPP
#define GRAVCAL_SIMD_HPP

#include "fp_contract.hpp"

#include <cstdlib>

#if defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__)) && defined(__SSE2__) && \
    !defined(GRAVCAL_NO_SIMD) && !defined(GRAVCAL_NO_AVX2)
#define GRAVCAL_AVX2 1
#define GRAVCAL_TARGET_AVX2 __attribute__((target("avx2")))
#include <immintrin.h>
#endif

namespace gravcal {

namespace simd_detail {
// -1: not yet asked; 0: baseline; 1: AVX2
inline int& avx2_state() {
  static int s = -1;
  return s;
}
inline bool cpu_has_avx2() {
#if defined(GRAVCAL_AVX2)
  __builtin_cpu_init();
  return __builtin_cpu_supports("avx2") != 0;
#else
  return false;
#endif
}
inline bool env_says_no() {
  const char* e = std::getenv("GRAVCAL_NO_AVX2");
  return e != nullptr && e[0] != '\0' && !(e[0] == '0' && e[1] == '\0');
}
}  // namespace simd_detail

// Whether the AVX2 paths run: the processor has AVX2, GRAVCAL_NO_AVX2 was
// not set and set_avx2(false) was not called.
inline bool use_avx2() {
  int& s = simd_detail::avx2_state();
  if (s < 0) s = simd_detail::cpu_has_avx2() && !simd_detail::env_says_no() ? 1 : 0;
  return s == 1;
}

// Turns the AVX2 paths off (false) or back on where the processor has AVX2
// (true); returns whether they now run. For tests and benchmarks.
inline bool set_avx2(bool on) {
  simd_detail::avx2_state() = on && simd_detail::cpu_has_avx2() ? 1 : 0;
  return use_avx2();
}

}  // namespace gravcal

#endif  // GRAVCAL_SIMD_HPP
