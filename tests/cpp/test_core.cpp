// Standalone tests of the header-only core, built without R:
//   make -C tests/cpp
// Checks the model round trip, chunk invariance of the segmenter, the bin
// rules and recovery of known parameters by the gradient fit, in double and
// float, and by the ICP fit (icp.hpp, with Eigen); and that the R-compatible
// window arithmetic is also chunk invariant.
#include <cmath>
#include <cstdio>
#include <cstdint>
#include <cstring>
#include <random>
#include <vector>

#include "gravcal/gravcal.hpp"
#include "gravcal/icp.hpp"

static int failures = 0;
#define CHECK(cond)                                                   \
  do {                                                                \
    if (!(cond)) {                                                    \
      std::printf("FAIL %s:%d: %s\n", __FILE__, __LINE__, #cond);     \
      ++failures;                                                     \
    }                                                                 \
  } while (0)

using gravcal::Vec3;

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
}

// A digest of the windows of a fixed stream, printed so that the Makefile
// can check that the SSE2 and the portable builds give the same bits.
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
    for (std::size_t i = 0; i < sizeof(w); ++i) h = (h ^ p[i]) * 1099511628211ull;
  });
  std::printf("digest %016llx\n", static_cast<unsigned long long>(h));
}

int main(int argc, char** argv) {
  if (argc > 1 && std::strcmp(argv[1], "--digest") == 0) {
    print_digest();
    return 0;
  }
  test_icp();
  test_r_arithmetic();
  test_model();
  test_segmenter();
  test_bins();
  test_gradient<double>(1e-4);
  test_gradient<float>(5e-3);
  std::printf("core: %s\n", failures ? "FAILED" : "all checks passed");
  return failures ? 1 : 0;
}
