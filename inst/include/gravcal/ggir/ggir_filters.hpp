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
// 2. ggir_filtered_signals(): what g.applymetrics computes per sample before
//    averaging, for metrics (FilteredMetric), from the three axes, each
//    filter run once per axis for all the metrics that read it:
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
// A block is filtered in parts (kFilterChunk samples), each filter's state
// carried from part to part, the signals handed to a sink part by part; a
// block whose filtered values come out NA anywhere is taken again whole,
// with R's NA rules (ggir_filtered_signals()).
//
// Header-only; no R. Allocated here: the divided coefficients and the
// parts' work space (or, for a block taken whole, the block's).
#ifndef GRAVCAL_GGIR_FILTERS_HPP
#define GRAVCAL_GGIR_FILTERS_HPP

#include "gravcal/mcu/fp_contract.hpp"

#include <algorithm>
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

template <bool Fused>
inline double madd(double acc, double p, double q) {
  return Fused ? kernels::replay_fma(p, q, acc) : acc + p * q;  // not contracted
}

// cfilter over c(rep(0, nb - 1), x), sides = 1, outputs i in [from, to)
// into y[i - from]: output i is z = 0, then z += f[j] * v[i - j] for j = 0,
// 1, ..., v[i - j] = x[i - j] or a leading zero where i - j < 0 (x: the
// block from its start); NA_real_ where an operand is NA. Past the leading
// zeros the sum is taken without the tests, and taken again with them only
// where it comes out NaN (a NA operand makes it NaN; an overflow too, and
// the tests then give the same NaN).
template <bool Fused>
inline void convolve(const double* f, std::size_t nb, const double* x, std::size_t from,
                     std::size_t to, double* y) {
  const double na_real = r_na_real();
  auto tested = [&](std::size_t i) {
    double z = 0;
    for (std::size_t j = 0; j < nb; ++j) {
      const double tmp = j <= i ? x[i - j] : 0.0;
      if (!r_ok(tmp)) return na_real;
      z = madd<Fused>(z, f[j], tmp);
    }
    return z;
  };
  std::size_t i = from;
  for (; i < to && i + 1 < nb; ++i) y[i - from] = tested(i);
  // four outputs side by side: each one's sum in its own order, so the
  // same bits as one at a time, but four independent chains
  for (; i + 4 <= to; i += 4) {
    double z0 = 0, z1 = 0, z2 = 0, z3 = 0;
    for (std::size_t j = 0; j < nb; ++j) {
      const double fj = f[j];
      const double* v = x + (i - j);
      z0 = madd<Fused>(z0, fj, v[0]);
      z1 = madd<Fused>(z1, fj, v[1]);
      z2 = madd<Fused>(z2, fj, v[2]);
      z3 = madd<Fused>(z3, fj, v[3]);
    }
    double* out = y + (i - from);
    out[0] = std::isnan(z0) ? tested(i) : z0;
    out[1] = std::isnan(z1) ? tested(i + 1) : z1;
    out[2] = std::isnan(z2) ? tested(i + 2) : z2;
    out[3] = std::isnan(z3) ? tested(i + 3) : z3;
  }
  for (; i < to; ++i) {
    double z = 0;
    for (std::size_t j = 0; j < nb; ++j) z = madd<Fused>(z, f[j], x[i - j]);
    y[i - from] = std::isnan(z) ? tested(i) : z;
  }
}

// rfilter's output i taken with R's tests (recurse()): sum = v[first + i],
// then sum += r[i - 1 - j] * g[j] for j = 0, ..., ng - 1 over the outputs r
// (written over y from y[0]), zero before the start (with `at_start`; else
// the outputs before y[0] are y[-1], y[-2], ...: a stream's history);
// NA_real_ where an operand is NA.
template <bool Fused>
inline double recurse_tested(const double* g, std::size_t ng, const double* y, std::size_t first,
                             std::size_t i, bool at_start = true) {
  double sum = y[first + i];
  if (!r_ok(sum)) return r_na_real();
  for (std::size_t j = 0; j < ng; ++j) {
    const double tmp = (!at_start || i >= j + 1) ? y[static_cast<std::ptrdiff_t>(i) - 1 - static_cast<std::ptrdiff_t>(j)] : 0.0;
    if (!r_ok(tmp)) return r_na_real();
    sum = madd<Fused>(sum, tmp, g[j]);
  }
  return sum;
}

