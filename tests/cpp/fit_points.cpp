// The gradient fit of the standalone core, for comparison with R and for
// counting instructions:
//   fit_points < cases.txt      one fit per case, the 9 parameters in %a
//   fit_points --once ARITH [DIFFERENCE]
//                               one calibration (18 points, 50 iterations)
//                               in ARITH (forward differences unless
//                               DIFFERENCE says), for callgrind (Makefile)
// A case is a line "ARITH DIFFERENCE MAX_ITER H N SQRT" (ARITH double,
// float, fixed32 or fixed16; DIFFERENCE forward, central or analytic; H in
// %a; SQRT 1 for the objective with the square root, else 0) followed by N
// lines "x y z" (%a). The points are rounded to ARITH as R's fit_gradient()
// rounds them, and the fit is the same template, so the output must be R's
// to the bit (check-r.R).
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "gravcal/gravcal.hpp"

template <typename T>
#if defined(__GNUC__)
__attribute__((noinline))
#endif
void run_fit(T* p, const T* x, const T* y, const T* z, int n,
             const gravcal::GradientConfig<T>& cfg) {
  gravcal::identity_params(p);
  gravcal::fit_gradient(p, x, y, z, n, cfg);
}

template <typename T>
static void fit_case(const std::vector<double>& xd, const std::vector<double>& yd,
                     const std::vector<double>& zd, int max_iter, double h,
                     gravcal::GradientMode mode, bool use_sqrt) {
  const int n = static_cast<int>(xd.size());
  std::vector<T> x(n), y(n), z(n);
  for (int i = 0; i < n; ++i) {
    x[i] = T(xd[i]);
    y[i] = T(yd[i]);
    z[i] = T(zd[i]);
  }
  gravcal::GradientConfig<T> cfg;
  cfg.max_iter = max_iter;
  cfg.h = T(h);
  cfg.gradient = mode;
  cfg.use_sqrt = use_sqrt;
  T p[9];
  run_fit(p, x.data(), y.data(), z.data(), n, cfg);
  for (int i = 0; i < 9; ++i) {
    std::printf(i ? " %a" : "%a", static_cast<double>(p[i]));
  }
  std::printf("\n");
}

static void dispatch(const std::string& a, const std::vector<double>& x,
                     const std::vector<double>& y, const std::vector<double>& z,
                     int max_iter, double h, gravcal::GradientMode mode,
                     bool use_sqrt = false) {
  if (a == "double") fit_case<double>(x, y, z, max_iter, h, mode, use_sqrt);
  else if (a == "float") fit_case<float>(x, y, z, max_iter, h, mode, use_sqrt);
  else if (a == "fixed32") fit_case<gravcal::fixed32>(x, y, z, max_iter, h, mode, use_sqrt);
  else if (a == "fixed16") fit_case<gravcal::fixed16>(x, y, z, max_iter, h, mode, use_sqrt);
  else {
    std::fprintf(stderr, "unknown arithmetic %s\n", a.c_str());
    std::exit(2);
  }
}

static gravcal::GradientMode mode_of(const char* d) {
  if (std::strcmp(d, "forward") == 0) return gravcal::GRADIENT_FORWARD;
  if (std::strcmp(d, "central") == 0) return gravcal::GRADIENT_CENTRAL;
  if (std::strcmp(d, "analytic") == 0) return gravcal::GRADIENT_ANALYTIC;
  std::fprintf(stderr, "unknown difference %s\n", d);
  std::exit(2);
}

int main(int argc, char** argv) {
  if ((argc == 3 || argc == 4) && std::strcmp(argv[1], "--once") == 0) {
    // 18 rest means of a sensor with p = (0.96, 1.04, 1.01, 0.02, -0.03,
    // 0.01, 0.05, -0.04, 0.02), two per bin
    static const double pts[18][3] = {
        {0.99, 0.05, 0.06}, {1.01, -0.18, 0.11}, {-1.06, 0.03, -0.07},
        {-1.00, 0.20, 0.10}, {0.05, 0.98, 0.16}, {-0.20, 0.94, -0.15},
        {0.02, -1.02, -0.09}, {0.21, -0.98, 0.12}, {0.04, 0.08, 0.98},
        {-0.19, 0.12, 0.96}, {0.09, -0.06, -1.03}, {-0.15, 0.19, -0.99},
        {0.70, 0.71, 0.05}, {-0.68, 0.02, 0.73}, {0.03, -0.71, 0.70},
        {0.71, 0.02, -0.70}, {-0.72, -0.69, 0.04}, {0.02, 0.72, -0.71}};
    std::vector<double> x, y, z;
    for (const auto& q : pts) {
      x.push_back(q[0]);
      y.push_back(q[1]);
      z.push_back(q[2]);
    }
    const std::string a = argv[2];
    dispatch(a, x, y, z, 50, a == "fixed16" ? 0.01 : 1e-5,
             mode_of(argc == 4 ? argv[3] : "forward"));
    return 0;
  }
  char arith[32], diff[32], hs[64];
  int max_iter, n, use_sqrt;
  while (std::scanf("%31s %31s %d %63s %d %d", arith, diff, &max_iter, hs, &n,
                    &use_sqrt) == 6) {
    std::vector<double> x(n), y(n), z(n);
    for (int i = 0; i < n; ++i) {
      char a[64], b[64], c[64];
      if (std::scanf("%63s %63s %63s", a, b, c) != 3) return 3;
      x[i] = std::strtod(a, nullptr);
      y[i] = std::strtod(b, nullptr);
      z[i] = std::strtod(c, nullptr);
    }
    dispatch(arith, x, y, z, max_iter, std::strtod(hs, nullptr),
             mode_of(diff), use_sqrt != 0);
  }
  return 0;
}
