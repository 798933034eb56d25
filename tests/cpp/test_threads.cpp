// gravcal: the work on a second thread. GGIR part 1's epoch signals on one
// thread and on two (ggir_epochs.hpp short_metrics(): the running medians
// of the angles and the sums that read them on a second thread): the same
// bits, for every mix of metrics and block shapes here. A byte source read
// ahead (read_ahead.hpp): the inner source's bytes, end and failure, for
// any sizes of buffer and read, and stopped before its end. GGIR's block
// rules with the segmenter's hours on a worker thread (ggir_blocks.hpp
// async()): the same windows and blocks as on one thread, and a sink's
// error raised on the caller's. Built also
// with ThreadSanitizer (make test: test_threads_tsan), which fails the run
// on a data race between the threads.
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "gravcal/decoders/read_ahead.hpp"
#include "gravcal/ggir/ggir_epochs.hpp"
#include "gravcal/ggir/pipeline.hpp"

namespace p1 = gravcal::ggir_part1;

static int failures = 0;

static bool same_bits(const std::vector<std::vector<double>>& a, const std::vector<std::vector<double>>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t k = 0; k < a.size(); ++k) {
    if (a[k].size() != b[k].size()) return false;
    if (!a[k].empty() && std::memcmp(a[k].data(), b[k].data(), a[k].size() * sizeof(double)) != 0) return false;
  }
  return true;
}

// A block of n samples at sf Hz: slow turns, rest and bursts; NaN rows
// where asked (the medians' NA rule).
static void block(std::size_t n, double sf, bool with_nan, std::vector<double>* v) {
  for (int a = 0; a < 3; ++a) v[a].resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double t = static_cast<double>(i) / sf;
    const double burst = (static_cast<std::size_t>(t / 30) % 4 == 1) ? 0.8 * std::sin(t * 11.0) : 0.0;
    v[0][i] = 0.3 * std::sin(t * 0.01) + burst;
    v[1][i] = 0.2 * std::cos(t * 0.003) - 0.5 * burst;
    v[2][i] = 0.93 + 0.05 * std::sin(t * 0.7) + burst * burst;
  }
  if (with_nan && n > 40) {
    v[1][n / 3] = std::numeric_limits<double>::quiet_NaN();
    v[2][n - 7] = std::numeric_limits<double>::quiet_NaN();
  }
}

static void check(const char* what, std::size_t n, double sf, bool with_nan,
                  const std::vector<std::string>& names) {
  std::vector<double> v[3];
  block(n, sf, with_nan, v);
  // the caller's sum beside (a long epoch's mean of the norm) and work
  // beside (reads the axes, as non-wear does)
  auto run = [&](int threads) {
    p1::PassSum<long double> en{p1::EpochSums<long double>(n, sf * 60, true),
                                [](std::size_t from, std::size_t to, const double* nm, double* o) {
                                  std::copy(nm, nm + (to - from), o);
                                },
                                true};
    p1::PassSum<long double>* extra[1] = {&en};
    double beside_sum = 0;
    const std::function<void()> beside = [&]() {
      for (std::size_t i = 0; i < n; ++i) beside_sum += std::fabs(v[0][i]);
    };
    std::vector<std::vector<double>> out =
        p1::short_metrics<long double>(v[0].data(), v[1].data(), v[2].data(), n, sf, 5, names, nullptr, {},
                                       extra, 1, threads, beside);
    out.push_back(en.sums.finish());
    out.push_back({beside_sum});
    return out;
  };
  const std::vector<std::vector<double>> one = run(1), two = run(2);
  if (!same_bits(one, two)) {
    std::printf("FAIL %s: one thread and two differ\n", what);
    ++failures;
  }
  if (one.empty() || (n >= static_cast<std::size_t>(sf * 5) && one[0].empty())) {
    std::printf("FAIL %s: no epochs\n", what);
    ++failures;
  }
}

