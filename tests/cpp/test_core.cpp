// Standalone tests of the header-only core, built without R:
//   make -C tests/cpp
// Checks the model round trip, chunk invariance of the segmenter, the bin
// rules and recovery of known parameters by the gradient fit, in double and
// float, and by the ICP fit (icp.hpp, with Eigen); and that the R-compatible
// window arithmetic is also chunk invariant.
// First, as in the package: no contraction anywhere in this translation
// unit (the test data's generators included), whatever the flags.
#include "gravcal/mcu/fp_contract.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "gravcal/decoders/decode_cwa.hpp"
#include "gravcal/decoders/decode_geneactiv.hpp"
#include "gravcal/ggir/ggir_blocks.hpp"
#include "gravcal/ggir/ggir_epochs.hpp"
#include "gravcal/gravcal.hpp"
#include "gravcal/host/segmenter.hpp"
#include "gravcal/ggir/icp.hpp"
#include "gravcal/host/big_array.hpp"

static int failures = 0;
#define CHECK(cond)                                                   \
  do {                                                                \
    if (!(cond)) {                                                    \
      std::printf("FAIL %s:%d: %s\n", __FILE__, __LINE__, #cond);     \
      ++failures;                                                     \
    }                                                                 \
  } while (0)

using gravcal::Vec3;

// Whether long double arithmetic really has the precision its type says
// (64 bits on x87). Valgrind's CPU emulation computes x87 operations in
// double precision, so there the checks that compare the core's proven
// shortcuts with a plain long double loop (R's arithmetic) cannot hold and
// are reported, not failed; `make core` runs them on the real CPU.
static bool long_double_as_declared() {
  volatile long double one = 1.0L;
  volatile long double tiny = std::numeric_limits<long double>::epsilon();
  return one + tiny != one;
}
static bool ld_ok = long_double_as_declared();
#define CHECK_LD(cond)                                                          \
  do {                                                                          \
    if (ld_ok) {                                                                \
      CHECK(cond);                                                              \
    } else if (!(cond)) {                                                       \
      std::printf("note %s:%d: %s does not hold with emulated long double\n",   \
                  __FILE__, __LINE__, #cond);                                   \
    }                                                                           \
  } while (0)

static void test_model() {
  const double p[9] = {1.05, 0.95, 1.02, 0.03, -0.04, 0.02, 0.08, -0.06, 0.05};
  const Vec3<double> a{0.3, 0.5, std::sqrt(1 - 0.34)};
  const Vec3<double> v = gravcal::invert_model(p, a);
  const Vec3<double> b = gravcal::apply_model(p, v);
  CHECK(std::fabs(b.x - a.x) < 1e-15 && std::fabs(b.y - a.y) < 1e-15 &&
        std::fabs(b.z - a.z) < 1e-15);
}

struct Collect {
  std::vector<gravcal::WindowStats>* out;
  void operator()(const gravcal::WindowStats& s) const { out->push_back(s); }
};

static void test_segmenter() {
  std::mt19937 rng(1);
  std::normal_distribution<double> noise(0.0, 0.01);
  const std::size_t n = 20000;
  std::vector<double> x(n), y(n), z(n), t(n);
  for (std::size_t i = 0; i < n; ++i) {
    x[i] = 0.1 + noise(rng);
    y[i] = -0.2 + noise(rng);
    z[i] = 0.97 + noise(rng);
    t[i] = 25.0 + 0.001 * static_cast<double>(i);
  }
  x[50] = y[50] = z[50] = 0.0;  // idle-sleep sample
  y[3000] = NAN;                // an invalid sample
  t[7000] = NAN;                // a missing temperature
  std::vector<gravcal::WindowStats> whole, parts;
  gravcal::Segmenter s1(428.5, true);
  s1.push(x.data(), y.data(), z.data(), t.data(), n, Collect{&whole});
  gravcal::Segmenter s2(428.5, true);
  std::uniform_int_distribution<int> len(1, 997);
  for (std::size_t i = 0; i < n;) {
    std::size_t k = static_cast<std::size_t>(len(rng));
    if (i + k > n) k = n - i;
    s2.push(x.data() + i, y.data() + i, z.data() + i, t.data() + i, k,
            Collect{&parts});
    i += k;
  }
  CHECK(whole.size() == parts.size());
  CHECK(whole.size() == 46);
  CHECK(s1.skipped_zero() == 1);
  CHECK(whole[6].n_invalid == 1 && whole[5].n_invalid == 0);
  CHECK(!std::isnan(whole[16].temperature));
  bool same = whole.size() == parts.size();
  for (std::size_t i = 0; same && i < whole.size(); ++i)
    same = std::memcmp(&whole[i], &parts[i], sizeof(gravcal::WindowStats)) == 0;
  CHECK(same);
  CHECK(std::fabs(whole[1].mean[2] - 0.97) < 0.005);
  CHECK(std::fabs(whole[1].sd[0] - 0.01) < 0.002);
  gravcal::RangeRestRule rr;
  CHECK(gravcal::is_rest(whole[1], rr));
  gravcal::SdRestRule sr;
  CHECK(gravcal::is_rest(whole[1], sr));
}

static void test_bins() {
  gravcal::BinConfig cfg;
  gravcal::BinSelector<double> sel(cfg);
  CHECK(sel.valid());
  CHECK(sel.offer(Vec3<double>{0, 0, 1}) == 8);          // z+
  CHECK(sel.offer(Vec3<double>{0, 0.05, 1}) == gravcal::BIN_TOO_CLOSE);
  CHECK(sel.offer(Vec3<double>{0.5, 0.5, 0.5}) == gravcal::BIN_OUTSIDE);
  CHECK(sel.offer(Vec3<double>{0.2, 0.05, 0.6}) == 4);   // y0
  CHECK(!sel.complete());
}

template <typename T>
static void test_gradient(double tol_param) {
  const double truth[9] = {0.96, 1.04, 1.01, 0.02, -0.03, 0.01,
                           0.05, -0.04, 0.02};
  std::mt19937 rng(7);
  std::normal_distribution<double> g(0.0, 1.0);
  gravcal::BinSelector<T> sel(gravcal::BinConfig{});
  for (int i = 0; i < 5000 && !sel.full(); ++i) {
    Vec3<double> a{g(rng), g(rng), g(rng)};
    const double r = std::sqrt(gravcal::norm2(a));
    a = Vec3<double>{a.x / r, a.y / r, a.z / r};
    const Vec3<double> v = gravcal::invert_model(truth, a);
    sel.offer(Vec3<T>{T(v.x), T(v.y), T(v.z)});
  }
  CHECK(sel.complete());
  const int n = sel.size();
  std::vector<T> x(n), y(n), z(n);
  for (int i = 0; i < n; ++i) {
    x[i] = sel.point(i).x;
    y[i] = sel.point(i).y;
    z[i] = sel.point(i).z;
  }
  T p[9];
  gravcal::identity_params(p);
  gravcal::GradientConfig<T> cfg;
  cfg.max_iter = 5000;
  gravcal::GradientResult r =
      gravcal::fit_gradient(p, x.data(), y.data(), z.data(), n, cfg);
  CHECK(r.finite);
  double worst = 0;
  for (int i = 0; i < 9; ++i) {
    const double d = std::fabs(static_cast<double>(p[i]) - truth[i]);
    if (d > worst) worst = d;
  }
  std::printf("gradient (%s): max |p - truth| = %.2e after %d iterations\n",
              sizeof(T) == 8 ? "double" : "float", worst, r.iterations);
  CHECK(worst < tol_param);
}

// ICP: noise-free points of a known GGIR model are recovered to rounding by
// the converged fit; GGIR's rule stops earlier.
static void test_icp() {
  std::mt19937 rng(7);
  std::normal_distribution<double> nd(0.0, 1.0);
  const double scale[3] = {1.02, 0.97, 1.01}, offset[3] = {0.03, -0.02, 0.01},
               to[3] = {0.002, -0.001, 0.0015};
  const std::size_t n = 400;
  std::vector<double> x(n), y(n), z(n), t(n);
  double tsum = 0.0;
  for (std::size_t i = 0; i < n; ++i) t[i] = 25.0 + 5.0 * std::sin(0.1 * i), tsum += t[i];
  const double tm = tsum / n;
  for (std::size_t i = 0; i < n; ++i) {
    double a[3] = {nd(rng), nd(rng), nd(rng)};
    const double r = std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
    double* out[3] = {&x[i], &y[i], &z[i]};
    for (int k = 0; k < 3; ++k) {
      // a = (v + o) * s + (T - tm) * to  =>  v = (a - (T - tm) to) / s - o
      *out[k] = (a[k] / r - (t[i] - tm) * to[k]) / scale[k] - offset[k];
    }
  }
  gravcal::IcpConfig cfg;
  cfg.stop = gravcal::StopRule::parameters;
  cfg.tol = 1e-13;
  const gravcal::IcpResult r = gravcal::fit_icp(x.data(), y.data(), z.data(), t.data(), n, cfg);
  double worst = 0.0;
  for (int k = 0; k < 3; ++k) {
    worst = std::fmax(worst, std::fabs(r.scale[k] - scale[k]));
    worst = std::fmax(worst, std::fabs(r.offset[k] - offset[k]));
    worst = std::fmax(worst, std::fabs(r.tempoffset[k] - to[k]));
  }
  std::printf("icp: max |p - truth| = %.2e after %d iterations\n", worst, r.iterations);
  CHECK(r.converged && r.finite && r.temp_used);
  CHECK(worst < 1e-9);
  gravcal::IcpConfig g;
  const gravcal::IcpResult rg = gravcal::fit_icp(x.data(), y.data(), z.data(), t.data(), n, g);
  CHECK(rg.iterations < r.iterations);
}

// R-compatible arithmetic gives the same windows however the stream is cut.
static void test_r_arithmetic() {
  std::mt19937 rng(9);
  std::normal_distribution<double> nd(0.0, 0.01);
  const std::size_t n = 5000;
  std::vector<double> x(n), y(n), z(n), t(n);
  for (std::size_t i = 0; i < n; ++i) {
    x[i] = 0.1 + nd(rng), y[i] = nd(rng), z[i] = 1 + nd(rng);
    t[i] = 20 + 1e-3 * static_cast<double>(i);
  }
  z[777] = NAN;  // window 7 goes through the sample-by-sample path
  t[1234] = NAN;
  std::vector<gravcal::WindowStats> a, b;
  std::vector<double> buf1(3 * 102), buf2(3 * 102);
  gravcal::Segmenter s1(100, false), s2(100, false);
  CHECK(s1.use_r_arithmetic(buf1.data(), buf1.size()));
  CHECK(s2.use_r_arithmetic(buf2.data(), buf2.size()));
  CHECK(!s1.use_r_arithmetic(buf1.data(), 10));
  // whole windows at once (the one-pass path) against 37-sample chunks
  s1.push(x.data(), y.data(), z.data(), t.data(), n, [&](const gravcal::WindowStats& w) { a.push_back(w); });
  for (std::size_t i = 0; i < n; i += 37) {
    const std::size_t m = std::min<std::size_t>(37, n - i);
    s2.push(x.data() + i, y.data() + i, z.data() + i, t.data() + i, m,
            [&](const gravcal::WindowStats& w) { b.push_back(w); });
  }
  CHECK(a.size() == 50 && b.size() == 50);
  bool same = a.size() == b.size();
  for (std::size_t k = 0; same && k < a.size(); ++k) {
    for (int c = 0; c < 3; ++c) {
      same = same && a[k].mean[c] == b[k].mean[c] && a[k].sd[c] == b[k].sd[c];
    }
    same = same && std::memcmp(&a[k], &b[k], sizeof(gravcal::WindowStats)) == 0;
  }
  CHECK(same);
  CHECK(a[7].n_invalid == 1 && std::isnan(a[7].mean[2]) == false);

  // min and max of whole windows (two samples at a time) against the
  // sample-by-sample rule, where it matters: zeros of both signs as the
  // extreme value, first at an even or an odd position; in R's arithmetic
  // and in the streaming one (trials from 64 on)
  const double zs[2] = {0.0, -0.0};
  for (int trial = 0; trial < 128; ++trial) {
    const bool r_mode = trial < 64;
    const std::size_t m = 8 + static_cast<std::size_t>(trial % 5);
    std::vector<double> u(3 * m);
    for (std::size_t i = 0; i < u.size(); ++i) {
      u[i] = (trial & 1 ? 1.0 : -1.0) * (0.5 + 0.01 * static_cast<double>(i % 7));
    }
    for (int k = 0; k < 3; ++k) {
      const std::size_t i = static_cast<std::size_t>((trial >> 1) + 3 * k) % (3 * m);
      u[i] = zs[(trial >> 2) & 1];
      u[(i + 1 + static_cast<std::size_t>(trial % 3)) % (3 * m)] = zs[((trial >> 3) & 1) ^ 1];
    }
    std::vector<gravcal::WindowStats> wa, wb;
    std::vector<double> ba(3 * (m + 2)), bb(3 * (m + 2));
    gravcal::Segmenter sa(static_cast<double>(m), false), sb(static_cast<double>(m), false);
    if (r_mode) {
      CHECK(sa.use_r_arithmetic(ba.data(), ba.size()));
      CHECK(sb.use_r_arithmetic(bb.data(), bb.size()));
    }
    sa.push(u.data(), u.data() + m, u.data() + 2 * m, nullptr, m,
            [&](const gravcal::WindowStats& w) { wa.push_back(w); });
    for (std::size_t i = 0; i < m; ++i) {
      sb.push(u.data() + i, u.data() + m + i, u.data() + 2 * m + i, nullptr, 1,
              [&](const gravcal::WindowStats& w) { wb.push_back(w); });
    }
    CHECK(wa.size() == 1 && wb.size() == 1 &&
          std::memcmp(&wa[0], &wb[0], sizeof(gravcal::WindowStats)) == 0);
  }
}

// r_var_mean_avx2() (r_var_means3_avx2(), r_arith.hpp) decides R's var() mean without R's two
// long double passes only when its bound allows, and is then R's double
// (r_mean(), the plain two-pass loop): on ordinary windows, on windows whose
// exact mean is a midpoint between two doubles or next to one (half the
// values d, half the next double; then one value moved by one ulp), on
// values crossing zero or spread wide about a small mean (where R's own
// rounding moves its mean off the exact one: with no bound, W = 0, this
// test fails), on values with few bits and on huge and tiny ones.
static void test_r_var_mean() {
#if defined(GRAVCAL_AVX2) && defined(__x86_64__)
  if (!gravcal::use_avx2()) {
    std::printf("note: no AVX2, r_var_mean_avx2() not tested\n");
    return;
  }
  std::mt19937_64 rng(17);
  std::normal_distribution<double> nd(0.0, 1.0);
  std::uniform_real_distribution<double> ud(0.0, 1.0);
  long decided = 0, tried = 0, wrong = 0, ordinary = 0, ordinary_decided = 0;
  for (int trial = 0; trial < 40000; ++trial) {
    const int kind = trial % 8;
    const std::size_t n = kind == 7 ? 2 + static_cast<std::size_t>(trial % 9)
                                    : 2 + static_cast<std::size_t>(ud(rng) * 1500);
    std::vector<double> x(n);
    const double centre = std::ldexp(0.5 + ud(rng), static_cast<int>(ud(rng) * 12) - 8);
    const double sd = std::ldexp(1.0, -static_cast<int>(ud(rng) * 30) - 3);
    switch (kind) {
      case 0:  // near a value, with noise
      case 1:
        for (auto& v : x) v = centre + sd * nd(rng);
        break;
      case 2: {  // mean exactly half-way between two doubles
        const double d = centre, e = std::nextafter(d, 2 * d);
        for (std::size_t i = 0; i < n; ++i) x[i] = i < n / 2 ? d : e;
        if (n % 2) x[n - 1] = std::nextafter(e, 2 * e) == e ? e : d;
        break;
      }
      case 3: {  // the same, one value moved by an ulp either way
        const double d = centre, e = std::nextafter(d, 2 * d);
        for (std::size_t i = 0; i < n; ++i) x[i] = i < n / 2 ? d : e;
        x[trial % n] = std::nextafter(x[trial % n], (trial & 8) ? 0.0 : 4 * d);
        break;
      }
      case 4:  // crossing zero, or spread wide about a small mean (so that
               // R's own rounding moves its mean)
        for (auto& v : x) v = (trial & 8) ? sd * nd(rng) : centre + 300 * centre * nd(rng);
        break;
      case 5:  // few bits (multiples of 2^-8), as raw counts give
        for (auto& v : x) v = std::ldexp(std::round(std::ldexp(centre + 0.01 * nd(rng), 8)), -8);
        break;
      case 6: {  // huge, tiny, or both signs at a scale
        const double sc = std::ldexp(1.0, (trial & 16 ? 1 : -1) * static_cast<int>(ud(rng) * 400));
        for (auto& v : x) v = sc * (centre + sd * nd(rng)) * ((trial & 32) ? -1.0 : 1.0);
        break;
      }
      default:  // short windows
        for (auto& v : x) v = centre + 0.01 * nd(rng);
    }
    double m = 0;
    ++tried;
    const bool ok = gravcal::kernels::r_var_mean_avx2(x.data(), n, &m);
    if (kind <= 1 && sd <= 0x1p-7 && n >= 100) {
      ++ordinary;
      ordinary_decided += ok;
    }
    if (!ok) continue;
    ++decided;
    const double r = gravcal::r_mean(x.data(), n);
    if (std::memcmp(&r, &m, sizeof m) != 0) {
      if (wrong < 5) std::printf("r_var_mean: n %zu kind %d: %a, R %a\n", n, kind, m, r);
      ++wrong;
    }
  }
  CHECK_LD(wrong == 0);
  // the shortcut is taken for most windows of a sensor at rest (sd at most
  // 8 mg about a value), else it would save nothing
  CHECK(ordinary > 1000 && ordinary_decided > 0.9 * static_cast<double>(ordinary));
  CHECK(decided < tried);  // and left alone somewhere (the midpoints)
  // non-finite values and sizes outside the bound's range are left to R
  double m = 0;
  const double bad[4] = {1.0, NAN, 1.0, 1.0}, inf[4] = {1.0, INFINITY, 1.0, 1.0};
  const double one[1] = {1.0}, zero[4] = {0.0, 0.0, 0.0, 0.0};
  CHECK(!gravcal::kernels::r_var_mean_avx2(bad, 4, &m));
  CHECK(!gravcal::kernels::r_var_mean_avx2(inf, 4, &m));
  CHECK(!gravcal::kernels::r_var_mean_avx2(one, 1, &m));
  CHECK(!gravcal::kernels::r_var_mean_avx2(zero, 4, &m));
#endif
}

// The temperature check's fast sd (runs_sd(), r_sd_below()) decides as R's
// sd() (r_mean_sd()) does, and leaves to R's arithmetic only what lies
// within rounding of the threshold: values scaled so that their sd is the
// threshold, then moved by a few doubles; and values clearly either side.
static void test_r_sd_below() {
  std::mt19937 rng(11);
  std::normal_distribution<double> nd(0.0, 1.0);
  std::uniform_int_distribution<int> runs_n(1, 60), count(1, 400), ulps(-3, 3);
  const double thr = 0.01;
  int decided = 0, near_exact = 0, disagree = 0, far_undecided = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    const int k = runs_n(rng);
    std::vector<double> v(static_cast<std::size_t>(k));
    std::vector<std::uint64_t> c(v.size());
    const double centre = trial % 3 == 0 ? 0.0 : (trial % 3 == 1 ? 25.0 : -1e6);
    for (std::size_t j = 0; j < v.size(); ++j) {
      v[j] = centre + nd(rng);
      c[j] = static_cast<std::uint64_t>(count(rng));
    }
    auto each_value = [&](auto&& f) {
      for (std::size_t j = 0; j < v.size(); ++j)
        for (std::uint64_t i = 0; i < c[j]; ++i) f(v[j]);
    };
    auto each_run = [&](auto&& f) {
      for (std::size_t j = 0; j < v.size(); ++j) f(v[j], c[j]);
    };
    const gravcal::RMeanSd r0 = gravcal::r_mean_sd(each_value);
    if (!(r0.sd > 0)) continue;
    // scale the deviations to an sd of thr (near), or 0.5 or 2 times it (far)
    const int kind = trial % 4;
    const double target = kind == 0 ? 0.5 * thr : (kind == 1 ? 2 * thr : thr);
    for (double& a : v) a = r0.mean + (a - r0.mean) * (target / r0.sd);
    if (kind >= 2) {
      for (double& a : v) {
        const int u = ulps(rng);
        for (int i = 0; i < (u < 0 ? -u : u); ++i)
          a = std::nextafter(a, u < 0 ? -INFINITY : INFINITY);
      }
    }
    const gravcal::RunsSd f = gravcal::runs_sd(each_run);
    const int b = gravcal::r_sd_below(f, thr);
    const double exact = gravcal::r_mean_sd(each_value).sd;
    if (b >= 0) {
      ++decided;
      if ((exact < thr) != (b == 1)) ++disagree;
    } else if (kind >= 2) {
      ++near_exact;
    }
    if (kind < 2 && b < 0) ++far_undecided;
  }
  CHECK_LD(disagree == 0);
  CHECK_LD(far_undecided == 0);
  CHECK(decided > 1000);
  CHECK(near_exact > 100);  // values at the threshold go to R's arithmetic
  // outside the bounds' domain: always R's arithmetic
  gravcal::RunsSd inf = gravcal::runs_sd([](auto&& f) {
    f(1.0, 3);
    f(INFINITY, 1);
  });
  CHECK(gravcal::r_sd_below(inf, thr) == -1);
  gravcal::RunsSd one = gravcal::runs_sd([](auto&& f) { f(1.0, 1); });
  CHECK(std::isnan(one.sd) && gravcal::r_sd_below(one, thr) == -1);
  gravcal::RunsSd same = gravcal::runs_sd([](auto&& f) { f(25.5, 1000); });
  CHECK(same.sd == 0 && gravcal::r_sd_below(same, thr) == 1);
}

// add_repeated() (r_arith.hpp): k additions of x to an accumulator Acc (R's:
// long double, or double in an R without long double) in a few
// steps, to the bit as the loop: sums growing and shrinking across
// binades, through zero, x below half a step, ties (x half-way between
// multiples of the grid of s), huge values.
template <class Acc>
static void test_add_repeated_acc() {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  int bad = 0;
  for (int t = 0; t < 40000; ++t) {
    Acc s = 0;
    double x = 0;
    switch (t % 7) {
      case 0: s = Acc(25.0) * (1 + U(rng)); x = 25 + U(rng); break;
      case 1: s = Acc(1e8) * U(rng); x = 30 * U(rng); break;
      case 2: s = Acc(0x1p20) - 50 * std::fabs(U(rng)); x = 0.7 + 0.1 * U(rng); break;
      case 3: s = Acc(0x1p20) + 50 * std::fabs(U(rng)); x = -0.7 - 0.1 * U(rng); break;
      case 4: s = Acc(3.0) * U(rng); x = static_cast<double>(-s / 7 * (1 + 1e-3 * U(rng))); break;
      case 5: {  // x half-way between multiples of the grid of s
        s = Acc(1027.0);
        const Acc q = std::ldexp(Acc(1.0), 11 - std::numeric_limits<Acc>::digits);
        x = static_cast<double>(q * (std::floor(1000 * U(rng)) + Acc(0.5)));
        break;
      }
      default: s = Acc(1e300) * U(rng); x = 1e290 * U(rng); break;
    }
    if (t % 97 == 0) s = 0;
    const std::uint64_t k = 1 + rng() % (t % 3 == 0 ? 5000 : 50);
    Acc a = s, b = s;
    for (std::uint64_t i = 0; i < k; ++i) a += x;
    gravcal::add_repeated(b, x, k);
    bad += !(a == b || (std::isnan(a) && std::isnan(b)));
  }
  // at a binade's edges: the last additions before 2^20 (from above) or
  // 2^21 (from below) round on the next binade's grid
  const int digits = std::numeric_limits<Acc>::digits;
  const Acc q = std::ldexp(Acc(1.0), 21 - digits);  // the grid of [2^20, 2^21)
  for (int m = 1; m <= 12; ++m) {
    for (int r = 1; r <= 3; ++r) {
      for (int f = 1; f <= 4; ++f) {
        for (int up = 0; up < 2; ++up) {
          const Acc s0 = up ? Acc(0x1p21) - m * q : Acc(0x1p20) + m * q;
          const double x = static_cast<double>((up ? 1 : -1) * (r + f / Acc(10.0)) * q);
          Acc a = s0, b = s0;
          for (int i = 0; i < 20; ++i) a += x;
          gravcal::add_repeated(b, x, 20);
          bad += a != b;
        }
      }
    }
  }
  CHECK_LD(bad == 0);
  // by runs, with the grid kept between calls
  std::vector<double> v(20000);
  for (std::size_t i = 0; i < v.size(); ++i) v[i] = 25.3 + 0.29 * static_cast<double>((i / 120) % 37);
  Acc a = 0, b = 0;
  for (double e : v) a += e;
  gravcal::Binade<Acc> g;
  gravcal::add_in_order(b, v.data(), 7000, g);
  gravcal::add_in_order(b, v.data() + 7000, v.size() - 7000, g);
  CHECK_LD(a == b);
}

static void test_add_repeated() {
  test_add_repeated_acc<long double>();
  test_add_repeated_acc<double>();
}

// Segmenter::lazy_r_sd() against R's sds everywhere, through GGIR's block
// rules: windows with sds near the rest threshold (1e-13 either side), at
// rest, moving, repeated stretches (GGIR's duplicates), invalid samples
// (windows without means) and idle-sleep zeros. Every other statistic is
// the same, so are the rest flags and the rest windows' sds (to the bit),
// and so are the ties GGIR's duplicate filter counts (a window's sd equal
// to that of the last window with means).
static void test_lazy_sd() {
  using W = gravcal::WindowStats;
  long long windows = 0, in_double = 0, ties = 0;
  bool ok = true;
  for (int seed = 0; seed < 60; ++seed) {
    std::mt19937_64 pick(static_cast<std::uint64_t>(seed));
    auto U = [&](int a, int b) { return std::uniform_int_distribution<int>(a, b)(pick); };
    const int H = U(20, 400);
    const double L = U(0, 2) ? static_cast<double>(U(2, 30)) : U(2, 30) + 0.5;
    const double T = U(0, 1) ? 0.013 : 0.02;
    std::vector<W> out[2];
    for (int lazy = 0; lazy < 2; ++lazy) {
      std::mt19937_64 g(static_cast<std::uint64_t>(seed) * 7 + 1);
      auto G = [&](int a, int b) { return std::uniform_int_distribution<int>(a, b)(g); };
      std::normal_distribution<double> nd(0, 1);
      const std::size_t cap = 3 * (static_cast<std::size_t>(std::ceil(L)) + 1);
      std::vector<double> buf(cap), held(cap);
      gravcal::LazySd state;
      gravcal::Segmenter seg(L, false);
      CHECK(seg.use_r_arithmetic(buf.data(), buf.size()));
      if (lazy) CHECK(seg.lazy_r_sd(T, &state, held.data(), held.size()));
      gravcal::GgirBlocks gb(seg, H, true, true);
      auto sink = [&](const W& w) { out[lazy].push_back(w); };
      const int blocks = G(1, 5);
      for (int b = 0; b < blocks; ++b) {
        const int n = G(0, 4 * H);
        std::vector<double> x(static_cast<std::size_t>(n)), y(x.size()), z(x.size()), t(x.size());
        double noise = 0.01;
        for (std::size_t i = 0; i < x.size(); ++i) {
          if (i % static_cast<std::size_t>(std::ceil(L)) == 0) {
            const int k = G(0, 9);
            noise = k < 3 ? T * (1 + (G(0, 1) ? 1e-13 : -1e-13) * G(0, 3))
                          : (k < 5 ? 0.003 : (k < 8 ? 0.2 : 0.0));
          }
          x[i] = 0.1 + noise * nd(g);
          y[i] = -0.4 + noise * nd(g);
          z[i] = 0.9 + noise * nd(g);
          t[i] = 25 + static_cast<double>(i / 120) * 0.01;
          if (G(0, 400) == 0) y[i] = NAN;
          if (G(0, 300) == 0) x[i] = y[i] = z[i] = 0;
        }
        if (n > 200 && G(0, 1)) {  // a repeated stretch
          const int len = G(1, 60), at = G(len, n - len - 1);
          for (int i = 0; i < len; ++i) {
            x[static_cast<std::size_t>(at + i)] = x[static_cast<std::size_t>(at - len + i)];
            y[static_cast<std::size_t>(at + i)] = y[static_cast<std::size_t>(at - len + i)];
            z[static_cast<std::size_t>(at + i)] = z[static_cast<std::size_t>(at - len + i)];
          }
        }
        if (n > 100 && G(0, 3) == 0) {  // windows without means
          const int at = G(0, n - 40);
          for (int i = 0; i < 40; ++i) x[static_cast<std::size_t>(at + i)] = NAN;
        }
        gb.begin_block();
        int i = 0;
        while (i < n) {
          const int k = std::min(n - i, G(1, 3 * H));
          const std::size_t o = static_cast<std::size_t>(i);
          gb.push(x.data() + o, y.data() + o, z.data() + o, t.data() + o,
                  static_cast<std::size_t>(k), sink);
          i += k;
        }
        gb.end_block(sink);
      }
    }
    CHECK(out[0].size() == out[1].size());
    if (out[0].size() != out[1].size()) continue;
    gravcal::SdRestRule rule;
    rule.max_sd = T;
    std::size_t last = out[0].size();
    for (std::size_t k = 0; k < out[0].size(); ++k) {
      const W& e = out[0][k];
      const W& a = out[1][k];
      ++windows;
      W u = a;
      std::memcpy(u.sd, e.sd, sizeof u.sd);
      ok = ok && std::memcmp(&u, &e, sizeof u) == 0;
      const bool r = gravcal::is_rest(e, rule);
      ok = ok && r == gravcal::is_rest(a, rule);
      const bool same_sd = std::memcmp(a.sd, e.sd, sizeof a.sd) == 0;
      ok = ok && (!r || same_sd);
      if (!same_sd) ++in_double;
      if (std::isnan(e.mean[2]) || std::isnan(e.mean_norm)) continue;
      if (last < out[0].size()) {
        for (int ax = 0; ax < 3; ++ax) {
          const bool te = e.sd[ax] == out[0][last].sd[ax];
          ties += te;
          ok = ok && te == (a.sd[ax] == out[1][last].sd[ax]);
        }
      }
      last = k;
    }
  }
  CHECK_LD(ok);
  CHECK(windows > 3000 && in_double > 500 && ties > 100);  // all cases met
}

// lazy_r_sd() where it is put to the test: windows whose R sd is the rest
// threshold to a few doubles, and windows that repeat the one before with
// the samples permuted (R's long double sds then often tie while sds in
// double do not). Rest flags and ties as with R's sds everywhere.
static void test_lazy_sd_edges() {
  using W = gravcal::WindowStats;
  const std::size_t L = 1000;
  const double T = 0.013;
  std::mt19937_64 g(99);
  std::normal_distribution<double> nd(0.0, 1.0);
  std::vector<double> x, y, z;
  std::vector<double> a(L), b(L), c(L);
  int at_threshold = 0;
  for (int w = 0; w < 400; ++w) {
    const int kind = w % 4;  // moving, permuted, at the threshold, moving
    if (kind == 1) {
      const std::size_t s0 = x.size() - L;
      for (std::size_t i = 0; i < L; ++i) {
        const std::size_t j = w % 8 < 4 ? L - 1 - i : (i + 1) % L;
        a[i] = x[s0 + j];
        b[i] = y[s0 + j];
        c[i] = z[s0 + j];
      }
    } else {
      const double noise = kind == 2 ? T : 0.05;
      for (std::size_t i = 0; i < L; ++i) {
        a[i] = (kind == 2 ? 0.0 : 1.3) + noise * nd(g);
        b[i] = -0.2 + 0.004 * nd(g);
        c[i] = 0.93 + 0.004 * nd(g);
      }
      if (kind == 2) {
        // x scaled so that its R sd is the threshold's double, or one of
        // the six either side (bisection on the scale)
        const std::vector<double> d = a;
        auto sd_at = [&](double f) {
          for (std::size_t i = 0; i < L; ++i) a[i] = d[i] * f;
          return gravcal::r_mean_sd([&](auto&& h) {
            for (double v : a) h(v);
          }).sd;
        };
        const int u = static_cast<int>((w / 4) % 13) - 6;
        double goal = T;
        for (int k = 0; k < (u < 0 ? -u : u); ++k) goal = std::nextafter(goal, u < 0 ? 0.0 : 1.0);
        double lo = 0.5, hi = 2.0;
        for (int it = 0; it < 200 && lo < hi; ++it) {
          const double mid = lo + (hi - lo) / 2;
          if (mid == lo || mid == hi) break;
          (sd_at(mid) < goal ? lo : hi) = mid;
        }
        sd_at(std::fabs(sd_at(lo) - goal) < std::fabs(sd_at(hi) - goal) ? lo : hi);
        ++at_threshold;
      }
    }
    x.insert(x.end(), a.begin(), a.end());
    y.insert(y.end(), b.begin(), b.end());
    z.insert(z.end(), c.begin(), c.end());
  }
  std::vector<W> out[2];
  for (int lazy = 0; lazy < 2; ++lazy) {
    std::vector<double> buf(3 * (L + 1)), held(buf.size());
    gravcal::LazySd state;
    gravcal::Segmenter seg(static_cast<double>(L), false);
    CHECK(seg.use_r_arithmetic(buf.data(), buf.size()));
    if (lazy) CHECK(seg.lazy_r_sd(T, &state, held.data(), held.size()));
    auto sink = [&](const W& w) { out[lazy].push_back(w); };
    for (std::size_t i = 0; i < x.size(); i += 10 * L) {  // whole windows
      const std::size_t n = std::min(10 * L, x.size() - i);
      seg.push(x.data() + i, y.data() + i, z.data() + i, nullptr, n, sink);
    }
    seg.finish(sink);
  }
  CHECK(out[0].size() == 400 && out[1].size() == 400);
  gravcal::SdRestRule rule;
  rule.max_sd = T;
  int rest = 0, not_rest = 0, ties = 0, bad = 0;
  for (std::size_t k = 0; k < out[0].size() && k < out[1].size(); ++k) {
    const W& e = out[0][k];
    const W& l = out[1][k];
    const bool r = gravcal::is_rest(e, rule);
    if (k % 4 == 2) (r ? rest : not_rest) += 1;  // the threshold's windows
    if (r != gravcal::is_rest(l, rule)) ++bad;
    if (r && std::memcmp(e.sd, l.sd, sizeof e.sd) != 0) ++bad;
    if (k > 0) {
      for (int ax = 0; ax < 3; ++ax) {
        const bool te = e.sd[ax] == out[0][k - 1].sd[ax];
        ties += te;
        if (te != (l.sd[ax] == out[1][k - 1].sd[ax])) ++bad;
      }
    }
  }
  CHECK(bad == 0);
  // both sides of the threshold, and R's ties between permuted windows
  CHECK(at_threshold == 100 && rest > 30 && not_rest > 30 && ties > 100);
}

// The GENEActiv decoder's hex digits sixteen at a time (hex16()) against
// its table, for every byte value in every position.
static void test_hex16() {
#if defined(GRAVCAL_SSE2)
  const unsigned char* h = gravcal::geneactiv::hex_table().v;
  bool ok = true;
  for (int pos = 0; pos < 16; ++pos) {
    for (int c = 0; c < 256; ++c) {
      unsigned char s[16], v[16];
      for (int k = 0; k < 16; ++k) s[k] = static_cast<unsigned char>("0123456789abcDEF"[k]);
      s[pos] = static_cast<unsigned char>(c);
      const int bad = gravcal::kernels::hex16(s, v);
      for (int k = 0; k < 16; ++k) {
        const bool digit = h[s[k]] < 16;
        ok = ok && (((bad >> k) & 1) == !digit) && (!digit || v[k] == h[s[k]]);
      }
    }
  }
  CHECK(ok);
#endif
}

// The GENEActiv decoder with its AVX2 path (where the processor has it)
// against the baseline one: random pages of upper- and lower-case digits,
// some with a character that is not a hex digit in a random place, some
// short or long, decoded both ways in both modes; every sample, time and
// temperature and the report's counts must be the same.
static std::string random_geneactiv(std::mt19937& rng, int pages) {
  std::string f =
      "Device Identity\r\nDevice Unique Serial Code:012967\r\nDevice Type:GENEActiv\r\n"
      "Device Model:1.1\r\nAccelerometer Range:-8 to 8\r\nConfiguration Info\r\n"
      "Measurement Frequency:100 Hz\r\nTime Zone:GMT +00:00\r\nCalibration Data\r\n"
      "x gain:25875\r\nx offset:439\r\ny gain:25734\r\ny offset:-662\r\nz gain:25538\r\n"
      "z offset:-3056\r\nVolts:300\r\nLux:800\r\n\r\nMemory Status\r\nNumber of Pages:" +
      std::to_string(pages) + "\r\n\r\n";
  const char* up = "0123456789ABCDEF";
  const char* lo = "0123456789abcdef";
  std::uniform_int_distribution<int> digit(0, 15), byte(0, 255), pct(0, 99), at(0, 3599);
  for (int p = 0; p < pages; ++p) {
    char stamp[64];
    std::snprintf(stamp, sizeof stamp, "2024-01-01 00:%02d:%02d:000", (p * 3) / 60, (p * 3) % 60);
    f += "Recorded Data\r\nDevice Unique Serial Code:012967\r\nSequence Number:" +
         std::to_string(p) + "\r\nPage Time:" + stamp +
         "\r\nUnassigned:\r\nTemperature:25.5\r\nBattery voltage:4.1\r\n"
         "Device Status:Recording\r\nMeasurement Frequency:100\r\n";
    const char* d = pct(rng) < 50 ? up : lo;
    std::string hex(3600, '0');
    for (char& c : hex) c = d[digit(rng)];
    const int kind = pct(rng);
    if (kind < 30) {  // one character that is not a hex digit
      char c;
      do c = static_cast<char>(byte(rng)); while (std::isxdigit(static_cast<unsigned char>(c)) ||
                                                 c == '\n' || c == '\r');
      hex[static_cast<std::size_t>(at(rng))] = c;
    } else if (kind < 35) {  // short: 1-299 samples and part of one
      hex.resize(static_cast<std::size_t>(1 + pct(rng) * 36 + digit(rng)));
    } else if (kind < 38) {  // long
      hex += "0ABC";
    }
    f += hex + "\r\n";
  }
  return f;
}

struct DecodedGa {
  std::vector<double> v;
  std::vector<std::int64_t> counts;
  std::vector<std::string> notes;
};

// A buffer over the five columns (x, y, z, temperature, time), as long as x.
static gravcal::SampleBuffer ga_buffer(std::vector<double>& x, std::vector<double>& y,
                                       std::vector<double>& z, std::vector<double>& t,
                                       std::vector<double>& tm) {
  gravcal::SampleBuffer out;
  out.x = x.data();
  out.y = y.data();
  out.z = z.data();
  out.t = t.data();
  out.time = tm.data();
  out.capacity = x.size();
  return out;
}

static DecodedGa decode_geneactiv(const std::string& file, bool compat) {
  gravcal::MemorySource src(reinterpret_cast<const unsigned char*>(file.data()), file.size());
  gravcal::Options opts;
  opts.set("compat", compat ? 1.0 : 0.0);
  gravcal::GeneactivDecoder dec(src, opts);
  DecodedGa d;
  if (!dec.open()) return d;
  const std::size_t cap = 1000;
  std::vector<double> x(cap), y(cap), z(cap), t(cap), tm(cap);
  while (!dec.done()) {
    gravcal::SampleBuffer out = ga_buffer(x, y, z, t, tm);
    const std::int64_t u = dec.read(out, 3);
    for (std::size_t i = 0; i < out.n; ++i) {
      d.v.insert(d.v.end(), {x[i], y[i], z[i], t[i], tm[i]});
    }
    if (out.n == 0 && u == 0) break;
  }
  const gravcal::Report& r = dec.report();
  d.counts = {r.samples, r.units, r.skipped, r.gaps, static_cast<std::int64_t>(r.truncated)};
  for (const auto& c : r.counters) {
    d.notes.push_back(c.first);
    d.counts.push_back(c.second);
  }
  d.notes.insert(d.notes.end(), r.notes.begin(), r.notes.end());
  return d;
}

static void test_avx2_geneactiv() {
  if (!gravcal::set_avx2(true)) {
    std::printf("note: no AVX2 paths (not in this build, or not on this processor): none compared\n");
    return;
  }
  std::mt19937 rng(2026);
  int differ = 0, skipped_pages = 0, read_damaged = 0;
  for (int rep = 0; rep < 100; ++rep) {
    const std::string f = random_geneactiv(rng, 30);
    for (int compat = 0; compat < 2; ++compat) {
      gravcal::set_avx2(true);
      const DecodedGa a = decode_geneactiv(f, compat != 0);
      gravcal::set_avx2(false);
      const DecodedGa b = decode_geneactiv(f, compat != 0);
      const bool same = a.counts == b.counts && a.notes == b.notes && a.v.size() == b.v.size() &&
                        (a.v.empty() || std::memcmp(a.v.data(), b.v.data(),
                                                    a.v.size() * sizeof(double)) == 0);
      if (!same) ++differ;
      if (a.counts.empty()) continue;
      if (compat == 0) {
        skipped_pages += static_cast<int>(a.counts[2]);
      } else {
        // (the counters' names lead the notes, in the counters' order)
        for (std::size_t c = 5; c < a.counts.size(); ++c) {
          if (a.notes[c - 5] == "damaged_hex") read_damaged += static_cast<int>(a.counts[c]);
        }
      }
    }
  }
  gravcal::set_avx2(true);
  CHECK(differ == 0);
  CHECK(skipped_pages > 1000);  // the damaged pages were met: skipped (compat 0)
  CHECK(read_damaged > 1000);   // and read as GGIRread reads them (compat 1)
}

// GGIRread's rules for a damaged GENEActiv page (geneactiv_ggir.hpp) against
// the standard library they follow, GCC's (GGIRread's reader is built with
// the R it runs in: libstdc++ on Linux and Windows): a value line as
// std::stringstream's ignore(':') and >> double read it (random lines of
// number-like characters; kept where the extraction leaves the value), and
// every group of up to 3 characters as std::stoll(group, nullptr, 16) reads
// it (or throws).
static void test_geneactiv_ggir_rules() {
#if defined(__GLIBCXX__)
  using gravcal::geneactiv::FieldRead;
  const std::string alpha = "0123456789.eE+- :xXafAFG\r\t";
  std::mt19937 rng(7);
  int differ = 0;
  for (int it = 0; it < 300000; ++it) {
    std::string s = (rng() % 2) ? "Temperature:" : "";
    for (int i = 0, n = static_cast<int>(rng() % 9); i < n; ++i) s += alpha[rng() % alpha.size()];
    double v = std::numeric_limits<double>::quiet_NaN();
    std::stringstream ss(s);
    ss.ignore(std::numeric_limits<std::streamsize>::max(), ':');
    ss >> v;
    const FieldRead r = gravcal::geneactiv::read_field(s.data(), s.size(), true);
    const bool same = std::isnan(v) ? r.kind == FieldRead::keep
                                    : r.kind == FieldRead::value && r.v == v &&
                                          std::signbit(r.v) == std::signbit(v);
    if (!same) ++differ;
  }
  const std::string ga = "0123456789aAfFgG+- \r\txX:\v";
  for (int len = 0; len <= 3; ++len) {
    long total = 1;
    for (int i = 0; i < len; ++i) total *= static_cast<long>(ga.size());
    for (long c = 0; c < total; ++c) {
      std::string s;
      for (long k = c, i = 0; i < len; ++i, k /= static_cast<long>(ga.size())) {
        s += ga[static_cast<std::size_t>(k % static_cast<long>(ga.size()))];
      }
      bool ok = true;
      long long ref = 0;
      try {
        ref = std::stoll(s, nullptr, 16);
      } catch (...) {
        ok = false;
      }
      int v = 0;
      const bool mine = gravcal::geneactiv::read_group(s.data(), s.size(), v);
      if (mine != ok || (ok && v != ref)) ++differ;
    }
  }
  CHECK(differ == 0);
#else
  std::printf("note: not GCC's standard library: GGIRread's rules not compared with it\n");
#endif
}

// SampleBuffer::time_ends_only (g.getmeta()'s block store): the GENEActiv
// decoder times a buffer's first row and its last two only, and those as
// it times every row without the flag; every other column the same. Random
// pages (damaged, short, long ones among them), both modes, buffers of 1
// to 1000 rows, reads of 3 pages or of as many as fit.
static std::vector<double> ga_read_ends(const std::string& file, bool compat, std::size_t cap,
                                        std::int64_t units, bool ends) {
  gravcal::MemorySource src(reinterpret_cast<const unsigned char*>(file.data()), file.size());
  gravcal::Options opts;
  opts.set("compat", compat ? 1.0 : 0.0);
  gravcal::GeneactivDecoder dec(src, opts);
  std::vector<double> got;
  if (!dec.open()) return got;
  std::vector<double> x(cap), y(cap), z(cap), t(cap), tm(cap, -1.0);
  while (!dec.done()) {
    gravcal::SampleBuffer out = ga_buffer(x, y, z, t, tm);
    out.time_ends_only = ends;
    const std::int64_t u = dec.read(out, units);
    for (std::size_t i = 0; i < out.n; ++i) got.insert(got.end(), {x[i], y[i], z[i], t[i]});
    if (out.n > 0) got.insert(got.end(), {tm[0], out.n >= 2 ? tm[out.n - 2] : 0.0, tm[out.n - 1]});
    got.push_back(static_cast<double>(out.n));
    if (out.n == 0 && u == 0) break;
  }
  return got;
}

static void test_geneactiv_time_ends() {
  std::mt19937 rng(61);
  int differ = 0, cases = 0;
  for (int rep = 0; rep < 20; ++rep) {
    const std::string f = random_geneactiv(rng, 12);
    for (int compat = 0; compat < 2; ++compat) {
      for (std::size_t cap : {std::size_t{1}, std::size_t{2}, std::size_t{7}, std::size_t{301},
                              std::size_t{1000}}) {
        for (std::int64_t units : {std::int64_t{3}, std::int64_t{-1}}) {
          const std::vector<double> a = ga_read_ends(f, compat != 0, cap, units, false);
          const std::vector<double> b = ga_read_ends(f, compat != 0, cap, units, true);
          ++cases;
          if (a.size() != b.size() || a.empty() ||
              std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) != 0) {
            ++differ;
          }
        }
      }
    }
  }
  CHECK(cases == 400);
  CHECK(differ == 0);
  std::printf("GENEActiv time_ends_only: %d cases, the same ends\n", cases);
}

