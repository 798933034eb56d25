// Rcpp glue for the kernel table (inst/include/gravcal/kernels/kernels.hpp): the
// switch the tests and benchmarks use, and every variant of a kernel run on
// the same input, for tests/testthat/test-simd.R to compare with the scalar
// reference. Converts and calls, nothing more.
#include "gravcal/mcu/fp_contract.hpp"  // first: see there

#include <Rcpp.h>

#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "gravcal/kernels/kernels.hpp"

namespace {

namespace k = gravcal::kernels;

// A long double's significant bytes (10 for x87's format), so that R can
// compare them bit for bit.
Rcpp::RawVector ld_bytes(const long double* v, int n) {
  const std::size_t b =
      std::numeric_limits<long double>::digits == 64 ? 10 : sizeof(long double);
  Rcpp::RawVector out(static_cast<R_xlen_t>(b) * n);
  for (int i = 0; i < n; ++i) std::memcpy(&out[static_cast<R_xlen_t>(b) * i], v + i, b);
  return out;
}

Rcpp::NumericVector num(const double* v, std::size_t n) {
  return Rcpp::NumericVector(v, v + n);
}

Rcpp::NumericVector lanes12(const double (*s)[4]) { return num(&s[0][0], 12); }

const double* col(const Rcpp::List& a, const char* name) {
  SEXP v = a[name];
  if (TYPEOF(v) != REALSXP) Rcpp::stop("`%s` must be a numeric vector", name);
  return REAL(v);
}

std::size_t len(const Rcpp::List& a, const char* name) {
  return static_cast<std::size_t>(Rf_xlength(a[name]));
}

// One kernel's variants on the same input: out(f) gives the outputs of
// variant f. Variants not compiled, or (AVX2) not runnable on this
// processor, are left out.
template <class F, class Out>
Rcpp::List each_variant(const k::Variants<F>& v, Out out) {
  Rcpp::List res;
  res["scalar"] = out(v.scalar);
  if (v.sse2 != nullptr) res["sse2"] = out(v.sse2);
  if (v.avx2 != nullptr && gravcal::simd_detail::cpu_has_avx2()) res["avx2"] = out(v.avx2);
  return res;
}

Rcpp::List window_kernel(const std::string& name, const Rcpp::List& a) {
  if (name == "run_end") {
    const double* v = col(a, "v");
    const std::size_t n = len(a, "v");
    const std::size_t i = static_cast<std::size_t>(Rcpp::as<double>(a["i"]));
    if (i >= n) Rcpp::stop("`i` must be below the length of `v`");
    return each_variant(k::run_end_variants, [&](k::RunEndFn f) {
      return Rcpp::List::create(Rcpp::_["end"] = static_cast<double>(f(v, i, n)));
    });
  }
  if (name == "order_next") {
    const double* w = col(a, "w");
    const std::size_t n = len(a, "w");
    const double v = Rcpp::as<double>(a["v"]);
    const bool down = Rcpp::as<bool>(a["down"]);
    return each_variant(k::order_next_variants, [&](k::OrderNextFn f) {
      double val = 0;
      std::size_t count = 0;
      f(w, n, v, down, &val, &count);
      return Rcpp::List::create(Rcpp::_["val"] = val, Rcpp::_["count"] = static_cast<double>(count));
    });
  }
  if (name == "offset_divide") {
    const Rcpp::NumericVector p = a["p"];
    const double o = Rcpp::as<double>(a["o"]), s = Rcpp::as<double>(a["s"]);
    const double term = Rcpp::as<double>(a["term"]);
    const bool add = Rcpp::as<bool>(a["add"]);
    return each_variant(k::offset_divide_variants, [&](k::OffsetDivideFn f) {
      std::vector<double> v(p.begin(), p.end());
      f(v.data(), v.size(), o, s, term, add);
      return Rcpp::List::create(Rcpp::_["p"] = Rcpp::NumericVector(v.begin(), v.end()));
    });
  }
  const double* x = col(a, "x");
  const double* y = col(a, "y");
  const double* z = col(a, "z");
  const std::size_t m = len(a, "x");
  if (len(a, "y") != m || len(a, "z") != m) Rcpp::stop("`x`, `y` and `z` must have one length");
  const double* const v[3] = {x, y, z};
  if (name == "stream_window") {
    if (m == 0) Rcpp::stop("a window needs a sample");
    const double* t = Rf_isNull(a["t"]) ? nullptr : col(a, "t");
    if (t != nullptr && len(a, "t") != m) Rcpp::stop("`t` must have the length of `x`");
    return each_variant(k::stream_window_variants, [&](k::StreamWindowFn f) {
      gravcal::StreamSums o;
      f(x, y, z, t, m, o);
      return Rcpp::List::create(
          Rcpp::_["s"] = lanes12(o.s), Rcpp::_["q"] = lanes12(o.q), Rcpp::_["lo"] = num(o.lo, 3),
          Rcpp::_["hi"] = num(o.hi, 3), Rcpp::_["nrm"] = num(o.nrm, 4),
          Rcpp::_["st"] = num(o.st, 4), Rcpp::_["zero"] = o.zero);
    });
  }
  if (name == "r_scan") {
    if (m == 0) Rcpp::stop("a window needs a sample");
    const Rcpp::NumericVector c0 = a["c"];
    const bool want_w = Rcpp::as<bool>(a["want_w"]);
    return each_variant(k::r_scan_variants, [&](k::RScanFn f) {
      long double c[4] = {c0[0], c0[1], c0[2], c0[3]};
      k::RScanOut o;
      f(x, y, z, m, c, want_w, o);
      return Rcpp::List::create(
          Rcpp::_["c"] = ld_bytes(c, 4), Rcpp::_["c_double"] = Rcpp::NumericVector::create(
                                              static_cast<double>(c[0]), static_cast<double>(c[1]),
                                              static_cast<double>(c[2]), static_cast<double>(c[3])),
          Rcpp::_["w"] = want_w ? Rcpp::RObject(ld_bytes(o.w, 3)) : Rcpp::RObject(),
          Rcpp::_["lo"] = num(o.lo, 3), Rcpp::_["hi"] = num(o.hi, 3),
          Rcpp::_["ls"] = lanes12(o.ls), Rcpp::_["zero"] = o.zero,
          Rcpp::_["repeats"] = static_cast<double>(o.repeats));
    });
  }
  if (name == "r_var_means3") {
    return each_variant(k::r_var_means3_variants, [&](k::RVarMeans3Fn f) {
      double mean[3] = {NA_REAL, NA_REAL, NA_REAL};
      const bool ok = f(v, m, mean);
      return Rcpp::List::create(Rcpp::_["decided"] = ok, Rcpp::_["mean"] = num(mean, 3));
    });
  }
  if (name == "first_zero") {
    return each_variant(k::first_zero_variants, [&](k::FirstZeroFn f) {
      return Rcpp::List::create(Rcpp::_["at"] = static_cast<double>(f(x, y, z, m)));
    });
  }
  Rcpp::stop("unknown kernel '%s'", name);
}

Rcpp::List decode_kernel(const std::string& name, const Rcpp::List& a) {
  if (name == "word_sum") {
    const Rcpp::RawVector b = a["bytes"];
    if (b.size() % 32 != 0) Rcpp::stop("`bytes` must be a multiple of 32 bytes");
    return each_variant(k::word_sum_variants, [&](k::WordSumFn f) {
      return Rcpp::List::create(
          Rcpp::_["sum"] = static_cast<double>(f(b.begin(), static_cast<std::size_t>(b.size()))));
    });
  }
  if (name == "scale_packed") {
    const Rcpp::RawVector b = a["bytes"];
    const double scale = Rcpp::as<double>(a["scale"]);
    const int n = static_cast<int>(b.size() / 4);
    return each_variant(k::scale_packed_variants, [&](k::ScalePackedFn f) {
      std::vector<double> x(n), y(n), z(n);
      f(b.begin(), scale, n, x.data(), y.data(), z.data());
      return Rcpp::List::create(Rcpp::_["x"] = x, Rcpp::_["y"] = y, Rcpp::_["z"] = z);
    });
  }
  if (name == "span_times") {
    const int n = Rcpp::as<int>(a["len"]);
    if (n < 1) Rcpp::stop("`len` must be at least 1");
    const double start = Rcpp::as<double>(a["start"]), spacing = Rcpp::as<double>(a["spacing"]);
    return each_variant(k::span_times_variants, [&](k::SpanTimesFn f) {
      std::vector<double> dst(static_cast<std::size_t>(n) + 1, 0.0);
      f(dst.data(), n, start, spacing);
      return Rcpp::List::create(Rcpp::_["times"] = dst);
    });
  }
  if (name == "cwa_interp") {
    const std::size_t n = len(a, "time");
    if (n < 2 || len(a, "x") != n || len(a, "y") != n || len(a, "z") != n) {
      Rcpp::stop("`time`, `x`, `y` and `z` must have one length, at least 2");
    }
    k::InterpSpan sp;
    sp.time = col(a, "time");
    sp.v[0] = col(a, "x");
    sp.v[1] = col(a, "y");
    sp.v[2] = col(a, "z");
    sp.len = static_cast<int>(n - 1);
    sp.lim = sp.time[n - 1];
    sp.start = Rcpp::as<double>(a["start"]);
    sp.step = Rcpp::as<double>(a["step"]);
    sp.end = Rcpp::as<double>(a["end"]);
    sp.temp = Rcpp::as<double>(a["temp"]);
    // GGIRread's multiply-add fused (the scalar reference only: a caller
    // that sets it runs no other variant)
    sp.fused = a.containsElementNamed("fused") && Rcpp::as<bool>(a["fused"]);
    const std::int64_t pos = static_cast<std::int64_t>(Rcpp::as<double>(a["pos"]));
    const std::int64_t stop = static_cast<std::int64_t>(Rcpp::as<double>(a["stop"]));
    const int source0 = Rcpp::as<int>(a["source"]);
    if (source0 < 1 || source0 > sp.len || stop < pos) Rcpp::stop("bad `source` or `stop`");
    const std::size_t room = static_cast<std::size_t>(stop - pos);
    return each_variant(k::cwa_interp_variants, [&](k::CwaInterpFn f) {
      std::vector<double> ox(room), oy(room), oz(room), ot(room), otime(room);
      const k::InterpOut o{ox.data(), oy.data(), oz.data(), ot.data(), otime.data()};
      int source = source0;
      double last[3] = {-1, -2, -3}, at = -4;
      const std::int64_t w = f(sp, pos, stop, source, o, last, at);
      const std::size_t ws = static_cast<std::size_t>(w);
      return Rcpp::List::create(
          Rcpp::_["written"] = static_cast<double>(w), Rcpp::_["x"] = num(ox.data(), ws),
          Rcpp::_["y"] = num(oy.data(), ws), Rcpp::_["z"] = num(oz.data(), ws),
          Rcpp::_["t"] = num(ot.data(), ws), Rcpp::_["time"] = num(otime.data(), ws),
          Rcpp::_["source"] = source, Rcpp::_["last"] = num(last, 3), Rcpp::_["at"] = at);
    });
  }
  if (name == "hex_counts") {
    const Rcpp::RawVector b = a["bytes"];
    const std::size_t n = static_cast<std::size_t>(b.size());
    const std::size_t rows = n / 12 + 1;
    return each_variant(k::hex_counts_variants, [&](k::HexCountsFn f) {
      std::vector<std::uint16_t> raw(3 * rows, 0);
      auto* r = reinterpret_cast<std::uint16_t(*)[3]>(raw.data());
      const unsigned bad = f(b.begin(), n / 12, n, r, rows);
      Rcpp::IntegerVector counts(raw.begin(), raw.begin() + 3 * (n / 12));
      return Rcpp::List::create(Rcpp::_["bad"] = bad != 0,
                                Rcpp::_["counts"] = bad != 0 ? Rcpp::RObject() : Rcpp::RObject(counts));
    });
  }
  Rcpp::stop("unknown kernel '%s'", name);
}

}  // namespace

