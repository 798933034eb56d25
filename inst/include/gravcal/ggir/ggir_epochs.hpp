// gravcal: GGIR part 1's epoch signals for one block, as g.getmeta()
// computes them (GGIR 3.3-9: g.getmeta, g.applymetrics,
// detect_nonwear_clipping), to the bit.
//
// g.getmeta() reads a recording in blocks of about 24 hours, keeps the
// whole long epochs (15 min) of each, applies the calibration, and computes
// per block: short-epoch metrics (5 s: ENMO, anglez, ...), and per long
// epoch non-wear and clipping scores and the means of the norm, the
// temperature and the light. Its arithmetic decides bits in ways that this
// header repeats (the reasons are GGIR's R code; the order of operations
// is R's):
// - calibration: scale(data, center = -offset, scale = 1 / scale), that is
//   (v + offset) / (1 / scale), then + (T - meantempcal) / (1 / tempoffset);
// - epoch means: a cumulative sum over the whole block (R's cumsum(), in
//   R's long double accumulator rounded to double after each addition),
//   read at round(seq(1, n + 1, by = sf * epoch)), differenced, divided by
//   the index difference. So a mean depends on where its block starts;
// - angles: every floor(sf / 10)-th sample, a running median of about 5 s
//   (zoo::rollmedian with zero fill), zeros near the head and tail of the
//   block replaced, values repeated back to the full rate (the raw signal
//   when the repeated length exceeds the block's), then atan(z / sqrt(x^2
//   + y^2)) / (pi / 180);
// - non-wear and clipping per long epoch, with R's sd() and the index
//   arithmetic of R's `:` and seq() on fractional bounds;
// - R's sequences (`:`, seq()) index with truncation, 0 dropped, beyond the
//   end NA (left out by the max/min/sd with na.rm).
// Rounding (round(x, 4)) and the text round trip of metashort are R's own,
// applied by the caller in R. Header-only, standard headers only.
#ifndef GRAVCAL_GGIR_EPOCHS_HPP
#define GRAVCAL_GGIR_EPOCHS_HPP

#include "gravcal/mcu/fp_contract.hpp"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <exception>
#include <functional>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <system_error>
#include <vector>

#include "gravcal/host/threads.hpp"
#include "gravcal/host/big_array.hpp"
#ifndef GRAVCAL_NO_THREADS
#include <future>
#include <thread>
#endif

#include "gravcal/ggir/ggir_filters.hpp"
#include "gravcal/host/r_arith.hpp"
#include "gravcal/kernels/kernels.hpp"

namespace gravcal {
namespace ggir_part1 {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// R's `from:to` on doubles (seq_colon): n = floor(|to - from| + 1 +
// FLT_EPSILON) values from, from +- 1, ... (integers when from is one).
struct RColon {
  double from = 0;
  std::int64_t n = 0;
  bool down = false;
  double at(std::int64_t k) const {
    return down ? from - static_cast<double>(k) : from + static_cast<double>(k);
  }
};

inline RColon r_colon(double from, double to) {
  RColon c;
  c.from = from;
  c.down = from > to;
  const double r = std::fabs(to - from);
  c.n = static_cast<std::int64_t>(r + 1 + FLT_EPSILON);
  return c;
}

// R's seq(from, to, by = by) for finite doubles with from <= to, by > 0,
// from and to not both integer-typed (the double branch of seq.default):
// n = as.integer((to - from) / by + 1e-10); from + k by, capped at to. A
// single `from` when (to - from) / max(|to|, |from|) < 100 eps. RSeqBy is
// the sequence without its values (at(k) gives value k); r_seq_by() the
// values.
struct RSeqBy {
  double from = 0, to = 0, by = 0;
  std::size_t n = 0;  // how many values
  double at(std::size_t k) const {
    if (k == 0) return from;
    return std::min(from + static_cast<double>(k) * by, to);
  }
};

inline RSeqBy r_seq_by_spec(double from, double to, double by) {
  RSeqBy s;
  s.to = to;
  s.by = by;
  const double del = to - from;
  if (del == 0 && to == 0) {
    s.from = to;
    s.n = 1;
    return s;
  }
  s.from = from;
  const double n = del / by;
  if (!std::isfinite(n) || n < 0) throw std::runtime_error("seq(): invalid (to - from) / by");
  if (n > 2147483647.0) throw std::runtime_error("seq(): 'by' is much too small");
  if (std::fabs(del) / std::max(std::fabs(to), std::fabs(from)) < 100 * DBL_EPSILON) {
    s.n = 1;
    return s;
  }
  s.n = static_cast<std::size_t>(static_cast<std::int64_t>(n + 1e-10)) + 1;
  return s;
}

inline std::vector<double> r_seq_by(double from, double to, double by) {
  const RSeqBy s = r_seq_by_spec(from, to, by);
  std::vector<double> out(s.n);
  for (std::size_t i = 0; i < s.n; ++i) out[i] = s.at(i);
  return out;
}

// R's round(x) (digits 0): to the nearest integer, ties to even.
inline double r_round0(double x) { return std::nearbyint(x); }

// GGIR's averagePerEpoch() (mean = true) and sumPerEpoch() (mean = false)
// of a block's values v[0], ..., v[n - 1], given as they stream, for epochs
// of `by` samples (sf * epoch length, maybe not whole): the differences of
// R's cumsum(c(0, v)) (R's accumulator Acc, each sum rounded to double) at
// round(seq(1, n + 1, by)), divided by the epoch's length. The running sum
// is read as it passes each bound (the rounded bounds never decrease), so
// neither the values nor their cumulative sums are held. Values past the
// last bound are not needed (and not summed).
template <class Acc>
class EpochSums {
 public:
  EpochSums(std::size_t n, double by, bool mean) : mean_(mean) {
    const std::vector<double> sel = r_seq_by(1.0, static_cast<double>(n + 1), by);
    if (sel.size() < 2) return;  // no epoch
    bound_.resize(sel.size());
    for (std::size_t k = 0; k < sel.size(); ++k) bound_[k] = r_round0(sel[k]);
    out_.resize(sel.size() - 1);
  }
  // The next `count` values, value i (counted from the block's start) as
  // f(i).
  template <class F>
  void feed(std::size_t count, F&& f) {
    advance(count, [this, &f](std::size_t from, std::size_t to) {
      Acc s = s_;
      for (std::size_t i = from; i < to; ++i) s += f(i);
      s_ = s;
    });
  }
  // The next `count` values from v[0].
  void add(const double* v, std::size_t count) {
    const std::size_t base = at_;
    feed(count, [v, base](std::size_t i) { return v[i - base]; });
  }
  // add() of the next `count` values of k sums at once, sums e[q] taking
  // v[q][0, count): sums of the same block (all given the same values so
  // far), their epochs maybe of different lengths. Each sum in its own
  // order (the same bits as add()), up to six side by side: independent
  // chains of additions (six long doubles and an operand fill seven of the
  // x87's eight registers).
  static void add_many(EpochSums* const* e, const double* const* v, std::size_t k,
                       std::size_t count) {
    for (std::size_t q = 0; q < k; q += 6) {
      switch (std::min<std::size_t>(6, k - q)) {
        case 6: feed_k<6>(e + q, v + q, count); break;
        case 5: feed_k<5>(e + q, v + q, count); break;
        case 4: feed_k<4>(e + q, v + q, count); break;
        case 3: feed_k<3>(e + q, v + q, count); break;
        case 2: feed_k<2>(e + q, v + q, count); break;
        default: e[q]->add(v[q], count); break;
      }
    }
  }
  // `count` copies of v, added as one product: only for values whose
  // running sums are all exact in Acc (run_sums_exact()), where v times a
  // count, and every addition, are exact, so that the sum at each bound is
  // that of the count additions one at a time.
  void add_run_exact(double v, std::size_t count) {
    advance(count, [this, v](std::size_t from, std::size_t to) {
      s_ += static_cast<Acc>(v) * static_cast<Acc>(to - from);
    });
  }
  // The epochs' values; every value up to the last bound must have been
  // given.
  std::vector<double> finish() {
    reached();
    if (k_ < bound_.size()) throw std::logic_error("EpochSums: values missing before an epoch's bound");
    return std::move(out_);
  }