// A digest of the windows of a fixed stream and of ICP fits, printed so that
// the Makefile can check that the SSE2 and the portable builds give the
// same bits.
// The statistics hashed: the fields before n_repeat (the digest's bytes
// since before n_repeat was added; n_repeat is an integer count that
// no vector path computes, and the whole-vs-parts check compares it).
static const std::size_t kDigestBytes = offsetof(gravcal::WindowStats, n_repeat);

static void print_digest() {
  std::mt19937 rng(77);
  std::normal_distribution<double> nd(0.0, 0.02);
  const std::size_t n = 100003;
  std::vector<double> x(n), y(n), z(n), t(n);
  for (std::size_t i = 0; i < n; ++i) {
    x[i] = 0.3 + nd(rng), y[i] = -0.5 + nd(rng), z[i] = 0.8 + nd(rng);
    t[i] = 30 + nd(rng);
  }
  std::uint64_t h = 1469598103934665603ull;
  gravcal::Segmenter s(85.7 * 5, false);
  s.push(x.data(), y.data(), z.data(), t.data(), n, [&](const gravcal::WindowStats& w) {
    const unsigned char* p = reinterpret_cast<const unsigned char*>(&w);
    for (std::size_t i = 0; i < kDigestBytes; ++i) h = (h ^ p[i]) * 1099511628211ull;
  });
  // and GGIR-compatible windows (R's arithmetic, sds in double where R's
  // cannot matter) through GGIR's block rules, with rest windows, windows
  // near the sd threshold, idle-sleep zeros and missing values
  {
    std::mt19937_64 g(99);
    std::normal_distribution<double> unit(0, 1);
    const double L = 257;  // odd: every loop's scalar tail
    std::vector<double> buf(3 * 258), held(3 * 258);
    gravcal::LazySd state;
    gravcal::Segmenter seg(L, false);
    seg.use_r_arithmetic(buf.data(), buf.size());
    seg.lazy_r_sd(0.013, &state, held.data(), held.size());
    gravcal::GgirBlocks gb(seg, 257 * 40, true, true);
    auto sink = [&](const gravcal::WindowStats& w) {
      const unsigned char* p = reinterpret_cast<const unsigned char*>(&w);
      for (std::size_t i = 0; i < kDigestBytes; ++i) h = (h ^ p[i]) * 1099511628211ull;
    };
    std::vector<double> a(n), b(n), c(n), tt(n);
    double noise = 0.01;
    for (std::size_t i = 0; i < n; ++i) {
      if (i % 257 == 0) {
        const int k = static_cast<int>(g() % 10);
        noise = k < 3 ? 0.013 * (1 + 1e-13 * static_cast<double>(g() % 7) - 3e-13)
                      : (k < 5 ? 0.003 : (k < 8 ? 0.2 : 0.0));
      }
      a[i] = 0.1 + noise * unit(g);
      b[i] = -0.4 + noise * unit(g);
      c[i] = 0.9 + noise * unit(g);
      tt[i] = 25 + static_cast<double>(i / 300) * 0.01;
      if (g() % 500 == 0) b[i] = NAN;
      if (g() % 400 == 0) a[i] = b[i] = c[i] = 0;
      // samples zero on some axes only (not idle sleep): the zero scans
      // look at x first
      if (g() % 90 == 0) a[i] = 0;
      if (g() % 300 == 0) a[i] = b[i] = 0;
      if (g() % 300 == 0) a[i] = c[i] = 0;
    }
    for (std::size_t at = 0; at < n;) {
      gb.begin_block();
      const std::size_t len = std::min<std::size_t>(n - at, 20000 + g() % 30000);
      gb.push(a.data() + at, b.data() + at, c.data() + at, tt.data() + at, len, sink);
      gb.end_block(sink);
      at += len;
    }
  }
  // and gravcal's ICP fit (its loops two points at a time with SSE2), with
  // and without the temperature term, on noisy rest means
  for (int temp = 0; temp < 2; ++temp) {
    const std::size_t m = 2001;  // odd: the scalar tail too
    std::vector<double> a(m), b(m), c(m), tt(m);
    for (std::size_t i = 0; i < m; ++i) {
      double v[3] = {nd(rng) * 20, nd(rng) * 20, nd(rng) * 20};
      const double r = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
      a[i] = 1.01 * v[0] / r + 0.02 + nd(rng) * 0.1;
      b[i] = 0.98 * v[1] / r - 0.01 + nd(rng) * 0.1;
      c[i] = v[2] / r + 0.03 + nd(rng) * 0.1;
      tt[i] = 25 + 200 * nd(rng);
    }
    gravcal::IcpConfig cfg;
    cfg.stop = gravcal::StopRule::parameters;
    const gravcal::IcpResult r =
        gravcal::fit_icp(a.data(), b.data(), c.data(), temp ? tt.data() : nullptr, m, cfg);
    const double out[10] = {r.scale[0], r.scale[1], r.scale[2], r.offset[0], r.offset[1],
                            r.offset[2], r.tempoffset[0], r.tempoffset[1], r.tempoffset[2],
                            r.statistic};
    const unsigned char* p = reinterpret_cast<const unsigned char*>(out);
    for (std::size_t i = 0; i < sizeof(out); ++i) h = (h ^ p[i]) * 1099511628211ull;
    h ^= static_cast<std::uint64_t>(r.iterations);
  }
  std::printf("digest %016llx\n", static_cast<unsigned long long>(h));
}