// An inner source that gives its bytes in pieces of `piece` and, with
// `fail_at`, fails there (a read error: fewer bytes, then failed()).
class PieceSource : public gravcal::ByteSource {
 public:
  PieceSource(const std::vector<unsigned char>& b, std::size_t piece, std::size_t fail_at)
      : b_(b), piece_(piece), end_(std::min(fail_at, b.size())), fails_(fail_at < b.size()) {}
  std::size_t read(unsigned char* buf, std::size_t n) override {
    const std::size_t k = std::min({n, piece_, end_ - at_});
    if (k) std::memcpy(buf, b_.data() + at_, k);
    at_ += k;
    return k;
  }
  bool failed() const override { return fails_ && at_ >= end_; }
  std::int64_t position() const override { return static_cast<std::int64_t>(at_); }

 private:
  const std::vector<unsigned char>& b_;
  std::size_t piece_, end_;
  bool fails_;
  std::size_t at_ = 0;
};

static void check_read_ahead() {
  std::vector<unsigned char> bytes(300007);
  std::uint32_t r = 12345;
  for (unsigned char& c : bytes) {
    r = r * 1103515245u + 12345u;
    c = static_cast<unsigned char>(r >> 24);
  }
  const std::size_t lens[] = {0, 1, 4096, 300007};
  for (std::size_t len : lens) {
    for (std::size_t chunk : {1, 7, 4096, 65536, 400000}) {
      for (std::size_t want : {1, 3, 1000, 500000}) {
        for (std::size_t fail_at : {static_cast<std::size_t>(-1), len / 2}) {
          if (fail_at == len / 2 && len == 0) continue;
          const std::vector<unsigned char> b(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(len));
          std::unique_ptr<gravcal::ByteSource> inner(new PieceSource(b, 5000, fail_at));
          gravcal::ReadAheadSource ra(std::move(inner), chunk, 3);
          std::vector<unsigned char> got, buf(want);
          for (;;) {
            const std::size_t k = ra.read(buf.data(), want);
            if (k == 0) break;
            got.insert(got.end(), buf.begin(), buf.begin() + static_cast<std::ptrdiff_t>(k));
          }
          const std::size_t expect = std::min(fail_at, len);
          const bool ok = got.size() == expect && std::equal(got.begin(), got.end(), b.begin()) &&
                          ra.read(buf.data(), want) == 0 && ra.failed() == (fail_at < len) &&
                          ra.position() == static_cast<std::int64_t>(expect);
          if (!ok) {
            std::printf("FAIL read ahead: %zu bytes, buffers of %zu, reads of %zu, failing at %zu: %zu bytes, failed %d\n",
                        len, chunk, want, fail_at, got.size(), static_cast<int>(ra.failed()));
            ++failures;
          }
        }
      }
    }
  }
  // stopped before the end (destroyed with the thread waiting on full
  // buffers, and before any read: no thread)
  for (std::size_t reads : {0, 1, 2}) {
    std::unique_ptr<gravcal::ByteSource> inner(new gravcal::MemorySource(bytes.data(), bytes.size()));
    gravcal::ReadAheadSource ra(std::move(inner), 1000, 2);
    unsigned char b[10];
    for (std::size_t i = 0; i < reads; ++i) {
      if (ra.read(b, sizeof b) != sizeof b || b[0] != bytes[i * sizeof b]) {
        std::printf("FAIL read ahead stopped early: read %zu\n", i);
        ++failures;
      }
    }
  }
}


// Columns given by read() (as a decoder writes them), not lent.
class WrittenSource : public gravcal::Source {
 public:
  WrittenSource(const std::vector<double>& x, const std::vector<double>& y, const std::vector<double>& z,
                const std::vector<double>& t)
      : c_(x.data(), y.data(), z.data(), t.data(), x.size()) {}
  std::int64_t read(gravcal::SampleBuffer& out, std::int64_t max_units) override {
    // at most 5000 at a time, as a decoder's reads are cut
    gravcal::SampleBuffer o = out;
    o.capacity = std::min(out.capacity, out.n + 5000);
    const std::int64_t u = c_.read(o, max_units);
    out.n = o.n;
    return u;
  }
  bool done() const override { return c_.done(); }
  bool has_temperature() const override { return true; }