 private:
  template <int K>  // 2 to 6
  static void feed_k(EpochSums* const* e, const double* const* v, std::size_t count) {
    const std::size_t base = e[0]->at_;
    for (int q = 1; q < K; ++q) {
      if (e[q]->at_ != base) throw std::logic_error("EpochSums::add_many: sums at different places");
    }
    const std::size_t end = base + count;
    std::size_t at = base;
    // the sums' pointers as named variables (registers), the unused ones idle
    const double* w0 = v[0] - base;
    const double* w1 = v[K > 1 ? 1 : 0] - base;
    const double* w2 = v[K > 2 ? 2 : 0] - base;
    const double* w3 = v[K > 3 ? 3 : 0] - base;
    const double* w4 = v[K > 4 ? 4 : 0] - base;
    const double* w5 = v[K > 5 ? 5 : 0] - base;
    for (;;) {
      // record the bounds reached; run to the nearest bound ahead
      std::size_t stop = end;
      for (int q = 0; q < K; ++q) {
        EpochSums& s = *e[q];
        s.at_ = at;
        s.reached();
        if (s.k_ < s.bound_.size()) stop = std::min(stop, static_cast<std::size_t>(s.bound_[s.k_]) - 1);
      }
      if (at >= stop) break;  // at the end (a sum past its last bound adds values no epoch reads)
      Acc s0 = e[0]->s_, s1 = e[K > 1 ? 1 : 0]->s_, s2 = e[K > 2 ? 2 : 0]->s_,
          s3 = e[K > 3 ? 3 : 0]->s_, s4 = e[K > 4 ? 4 : 0]->s_, s5 = e[K > 5 ? 5 : 0]->s_;
      for (std::size_t i = at; i < stop; ++i) {
        s0 += w0[i];
        if (K > 1) s1 += w1[i];
        if (K > 2) s2 += w2[i];
        if (K > 3) s3 += w3[i];
        if (K > 4) s4 += w4[i];
        if (K > 5) s5 += w5[i];
      }
      e[0]->s_ = s0;
      if (K > 1) e[1]->s_ = s1;
      if (K > 2) e[2]->s_ = s2;
      if (K > 3) e[3]->s_ = s3;
      if (K > 4) e[4]->s_ = s4;
      if (K > 5) e[5]->s_ = s5;
      at = stop;
    }
    for (int q = 0; q < K; ++q) e[q]->at_ = end;
  }
  // The next `count` values: add(from, to) adds those of [from, to) to s_,
  // called for the spans between the bounds (each bound's sum recorded as
  // it is reached); values past the last bound are not added.
  template <class Add>
  void advance(std::size_t count, Add&& add) {
    const std::size_t end = at_ + count;
    while (at_ < end && k_ < bound_.size()) {
      const std::size_t to = static_cast<std::size_t>(bound_[k_]) - 1;  // values before the bound
      if (at_ == to) {
        record();
        continue;
      }
      const std::size_t stop = std::min(end, to);
      add(at_, stop);
      at_ = stop;
    }
    at_ = end;
    reached();
  }
  // the running sum is cumsum(c(0, v))[bound] for every bound at the values
  // given so far
  void reached() {
    while (k_ < bound_.size() && at_ == static_cast<std::size_t>(bound_[k_]) - 1) record();
  }
  void record() {
    const double cur = bound_[k_];
    const double c = static_cast<double>(s_);
    if (k_ > 0) {
      const double d = c - cprev_;
      out_[k_ - 1] = mean_ ? d / std::fabs(cur - prev_) : d;
    }
    prev_ = cur;
    cprev_ = c;
    ++k_;
  }
  std::vector<double> bound_;  // round(seq(1, n + 1, by)), 1-based
  std::vector<double> out_;
  bool mean_;
  Acc s_ = 0;
  std::size_t at_ = 0;  // values given so far (the sum holds those before the next bound)
  std::size_t k_ = 0;   // the next bound
  double prev_ = 0, cprev_ = 0;
};

// EpochSums of the values f(0), ..., f(n - 1) (f called in that order).
template <class Acc, class F>
std::vector<double> per_epoch_of(std::size_t n, double by, bool mean, F&& f) {
  EpochSums<Acc> e(n, by, mean);
  e.feed(n, f);
  return e.finish();
}

template <class Acc>
std::vector<double> per_epoch(const double* x, std::size_t n, double by, bool mean) {
  return per_epoch_of<Acc>(n, by, mean, [x](std::size_t i) { return x[i]; });
}

// Whether every running sum, in Acc, of the values that `spans(f)` gives
// (f(from, to, v): rows [from, to) of value v) is exact: the values
// finite, each a whole multiple of 2^q (q the least exponent of their
// lowest set bits), the sum of their magnitudes under 2^(q + digits - 2).
// Then each running sum, and each value times a count of rows, is a
// multiple of 2^q under 2^(q + digits): Acc holds it, no addition rounds,
// and a run of one value can be added as one product
// (EpochSums::add_run_exact()), the same bits as row by row. A .cwa
// file's temperature (multiples of 2^-8) and light (whole numbers) are
// such values.
template <class Acc, class Spans>
bool run_sums_exact(Spans&& spans) {
  bool ok = true;
  int q = std::numeric_limits<int>::max();
  double total = 0;  // (rounded: the bound has a factor of 2 to spare)
  spans([&](std::size_t from, std::size_t to, double v) {
    if (!ok || v == 0) return;
    if (!std::isfinite(v)) {
      ok = false;
      return;
    }
    int e = 0;
    const double f = std::frexp(std::fabs(v), &e);  // |v| = f 2^e, f in [0.5, 1)
    std::uint64_t m = static_cast<std::uint64_t>(std::ldexp(f, 53));  // (whole: 53 bits)
    int low = e - 53;
    while ((m & 1u) == 0) {
      m >>= 1;
      ++low;
    }
    q = std::min(q, low);
    total += std::fabs(v) * static_cast<double>(to - from);
  });
  if (!ok) return false;
  if (q == std::numeric_limits<int>::max()) return true;  // zeros only
  return total < std::ldexp(1.0, q + std::numeric_limits<Acc>::digits - 2);
}

// One sum of a pass over a block's rows (run_pass()): its epochs, and how
// its values are made: fill(from, to, norm, out) writes the values of rows
// [from, to) to out[0, to - from), asked for rows in increasing order;
// norm holds r_norm() of the same rows when the sum says it needs them
// (nullptr otherwise).
template <class Acc>
struct PassSum {
  EpochSums<Acc> sums;
  std::function<void(std::size_t, std::size_t, const double*, double*)> fill;
  bool needs_norm = false;
};

inline double r_norm(double x, double y, double z);

// The sums of one block of n rows (x, y, z: the calibrated axes) in one
// pass, a chunk of rows at a time: each sum's values for the chunk are made
// into a buffer (the norm once for all that need it), then added, up to
// six sums side by side (EpochSums::add_many()). Each sum's bits are
// those of its own pass (the same values added in the same order); the
// pass reads the block once where separate passes read it once per sum.
// `on_rows`, when given, is called with each chunk's rows [from, to) while
// they are in cache (ClipLattice::feed()), in increasing order, every row.
template <class Acc>
void run_pass(PassSum<Acc>* const* ps, std::size_t k, const double* x, const double* y,
              const double* z, std::size_t n,
              const std::function<void(std::size_t, std::size_t)>& on_rows = {}) {
  if (k == 0 && !on_rows) return;
  constexpr std::size_t C = 1024;  // rows per chunk: the buffers fit the first-level cache
  bool norm = false;
  for (std::size_t q = 0; q < k; ++q) norm = norm || ps[q]->needs_norm;
  std::vector<double> buf((k + 1) * C);
  double* nb = buf.data() + k * C;
  std::vector<EpochSums<Acc>*> e(k);
  std::vector<const double*> v(k);
  for (std::size_t q = 0; q < k; ++q) {
    e[q] = &ps[q]->sums;
    v[q] = buf.data() + q * C;
  }
  for (std::size_t from = 0; from < n; from += C) {
    const std::size_t to = std::min(n, from + C);
    if (norm) {
      for (std::size_t i = from; i < to; ++i) nb[i - from] = r_norm(x[i], y[i], z[i]);
    }
    for (std::size_t q = 0; q < k; ++q) ps[q]->fill(from, to, ps[q]->needs_norm ? nb : nullptr, buf.data() + q * C);
    if (k > 0) EpochSums<Acc>::add_many(e.data(), v.data(), k, to - from);
    if (on_rows) on_rows(from, to);
  }
}

// The calibration as g.getmeta applies it, in place: v = (v + offset) /
// inv_scale (inv_scale = 1 / scale, computed by R), then, with a
// temperature, + (t - meantemp) / inv_tempoffset.
struct Calibration {
  double offset[3] = {0, 0, 0};
  double inv_scale[3] = {1, 1, 1};
  bool temp = false;  // apply the temperature term
  double meantemp = 0;
  double inv_tempoffset[3] = {1, 1, 1};
};

// `spans(n, f)` calls f(from, to, t) for spans of rows [0, n) of one
// temperature t, in increasing order (RunColumn::spans()); `have_t`
// whether there is a temperature. A temperature holds for a page: its term
// is computed once per span, the same operands, the same bits. Each span
// of an axis in one call of the kernel offset_divide (kernels/apply.hpp).
template <class Spans>
void apply_calibration(const Calibration& c, double* x, double* y, double* z, Spans&& spans,
                       bool have_t, std::size_t n) {
  const kernels::OffsetDivideFn f = kernels::active().offset_divide;
  double* v[3] = {x, y, z};
  if (!(c.temp && have_t)) {
    for (int a = 0; a < 3; ++a) f(v[a], n, c.offset[a], c.inv_scale[a], 0, false);
    return;
  }
  spans(n, [&](std::size_t from, std::size_t to, double t) {
    for (int a = 0; a < 3; ++a) {
      const double term = (t - c.meantemp) / c.inv_tempoffset[a];
      f(v[a] + from, to - from, c.offset[a], c.inv_scale[a], term, true);
    }
  });
}

// sqrt(x^2 + y^2 + z^2) in R's order.
inline double r_norm(double x, double y, double z) {
  return std::sqrt(x * x + y * y + z * z);
}

// A running median of odd width k over the N values of v
// (zoo::rollmedian(v, k, fill = 0), centred): out[c] = the median of v[c -
// m .. c + m] (m = k / 2), for the centres c in [from, to), which must lie
// in [m, N - m); a window holding NaN gives NaN (zoo then uses median(),
// whose result is NA). A window's median depends on its values only, so
// that the centres may be made in parts, in any order, by any thread.
// The N values are v[0], v[stride], v[2 * stride], ... (a subsample read
// in place).
//
// The window's K = 2m + 1 values sit in a ring, in time order. The median
// is known by its value `med`, with `lo` values below it and `eq` equal
// (lo <= m < lo + eq). A step changes lo and eq by the value leaving and
// the one entering, by compares alone; only where m leaves [lo, lo + eq)
// does the median move, one value down or up: to the window's largest
// value below it or its smallest above (the kernel order_next, four or
// two lanes at a time where the processor has them). On a week's
// recording the median moves at about a quarter of the steps.
//
// The median's bits are those of the window sorted stably (equal values in
// their order in time): for a median of zero, the zero of the sign found
// at its place among the window's zeros in time order (-0 and +0 compare
// equal; GGIR's angles keep the sign).
inline void rolling_median_range(const double* v, std::size_t N, std::size_t k, double* out,
                                 std::size_t from, std::size_t to, std::size_t stride = 1) {
  const std::size_t m = k / 2;
  if (k == 0 || from >= to) return;
  if (from < m || to > N - m) throw std::out_of_range("running median centres out of range");
  const std::size_t K = 2 * m + 1;
  const kernels::OrderNextFn next = kernels::active().order_next;
  std::vector<double> ring(K), sorted;
  double* r = ring.data();
  std::size_t head = 0, nans = 0;  // r[head]: the oldest value
  for (std::size_t i = 0; i < K; ++i) {
    r[i] = v[(from - m + i) * stride];
    nans += std::isnan(r[i]) ? 1 : 0;
  }
  double med = 0;
  std::size_t lo = 0, eq = 0;
  bool known = false;  // med, lo and eq hold for the window
  for (std::size_t c = from;; ++c) {
    if (nans != 0) {
      out[c] = kNaN;
    } else {
      if (!known) {  // the window's median found anew (at the start, after NaN)
        sorted.assign(r, r + K);
        std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(m), sorted.end());
        med = sorted[m];
        lo = eq = 0;
        for (std::size_t i = 0; i < K; ++i) {
          lo += r[i] < med ? 1 : 0;
          eq += r[i] == med ? 1 : 0;
        }
        known = true;
      }
      double value = med;
      if (med == 0) {  // the (m - lo)-th zero in time order
        std::size_t seen = 0;
        for (std::size_t j = 0, i = head; j < K; ++j, i = i + 1 == K ? 0 : i + 1) {
          if (r[i] == 0 && seen++ == m - lo) {
            value = r[i];
            break;
          }
        }
      }
      out[c] = value;
    }
    if (c + 1 >= to) break;
    const double o = r[head], a = v[(c + m + 1) * stride];
    r[head] = a;
    head = head + 1 == K ? 0 : head + 1;
    nans = nans + (std::isnan(a) ? 1 : 0) - (std::isnan(o) ? 1 : 0);
    if (nans != 0 || !known) {  // (a known median had no NaN: o is a number)
      known = false;
      continue;
    }
    lo = lo + (a < med ? 1 : 0) - (o < med ? 1 : 0);
    eq = eq + (a == med ? 1 : 0) - (o == med ? 1 : 0);
    double nv = 0;
    std::size_t n_eq = 0;
    if (lo > m) {  // one value down: the largest below
      next(r, K, med, true, &nv, &n_eq);
      med = nv;
      eq = n_eq;
      lo -= n_eq;
    } else if (lo + eq <= m) {  // one value up: the smallest above
      next(r, K, med, false, &nv, &n_eq);
      lo += eq;
      med = nv;
      eq = n_eq;
    }
  }
}

// The centres a running median of width k over N values has: [m, N - m),
// none (from == to) where the window never fits (zoo: all fill).
inline void median_centres(std::size_t N, std::size_t k, std::size_t* from, std::size_t* to) {
  if (k == 0 || k > N) {
    *from = *to = 0;
    return;
  }
  *from = k / 2;
  *to = N - k / 2;
}

inline void rolling_median(const std::vector<double>& v, std::size_t k, std::vector<double>& out) {
  const std::size_t N = v.size();
  out.assign(N, 0.0);
  std::size_t from = 0, to = 0;
  median_centres(N, k, &from, &to);
  rolling_median_range(v.data(), N, k, out.data(), from, to);
}

// GGIR's rollmed() of one axis of a block, as a view: the value at sample
// i is the running median of the 10 Hz subsample (xm[i / step]) up to LN
// = xm.size() * step, the last median after it; or, in GGIR's fallback
// (when LN exceeds the block), the raw axis itself. Held at the
// subsample's rate: a tenth of the block, or none.
struct RollMed {
  BigVector xm;
  const double* raw = nullptr;  // the fallback: the raw axis
  std::size_t step = 1, LN = 0;
  double tail = kNaN;
  double operator[](std::size_t i) const {
    if (raw != nullptr) return raw[i];
    return i < LN ? xm[i / step] : tail;
  }
};

// GGIR's rollmed(): the smoothed axis used for the angles and the
// roll_med_acc metrics, for one axis of a block, in three steps, so that
// its medians can be made in parts (by two threads): rollmed_begin() (the
// 10 Hz subsample; r.xm sized, zeros), rollmed_part() for centres covering
// RollMedWork's [from, to) once, rollmed_end() (the head and tail, GGIR's
// fallback). ggir_rollmed() runs the three.
struct RollMedWork {
  const double* axis = nullptr;  // the axis; its subsample: every step-th value
  std::size_t count = 0;          // the subsample's values
  std::size_t k = 0, step = 1;
  std::size_t from = 0, to = 0;  // the centres (median_centres())
};

inline void rollmed_begin(const double* x, std::size_t LX, double sf, RollMed& r, RollMedWork& w) {
  const double fl = std::floor(sf / 10);
  w.step = static_cast<std::size_t>(std::max(fl, 1.0));
  const double newsf = w.step > 1 ? 10.0 : sf;
  double winsi = r_round0(newsf * 5);
  if (r_round0(winsi / 2) == winsi / 2) winsi = winsi + 1;
  if (std::fmod(winsi, 2.0) == 0) winsi = winsi + 1;
  w.k = static_cast<std::size_t>(winsi);
  // (the subsample is read in place, not copied: a tenth of the block less
  // memory, its pages not faulted and zeroed each block)
  w.axis = x;
  w.count = LX == 0 ? 0 : (LX - 1) / w.step + 1;
  r = RollMed();
  r.xm.assign(w.count, 0.0);
  median_centres(w.count, w.k, &w.from, &w.to);
}

// The medians of centres [from, to) (within w.from, w.to).
inline void rollmed_part(RollMed& r, const RollMedWork& w, std::size_t from, std::size_t to) {
  rolling_median_range(w.axis, w.count, w.k, r.xm.data(), from, to, w.step);
}

inline void rollmed_end(RollMed& r, RollMedWork& w, const double* x, std::size_t LX, double sf) {
  const std::size_t step = w.step;
  BigVector& xm = r.xm;
  const std::size_t LN0 = xm.size();
  // the head: zeros among the first S2check values take the first value
  // there that is not zero (NA when there is none)
  double S2check = std::max(sf * 60, 1000.0);
  {
    const RColon c = r_colon(1, S2check);
    const std::size_t lim = static_cast<std::size_t>(std::min<double>(static_cast<double>(c.n), static_cast<double>(LN0)));
    double first = kNaN;
    for (std::size_t i = 0; i < lim; ++i) {
      if (!std::isnan(xm[i]) && xm[i] != 0) {
        first = xm[i];
        break;
      }
    }
    for (std::size_t i = 0; i < lim; ++i) {
      if (xm[i] == 0) xm[i] = first;
    }
  }
  // the tail: xm[(LN - S2check):LN], zeros there take the first value of
  // the tail that is not zero (NA when there is none)
  if (LN0 >= 1) {
    S2check = std::min(static_cast<double>(LN0) - 1, S2check);
    const RColon c = r_colon(static_cast<double>(LN0) - S2check, static_cast<double>(LN0));
    std::vector<std::size_t> idx;
    idx.reserve(static_cast<std::size_t>(c.n));
    for (std::int64_t k = 0; k < c.n; ++k) {
      const double d = c.at(k);
      const std::int64_t j = static_cast<std::int64_t>(d);  // R truncates
      if (j >= 1 && j <= static_cast<std::int64_t>(LN0)) idx.push_back(static_cast<std::size_t>(j - 1));
    }
    double lastvalue = kNaN;
    for (std::size_t j : idx) {
      if (!std::isnan(xm[j]) && xm[j] != 0) {
        lastvalue = xm[j];
        break;
      }
    }
    for (std::size_t j : idx) {
      if (xm[j] == 0) xm[j] = lastvalue;
    }
  }
  const std::size_t LN = LN0 * step;
  if (LN > LX) {
    BigVector().swap(xm);
    r.raw = x;  // GGIR's fallback: the raw axis
    return;
  }
  r.step = step;
  r.LN = LN;
  r.tail = LN ? xm[LN0 - 1] : kNaN;
}

inline RollMed ggir_rollmed(const double* x, std::size_t LX, double sf) {
  RollMed r;
  RollMedWork w;
  rollmed_begin(x, LX, sf, r, w);
  rollmed_part(r, w, w.from, w.to);
  rollmed_end(r, w, x, LX, sf);
  return r;
}

// After rollmed() of the three axes (n samples each): when any value of
// any axis is NA, each axis's NA values take that axis's last value that is
// not NA.
inline void fill_na_last(RollMed* ax[3], std::size_t n) {
  auto has_nan = [n](const RollMed& r) {
    if (r.raw != nullptr) {
      for (std::size_t i = 0; i < n; ++i) {
        if (std::isnan(r.raw[i])) return true;
      }
      return false;
    }
    const std::size_t used = r.LN / r.step;
    for (std::size_t j = 0; j < used; ++j) {
      if (std::isnan(r.xm[j])) return true;
    }
    return r.LN < n && std::isnan(r.tail);
  };
  bool any = false;
  for (int a = 0; a < 3 && !any; ++a) any = has_nan(*ax[a]);
  if (!any) return;
  for (int a = 0; a < 3; ++a) {
    RollMed& r = *ax[a];
    if (r.raw != nullptr) {
      if (!has_nan(r)) continue;
      // the raw axis copied, to be filled
      r.xm.assign(r.raw, r.raw + n);
      r.raw = nullptr;
      r.step = 1;
      r.LN = n;
      r.tail = kNaN;
    }
    double last = kNaN;
    for (std::size_t i = n; i-- > 0;) {
      const double v = r[i];
      if (!std::isnan(v)) {
        last = v;
        break;
      }
    }
    const std::size_t used = r.LN / r.step;
    for (std::size_t j = 0; j < used; ++j) {
      if (std::isnan(r.xm[j])) r.xm[j] = last;
    }
    if (std::isnan(r.tail)) r.tail = last;
  }
}

// Non-wear and clipping per long epoch (GGIR's medium epoch, ws2),
// detect_nonwear_clipping() for approaches "2013" and "2023" without a
// wear column.
struct NonwearConfig {
  double sf = 0;
  double ws2 = 900;   // seconds
  double ws = 3600;   // seconds
  double clipthres = 7.5;
  double sdcriter = 0.013;
  double racriter = 0.15;
  bool approach_2023 = true;
  bool r_long_double = true;
};

struct NonwearResult {
  std::vector<double> nonwear;   // NWav
  std::vector<double> clipping;  // CWav
  std::int64_t epochs = 0;       // nmin
};

// Values of one axis at R's indices (1-based, truncated), keeping those
// within 1..n (R's NA beyond the end, left out by na.rm); 0 dropped.
// A negative index would be R's exclusion: GGIR's sequences give none for
// blocks of at least one window `ws`.
template <class F>
inline void at_r_indices(const RColon& c, std::size_t n, F&& f) {
  if (!c.down && c.from >= 1 && c.from == std::floor(c.from) && c.from < 9007199254740992.0) {
    // a whole start counting up: the indices are from, from + 1, ... (the
    // sums are exact), those within 1..n
    const std::int64_t first = static_cast<std::int64_t>(c.from);
    const std::int64_t last = std::min<std::int64_t>(first + c.n - 1, static_cast<std::int64_t>(n));
    for (std::int64_t j = first; j <= last; ++j) f(static_cast<std::size_t>(j - 1));
    return;
  }
  for (std::int64_t k = 0; k < c.n; ++k) {
    const double d = c.at(k);
    if (d < 0) throw std::runtime_error("negative index in GGIR's non-wear window");
    const std::int64_t j = static_cast<std::int64_t>(d);
    if (j >= 1 && j <= static_cast<std::int64_t>(n)) f(static_cast<std::size_t>(j - 1));
  }
}

// The part of nonwear_clipping() that reads every row, for approach
// "2023" on its lattice (whole stride and long epoch, the epoch a multiple
// of the stride): each axis's count of values beyond clipthres (and
// whether any is beyond 1.5 times it) per long epoch, and its rows on the
// lattice (every stride-th from the first). Fed rows in increasing order,
// a chunk at a time (feed()), so that it can read them in the pass that
// reads them for the sums (run_pass()'s `on_rows`) rather than in one of
// its own; nonwear_clipping() then reads only the lattice. `usable`: the
// block is on such a lattice (otherwise nonwear_clipping() reads the rows
// itself).
struct ClipLattice {
  bool usable = false;
  std::size_t nrow = 0, st = 0, M = 0, N = 0;
  double clipthres = 0, clip15 = 0;
  std::vector<double> lattice[3];
  std::vector<std::size_t> over[3];  // per long epoch
  std::vector<unsigned char> over15[3];
  std::size_t fed = 0;