// The .cwa checksum's word sum (SSE2 lanes of 16 bits where built with
// them) against the word-by-word sum, on random blocks and on blocks made
// to sum to 0 (a good checksum) or to each single-bit error of one.
static void test_cwa_word_sum() {
  std::mt19937_64 g(7);
  std::vector<unsigned char> b(gravcal::cwa::block_bytes);
  int bad = 0;
  for (int rep = 0; rep < 20000; ++rep) {
    for (auto& c : b) c = static_cast<unsigned char>(rep % 3 == 0 ? 0xff : g());
    unsigned ref = 0;
    for (std::size_t i = 0; i < b.size(); i += 2) ref += gravcal::le16(b.data() + i);
    bad += gravcal::cwa::word_sum(b.data()) != (ref & 0xffffu);
    // make the block's sum 0 with its last word, then flip one bit
    const unsigned fix = (0x10000u - ((ref - gravcal::le16(b.data() + 510)) & 0xffffu)) & 0xffffu;
    b[510] = static_cast<unsigned char>(fix & 0xff);
    b[511] = static_cast<unsigned char>(fix >> 8);
    bad += gravcal::cwa::word_sum(b.data()) != 0;
    const std::size_t bit = g() % (8 * b.size());
    b[bit / 8] ^= static_cast<unsigned char>(1u << (bit % 8));
    bad += gravcal::cwa::word_sum(b.data()) == 0;
  }
  CHECK(bad == 0);
}

