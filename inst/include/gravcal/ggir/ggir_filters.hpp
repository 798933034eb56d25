// gravcal: the filtered signals of GGIR's g.applymetrics(), per sample, to
// the bit.
//
// GGIR 3.3-9's part 1 (g.getmeta() -> g.applymetrics()) filters each block
// of calibrated samples (about 24 h; the filter state starts from zero at
// every block) with signal::filter() and a Butterworth `Arma` from
// signal::butter(), then derives per-sample signals from the filtered axes
// and averages them per epoch (averagePerEpoch, sumPerEpoch: not here). This
// header gives the per-sample signals; the coefficients come from R
// (signal::butter(), R/ggir-filters.R ggir_filter_coefs()).
//
// 1. filter_arma(): signal 1.8.1's filter.default for an Arma (b, a), with
//    its default zero initial state, which is
//      - all of x NA or NaN: x itself;
//      - x1 = stats::filter(c(init.x, x), b / a[1], sides = 1): R's C
//        routine cfilter (src/library/stats/src/filter.c), over x preceded
//        by length(b) - 1 zeros. Per output, z = 0, then for j = 0, 1, ...
//        z += f[j] * v[i - j], in that order; a NA or NaN operand makes the
//        output NA_real_ (not NaN);
//      - all of x1 NA: x itself; else na.omit(x1) (na.omit.ts): the leading
//        and trailing NAs dropped (is.na: NaN too), so the result can be
//        shorter than x; a NA left inside stops R ("time series contains
//        internal NAs");
//      - stats::filter(., -a[-1] / a[1], method = "recursive"): R's rfilter,
//        zero initial state; sum = v[i], then sum += r[i - 1 - j] * g[j] for
//        j = 0, 1, ...; a NA or NaN operand makes the output NA_real_. (R
//        before 4.3.0 did not test v[i] itself; after na.omit it is never
//        NA, so both give the same bits.)
//    The coefficients are divided here as R divides them (b[j] / a[1],
//    (-a[j]) / a[1]): pass signal::butter()'s b and a untouched.
// 2. ggir_filtered_signal(): what g.applymetrics computes per sample before
//    averaging, for one metric (FilteredMetric), from the three axes:
//      BFX/BFY/BFZ |band(lb, hb)| per axis; BFEN their norm;
//      LFX/LFY/LFZ |low(hb)|; LFEN their norm; LFENMO that norm - 1, values
//        below 0 set to 0;
//      HFX/HFY/HFZ |high(lb)|; HFEN their norm;
//      HFENplus norm(high(lb)) + (norm(low(hb)) - 1), below 0 set to 0. Note
//        GGIR's process_axes() takes the bound of a "low" filter from hb
//        whatever its cut_point: HFENplus's "low at lb" is low at hb;
//      ZCX/ZCY/ZCZ band(zc.lb, zc.hb) of order zc.order; |v| < zc.sb set to
//        0; +1 where v >= 0, -1 below (NA stays NA: ifelse); then
//        |sign(s[k]) - sign(s[k - 1])| * 0.5 for k >= 1, its first value
//        repeated in front (GGIR's zerocross(); needs n >= 2).
//    The norm is sqrt((x^2 + y^2) + z^2), R's order; x^2 is x * x in R. A
//    filtered axis shorter than the block (NA at the block's ends) goes into
//    GGIR's matrix column as R assigns it: recycled when its length divides
//    the block's, else R stops ("number of items to replace is not a
//    multiple of replacement length"); the status says which.
//    GGIR's hb rule (hb = round(sf / 2) - 1 when sf <= 2 hb) and its butter
//    calls are the coefficients' business (R).
//
// R's compiler may fuse z += f * v into one multiply-add where the target
// has one (GCC's default on aarch64): filter_arma's `fused` replays that
// (kernels::replay_fma), as asked of R's own stats::filter() on operands
// where the two differ (R/ggir-filters.R stats_filter_fused()). Nothing
// here depends on long double.
//
// Header-only; no R; the caller owns the signal buffers (allocated here:
// the divided coefficients, and the work space of the convenience overload
// of ggir_filtered_signal()).
#ifndef GRAVCAL_GGIR_FILTERS_HPP
#define GRAVCAL_GGIR_FILTERS_HPP

#include "gravcal/mcu/fp_contract.hpp"

#include <cmath>
#include <cstddef>
#include <vector>

#include "gravcal/decoders/decode.hpp"          // r_na_real()
#include "gravcal/kernels/decode.hpp"  // kernels::replay_fma()

