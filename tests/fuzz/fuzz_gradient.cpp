// libFuzzer harness: the gradient fit on arbitrary points and settings
// (forward, central or analytic gradient), in double, float and both
// fixed-point types. Checks: no sanitizer finding,
// the iteration count within bounds, and a fit that reports itself finite
// has finite parameters (double, float).
#include <cmath>
#include <vector>

#include "fuzz_input.hpp"
#include "gravcal/mcu/fixed_point.hpp"
#include "gravcal/mcu/gradient.hpp"

template <typename T>
static void run(const std::vector<double>& xs, const std::vector<double>& ys,
                const std::vector<double>& zs, int max_iter, double h,
                const double* rates, bool use_sqrt, bool sum, gravcal::GradientMode mode) {
  const int n = static_cast<int>(xs.size());
  std::vector<T> x(n), y(n), z(n);
  for (int i = 0; i < n; ++i) x[i] = T(xs[i]), y[i] = T(ys[i]), z[i] = T(zs[i]);
  gravcal::GradientConfig<T> cfg;
  cfg.max_iter = max_iter;
  cfg.h = T(h);
  for (int i = 0; i < 9; ++i) cfg.rate[i] = T(rates[i]);
  cfg.use_sqrt = use_sqrt;
  cfg.scale = sum ? gravcal::SCALE_SUM : gravcal::SCALE_MEAN;
  cfg.gradient = mode;
  T p[9];
  gravcal::identity_params(p);
  const gravcal::GradientResult r =
      gravcal::fit_gradient(p, x.data(), y.data(), z.data(), n, cfg);
  if (r.iterations < 0 || r.iterations > max_iter) __builtin_trap();
  if (r.finite) {
    for (int i = 0; i < 9; ++i) {
      if (!std::isfinite(static_cast<double>(p[i]))) __builtin_trap();
    }
  }
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  FuzzInput in{data, size};
  const int type = in.byte() % 4;
  const int max_iter = in.byte() % 60;
  const double h = (1 + in.byte()) * 1e-5;
  double rates[9];
  for (double& r : rates) r = (1 + in.byte()) / 128.0;
  const std::uint8_t flags = in.byte();
  std::vector<double> x, y, z;
  while (!in.empty() && x.size() < 64) {
    x.push_back(in.sample());
    y.push_back(in.sample());
    z.push_back(in.sample());
  }
  const bool s = flags & 1, sum = flags & 2;
  const gravcal::GradientMode c = static_cast<gravcal::GradientMode>((flags >> 2) % 3);
  if (type == 0) run<double>(x, y, z, max_iter, h, rates, s, sum, c);
  else if (type == 1) run<float>(x, y, z, max_iter, h, rates, s, sum, c);
  else if (type == 2) run<gravcal::fixed32>(x, y, z, max_iter, h, rates, s, sum, c);
  else run<gravcal::fixed16>(x, y, z, max_iter, h, rates, s, sum, c);
  return 0;
}