// GGIR's running median (ggir_epochs.hpp's rolling_median(), zoo's
// rollmedian with fill 0, and its parts, rolling_median_range()) against
// the plain rule: each window sorted
// stably (equal values, -0 and +0 among them, in their order in time),
// its middle value, to the bit; NaN where the window holds one. Sensor-like
// data with many ties, signed zeros, infinities, NaN runs, widths 1 to 51;
// with the kernel table at each level (the median's kernel order_next).
// big_array() and BigVector (host/big_array.hpp): memory that holds what is
// written; from kHugeFrom bytes on Linux aligned to 2 MB and advised as
// huge-page memory (the mapping's VmFlags carry "hg" in /proc/self/smaps
// wherever the kernel has transparent huge pages, whatever their mode).
#if defined(__linux__) && defined(MADV_HUGEPAGE)
static bool huge_advised(const void* p) {
  std::FILE* f = std::fopen("/proc/self/smaps", "r");
  if (f == nullptr) return false;
  const auto a = reinterpret_cast<std::uintptr_t>(p);
  char line[512];
  bool inside = false, found = false;
  while (std::fgets(line, sizeof line, f) != nullptr) {
    unsigned long lo = 0, hi = 0;
    if (std::sscanf(line, "%lx-%lx ", &lo, &hi) == 2 && std::strchr(line, '-') != nullptr &&
        std::isxdigit(static_cast<unsigned char>(line[0]))) {
      inside = a >= lo && a < hi;
      continue;
    }
    if (inside && std::strncmp(line, "VmFlags:", 8) == 0) {
      found = std::strstr(line, " hg") != nullptr;
      break;
    }
  }
  std::fclose(f);
  return found;
}
#endif

