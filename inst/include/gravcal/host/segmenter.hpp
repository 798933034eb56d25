// gravcal: the segmenter, a window cutter with its arithmetic chosen when
// the program runs.
//
// The segmenter cuts a sample stream into consecutive, non-overlapping
// windows of a fixed duration and gives, per window, the mean, standard
// deviation (n - 1), min, max and range of each axis, the mean of the
// per-sample vector norm, the mean temperature and the number of samples
// equal in x, y and z to the one before them (WindowStats). The cutting
// is the window cutter's (window_cutter.hpp); the statistics are one of
// three policies:
// - streaming (the default; stats_streaming.hpp): sums about the first
//   valid sample of the window, in four lanes by position; what a
//   microcontroller runs (StreamSegmenter, with the scalar whole-window
//   loop; here the kernel table's);
// - R's arithmetic (use_r_arithmetic(); stats_r.hpp, RExactStats): the
//   numbers GGIR gets in R, to the last bit;
// - R's arithmetic for what GGIR's procedure sees of the sds (lazy_r_sd();
//   stats_r.hpp, LazyRStats): R's sds only where a comparison could tell
//   them from sds in double; windows reach the sink one window late.
// R's arithmetic has two flavours, as R's accumulator (r_arith.hpp): long
// double (R's default) or double (an R built without long double); the
// segmenter holds a cutter of each (RExactStatsT<Acc>, LazyRStatsT<Acc>).
//
// Header-only, standard headers only, no heap.
#ifndef GRAVCAL_SEGMENTER_HPP
#define GRAVCAL_SEGMENTER_HPP

#include <cstddef>
#include <cstdint>

#include "gravcal/host/stats_r.hpp"
#include "gravcal/mcu/stats_streaming.hpp"
#include "gravcal/mcu/window_cutter.hpp"
#include "gravcal/mcu/window_stats.hpp"

namespace gravcal {

// The streaming whole-window loop the kernel table chose.
struct TableStreamWindow {
  static void run(const double* x, const double* y, const double* z, const double* t,
                  std::size_t m, StreamSums& o) {
    kernels::active().stream_window(x, y, z, t, m, o);
  }
};

class Segmenter {
  enum class Mode { streaming, r, lazy, r_double, lazy_double };

  // f(the cutter of the arithmetic in use); visit() and cvisit() come
  // first: the methods below deduce their return types from them
  template <class F>
  decltype(auto) visit(F&& f) {
    if (mode_ == Mode::r) return f(r_);
    if (mode_ == Mode::lazy) return f(lazy_);
    if (mode_ == Mode::r_double) return f(r_d_);
    if (mode_ == Mode::lazy_double) return f(lazy_d_);
    return f(stream_);
  }
  template <class F>
  decltype(auto) cvisit(F&& f) const {
    if (mode_ == Mode::r) return f(r_);
    if (mode_ == Mode::lazy) return f(lazy_);
    if (mode_ == Mode::r_double) return f(r_d_);
    if (mode_ == Mode::lazy_double) return f(lazy_d_);
    return f(stream_);
  }

 public:
  // samples_per_window: L = duration (s) * sampling rate (Hz), at least 1.
  // skip_zero: drop samples with x = y = z = 0 before windowing.
  Segmenter(double samples_per_window, bool skip_zero)
      : stream_(samples_per_window, skip_zero),
        r_(samples_per_window, skip_zero),
        lazy_(samples_per_window, skip_zero),
        r_d_(samples_per_window, skip_zero),
        lazy_d_(samples_per_window, skip_zero) {}

