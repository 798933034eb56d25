// gravcal: GGIR part 1's epoch signals on one thread and on two
// (ggir_epochs.hpp short_metrics(): the running medians of the angles and
// the sums that read them on a second thread). The two must give the same
// bits, for every mix of metrics and block shapes here; built also with
// ThreadSanitizer (make test: test_threads_tsan), which fails the run on a
// data race between the threads.
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <limits>
#include <string>
#include <vector>

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

int main() {
  const std::vector<std::string> dflt = {"ENMO", "angle_z"};
  const std::vector<std::string> all = {"angle_x", "angle_y", "angle_z", "roll_med_acc_x", "dev_roll_med_acc_y",
                                        "ENMO", "EN", "ENMOa", "MAD"};
  const std::vector<std::string> no_medians = {"ENMO", "EN", "MAD"};
  check("default, 6 h at 100 Hz", 6 * 3600 * 100, 100, false, dflt);
  check("every unfiltered metric, 2 h at 30 Hz", 2 * 3600 * 30, 30, false, all);
  check("every unfiltered metric, NaN rows", 3600 * 50, 50, true, all);
  check("no medians (one thread used)", 3600 * 100, 100, false, no_medians);
  check("85.7 Hz (the medians at the full rate)", 3600 * 857 / 10, 85.7, false, all);
  check("shorter than the median's window", 30, 10, false, all);
  check("empty block", 0, 100, false, dflt);
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