static void test_big_array() {
  for (std::size_t n : {std::size_t{0}, std::size_t{1}, std::size_t{1000},
                        gravcal::kHugeFrom / sizeof(double) + 3}) {
    gravcal::BigArray a = gravcal::big_array(n);
    CHECK(a != nullptr);
    for (std::size_t i = 0; i < n; ++i) a[i] = static_cast<double>(i) * 0.5;
    bool same = true;
    for (std::size_t i = 0; i < n; ++i) same = same && a[i] == static_cast<double>(i) * 0.5;
    CHECK(same);
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    if (n * sizeof(double) >= gravcal::kHugeFrom) {
      CHECK(reinterpret_cast<std::uintptr_t>(a.get()) % (std::size_t{2} << 20) == 0);
      std::FILE* thp = std::fopen("/sys/kernel/mm/transparent_hugepage/enabled", "r");
      if (thp != nullptr) {
        std::fclose(thp);
        CHECK(huge_advised(a.get()));
      }
    }
#endif
  }
  // a vector of them: the same values as std::vector's through assign,
  // growth, copy and swap
  std::vector<double> ref;
  gravcal::BigVector v;
  const std::size_t big = gravcal::kHugeFrom / sizeof(double) * 2;
  ref.assign(big, 0.25);
  v.assign(big, 0.25);
  for (std::size_t i = 0; i < big; i += 4097) {
    ref[i] = static_cast<double>(i);
    v[i] = static_cast<double>(i);
  }
  ref.resize(big + 10, -1.0);
  v.resize(big + 10, -1.0);
  gravcal::BigVector w(v);
  gravcal::BigVector().swap(v);
  CHECK(v.empty());
  CHECK(w.size() == ref.size() && std::equal(w.begin(), w.end(), ref.begin()));
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  CHECK(reinterpret_cast<std::uintptr_t>(w.data()) % (std::size_t{2} << 20) == 0);
#endif
  std::printf("big_array: ok\n");
}