  // Switch to R's arithmetic, with R's accumulator long double
  // (r_long_double, R's default) or double (an R without long double).
  // `buffer` must hold 3 * (ceil(L) + 1) doubles and outlive the segmenter;
  // call before the first push. Returns false (and changes nothing) when it
  // is too small.
  bool use_r_arithmetic(double* buffer, std::size_t capacity, bool r_long_double = true) {
    const double L = r_.samples_per_window();
    if (r_long_double) {
      if (!r_.stats().lend(buffer, capacity, L)) return false;
      lazy_.stats().lend(buffer, capacity, L);
      mode_ = Mode::r;
    } else {
      if (!r_d_.stats().lend(buffer, capacity, L)) return false;
      lazy_d_.stats().lend(buffer, capacity, L);
      mode_ = Mode::r_double;
    }
    return true;
  }
  bool r_arithmetic() const { return mode_ != Mode::streaming; }

  // R's arithmetic for what GGIR's procedure can see of the sds (call after
  // use_r_arithmetic(); see LazyRStats and LazySd, stats_r.hpp): windows
  // then reach the sink one window late, and finish() gives the last one
  // (call it at the end of each of GGIR's blocks). `buffer` (3 * (ceil(L) +
  // 1) doubles, outliving the segmenter) keeps the samples of the window
  // held back. Returns false (and changes nothing) when the buffer is too
  // small, the arithmetic is not R's, or max_sd is not positive and finite.
  bool lazy_r_sd(double max_sd, LazySd* state, double* buffer, std::size_t capacity) {
    if (mode_ == Mode::streaming) return false;
    if (mode_ == Mode::r_double || mode_ == Mode::lazy_double) {
      if (!lazy_d_.stats().lazy(max_sd, state, buffer, capacity)) return false;
      mode_ = Mode::lazy_double;
    } else {
      if (!lazy_.stats().lazy(max_sd, state, buffer, capacity)) return false;
      mode_ = Mode::lazy;
    }
    return true;
  }

  // R's arithmetic: a sample with a non-finite x, y or z enters R's
  // cumulative sums (GGIR's rule for the samples its readers give; on), or
  // is left out of its window (off, the default). See
  // RExactStatsT::keep_nonfinite().
  void keep_nonfinite(bool on) {
    r_.stats().keep_nonfinite(on);
    lazy_.stats().keep_nonfinite(on);
    r_d_.stats().keep_nonfinite(on);
    lazy_d_.stats().keep_nonfinite(on);
  }

  // Push a chunk of n samples. t may be null (no temperature). sink(stats) is
  // called once for every window given out, in order.
  template <class Sink>
  void push(const double* x, const double* y, const double* z, const double* t, std::size_t n,
            Sink&& sink) {
    visit([&](auto& c) { c.push(x, y, z, t, n, sink); });
  }

  // Gives the window held back by lazy_r_sd() (a no-op otherwise).
  template <class Sink>
  void finish(Sink&& sink) {
    visit([&](auto& c) { c.finish(sink); });
  }

  // Restart the cumulative sums, as GGIR does at each block it reads. Only at
  // a window boundary (no open window); returns false otherwise.
  bool new_block() {
    return visit([](auto& c) { return c.new_block(); });
  }

  void reset() {
    visit([](auto& c) { c.reset(); });
  }

  // Samples in the open (incomplete) window; these are dropped at the end.
  std::int64_t pending() const { return cvisit([](const auto& c) { return c.pending(); }); }
  std::int64_t windows() const { return cvisit([](const auto& c) { return c.windows(); }); }
  std::int64_t retained() const { return cvisit([](const auto& c) { return c.retained(); }); }
  std::int64_t skipped_zero() const {
    return cvisit([](const auto& c) { return c.skipped_zero(); });
  }

 private:
  Mode mode_ = Mode::streaming;
  WindowCutter<StreamingStatsT<TableStreamWindow>> stream_;
  WindowCutter<RExactStats> r_;
  WindowCutter<LazyRStats> lazy_;
  WindowCutter<RExactStatsT<double>> r_d_;
  WindowCutter<LazyRStatsT<double>> lazy_d_;
};

}  // namespace gravcal

#endif  // GRAVCAL_SEGMENTER_HPP