// rfilter in place: output i is written to y[i] over its input y[first +
// i] (not yet overwritten: first + i >= i). Past the start, untested, as
// convolve(). Without `at_start`, y[-ng, 0) holds the outputs before y[0]
// (first = 0).
template <bool Fused>
inline void recurse(const double* g, std::size_t ng, double* y, std::size_t first,
                    std::size_t len, bool at_start = true) {
  for (std::size_t i = 0; i < len; ++i) {
    if (at_start && i < ng) {
      y[i] = recurse_tested<Fused>(g, ng, y, first, i);
      continue;
    }
    double sum = y[first + i];
    for (std::size_t j = 0; j < ng; ++j)
      sum = madd<Fused>(sum, y[static_cast<std::ptrdiff_t>(i) - 1 - static_cast<std::ptrdiff_t>(j)], g[j]);
    y[i] = std::isnan(sum) ? recurse_tested<Fused>(g, ng, y, first, i, at_start) : sum;
  }
}

// recurse() of three columns of len values (first = 0), side by side: the
// same operations on each column in the same order, so the same bits, but
// three independent chains of sums where one would wait on its last sum
// (rfilter's time is that chain's).
template <bool Fused>
inline void recurse3(const double* g, std::size_t ng, double* const y[3], std::size_t len,
                     bool at_start = true) {
  double* const a = y[0];
  double* const b = y[1];
  double* const c = y[2];
  for (std::size_t i = 0; i < len; ++i) {
    if (at_start && i < ng) {
      for (int k = 0; k < 3; ++k) y[k][i] = recurse_tested<Fused>(g, ng, y[k], 0, i);
      continue;
    }
    const std::ptrdiff_t ii = static_cast<std::ptrdiff_t>(i);
    double sa = a[i], sb = b[i], sc = c[i];
    for (std::size_t j = 0; j < ng; ++j) {
      const std::ptrdiff_t at = ii - 1 - static_cast<std::ptrdiff_t>(j);
      sa = madd<Fused>(sa, a[at], g[j]);
      sb = madd<Fused>(sb, b[at], g[j]);
      sc = madd<Fused>(sc, c[at], g[j]);
    }
    a[i] = std::isnan(sa) ? recurse_tested<Fused>(g, ng, a, 0, i, at_start) : sa;
    b[i] = std::isnan(sb) ? recurse_tested<Fused>(g, ng, b, 0, i, at_start) : sb;
    c[i] = std::isnan(sc) ? recurse_tested<Fused>(g, ng, c, 0, i, at_start) : sc;
  }
}

// b / a[1] and -a[-1] / a[1], as R divides them.
struct DividedArma {
  std::vector<double> f, g;
  DividedArma(const double* b, std::size_t nb, const double* a, std::size_t na)
      : f(nb), g(na > 1 ? na - 1 : 0) {
    for (std::size_t j = 0; j < nb; ++j) f[j] = b[j] / a[0];
    for (std::size_t j = 0; j + 1 < na; ++j) g[j] = (-a[j + 1]) / a[0];
  }
};

// filter_arma() up to the recursion: x's NA cases, the convolution into y
// and na.omit()'s span. A result whose status is not ok (all_na,
// internal_na, no_output) is final; else res.length is the span's length
// and `first` its start, and the recursion (recurse_from()) remains.
inline FilterResult filter_front(const DividedArma& d, const double* x, std::size_t n, double* y,
                                 RFilterArith arith, std::size_t* first) {
  FilterResult res;
  *first = 0;
  if (n == 0) {
    res.status = FilterStatus::no_output;
    return res;
  }
  bool any_ok = false;
  for (std::size_t i = 0; i < n && !any_ok; ++i) any_ok = r_ok(x[i]);
  if (!any_ok) {  // all(is.na(x)): x
    for (std::size_t i = 0; i < n; ++i) y[i] = x[i];
    res.status = FilterStatus::all_na;
    res.length = n;
    return res;
  }
  const std::size_t nb = d.f.size();
  std::size_t last = n;  // the convolution's non-NA span [first, last)
  if (nb > 0) {
    // cfilter over the nb - 1 zeros and x: its nb - 1 outputs before x's
    // first are NA (cut by na.omit); output i of the rest reads x[i - j],
    // or a leading zero
    if (arith.conv_fused) convolve<true>(d.f.data(), nb, x, 0, n, y);
    else convolve<false>(d.f.data(), nb, x, 0, n, y);
    // na.omit(): the leading and trailing NAs dropped
    while (*first < n && !r_ok(y[*first])) ++*first;
    if (*first == n) {  // all(is.na(x1)): x
      for (std::size_t i = 0; i < n; ++i) y[i] = x[i];
      res.status = FilterStatus::all_na;
      res.length = n;
      return res;
    }
    while (!r_ok(y[last - 1])) --last;
    for (std::size_t i = *first; i < last; ++i) {
      if (!r_ok(y[i])) {
        res.status = FilterStatus::internal_na;
        return res;
      }
    }
  } else {
    for (std::size_t i = 0; i < n; ++i) y[i] = x[i];
  }
  res.length = last - *first;
  return res;
}

