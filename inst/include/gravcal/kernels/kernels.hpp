// gravcal: the kernel table, the one place where the instruction set is
// chosen.
//
// The loops that have vector code (kernels/*.hpp: window statistics, the
// device decoders, GGIR's calibration of a block) are called through one
// table of function pointers, filled once, when first used: each kernel its
// best variant for this processor (AVX2 where it has it, else SSE2 where
// compiled, else the scalar reference). No kernel tests the processor
// itself. Every variant gives its reference's bits, so the choice changes
// only the time; and a variant stays only where it saves a measured share
// of a week's calibration or part 1 (5 % for floating-point ones:
// bench/results/ab-kernels.md).
//
// Environment, read when the table is filled:
// - GRAVCAL_NO_AVX2 set to anything but "" or "0": no AVX2 variant.
// - GRAVCAL_KERNELS="name=level,...", level scalar, sse2 or avx2, name a
//   kernel's (Table's field) or "all", the last item naming a kernel
//   winning: at most that level for that kernel (for measuring what a
//   variant saves: bench/ab.sh).
// set_avx2() refills the table (for the tests).
//
// Where the build has no vector code (GRAVCAL_NO_SIMD, or not x86) the
// table is a constant of scalar references: nothing is read or chosen.
//
// Header-only, standard headers only.
#ifndef GRAVCAL_KERNELS_HPP
#define GRAVCAL_KERNELS_HPP

#include "gravcal/mcu/fp_contract.hpp"

#include "gravcal/kernels/simd.hpp"
#include "gravcal/kernels/apply.hpp"
#include "gravcal/kernels/decode.hpp"
#include "gravcal/kernels/r_mean.hpp"
#include "gravcal/kernels/window.hpp"

#if defined(GRAVCAL_SSE2)
#include <cstdlib>
#include <cstring>
#endif

namespace gravcal {
namespace kernels {

struct Table {
  int level = scalar;  // the highest instruction set allowed
  // window statistics (kernels/window.hpp, kernels/r_mean.hpp)
  RunEndFn run_end = nullptr;
  StreamWindowFn stream_window = nullptr;
  RScanFn r_scan = nullptr;
  RVarMeans3Fn r_var_means3 = nullptr;
  FirstZeroFn first_zero = nullptr;
  OrderNextFn order_next = nullptr;  // the running median (ggir_epochs.hpp)
  // GGIR's calibration of a block (kernels/apply.hpp)
  OffsetDivideFn offset_divide = nullptr;
  // device decoders (kernels/decode.hpp)
  WordSumFn word_sum = nullptr;
  ScalePackedFn scale_packed = nullptr;
  SpanTimesFn span_times = nullptr;
  CwaInterpFn cwa_interp = nullptr;
  HexCountsFn hex_counts = nullptr;
};

// visit(slot, variants, name) for every kernel of table t.
template <class T, class Visit>
constexpr void each_kernel(T& t, Visit&& visit) {
  visit(t.run_end, run_end_variants, "run_end");
  visit(t.stream_window, stream_window_variants, "stream_window");
  visit(t.r_scan, r_scan_variants, "r_scan");
  visit(t.r_var_means3, r_var_means3_variants, "r_var_means3");
  visit(t.first_zero, first_zero_variants, "first_zero");
  visit(t.order_next, order_next_variants, "order_next");
  visit(t.offset_divide, offset_divide_variants, "offset_divide");
  visit(t.word_sum, word_sum_variants, "word_sum");
  visit(t.scale_packed, scale_packed_variants, "scale_packed");
  visit(t.span_times, span_times_variants, "span_times");
  visit(t.cwa_interp, cwa_interp_variants, "cwa_interp");
  visit(t.hex_counts, hex_counts_variants, "hex_counts");
}

// A table with every slot pick(variants, name).
template <class Pick>
constexpr Table fill(int level, Pick pick) {
  Table t;
  t.level = level;
  each_kernel(t, [&pick](auto& slot, const auto& v, const char* name) { slot = pick(v, name); });
  return t;
}

#if defined(GRAVCAL_SSE2)
namespace table_detail {

inline bool env_no_avx2() {
  const char* e = std::getenv("GRAVCAL_NO_AVX2");
  return e != nullptr && e[0] != '\0' && !(e[0] == '0' && e[1] == '\0');
}

// The level GRAVCAL_KERNELS gives kernel `name` (its last item naming it or
// "all"), at most `level`.
inline int env_level(const char* name, int level) {
  const char* e = std::getenv("GRAVCAL_KERNELS");
  const std::size_t nl = std::strlen(name);
  int given = level;
  while (e != nullptr && *e != '\0') {
    const char* eq = std::strchr(e, '=');
    if (eq == nullptr) break;
    const char* end = std::strchr(eq, ',');
    if (end == nullptr) end = eq + std::strlen(eq);
    const std::size_t kl = static_cast<std::size_t>(eq - e);
    if ((kl == nl && std::strncmp(e, name, nl) == 0) || (kl == 3 && std::strncmp(e, "all", 3) == 0)) {
      const std::size_t vl = static_cast<std::size_t>(end - eq - 1);
      const char* v = eq + 1;
      if (vl == 6 && std::strncmp(v, "scalar", 6) == 0) given = scalar;
      if (vl == 4 && std::strncmp(v, "sse2", 4) == 0) given = sse2;
      if (vl == 4 && std::strncmp(v, "avx2", 4) == 0) given = avx2;
    }
    e = *end == ',' ? end + 1 : end;
  }
  return given < level ? given : level;
}

inline Table choose(int level) {
  return fill(level, [level](const auto& v, const char* name) {
    int l = env_level(name, level);
    while (l > scalar && v.at(l) == nullptr) --l;
    return v.at(l);
  });
}

inline Table& slot() {
  static Table t = choose(simd_detail::cpu_has_avx2() && !env_no_avx2() ? avx2 : sse2);
  return t;
}

}  // namespace table_detail

// The table in use.
inline const Table& active() { return table_detail::slot(); }

inline void refill(int level) { table_detail::slot() = table_detail::choose(level); }
#else
inline const Table& active() {
  static constexpr Table t = fill(scalar, [](const auto& v, const char*) { return v.scalar; });
  return t;
}

inline void refill(int) {}
#endif

// Whether the table's r_var_means3 decides any means; where it does not,
// callers keep R's first pass in a loop of other long double sums.
inline bool r_var_means_available() { return active().r_var_means3 != r_var_means3_scalar; }

}  // namespace kernels

// Whether the table allows the AVX2 variants.
inline bool use_avx2() { return kernels::active().level == kernels::avx2; }

// Allows the AVX2 variants (true; where the processor has AVX2) or only the
// baseline ones (false); returns whether AVX2 is now allowed. For tests and
// benchmarks.
inline bool set_avx2(bool on) {
  kernels::refill(on && simd_detail::cpu_has_avx2() ? kernels::avx2 : kernels::sse2);
  return use_avx2();
}

}  // namespace gravcal

#endif  // GRAVCAL_KERNELS_HPP