 private:
  gravcal::ColumnsSource c_;
};

// GGIR's block rules over a recording of `hours` at sf Hz (idle-sleep
// zeros in runs, one at each block's end, a temperature), in blocks of
// `units` samples, written through the pump: every window and every
// block's numbers, with the segmenter on this thread or on a worker's.
struct BlockRun {
  std::vector<gravcal::WindowStats> windows;
  std::vector<gravcal::GgirBlockInfo> blocks;
};

static BlockRun block_run(double sf, double hours, std::int64_t units, bool compat, bool async,
                          std::int64_t throw_at = -1) {
  const std::size_t n = static_cast<std::size_t>(sf * 3600 * hours);
  std::vector<double> x(n), y(n), z(n), t(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double u = static_cast<double>(i) / sf;
    const bool moving = std::fmod(u, 5400.0) < 1800.0;
    x[i] = 0.1 * std::sin(u / 700) + (moving ? 0.2 * std::sin(u * 3.1) : 1e-4 * std::sin(u * 7.7));
    y[i] = 0.98 - 0.05 * std::cos(u / 900);
    z[i] = 0.15 + (moving ? 0.1 * std::cos(u * 2.3) : 0.0);
    t[i] = 20 + std::floor(u / 600) * 0.0625;
    const bool idle = std::fmod(u, 7000.0) < 300.0 ||
                      (units > 0 && (i + 1) % static_cast<std::size_t>(units) == 0);
    if (idle) x[i] = y[i] = z[i] = 0.0;
  }
  WrittenSource src(x, y, z, t);
  gravcal::Segmenter seg(10 * sf, true);
#ifndef GRAVCAL_NO_THREADS
  gravcal::Worker worker;
#endif
  gravcal::GgirBlocks blocks(seg, 3600 * sf, compat, true);
#ifndef GRAVCAL_NO_THREADS
  if (async) blocks.async(&worker);
#else
  (void)async;  // (no threads: both runs on this one)
#endif
  gravcal::BlocksStage stage(blocks, true);
  BlockRun out;
  for (;;) {
    auto sink = [&](const gravcal::WindowStats& w) {
      if (throw_at >= 0 && static_cast<std::int64_t>(out.windows.size()) == throw_at) {
        throw std::runtime_error("the sink's error");
      }
      out.windows.push_back(w);
    };
    const gravcal::GgirBlockRead r = gravcal::read_ggir_block(src, blocks, stage, units, sink, [] { return false; });
    if (r.pump.units == 0 && r.pump.samples == 0) break;
    out.blocks.push_back(r.info);
    if (r.pump.done) break;
  }
  return out;
}

static void check_async_blocks() {
  struct Case {
    double sf, hours;
    std::int64_t units;
    bool compat;
  } cases[] = {{10, 30, 250000, true}, {10, 30, 250000, false}, {10, 7, 36000 * 3, true},
               {33.3, 6, 300000, true}, {2, 20, 40000, true}, {10, 0.5, 100000, true}};
  for (const Case& c : cases) {
    const BlockRun a = block_run(c.sf, c.hours, c.units, c.compat, false);
    const BlockRun b = block_run(c.sf, c.hours, c.units, c.compat, true);
    bool ok = a.windows.size() == b.windows.size() && a.blocks.size() == b.blocks.size() &&
              !a.windows.empty() == (c.hours >= 1);
    for (std::size_t i = 0; ok && i < a.windows.size(); ++i) {
      ok = std::memcmp(&a.windows[i], &b.windows[i], sizeof(gravcal::WindowStats)) == 0;
    }
    for (std::size_t i = 0; ok && i < a.blocks.size(); ++i) {
      const gravcal::GgirBlockInfo &p = a.blocks[i], &q = b.blocks[i];
      ok = p.rows == q.rows && p.zeros == q.zeros && p.ld == q.ld && p.used == q.used &&
           p.carried == q.carried && std::memcmp(&p.first_mean, &q.first_mean, sizeof(double)) == 0 &&
           std::memcmp(&p.temp_sd, &q.temp_sd, sizeof(double)) == 0;
    }
    if (!ok) {
      std::printf("FAIL async block rules: %g Hz, %g h, blocks of %lld, compat %d: %zu / %zu windows\n", c.sf,
                  c.hours, static_cast<long long>(c.units), static_cast<int>(c.compat), a.windows.size(),
                  b.windows.size());
      ++failures;
    }
  }
  // the sink's error on the worker: raised on this thread, by the read
  for (bool async : {false, true}) {
    std::string what;
    try {
      block_run(10, 5, 100000, true, async, 700);
    } catch (const std::runtime_error& e) {
      what = e.what();
    }
    if (what != "the sink's error") {
      std::printf("FAIL async block rules: the sink's error (async %d): \"%s\"\n", static_cast<int>(async),
                  what.c_str());
      ++failures;
    }
  }
}