// The rest of filter_arma() after filter_front(): the recursion over the
// span (or the span moved to y[0]); the status ok or shortened.
inline FilterResult recurse_from(const DividedArma& d, double* y, std::size_t n, std::size_t first,
                                 std::size_t len, RFilterArith arith) {
  if (!d.g.empty()) {
    if (arith.rec_fused) recurse<true>(d.g.data(), d.g.size(), y, first, len);
    else recurse<false>(d.g.data(), d.g.size(), y, first, len);
  } else if (first > 0) {
    for (std::size_t i = 0; i < len; ++i) y[i] = y[first + i];
  }
  FilterResult res;
  res.length = len;
  res.status = len == n ? FilterStatus::ok : FilterStatus::shortened;
  return res;
}

}  // namespace ggir_filters_detail

// signal::filter(Arma(b, a), x) with zero initial state (GGIR's call), see
// the header's comment. y: room for n values, distinct from x. The
// coefficients must be finite with a[0] != 0 (R's butter gives a[0] = 1).
inline FilterResult filter_arma(const double* b, std::size_t nb, const double* a, std::size_t na,
                                const double* x, std::size_t n, double* y,
                                RFilterArith arith = RFilterArith()) {
  namespace d = ggir_filters_detail;
  const d::DividedArma da(b, nb, a, na);
  std::size_t first = 0;
  const FilterResult res = d::filter_front(da, x, n, y, arith, &first);
  if (res.status != FilterStatus::ok) return res;
  return d::recurse_from(da, y, n, first, res.length, arith);
}