  ClipLattice(std::size_t n, const NonwearConfig& cf) : nrow(n) {
    const double Md = cf.ws2 * cf.sf;
    const double stride = std::ceil(cf.sf / 5);
    usable = cf.approach_2023 && stride >= 1 && stride < 1e9 && Md == std::floor(Md) && Md >= 1 &&
             std::fmod(Md, stride) == 0;
    if (!usable) return;
    st = static_cast<std::size_t>(stride);
    M = static_cast<std::size_t>(Md);
    N = nrow / M;
    clipthres = cf.clipthres;
    clip15 = cf.clipthres * 1.5;
    for (int a = 0; a < 3; ++a) {
      lattice[a].reserve(nrow / st + 1);
      over[a].assign(N, 0);
      over15[a].assign(N, 0);
    }
  }
  // rows [from, to) of the three axes (from: the rows fed so far)
  void feed(const double* const xyz[3], std::size_t from, std::size_t to) {
    if (!usable) return;
    if (from != fed) throw std::logic_error("ClipLattice: rows out of order");
    fed = to;
    for (int a = 0; a < 3; ++a) {
      const double* v = xyz[a];
      for (std::size_t j = (from + st - 1) / st * st; j < to; j += st) lattice[a].push_back(v[j]);
      // the long epochs' counts (rows after the last whole epoch: none)
      for (std::size_t i = from; i < std::min(to, N * M);) {
        const std::size_t e = i / M;
        const std::size_t stop = std::min(std::min(to, N * M), (e + 1) * M);
        std::size_t n_over = 0;
        bool big = false;
        for (std::size_t k = i; k < stop; ++k) {  // (no branch)
          const double av = std::fabs(v[k]);
          n_over += av > clipthres ? 1 : 0;
          big = big | (av > clip15);
        }
        over[a][e] += n_over;
        over15[a][e] = static_cast<unsigned char>(over15[a][e] | big);
        i = stop;
      }
    }
  }
};

// With `wear` (an ad hoc csv file's wear flags, row i's as wear(i): 1, 0
// or NaN), a window's non-wear score is its flags' most frequent value
// times 3 (GGIR's rule: over (1 + nwstart):nwend, NA left out, a tie goes
// to 1), whatever the axes say; a window without a flag is an error (GGIR
// stops there: its table of flags is empty).
template <class Acc>
NonwearResult nonwear_clipping(const double* const xyz[3], std::size_t nrow, const NonwearConfig& cf,
                               const std::function<double(std::size_t)>* wear = nullptr,
                               const ClipLattice* read = nullptr) {
  NonwearResult r;
  const double M = cf.ws2 * cf.sf;  // MediumEpochSize
  const double L = cf.ws * cf.sf;   // LongEpochSize
  const std::int64_t N = static_cast<std::int64_t>(std::floor(static_cast<double>(nrow) / M));
  r.epochs = N;
  if (N <= 0) return r;
  std::vector<double> nwlog(static_cast<std::size_t>(N) * 3, 0.0);
  r.nonwear.assign(static_cast<std::size_t>(N), 0.0);
  r.clipping.assign(static_cast<std::size_t>(N), 0.0);
  const double minimumEpochCount = ((L / M) / 2) + 1;
  const double stride = std::ceil(cf.sf / 5);
  // long epoch h's windows: clipping's, non-wear's, and the epochs its
  // non-wear flags
  struct Window {
    double clipstart, clipend, nwstart, nwend;
    std::int64_t flag_from, flag_to;
  };
  auto window = [&](std::int64_t h) {
    const double hd = static_cast<double>(h);
    Window w;
    w.clipstart = (((hd - 1) * M) + M * 0.5) - M * 0.5;
    w.clipend = (((hd - 1) * M) + M * 0.5) + M * 0.5;
    w.flag_from = w.flag_to = h;
    if (!cf.approach_2023) {
      if (hd <= minimumEpochCount) {
        w.nwstart = 1;
        w.nwend = L;
      } else if (hd >= (static_cast<double>(N) - minimumEpochCount)) {
        w.nwstart = (static_cast<double>(N) - minimumEpochCount) * M;
        w.nwend = static_cast<double>(N) * M;
      } else {
        w.nwstart = (((hd - 1) * M) + M * 0.5) - L * 0.5;
        w.nwend = (((hd - 1) * M) + M * 0.5) + L * 0.5;
      }
    } else {
      // h:(h + L / M - 1), those beyond N left out
      const RColon fc = r_colon(hd, hd + L / M - 1);
      if (fc.n > 0) {
        const double lastv = fc.at(fc.n - 1);
        w.flag_to = static_cast<std::int64_t>(std::min(lastv, static_cast<double>(N)));
      }
      w.nwstart = hd * M - M;
      w.nwend = w.nwstart + L;
      if (w.nwend > static_cast<double>(nrow)) w.nwend = static_cast<double>(nrow);
    }
    return w;
  };
  // approach "2023" reads every stride-th row of windows that overlap
  // (ws / ws2 of them hold each row): where the windows start on one
  // lattice of rows (whole stride and long epoch, the epoch a multiple of
  // the stride), each axis's rows on it are copied once, in order, and the
  // windows read the copy (the same values, the axis read once rather than
  // once per window a row out of every few cache lines); the clipping
  // counts are made in the same read (ClipLattice: `read`, when given, has
  // read the rows already)
  std::unique_ptr<ClipLattice> own;
  const ClipLattice* cl = read;
  if (cl == nullptr) {
    own.reset(new ClipLattice(nrow, cf));
    own->feed(xyz, 0, nrow);
    cl = own.get();
  }
  if (cl->usable && (cl->nrow != nrow || cl->fed != nrow)) throw std::logic_error("ClipLattice: not the block's rows");
  const bool on_lattice = cl->usable;
  std::vector<double> vals;
  const double clip15 = cf.clipthres * 1.5;
  for (int a = 0; a < 3; ++a) {
    const double* v = xyz[a];
    // first the clipping of every long epoch, then the non-wear (whose
    // windows reach long epochs ahead). Clipping: values beyond clipthres
    // in (1 + clipstart):clipend; on the lattice, M is whole and those are
    // rows [(h - 1) M, h M), counted by ClipLattice.
    const std::vector<double>& lattice = cl->lattice[a];
    for (std::int64_t h = 1; h <= N; ++h) {
      double count = 0;
      bool extreme = false;
      if (on_lattice) {
        count = static_cast<double>(cl->over[a][static_cast<std::size_t>(h - 1)]);  // (whole counts: exact)
        extreme = cl->over15[a][static_cast<std::size_t>(h - 1)] != 0;
      } else {
        const Window w = window(h);
        at_r_indices(r_colon(1 + w.clipstart, w.clipend), nrow, [&](std::size_t j) {
          const double av = std::fabs(v[j]);
          if (av > cf.clipthres) {
            count += 1;
            if (av > clip15) extreme = true;
          }
        });
      }
      if (count > 0 && extreme) count = M;
      // R's max(c(...)) of the three clipping fractions
      double& cm = r.clipping[static_cast<std::size_t>(h - 1)];
      cm = a == 0 ? count / M : std::max(cm, count / M);
    }
    for (std::int64_t h = 1; h <= N; ++h) {
      const Window w = window(h);
      // non-wear: range, then sd, of the window's values
      vals.clear();
      if (!cf.approach_2023) {
        at_r_indices(r_colon(1 + w.nwstart, w.nwend), nrow, [&](std::size_t j) { vals.push_back(v[j]); });
      } else {
        const RSeqBy s = r_seq_by_spec(1 + w.nwstart, w.nwend, stride);
        const double from = s.at(0);
        if (on_lattice && from >= 1 && from == std::floor(from) && std::fmod(from - 1, stride) == 0) {
          // the rows from, from + stride, ... within 1..nrow: the copy's
          const std::size_t j0 = static_cast<std::size_t>((from - 1) / stride);
          const std::size_t stop = std::min(lattice.size(), j0 + s.n);
          if (j0 < stop) {
            vals.insert(vals.end(), lattice.begin() + static_cast<std::ptrdiff_t>(j0),
                        lattice.begin() + static_cast<std::ptrdiff_t>(stop));
          }
        } else {
          for (std::size_t k = 0; k < s.n; ++k) {
            const std::int64_t j = static_cast<std::int64_t>(s.at(k));
            if (j >= 1 && j <= static_cast<std::int64_t>(nrow)) vals.push_back(v[static_cast<std::size_t>(j - 1)]);
          }
        }
      }
      double mx = -std::numeric_limits<double>::infinity();
      double mn = std::numeric_limits<double>::infinity();
      for (double e : vals) {
        if (std::isnan(e)) continue;
        if (e > mx) mx = e;
        if (e < mn) mn = e;
      }
      const double absrange = std::fabs(mx - mn);
      // GGIR tests the range and then the sd with if(), which stops on NA:
      // a range that is NaN (values all +Inf or all -Inf), or an sd of a
      // window with one value that is not NA (sd() gives NA; in an Axivity
      // csv export after an hour its zone's clocks skip the samples are NA)
      if (std::isnan(absrange)) {
        throw std::runtime_error("a non-wear window of a block holds infinite values only: GGIR's "
                                 "g.getmeta() stops there too (detect_nonwear_clipping(): its range is NaN)");
      }
      if (absrange < cf.racriter) {
        const RMeanSd ms = r_mean_sd<Acc>([&](auto&& f) {
          for (double e : vals) f(e);
        });
        if (std::isnan(ms.sd)) {
          throw std::runtime_error("a non-wear window of a block (long epoch " + std::to_string(h) +
                                   ") holds one value that is not NA: GGIR's g.getmeta() stops there "
                                   "too (detect_nonwear_clipping(): the sd of one value is NA)");
        }
        if (ms.sd < cf.sdcriter) {
          for (std::int64_t g = w.flag_from; g <= w.flag_to; ++g) {
            nwlog[static_cast<std::size_t>(g - 1) * 3 + static_cast<std::size_t>(a)] = 1;
          }
        }
      }
    }
  }
  for (std::int64_t h = 1; h <= N; ++h) {
    const std::size_t b = static_cast<std::size_t>(h - 1) * 3;
    r.nonwear[static_cast<std::size_t>(h - 1)] = nwlog[b] + nwlog[b + 1] + nwlog[b + 2];
    if (wear != nullptr) {
      const Window w = window(h);
      double n0 = 0, n1 = 0;
      at_r_indices(r_colon(1 + w.nwstart, w.nwend), nrow, [&](std::size_t j) {
        const double wv = (*wear)(j);
        if (wv == 0) n0 += 1;
        else if (wv == 1) n1 += 1;
      });
      if (n0 + n1 == 0) {
        throw std::runtime_error("the wear column (rmc.col.wear) has no TRUE/FALSE value in the non-wear window of "
                                 "long epoch " + std::to_string(h) + " of a block: GGIR's g.getmeta() stops there "
                                 "too (its table of the window's wear values is empty)");
      }
      r.nonwear[static_cast<std::size_t>(h - 1)] = n1 >= n0 ? 3 : 0;
    }
  }
  // an isolated 1 between two scores above 1 becomes 2
  for (std::size_t i = 1; i + 1 < r.nonwear.size(); ++i) {
    if (r.nonwear[i] == 1 && r.nonwear[i - 1] > 1 && r.nonwear[i + 1] > 1) r.nonwear[i] = 2;
  }
  return r;
}

// GGIR's lightpeak: for li in 1:(n / M), max(light[((li - 1) M):(li M)])
// (index 0 dropped, so the first epoch has M values and the others M + 1).
// `light(i)`: row i's value; `range(from, to, f)` calls f(v) for the
// values of rows [from, to) (a value once per run of it is enough: a
// maximum), for the usual epochs of whole rows.
template <class L, class Range>
std::vector<double> light_peaks(L&& light, std::size_t n, double M, Range&& range) {
  std::vector<double> out;
  const RColon loop = r_colon(1, static_cast<double>(n) / M);
  if (static_cast<double>(n) / M < 1) return out;
  out.resize(static_cast<std::size_t>(loop.n), 0.0);
  for (std::int64_t k = 0; k < loop.n; ++k) {
    const double li = loop.at(k);
    double mx = -std::numeric_limits<double>::infinity();
    bool na = false;
    const RColon c = r_colon((li - 1) * M, li * M);
    auto take = [&](double v) {
      if (std::isnan(v)) na = true;
      else if (v > mx) mx = v;
    };
    if (!c.down && c.from >= 0 && c.from == std::floor(c.from) && c.from < 9007199254740992.0) {
      // whole indices from, from + 1, ...: rows [max(from, 1) - 1, min(last, n))
      const std::int64_t first = std::max<std::int64_t>(static_cast<std::int64_t>(c.from), 1);
      const std::int64_t last = std::min<std::int64_t>(static_cast<std::int64_t>(c.from) + c.n - 1,
                                                       static_cast<std::int64_t>(n));
      if (first <= last) range(static_cast<std::size_t>(first - 1), static_cast<std::size_t>(last), take);
    } else {
      at_r_indices(c, n, [&](std::size_t j) { take(light(j)); });
    }
    // indices beyond the end are NA in R, and max() without na.rm is NA
    if (static_cast<std::int64_t>(c.at(c.n - 1)) > static_cast<std::int64_t>(n)) na = true;
    out[static_cast<std::size_t>(k)] = na ? kNaN : mx;
  }
  return out;
}

// The share of z's running medians the calling thread of short_metrics()
// makes when it has little else to do.
constexpr double kShareOfZ = 0.2;

// The short-epoch metrics of g.applymetrics() that need no filter, for a
// block of calibrated samples: "roll_med_acc_x" (and y, z),
// "dev_roll_med_acc_x" (y, z), "angle_x" (y, z), "ENMO", "MAD", "EN",
// "ENMOa"; with filter coefficients `fc`, also the filtered metrics of
// ggir_filters.hpp ("BFEN", "LFENMO", "ZCX", ...: zero crossings summed
// per epoch, the others averaged). Each asked name gets its epoch values
// (unrounded), in the order asked. Unknown names are an error. The
// caller's own sums of the block (`extra`: the long epochs' means) are
// made in the same pass as the metrics' (run_pass()); the caller finishes
// them. `beside`, when given, is the caller's other work on the block (it
// reads x, y, z and writes none of what is here), made after the pass;
// `on_rows`, when given, reads the rows in the pass (run_pass()).
//
// With `threads` 2, the running medians of GGIR's angles (a fifth of a
// block's time) and the sums that read them are made on a second thread,
// beside the rest (the filters, the other sums, `beside`): each sum is
// made whole by one thread, in its order, so the bits do not depend on
// the threads; with the default metrics this thread makes part of the
// medians too (kShareOfZ; a median depends on its window only, so the
// bits do not depend on who makes it).
template <class Acc>
std::vector<std::vector<double>> short_metrics(const double* x, const double* y, const double* z,
                                               std::size_t n, double sf, double ws3,
                                               const std::vector<std::string>& names,
                                               const GgirFilterCoefs* fc = nullptr,
                                               RFilterArith arith = {},
                                               PassSum<Acc>* const* extra = nullptr,
                                               std::size_t n_extra = 0, int threads = 1,
                                               const std::function<void()>& beside = {},
                                               const std::function<void(std::size_t, std::size_t)>& on_rows = {}) {
  const double by = sf * ws3;
  std::vector<std::vector<double>> out(names.size());
  // the sums of the metrics computed sample by sample, made in one pass
  // (run_pass()) after the loop over the names: the names they are for,
  // and whether they read the running medians
  std::vector<PassSum<Acc>> pass;
  std::vector<std::size_t> pass_k;
  std::vector<bool> pass_rm;
  pass.reserve(names.size());
  RollMed rm[3];
  auto make_rm = [&]() {
    const double* v[3] = {x, y, z};
    for (int a = 0; a < 3; ++a) rm[a] = ggir_rollmed(v[a], n, sf);
    RollMed* p[3] = {&rm[0], &rm[1], &rm[2]};
    fill_na_last(p, n);
  };
  auto en = [x, y, z](std::size_t i) { return r_norm(x[i], y[i], z[i]); };
  const double deg = 3.141592653589793238462643383280 / 180;  // R: pi / 180
  std::vector<FilteredMetric> fms;
  std::vector<std::size_t> fk;    // their places among names
  std::vector<std::size_t> mad_k;  // MAD's places: a pass of its own
  for (std::size_t k = 0; k < names.size(); ++k) {
    const std::string& nm = names[k];
    FilteredMetric fm;
    if (filtered_metric_from_name(nm.c_str(), &fm)) {
      if (fc == nullptr) throw std::runtime_error("no filter coefficients for " + nm);
      fms.push_back(fm);
      fk.push_back(k);
      continue;
    }
    int axis = -1;
    if (nm.size() > 2 && nm[nm.size() - 2] == '_') {
      const char c = nm.back();
      axis = c == 'x' ? 0 : c == 'y' ? 1 : c == 'z' ? 2 : -1;
    }
    const std::string base = axis >= 0 ? nm.substr(0, nm.size() - 2) : nm;
    using Fill = std::function<void(std::size_t, std::size_t, const double*, double*)>;
    auto sum = [&](bool needs_norm, bool reads_rm, Fill fill) {
      pass.push_back(PassSum<Acc>{EpochSums<Acc>(n, by, true), std::move(fill), needs_norm});
      pass_k.push_back(k);
      pass_rm.push_back(reads_rm);
    };
    if (base == "roll_med_acc" && axis >= 0) {
      const RollMed& r = rm[axis];
      sum(false, true, [&r](std::size_t from, std::size_t to, const double*, double* o) {
        for (std::size_t i = from; i < to; ++i) o[i - from] = r[i];
      });
    } else if (base == "dev_roll_med_acc" && axis >= 0) {
      const double* v = axis == 0 ? x : axis == 1 ? y : z;
      const RollMed& r = rm[axis];
      sum(false, true, [v, &r](std::size_t from, std::size_t to, const double*, double* o) {
        for (std::size_t i = from; i < to; ++i) o[i - from] = std::fabs(v[i] - r[i]);
      });
    } else if (base == "angle" && axis >= 0) {
      const RollMed& a = rm[axis];
      const RollMed& b = rm[(axis + 1) % 3];
      const RollMed& c = rm[(axis + 2) % 3];
      // GGIR's order: angle_x: atan(x / sqrt(y^2 + z^2)); angle_y: y over
      // x, z; angle_z: z over x, y
      const RollMed& p = axis == 1 ? c : b;  // first in the sum
      const RollMed& q = axis == 1 ? b : c;
      auto angle = [&a, &p, &q, deg](std::size_t i) {
        const double pi = p[i], qi = q[i];
        return std::atan(a[i] / (std::sqrt(pi * pi + qi * qi))) / deg;
      };
      // the medians hold for `step` samples (10 Hz): their angle is taken
      // once per subsample value (the same inputs, the same result); rows
      // come in increasing order: the value is new where a row reaches the
      // next multiple of the step (whether the medians are held is known
      // once they are made: at the first row)
      sum(false, true, [angle, &a, &p, &q, held = false, next = std::size_t(0), value = 0.0](
                           std::size_t from, std::size_t to, const double*, double* o) mutable {
        if (from == 0) {
          held = a.raw == nullptr && p.raw == nullptr && q.raw == nullptr && a.step == p.step &&
                 a.step == q.step && a.LN == p.LN && a.LN == q.LN;
        }
        for (std::size_t i = from; i < to; ++i) {
          if (!held || i >= a.LN) {
            o[i - from] = angle(i);
            continue;
          }
          if (i >= next) {
            next = (i / a.step + 1) * a.step;
            value = angle(i);
          }
          o[i - from] = value;
        }
      });
    } else if (nm == "ENMO") {
      sum(true, false, [](std::size_t from, std::size_t to, const double* e, double* o) {
        for (std::size_t i = 0; i < to - from; ++i) {
          const double d = e[i] - 1;
          o[i] = d < 0 ? 0 : d;
        }
      });
    } else if (nm == "EN") {
      sum(true, false, [](std::size_t from, std::size_t to, const double* e, double* o) {
        std::copy(e, e + (to - from), o);
      });
    } else if (nm == "ENMOa") {
      sum(true, false, [](std::size_t from, std::size_t to, const double* e, double* o) {
        for (std::size_t i = 0; i < to - from; ++i) o[i] = std::fabs(e[i] - 1);
      });
    } else if (nm == "MAD") {
      mad_k.push_back(k);
    } else {
      throw std::runtime_error("unknown GGIR metric: " + nm);
    }
  }
  std::vector<PassSum<Acc>*> near, far;  // the sums without and with the medians
  for (std::size_t j = 0; j < pass.size(); ++j) (pass_rm[j] ? far : near).push_back(&pass[j]);
  for (std::size_t i = 0; i < n_extra; ++i) near.push_back(extra[i]);
  // the second thread: the medians and the sums that read them; joined
  // before any exception of this thread leaves (the guard), its own
  // exception raised here after the join
#ifndef GRAVCAL_NO_THREADS
  // (what the second thread reads is declared before the guard, so that it
  // outlives the thread whatever leaves this one)
  RollMedWork rw[3];
  std::size_t z_split = 0;
  std::promise<void> z_begun;
  std::future<void> z_begun_f = z_begun.get_future();
  std::exception_ptr far_error;
  std::thread side;
  const JoinGuard join{side};
  bool two = threads >= 2 && !far.empty();
#else
  const bool two = false;
  (void)threads;
#endif
#ifndef GRAVCAL_NO_THREADS
  // Where this thread has only the sums without the medians and `beside`
  // (no filter, no MAD: the default metrics), it first makes the last
  // kShareOfZ of z's medians, so that the two threads end together: the
  // second makes x's and y's, then the rest of z's once this thread has
  // begun z (`z_begun`), then the sums that read them. A week's .cwa
  // (per-thread timers, stop 60): per block of 36 h, the medians of an axis
  // about 0.017 s, the sums without them (0.07 s) and `beside` (0.045 s) on
  // this thread, those with them 0.04 s; with kShareOfZ 0.2 or 0 the
  // threads take 0.11-0.12 s (2/3: 0.12-0.13 s).
  // `z_begun` is set, with a value or this thread's error, before this
  // thread does anything else.
  const bool share = two && fms.empty() && mad_k.empty();
  if (two) {
    try {
      side = std::thread([&]() {
        try {
          if (!share) {
            make_rm();
          } else {
            const double* v[2] = {x, y};
            for (int a = 0; a < 2; ++a) {
              rollmed_begin(v[a], n, sf, rm[a], rw[a]);
              rollmed_part(rm[a], rw[a], rw[a].from, rw[a].to);
              rollmed_end(rm[a], rw[a], v[a], n, sf);
            }
            z_begun_f.get();  // z begun, its last part made
            rollmed_part(rm[2], rw[2], rw[2].from, z_split);
            rollmed_end(rm[2], rw[2], z, n, sf);
            RollMed* p[3] = {&rm[0], &rm[1], &rm[2]};
            fill_na_last(p, n);
          }
          run_pass<Acc>(far.data(), far.size(), x, y, z, n);
        } catch (...) {
          far_error = std::current_exception();
        }
      });
    } catch (const std::system_error&) {
      two = false;  // no thread to be had: all on this one
    }
  }
  if (two && share) {
    try {
      rollmed_begin(z, n, sf, rm[2], rw[2]);
      const std::size_t c = rw[2].to - rw[2].from;
      z_split = rw[2].from + c - static_cast<std::size_t>(static_cast<double>(c) * kShareOfZ);
      rollmed_part(rm[2], rw[2], z_split, rw[2].to);
      z_begun.set_value();
    } catch (...) {
      z_begun.set_exception(std::current_exception());
      throw;
    }
  }
#endif
  if (!two && !far.empty()) {
    make_rm();
    for (PassSum<Acc>* f : far) near.push_back(f);  // all in one pass
  }
  // the filtered metrics, each filter run once for all of them
  // (ggir_filtered_signals()); their errors raised in the order asked
  std::vector<SignalStatus> fstatus(names.size(), SignalStatus::ok);
  if (fc != nullptr && !fms.empty()) {
    // each filtered signal summed per epoch as its parts come
    std::vector<EpochSums<Acc>> sums;
    sums.reserve(fms.size());
    for (std::size_t i = 0; i < fms.size(); ++i) sums.emplace_back(n, by, true);
    struct Sink {
      const std::vector<FilteredMetric>& fms;
      const std::vector<std::size_t>& fk;
      std::vector<SignalStatus>& fstatus;
      std::vector<EpochSums<Acc>>& sums;
      std::size_t n;
      double by;
      void begin(std::size_t i, SignalStatus st) {  // (again: from the start)
        fstatus[fk[i]] = st;
        const FilteredMetric fm = fms[i];
        const bool zc = fm == FilteredMetric::ZCX || fm == FilteredMetric::ZCY || fm == FilteredMetric::ZCZ;
        sums[i] = EpochSums<Acc>(n, by, !zc);  // sumPerEpoch for ZC*
      }
      // a part's values, summed when the part is whole (end_part()): the
      // metrics' sums side by side
      std::vector<EpochSums<Acc>*> pe;
      std::vector<const double*> pv;
      std::size_t plen = 0;
      void values(std::size_t i, const double* v, std::size_t len) {
        pe.push_back(&sums[i]);
        pv.push_back(v);
        plen = len;
      }
      void end_part() {
        EpochSums<Acc>::add_many(pe.data(), pv.data(), pe.size(), plen);
        pe.clear();
        pv.clear();
      }
    } sink{fms, fk, fstatus, sums, n, by, {}, {}, 0};
    ggir_filtered_signals(fms.data(), fms.size(), x, y, z, n, *fc, arith, sink);
    for (std::size_t i = 0; i < fms.size(); ++i) {
      if (fstatus[fk[i]] == SignalStatus::ok) out[fk[i]] = sums[i].finish();
    }
  }
  for (std::size_t k : fk) {
    const SignalStatus st = fstatus[k];
    if (st == SignalStatus::internal_na) throw std::runtime_error("time series contains internal NAs");
    if (st == SignalStatus::replacement_length)
      throw std::runtime_error("number of items to replace is not a multiple of replacement length");
    if (st == SignalStatus::too_short) throw std::runtime_error("GGIR's zero crossings need at least 2 samples");
  }
  for (std::size_t k : mad_k) {
    // rep(epoch means, each = sf * ws3) (each truncated to an integer),
    // recycled against EN as R's `-` recycles
    const std::vector<double> means = per_epoch_of<Acc>(n, by, true, en);
    const std::size_t each = static_cast<std::size_t>(by);
    const std::size_t m = means.size() * each;
    const std::size_t len = (n == 0 || m == 0) ? 0 : std::max(n, m);
    out[k] = per_epoch_of<Acc>(len, by, true, [&en, &means, n, m, each](std::size_t i) {
      return std::fabs(en(i % n) - means[(i % m) / each]);
    });
  }
  run_pass<Acc>(near.data(), near.size(), x, y, z, n, on_rows);
  if (beside) beside();
#ifndef GRAVCAL_NO_THREADS
  if (two) {
    side.join();
    if (far_error) std::rethrow_exception(far_error);
  }
#endif
  for (std::size_t j = 0; j < pass.size(); ++j) out[pass_k[j]] = pass[j].sums.finish();
  return out;
}

// The gradient of each short epoch's ENMO with respect to the coefficients
// of a linear calibration, for the standard error that the coefficients'
// uncertainty puts on summaries of ENMO (the delta method; R/outcome-se.R).
// Model: a = K (v + o) + (t - meantemp) tempoffset, K lower triangular (the
// fit's; GGIR's diagonal scale is K = diag(scale)). ENMO of a sample is
// max(|a| - 1, 0), so its gradient is [|a| > 1] (a / |a|)' da/dtheta with
// da/dk_ij = (v_j + o_j) e_i (i >= j), da/do_j = K[, j] and
// da/dt_j = (t - meantemp) e_j. An epoch's gradient is the mean of its
// samples' over the epochs per_epoch() cuts (R's round(seq(1, n + 1, by))
// bounds), in plain double sums: a derivative, not a promised bit.
// Columns in coef()'s order: k_xx, k_yy, k_zz, k_xy, k_xz, k_yz, o_x, o_y,
// o_z, t_x, t_y, t_z; row-major, out[e * kGradientColumns + c].
constexpr std::size_t kGradientColumns = 12;

struct LinearCalibration {
  double K[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};  // K[row][column]
  double offset[3] = {0, 0, 0};
  bool temp = false;  // the temperature term applies
  double meantemp = 0;
  double tempoffset[3] = {0, 0, 0};
};

template <class T>
std::vector<double> enmo_gradient(const double* x, const double* y, const double* z,
                                         T&& t, bool have_t, std::size_t n, double by,
                                         const LinearCalibration& m) {
  constexpr std::size_t C = kGradientColumns;
  const std::vector<double> sel = r_seq_by(1.0, static_cast<double>(n + 1), by);
  std::vector<double> out;
  if (sel.size() < 2) return out;
  const std::size_t ne = sel.size() - 1;
  out.assign(ne * C, 0.0);
  const bool temp = m.temp && have_t;
  std::size_t from = static_cast<std::size_t>(r_round0(sel[0])) - 1;
  for (std::size_t e = 0; e < ne; ++e) {
    const std::size_t to = static_cast<std::size_t>(r_round0(sel[e + 1])) - 1;
    double* g = &out[e * C];
    for (std::size_t i = from; i < to; ++i) {
      const double u[3] = {x[i] + m.offset[0], y[i] + m.offset[1], z[i] + m.offset[2]};
      const double dt = temp ? t(i) - m.meantemp : 0;
      double a[3];
      for (int r = 0; r < 3; ++r) {
        a[r] = m.K[r][0] * u[0] + m.K[r][1] * u[1] + m.K[r][2] * u[2];
        if (temp) a[r] = a[r] + dt * m.tempoffset[r];
      }
      const double na = std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
      if (!(na > 1)) continue;  // ENMO is 0 here, and so is its gradient
      const double q[3] = {a[0] / na, a[1] / na, a[2] / na};
      g[0] += q[0] * u[0];
      g[1] += q[1] * u[1];
      g[2] += q[2] * u[2];
      g[3] += q[1] * u[0];
      g[4] += q[2] * u[0];
      g[5] += q[2] * u[1];
      for (int j = 0; j < 3; ++j) {
        g[6 + j] += q[0] * m.K[0][j] + q[1] * m.K[1][j] + q[2] * m.K[2][j];
      }
      if (temp) {
        g[9] += q[0] * dt;
        g[10] += q[1] * dt;
        g[11] += q[2] * dt;
      }
    }
    const double len = static_cast<double>(to > from ? to - from : 1);
    for (std::size_t c = 0; c < C; ++c) g[c] = g[c] / len;
    from = to;
  }
  return out;
}

}  // namespace ggir_part1
}  // namespace gravcal

#endif  // GRAVCAL_GGIR_EPOCHS_HPP