int main() {
  check_read_ahead();
  check_async_blocks();
  const std::vector<std::string> dflt = {"ENMO", "angle_z"};
  const std::vector<std::string> all = {"angle_x", "angle_y", "angle_z", "roll_med_acc_x", "dev_roll_med_acc_y",
                                        "ENMO", "EN", "ENMOa", "MAD"};
  const std::vector<std::string> no_medians = {"ENMO", "EN", "MAD"};
  // no filter, no MAD: the first thread makes part of z's medians
  const std::vector<std::string> shared = {"angle_x", "angle_y", "angle_z", "roll_med_acc_z",
                                           "dev_roll_med_acc_x", "ENMO", "EN", "ENMOa"};
  check("default, 6 h at 100 Hz", 6 * 3600 * 100, 100, false, dflt);
  check("every unfiltered metric, 2 h at 30 Hz", 2 * 3600 * 30, 30, false, all);
  check("every unfiltered metric, NaN rows", 3600 * 50, 50, true, all);
  check("no medians (one thread used)", 3600 * 100, 100, false, no_medians);
  check("85.7 Hz (the medians at the full rate)", 3600 * 857 / 10, 85.7, false, all);
  check("shorter than the median's window", 30, 10, false, all);
  check("empty block", 0, 100, false, dflt);
  check("medians shared, NaN rows", 3600 * 50, 50, true, shared);
  check("medians shared, 85.7 Hz", 3600 * 857 / 10, 85.7, false, shared);
  check("medians shared, shorter than the median's window", 30, 10, false, shared);
  check("medians shared, a window and a bit", 520, 100, false, shared);
  // an error of the first thread's while the second makes its medians:
  // the second joined, the error raised
  {
    std::vector<double> w[3];
    block(3600 * 100, 100, false, w);
    std::string got;
    try {
      p1::short_metrics<long double>(w[0].data(), w[1].data(), w[2].data(), w[0].size(), 100, 5, dflt,
                                     nullptr, {}, nullptr, 0, 2,
                                     [] { throw std::runtime_error("beside failed"); });
    } catch (const std::runtime_error& e) {
      got = e.what();
    }
    if (got != "beside failed") {
      std::printf("FAIL an error beside the medians: \"%s\"\n", got.c_str());
      ++failures;
    }
  }
  std::vector<double> v[3];
  block(1000, 100, false, v);
  bool threw = false;
  try {
    p1::short_metrics<long double>(v[0].data(), v[1].data(), v[2].data(), 1000, 100, 5, {"angle_z", "nonsense"},
                                   nullptr, {}, nullptr, 0, 2);
  } catch (const std::runtime_error& e) {
    threw = std::strstr(e.what(), "unknown GGIR metric: nonsense") != nullptr;
  }
  if (!threw) {
    std::printf("FAIL an unknown metric is not an error on two threads\n");
    ++failures;
  }
  if (failures == 0) std::printf("threads: one thread and two agree, all checks passed\n");
  return failures == 0 ? 0 : 1;
}