// filter_arma() of three columns x[k] into y[k] (each distinct from the
// x's), res[k] each one's result: the same bits as three calls. Where
// each column's span is whole (no NA: the usual case), the three
// recursions run side by side (recurse3()).
inline void filter_arma3(const ArmaCoefs& c, const double* const x[3], std::size_t n,
                         double* const y[3], RFilterArith arith, FilterResult res[3]) {
  namespace d = ggir_filters_detail;
  const d::DividedArma da(c.b, c.nb, c.a, c.na);
  std::size_t first[3];
  bool whole = true;
  for (int k = 0; k < 3; ++k) {
    res[k] = d::filter_front(da, x[k], n, y[k], arith, &first[k]);
    whole = whole && res[k].status == FilterStatus::ok && first[k] == 0 && res[k].length == n;
  }
  if (whole && !da.g.empty()) {
    if (arith.rec_fused) d::recurse3<true>(da.g.data(), da.g.size(), y, n);
    else d::recurse3<false>(da.g.data(), da.g.size(), y, n);
    return;
  }
  for (int k = 0; k < 3; ++k) {
    if (res[k].status == FilterStatus::ok) res[k] = d::recurse_from(da, y[k], n, first[k], res[k].length, arith);
  }
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

// data_processed[, i] <- a column's filter_arma() result r (in y, n long):
// its status, the shortened result recycled as R's matrix assignment does.
inline SignalStatus assign_column(const FilterResult& r, double* y, std::size_t n) {
  if (r.status == FilterStatus::internal_na) return SignalStatus::internal_na;
  if (r.status == FilterStatus::shortened) {  // R's matrix assignment recycles
    if (n % r.length != 0) return SignalStatus::replacement_length;
    for (std::size_t i = r.length; i < n; ++i) y[i] = y[i - r.length];
  }
  return SignalStatus::ok;
}

// data_processed[, i] = signal::filter(coef, data[, i]) into a column of n.
inline SignalStatus filter_column(const ArmaCoefs& c, const double* x, std::size_t n, double* y,
                                  RFilterArith arith) {
  return assign_column(filter_arma(c, x, n, y, arith), y, n);
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

// The filter a metric's signal reads: the coefficient set, in the order
// GGIR runs them (HFENplus reads "low", then "high").
enum class FilterGroup { band, low, high, zc };
constexpr int kFilterGroups = 4;

namespace ggir_filters_detail {

// What metric m reads: its last filter group, its axis (0, 1, 2; -1 for all
// three), and whether it also reads "low" first (HFENplus).
struct MetricUse {
  FilterGroup group;
  int axis;
  bool low_first;
};

inline MetricUse metric_use(FilteredMetric m) {
  switch (m) {
    case FilteredMetric::BFEN: return {FilterGroup::band, -1, false};
    case FilteredMetric::BFX: return {FilterGroup::band, 0, false};
    case FilteredMetric::BFY: return {FilterGroup::band, 1, false};
    case FilteredMetric::BFZ: return {FilterGroup::band, 2, false};
    case FilteredMetric::LFENMO:
    case FilteredMetric::LFEN: return {FilterGroup::low, -1, false};
    case FilteredMetric::LFX: return {FilterGroup::low, 0, false};
    case FilteredMetric::LFY: return {FilterGroup::low, 1, false};
    case FilteredMetric::LFZ: return {FilterGroup::low, 2, false};
    case FilteredMetric::HFEN: return {FilterGroup::high, -1, false};
    case FilteredMetric::HFX: return {FilterGroup::high, 0, false};
    case FilteredMetric::HFY: return {FilterGroup::high, 1, false};
    case FilteredMetric::HFZ: return {FilterGroup::high, 2, false};
    case FilteredMetric::HFENplus: return {FilterGroup::high, -1, true};
    case FilteredMetric::ZCX: return {FilterGroup::zc, 0, false};
    case FilteredMetric::ZCY: return {FilterGroup::zc, 1, false};
    case FilteredMetric::ZCZ: return {FilterGroup::zc, 2, false};
  }
  return {FilterGroup::band, -1, false};
}

inline const ArmaCoefs& group_coefs(const GgirFilterCoefs& c, FilterGroup g) {
  return g == FilterGroup::band ? c.band : g == FilterGroup::low ? c.low
                                      : g == FilterGroup::high ? c.high : c.zc;
}

// The first status that is not ok among a metric's axes (x, y, z order), as
// R stops at the first column it cannot assign.
inline SignalStatus first_failed(const SignalStatus* st, int axis) {
  if (axis >= 0) return st[axis];
  for (int k = 0; k < 3; ++k)
    if (st[k] != SignalStatus::ok) return st[k];
  return SignalStatus::ok;
}

// GGIR's zerocross() of a filtered axis, n values of it in v (overwritten)
// into out: |v| < zc_sb set to 0; +1 where v >= 0, -1 below (NA stays NA:
// ifelse); then |sign(s[k]) - sign(s[k - 1])| * 0.5. At the block's start
// (`at_start`, n >= 2) the first value is repeated in front; further on,
// s[-1] is *last, the sign value the part before ended on. *last: v's last.
inline void zero_crossings(double* v, std::size_t n, double zc_sb, double* out, bool at_start,
                           double* last) {
  const double na_real = r_na_real();
  for (std::size_t i = 0; i < n; ++i) {
    double w = v[i];
    if (std::fabs(w) < zc_sb) w = 0;  // false for NA
    // ifelse(w >= 0, 1, -1): a NA test gives NA_real_
    v[i] = std::isnan(w) ? na_real : (w >= 0 ? 1.0 : -1.0);
  }
  if (n == 0) return;
  if (!at_start) out[0] = std::fabs(r_sign(v[0]) - r_sign(*last)) * 0.5;
  for (std::size_t i = 1; i < n; ++i) out[i] = std::fabs(r_sign(v[i]) - r_sign(v[i - 1])) * 0.5;
  if (at_start) out[0] = out[1];
  *last = v[n - 1];
}

// What the metrics ms[] need filtered: per coefficient set (FilterGroup),
// the axes; whether HFENplus is asked (it reads "low" too).
struct FilterPlan {
  bool need[kFilterGroups][3] = {};
  bool norm[kFilterGroups] = {};  // a metric reads the three axes' norm
  bool plus = false;
  bool any(int g) const { return need[g][0] || need[g][1] || need[g][2]; }
  bool all(int g) const { return need[g][0] && need[g][1] && need[g][2]; }
};

inline FilterPlan plan_filters(const FilteredMetric* ms, std::size_t count, std::size_t n) {
  FilterPlan p;
  for (std::size_t i = 0; i < count; ++i) {
    const MetricUse u = metric_use(ms[i]);
    if (u.group == FilterGroup::zc && n < 2) continue;  // zerocross() needs 2 samples: nothing is filtered
    p.plus = p.plus || u.low_first;
    if (u.axis < 0) p.norm[static_cast<int>(u.group)] = true;
    if (u.low_first) p.norm[static_cast<int>(FilterGroup::low)] = true;
    for (int k = 0; k < 3; ++k) {
      const bool on = u.axis < 0 || u.axis == k;
      p.need[static_cast<int>(u.group)][k] = p.need[static_cast<int>(u.group)][k] || on;
      if (u.low_first) p.need[static_cast<int>(FilterGroup::low)][k] = p.need[static_cast<int>(FilterGroup::low)][k] || on;
    }
  }
  return p;
}

// The norm of a coefficient set's three filtered axes over len samples,
// sqrt((x^2 + y^2) + z^2): the same bits whether GGIR takes |.| of the axes
// first (BFEN, LFEN, LFENMO, HFEN) or not (HFENplus): |v| * |v| is v * v.
inline void norm_of(const double* const f[3], std::size_t len, double* out) {
  for (std::size_t j = 0; j < len; ++j) out[j] = norm3(f[0][j], f[1][j], f[2][j], false);
}

// Metric m's signal (not ZC*) over len samples from its group's filtered
// axes f[], their norm `nrm` (norm_of(); for the metrics of all three axes)
// and, for HFENplus, the low filter's norm `low_nrm` (GCP = that norm - 1).
inline void derive_signal(FilteredMetric m, const MetricUse& u, const double* const f[3],
                          const double* nrm, const double* low_nrm, std::size_t len, double* out) {
  if (u.axis >= 0) {
    const double* v = f[u.axis];
    for (std::size_t j = 0; j < len; ++j) out[j] = std::fabs(v[j]);
  } else if (u.low_first) {  // HFENplus: EN(high) + GCP, below 0 set to 0
    for (std::size_t j = 0; j < len; ++j) {
      const double gcp = low_nrm[j] - 1;
      const double v = nrm[j] + gcp;
      out[j] = v < 0 ? 0.0 : v;
    }
  } else if (m == FilteredMetric::LFENMO) {
    for (std::size_t j = 0; j < len; ++j) {
      const double v = nrm[j] - 1;
      out[j] = v < 0 ? 0.0 : v;  // NA stays NA (which() skips it)
    }
  } else {  // BFEN, LFEN, HFEN
    std::copy(nrm, nrm + len, out);
  }
}

// The whole block at once, with R's NA rules (filter_front(): the NAs at
// the ends omitted and recycled, R's stops): the three filtered axes of one
// coefficient set at a time, one signal, and HFENplus's GCP, n values each.
template <class Sink>
void block_signals(const FilteredMetric* ms, std::size_t count, const double* const axes[3],
                   std::size_t n, const GgirFilterCoefs& c, RFilterArith arith,
                   const FilterPlan& plan, Sink& sink) {
  std::vector<double> work, sig, nrm, low_nrm;
  double* f[3] = {nullptr, nullptr, nullptr};
  SignalStatus low_status[3] = {SignalStatus::ok, SignalStatus::ok, SignalStatus::ok};
  for (std::size_t i = 0; i < count; ++i) {
    if (metric_use(ms[i]).group == FilterGroup::zc && n < 2) sink.begin(i, SignalStatus::too_short);
  }
  for (int gi = 0; gi < kFilterGroups; ++gi) {
    const FilterGroup g = static_cast<FilterGroup>(gi);
    if (!plan.any(gi)) continue;
    if (work.empty()) {
      work.resize(3 * n);
      sig.resize(n);
      for (int k = 0; k < 3; ++k) f[k] = work.data() + k * n;
    }
    SignalStatus st[3] = {SignalStatus::ok, SignalStatus::ok, SignalStatus::ok};
    const ArmaCoefs& co = group_coefs(c, g);
    if (plan.all(gi)) {
      FilterResult r[3];
      filter_arma3(co, axes, n, f, arith, r);
      for (int k = 0; k < 3; ++k) st[k] = assign_column(r[k], f[k], n);
    } else {
      for (int k = 0; k < 3; ++k)
        if (plan.need[gi][k]) st[k] = filter_column(co, axes[k], n, f[k], arith);
    }
    if (plan.norm[gi] && first_failed(st, -1) == SignalStatus::ok) {
      nrm.resize(n);
      norm_of(f, n, nrm.data());
    }
    if (g == FilterGroup::low && plan.plus) {
      // HFENplus's GCP = EN(low) - gravity: the low filter's norm kept for
      // the high filter
      for (int k = 0; k < 3; ++k) low_status[k] = st[k];
      if (first_failed(st, -1) == SignalStatus::ok) low_nrm = nrm;
    }
    for (std::size_t i = 0; i < count; ++i) {
      const FilteredMetric m = ms[i];
      const MetricUse u = metric_use(m);
      if (u.group != g) continue;
      SignalStatus s = u.low_first ? first_failed(low_status, -1) : SignalStatus::ok;
      if (s == SignalStatus::ok) s = first_failed(st, u.axis);
      sink.begin(i, s);
      if (s != SignalStatus::ok) continue;
      double* out = sig.data();
      if (g == FilterGroup::zc) {
        double last = 0;
        zero_crossings(f[u.axis], n, c.zc_sb, out, true, &last);
      } else {
        derive_signal(m, u, f, nrm.data(), low_nrm.data(), n, out);
      }
      sink.values(i, static_cast<const double*>(out), n);
      sink.end_part();
    }
  }
}

// The block in parts of `chunk` samples, each filter's state carried from
// part to part (the convolution reads the block's samples before the part;
// the recursion its last outputs, kept in front of the part's), the same
// operations on each sample as block_signals(). Work space: for each
// coefficient set, three axes of `chunk` values, the recursion's history
// and their norm; a part of each signal. false, after the sink has been given
// some parts, when a filtered value comes out NA (a NA sample, or an
// overflow): R's NA rules need the whole block (block_signals()).
template <class Sink>
bool stream_signals(const FilteredMetric* ms, std::size_t count, const double* const axes[3],
                    std::size_t n, const GgirFilterCoefs& c, RFilterArith arith,
                    const FilterPlan& plan, std::size_t chunk, Sink& sink) {
  struct Stage {
    DividedArma d;
    std::size_t hist = 0;     // the recursion's history in front of each axis's part
    std::vector<double> buf;  // 3 x (hist + chunk)
    double* f[3] = {nullptr, nullptr, nullptr};
    std::vector<double> nrm;  // the three axes' norm (chunk), where a metric reads it
    explicit Stage(const ArmaCoefs& co) : d(co.b, co.nb, co.a, co.na) {}
  };
  std::vector<Stage> stages;
  stages.reserve(kFilterGroups);
  int stage_of[kFilterGroups] = {-1, -1, -1, -1};
  for (int gi = 0; gi < kFilterGroups; ++gi) {
    if (!plan.any(gi)) continue;
    stage_of[gi] = static_cast<int>(stages.size());
    stages.emplace_back(group_coefs(c, static_cast<FilterGroup>(gi)));
    Stage& st = stages.back();
    st.hist = st.d.g.size();
    st.buf.assign(3 * (st.hist + chunk), 0.0);  // zeros before the block: R's start
    for (int k = 0; k < 3; ++k) st.f[k] = st.buf.data() + k * (st.hist + chunk) + st.hist;
    if (plan.norm[gi]) st.nrm.resize(chunk);
  }
  std::vector<double> sig(count * chunk);  // a part of each signal
  double zc_last[3] = {0, 0, 0};
  for (std::size_t i = 0; i < count; ++i) sink.begin(i, SignalStatus::ok);
  for (std::size_t from = 0; from < n; from += chunk) {
    const std::size_t len = std::min(chunk, n - from);
    const bool at_start = from == 0;
    for (int gi = 0; gi < kFilterGroups; ++gi) {
      if (stage_of[gi] < 0) continue;
      const FilterGroup g = static_cast<FilterGroup>(gi);
      Stage& st = stages[static_cast<std::size_t>(stage_of[gi])];
      const std::vector<double>& fb = st.d.f;
      const std::vector<double>& gg = st.d.g;
      for (int k = 0; k < 3; ++k) {
        if (!plan.need[gi][k]) continue;
        if (arith.conv_fused) convolve<true>(fb.data(), fb.size(), axes[k], from, from + len, st.f[k]);
        else convolve<false>(fb.data(), fb.size(), axes[k], from, from + len, st.f[k]);
      }
      if (!gg.empty()) {
        // the history holds zeros at the start (R's zero initial state: the
        // same operations as the tested start of recurse())
        if (plan.all(gi)) {
          if (arith.rec_fused) recurse3<true>(gg.data(), gg.size(), st.f, len, false);
          else recurse3<false>(gg.data(), gg.size(), st.f, len, false);
        } else {
          for (int k = 0; k < 3; ++k) {
            if (!plan.need[gi][k]) continue;
            if (arith.rec_fused) recurse<true>(gg.data(), gg.size(), st.f[k], 0, len, false);
            else recurse<false>(gg.data(), gg.size(), st.f[k], 0, len, false);
          }
        }
      }
      for (int k = 0; k < 3; ++k) {
        if (!plan.need[gi][k]) continue;
        // a NA: the recursion carries it to every later output (R's tests
        // give NA for a NA operand), so the part's last tells
        if (gg.empty()) {
          for (std::size_t i = 0; i < len; ++i)
            if (std::isnan(st.f[k][i])) return false;
        } else if (std::isnan(st.f[k][len - 1])) {
          return false;
        }
        // the last outputs, the next part's history
        if (st.hist > 0) std::copy(st.f[k] + len - st.hist, st.f[k] + len, st.f[k] - st.hist);
      }
      if (!st.nrm.empty()) norm_of(st.f, len, st.nrm.data());
      const double* low_nrm =
          plan.plus ? stages[static_cast<std::size_t>(stage_of[static_cast<int>(FilterGroup::low)])].nrm.data() : nullptr;
      for (std::size_t i = 0; i < count; ++i) {
        const FilteredMetric m = ms[i];
        const MetricUse u = metric_use(m);
        if (u.group != g) continue;
        double* out = sig.data() + i * chunk;
        if (g == FilterGroup::zc) {
          zero_crossings(st.f[u.axis], len, c.zc_sb, out, at_start, &zc_last[u.axis]);
        } else {
          derive_signal(m, u, st.f, st.nrm.data(), low_nrm, len, out);
        }
        sink.values(i, static_cast<const double*>(out), len);
      }
    }
    sink.end_part();
  }
  return true;
}

}  // namespace ggir_filters_detail

// The parts a block is filtered in (ggir_filtered_signals()): the work
// space stays in the processor's cache.
constexpr std::size_t kFilterChunk = 4096;

// The per-sample signals of `count` metrics ms[] over a block of n samples
// (x, y, z: calibrated axes), each filter run once per coefficient set and
// axis however many metrics read it (a filtered axis is the same bits for
// every metric that reads it). The sink is told, for each metric i,
// sink.begin(i, status): ok, or why R stops there; then, when ok, the
// signal in consecutive parts, sink.values(i, values, len), n values in
// all; sink.end_part() after each part (of one metric, or of all), up to
// which the values given since the last stay valid. A block whose filtered values come out NA
// anywhere is taken again whole (R's NA rules): the sink is then told
// begin() again for every metric, and must start over.
// The block goes in parts of `chunk` samples (at least 2) where it can:
// the work space is that of the parts, not of the block.
template <class Sink>
void ggir_filtered_signals(const FilteredMetric* ms, std::size_t count, const double* x,
                           const double* y, const double* z, std::size_t n,
                           const GgirFilterCoefs& c, RFilterArith arith, Sink& sink,
                           std::size_t chunk = kFilterChunk) {
  namespace d = ggir_filters_detail;
  const double* const axes[3] = {x, y, z};
  const d::FilterPlan plan = d::plan_filters(ms, count, n);
  chunk = std::max<std::size_t>(chunk, 2);
  bool parts = n >= 2;  // (ZC* of one sample: R's stop, from the block)
  for (int gi = 0; gi < kFilterGroups && parts; ++gi) {
    if (plan.any(gi) && d::group_coefs(c, static_cast<FilterGroup>(gi)).nb == 0) parts = false;
  }
  if (parts && d::stream_signals(ms, count, axes, n, c, arith, plan, chunk, sink)) return;
  d::block_signals(ms, count, axes, n, c, arith, plan, sink);
}

}  // namespace gravcal

#endif  // GRAVCAL_GGIR_FILTERS_HPP