namespace gravcal {

// How R's compiler built stats' filter.c: multiply-adds rounded twice
// (R's arithmetic as written) or fused, per routine.
struct RFilterArith {
  bool conv_fused = false;  // cfilter's z += f[j] * v
  bool rec_fused = false;   // rfilter's sum += r * g[j]
};

// One Arma's coefficients as signal::butter() gives them (a[0] is a[1] in
// R), not divided.
struct ArmaCoefs {
  const double* b = nullptr;
  std::size_t nb = 0;
  const double* a = nullptr;
  std::size_t na = 0;
};

enum class FilterStatus {
  ok,           // length == n
  all_na,       // all of x, or of the convolution, NA: y is x (length n)
  shortened,    // NAs at the ends omitted: length < n values from y[0]
  internal_na,  // R stops: "time series contains internal NAs"
  no_output     // n == 0 (R returns x)
};

struct FilterResult {
  FilterStatus status = FilterStatus::ok;
  std::size_t length = 0;  // values written from y[0]
};

namespace ggir_filters_detail {

inline bool r_ok(double v) { return !std::isnan(v); }  // filter.c's my_isok

inline double madd(double acc, double p, double q, bool fused) {
  return fused ? kernels::replay_fma(p, q, acc) : acc + p * q;  // not contracted
}

}  // namespace ggir_filters_detail

// signal::filter(Arma(b, a), x) with zero initial state (GGIR's call), see
// the header's comment. y: room for n values, distinct from x. The
// coefficients must be finite with a[0] != 0 (R's butter gives a[0] = 1).
inline FilterResult filter_arma(const double* b, std::size_t nb, const double* a, std::size_t na,
                                const double* x, std::size_t n, double* y,
                                RFilterArith arith = RFilterArith()) {
  namespace d = ggir_filters_detail;
  FilterResult res;
  if (n == 0) {
    res.status = FilterStatus::no_output;
    return res;
  }
  bool any_ok = false;
  for (std::size_t i = 0; i < n && !any_ok; ++i) any_ok = d::r_ok(x[i]);
  if (!any_ok) {  // all(is.na(x)): x
    for (std::size_t i = 0; i < n; ++i) y[i] = x[i];
    res.status = FilterStatus::all_na;
    res.length = n;
    return res;
  }
  // b / a[1] and -a[-1] / a[1], as R divides them
  std::vector<double> fb(nb), ga(na > 1 ? na - 1 : 0);
  for (std::size_t j = 0; j < nb; ++j) fb[j] = b[j] / a[0];
  for (std::size_t j = 0; j + 1 < na; ++j) ga[j] = (-a[j + 1]) / a[0];
  const double na_real = r_na_real();
  std::size_t first = 0, last = n;  // the convolution's non-NA span [first, last)
  if (nb > 0) {
    // cfilter over c(rep(0, nb - 1), x), sides = 1: its first nb - 1
    // outputs are NA (cut by na.omit); output i of the rest reads
    // v[i - j] = x[i - j], or a leading zero where i - j < 0.
    for (std::size_t i = 0; i < n; ++i) {
      double z = 0;
      bool bad = false;
      for (std::size_t j = 0; j < nb; ++j) {
        const double tmp = j <= i ? x[i - j] : 0.0;
        if (!d::r_ok(tmp)) {
          bad = true;
          break;
        }
        z = d::madd(z, fb[j], tmp, arith.conv_fused);
      }
      y[i] = bad ? na_real : z;
    }
    // na.omit(): the leading and trailing NAs dropped
    while (first < n && !d::r_ok(y[first])) ++first;
    if (first == n) {  // all(is.na(x1)): x
      for (std::size_t i = 0; i < n; ++i) y[i] = x[i];
      res.status = FilterStatus::all_na;
      res.length = n;
      return res;
    }
    while (!d::r_ok(y[last - 1])) --last;
    for (std::size_t i = first; i < last; ++i) {
      if (!d::r_ok(y[i])) {
        res.status = FilterStatus::internal_na;
        return res;
      }
    }
  } else {
    for (std::size_t i = 0; i < n; ++i) y[i] = x[i];
  }
  const std::size_t len = last - first;
  if (na >= 2) {
    // rfilter in place: output i (written to y[i]) reads input y[first + i]
    // (not yet overwritten: first + i >= i) and the outputs y[i - 1 - j],
    // zero before the start.
    const std::size_t nf = na - 1;
    for (std::size_t i = 0; i < len; ++i) {
      double sum = y[first + i];
      bool bad = !d::r_ok(sum);
      for (std::size_t j = 0; j < nf && !bad; ++j) {
        const double tmp = i >= j + 1 ? y[i - 1 - j] : 0.0;
        if (!d::r_ok(tmp)) {
          bad = true;
          break;
        }
        sum = d::madd(sum, tmp, ga[j], arith.rec_fused);
      }
      y[i] = bad ? na_real : sum;
    }
  } else if (first > 0) {
    for (std::size_t i = 0; i < len; ++i) y[i] = y[first + i];
  }
  res.length = len;
  res.status = len == n ? FilterStatus::ok : FilterStatus::shortened;
  return res;
}

inline FilterResult filter_arma(const ArmaCoefs& c, const double* x, std::size_t n, double* y,
                                RFilterArith arith = RFilterArith()) {
  return filter_arma(c.b, c.nb, c.a, c.na, x, n, y, arith);
}

// The per-sample signals of g.applymetrics() that need a filter.
enum class FilteredMetric {
  BFEN, BFX, BFY, BFZ,
  LFENMO, LFEN, LFX, LFY, LFZ,
  HFEN, HFX, HFY, HFZ,
  HFENplus,
  ZCX, ZCY, ZCZ
};

// GGIR's names (metashort's columns), in FilteredMetric's order.
inline const char* filtered_metric_name(FilteredMetric m) {
  static const char* const names[] = {"BFEN", "BFX", "BFY", "BFZ", "LFENMO", "LFEN",
                                      "LFX", "LFY", "LFZ", "HFEN", "HFX", "HFY",
                                      "HFZ", "HFENplus", "ZCX", "ZCY", "ZCZ"};
  return names[static_cast<int>(m)];
}

// false when the name is none of them.
inline bool filtered_metric_from_name(const char* name, FilteredMetric* m) {
  for (int k = 0; k <= static_cast<int>(FilteredMetric::ZCZ); ++k) {
    const char* s = filtered_metric_name(static_cast<FilteredMetric>(k));
    const char* t = name;
    while (*s != 0 && *s == *t) ++s, ++t;
    if (*s == 0 && *t == 0) {
      *m = static_cast<FilteredMetric>(k);
      return true;
    }
  }
  return false;
}

// The coefficient sets g.applymetrics() builds for block's sf (GGIR's
// names; hb already capped by GGIR's rule).
struct GgirFilterCoefs {
  ArmaCoefs band;  // butter(n, c(lb, hb) / (sf / 2), "pass"): BF*
  ArmaCoefs low;   // butter(n, hb / (sf / 2), "low"): LF*, HFENplus
  ArmaCoefs high;  // butter(n, lb / (sf / 2), "high"): HF*, HFENplus
  ArmaCoefs zc;    // butter(zc.order, c(zc.lb, zc.hb) / (sf / 2), "pass"): ZC*
  double zc_sb = 0.01;
};

enum class SignalStatus {
  ok,
  internal_na,         // R stops in na.omit: "time series contains internal NAs"
  replacement_length,  // R stops: "number of items to replace is not a
                       // multiple of replacement length"
  too_short            // ZC* of fewer than 2 samples (GGIR's zerocross())
};

namespace ggir_filters_detail {

// data_processed[, i] = signal::filter(coef, data[, i]) into a column of n.
inline SignalStatus filter_column(const ArmaCoefs& c, const double* x, std::size_t n, double* y,
                                  RFilterArith arith) {
  const FilterResult r = filter_arma(c, x, n, y, arith);
  if (r.status == FilterStatus::internal_na) return SignalStatus::internal_na;
  if (r.status == FilterStatus::shortened) {  // R's matrix assignment recycles
    if (n % r.length != 0) return SignalStatus::replacement_length;
    for (std::size_t i = r.length; i < n; ++i) y[i] = y[i - r.length];
  }
  return SignalStatus::ok;
}

// R's sign() of a double
inline double r_sign(double v) {
  if (std::isnan(v)) return v;
  return v > 0 ? 1.0 : (v == 0 ? 0.0 : -1.0);
}

// EuclideanNorm() of three columns, each taken |.| first when `absolute`
// (abs(data_processed) in GGIR: the same squares, written as GGIR does).
inline double norm3(double p, double q, double r, bool absolute) {
  if (absolute) {
    p = std::fabs(p);
    q = std::fabs(q);
    r = std::fabs(r);
  }
  return std::sqrt(p * p + q * q + r * r);
}

}  // namespace ggir_filters_detail

// One metric's per-sample signal over a block of n samples (x, y, z:
// calibrated axes) into out[0, n). work: room for 3 n doubles (the filtered
// axes), none of it aliasing x, y, z or out. On a status other than ok, out
// holds nothing defined (R stops there).
inline SignalStatus ggir_filtered_signal(FilteredMetric m, const double* x, const double* y,
                                         const double* z, std::size_t n,
                                         const GgirFilterCoefs& c, double* out, double* work,
                                         RFilterArith arith = RFilterArith()) {
  namespace d = ggir_filters_detail;
  const double* axes[3] = {x, y, z};
  double* f[3] = {work, work + n, work + 2 * n};
  SignalStatus s = SignalStatus::ok;
  auto filter3 = [&](const ArmaCoefs& co) {
    for (int k = 0; k < 3 && s == SignalStatus::ok; ++k)
      s = d::filter_column(co, axes[k], n, f[k], arith);
    return s == SignalStatus::ok;
  };
  auto one_axis = [&](const ArmaCoefs& co, int k) {
    s = d::filter_column(co, axes[k], n, out, arith);
    if (s == SignalStatus::ok)
      for (std::size_t i = 0; i < n; ++i) out[i] = std::fabs(out[i]);
    return s;
  };
  switch (m) {
    case FilteredMetric::BFX: return one_axis(c.band, 0);
    case FilteredMetric::BFY: return one_axis(c.band, 1);
    case FilteredMetric::BFZ: return one_axis(c.band, 2);
    case FilteredMetric::LFX: return one_axis(c.low, 0);
    case FilteredMetric::LFY: return one_axis(c.low, 1);
    case FilteredMetric::LFZ: return one_axis(c.low, 2);
    case FilteredMetric::HFX: return one_axis(c.high, 0);
    case FilteredMetric::HFY: return one_axis(c.high, 1);
    case FilteredMetric::HFZ: return one_axis(c.high, 2);
    case FilteredMetric::BFEN:
    case FilteredMetric::LFEN:
    case FilteredMetric::HFEN: {
      const ArmaCoefs& co = m == FilteredMetric::BFEN ? c.band
                            : m == FilteredMetric::LFEN ? c.low : c.high;
      if (!filter3(co)) return s;
      for (std::size_t i = 0; i < n; ++i) out[i] = d::norm3(f[0][i], f[1][i], f[2][i], true);
      return s;
    }
    case FilteredMetric::LFENMO: {
      if (!filter3(c.low)) return s;
      for (std::size_t i = 0; i < n; ++i) {
        const double v = d::norm3(f[0][i], f[1][i], f[2][i], true) - 1;
        out[i] = v < 0 ? 0.0 : v;  // NA stays NA (which() skips it)
      }
      return s;
    }
    case FilteredMetric::HFENplus: {
      if (!filter3(c.low)) return s;  // GCP = EN(low) - gravity, not |.|
      for (std::size_t i = 0; i < n; ++i) out[i] = d::norm3(f[0][i], f[1][i], f[2][i], false) - 1;
      if (!filter3(c.high)) return s;
      for (std::size_t i = 0; i < n; ++i) {
        const double v = d::norm3(f[0][i], f[1][i], f[2][i], false) + out[i];
        out[i] = v < 0 ? 0.0 : v;
      }
      return s;
    }
    case FilteredMetric::ZCX:
    case FilteredMetric::ZCY:
    case FilteredMetric::ZCZ: {
      if (n < 2) return SignalStatus::too_short;
      const int k = m == FilteredMetric::ZCX ? 0 : m == FilteredMetric::ZCY ? 1 : 2;
      double* v = f[0];
      s = d::filter_column(c.zc, axes[k], n, v, arith);
      if (s != SignalStatus::ok) return s;
      const double na_real = r_na_real();
      for (std::size_t i = 0; i < n; ++i) {
        double w = v[i];
        if (std::fabs(w) < c.zc_sb) w = 0;  // false for NA
        // ifelse(w >= 0, 1, -1): a NA test gives NA_real_
        v[i] = std::isnan(w) ? na_real : (w >= 0 ? 1.0 : -1.0);
      }
      for (std::size_t i = 1; i < n; ++i)
        out[i] = std::fabs(d::r_sign(v[i]) - d::r_sign(v[i - 1])) * 0.5;
      out[0] = out[1];
      return s;
    }
  }
  return s;
}

// The same with its own work space.
inline SignalStatus ggir_filtered_signal(FilteredMetric m, const double* x, const double* y,
                                         const double* z, std::size_t n,
                                         const GgirFilterCoefs& c, double* out,
                                         RFilterArith arith = RFilterArith()) {
  std::vector<double> work(3 * n);
  return ggir_filtered_signal(m, x, y, z, n, c, out, work.data(), arith);
}

}  // namespace gravcal

#endif  // GRAVCAL_GGIR_FILTERS_HPP