// Every compiled variant of kernel `name` on the inputs in `args` (what
// each kernel takes: tests/testthat/test-simd.R), as a list with one
// element per variant (scalar, sse2, avx2; AVX2 only where the processor
// has it), each the kernel's outputs.
// [[Rcpp::export(rng = false)]]
Rcpp::List gc_kernel_check(const std::string& name, const Rcpp::List& args) {
  if (name == "word_sum" || name == "scale_packed" || name == "span_times" ||
      name == "cwa_interp" || name == "hex_counts") {
    return decode_kernel(name, args);
  }
  return window_kernel(name, args);
}

// The kernels and the variant each runs in this process.
// [[Rcpp::export(rng = false)]]
Rcpp::CharacterVector gc_kernels() {
  const k::Table& t = k::active();
  Rcpp::CharacterVector out;
  k::each_kernel(t, [&](auto f, const auto& v, const char* name) {
    out.push_back(f == v.avx2 ? "avx2" : f == v.sse2 ? "sse2" : "scalar", name);
  });
  return out;
}

// Allows the AVX2 kernels (true; where the processor has AVX2) or only the
// baseline ones (false), for the tests that compare them; returns whether
// AVX2 is now allowed.
// [[Rcpp::export(rng = false)]]
bool gc_set_avx2(bool on) {
  return gravcal::set_avx2(on);
}

// Whether the AVX2 kernels are allowed in this process.
// [[Rcpp::export(rng = false)]]
bool gc_use_avx2() {
  return gravcal::use_avx2();
}
