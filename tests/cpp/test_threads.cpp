// gravcal: the work on a second thread. GGIR part 1's epoch signals on one
// thread and on two (ggir_epochs.hpp short_metrics(): the running medians
// of the angles and the sums that read them on a second thread): the same
// bits, for every mix of metrics and block shapes here. A byte source read
// ahead (read_ahead.hpp): the inner source's bytes, end and failure, for
// any sizes of buffer and read, and stopped before its end. Built also
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

int main() {
  check_read_ahead();
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