static void test_rolling_median_at() {
  std::mt19937 rng(2024);
  std::uniform_int_distribution<int> level(-40, 40);
  std::uniform_real_distribution<double> u(0, 1);
  int bad = 0;
  for (int trial = 0; trial < 40; ++trial) {
    const std::size_t N = 50 + static_cast<std::size_t>(trial) * 37;
    std::vector<double> v(N);
    for (std::size_t i = 0; i < N; ++i) {
      const double r = u(rng);
      if (r < 0.1) v[i] = 0.0;
      else if (r < 0.2) v[i] = -0.0;
      else if (r < 0.21 && trial % 5 == 4) v[i] = r < 0.205 ? HUGE_VAL : -HUGE_VAL;
      else if (r < 0.6) v[i] = level(rng) / 256.0;  // ties, as a 8-bit sensor gives
      else v[i] = u(rng) - 0.5;
    }
    if (trial % 4 == 3) {
      for (std::size_t i = N / 3; i < N / 3 + 5 && i < N; ++i) v[i] = std::nan("");
    }
    for (std::size_t k = 1; k <= 51; k += 2) {
      std::vector<double> out;
      gravcal::ggir_part1::rolling_median(v, k, out);
      if (out.size() != N) {
        ++bad;
        continue;
      }
      // the same centres made in three parts, the later ones first (as two
      // threads may make them: short_metrics()'s share), to the bit
      if (k <= N) {
        std::size_t from = 0, to = 0;
        gravcal::ggir_part1::median_centres(N, k, &from, &to);
        const std::size_t a = from + (to - from) / 3, b = from + 2 * (to - from) / 3 + trial % 3;
        std::vector<double> parts(N, 0.0);
        gravcal::ggir_part1::rolling_median_range(v.data(), N, k, parts.data(), std::min(b, to), to);
        gravcal::ggir_part1::rolling_median_range(v.data(), N, k, parts.data(), a, std::min(b, to));
        gravcal::ggir_part1::rolling_median_range(v.data(), N, k, parts.data(), from, a);
        if (std::memcmp(parts.data(), out.data(), N * sizeof(double)) != 0) ++bad;
      }
      const std::size_t m = k / 2;
      for (std::size_t i = 0; i < N; ++i) {
        double want = 0.0;
        if (k <= N && i >= m && i + m < N) {
          std::vector<double> w(v.begin() + static_cast<std::ptrdiff_t>(i - m),
                                v.begin() + static_cast<std::ptrdiff_t>(i + m + 1));
          bool nan = false;
          for (double a : w) nan = nan || std::isnan(a);
          if (nan) {
            want = std::nan("");
          } else {
            std::stable_sort(w.begin(), w.end());
            want = w[m];
          }
        }
        const bool same = (std::isnan(want) && std::isnan(out[i])) ||
                          std::memcmp(&want, &out[i], sizeof want) == 0;
        if (!same) ++bad;
      }
    }
  }
  CHECK(bad == 0);
}

static void test_rolling_median() {
  gravcal::kernels::refill(gravcal::kernels::scalar);
  test_rolling_median_at();
  gravcal::set_avx2(false);  // SSE2 where compiled
  test_rolling_median_at();
  if (gravcal::set_avx2(true)) test_rolling_median_at();
}

int main(int argc, char** argv) {
  if (argc > 1 && std::strcmp(argv[1], "--digest") == 0) {
    // --digest baseline: without the AVX2 paths
    if (argc > 2 && std::strcmp(argv[2], "baseline") == 0) gravcal::set_avx2(false);
    print_digest();
    return 0;
  }
  test_icp();
  test_r_arithmetic();
  test_r_var_mean();
  test_r_sd_below();
  test_hex16();
  test_cwa_word_sum();
  test_avx2_geneactiv();
  test_geneactiv_time_ends();
  test_geneactiv_ggir_rules();
  test_add_repeated();
  test_lazy_sd();
  test_lazy_sd_edges();
  test_model();
  test_segmenter();
  test_bins();
  test_rolling_median();
  test_big_array();
  test_gradient<double>(1e-4);
  test_gradient<float>(5e-3);
  std::printf("core: %s\n", failures ? "FAILED" : "all checks passed");
  return failures ? 1 : 0;
}
