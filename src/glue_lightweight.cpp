// Rcpp glue for the segmenter, the bin selector and the gradient fit.
// Converts, checks shapes, calls the core in inst/include/gravcal. No
// algorithm lives here, and R's memory is only read.
#include "gravcal/mcu/fp_contract.hpp"  // first: see there

#include <Rcpp.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "gravcal/gravcal.hpp"

// Offer rest means in order until the bins are full. Returns, per row, the
// bin it was counted for (0..8) or the negative reason, NA for rows not
// offered because the bins were already full.
namespace {

// The bin selector in number type T: the coordinates are rounded to T as a
// device would hold them.
template <typename T>
Rcpp::List run_select(const Rcpp::NumericVector& x, const Rcpp::NumericVector& y,
                      const Rcpp::NumericVector& z, int min_per_bin,
                      int max_per_bin, double min_distance) {
  typedef gravcal::BinSelector<T, 9 * 64> Selector;
  gravcal::BinConfig cfg;
  cfg.min_per_bin = min_per_bin;
  cfg.max_per_bin = max_per_bin;
  cfg.min_distance = min_distance;
  std::unique_ptr<Selector> sel(new Selector(cfg));
  if (!sel->valid()) Rcpp::stop("invalid bin configuration");
  const R_xlen_t n = x.size();
  Rcpp::IntegerVector res(n, NA_INTEGER);
  for (R_xlen_t i = 0; i < n && !sel->full(); ++i) {
    res[i] = sel->offer(gravcal::Vec3<T>{T(x[i]), T(y[i]), T(z[i])});
  }
  Rcpp::IntegerVector counts(9);
  for (int b = 0; b < 9; ++b) counts[b] = sel->count(b);
  return Rcpp::List::create(Rcpp::Named("bin") = res,
                            Rcpp::Named("counts") = counts,
                            Rcpp::Named("complete") = sel->complete());
}

}  // namespace

// [[Rcpp::export(rng = false)]]
Rcpp::List gc_select_points(const Rcpp::NumericVector& x,
                            const Rcpp::NumericVector& y,
                            const Rcpp::NumericVector& z, int min_per_bin,
                            int max_per_bin, double min_distance,
                            std::string arithmetic = "double") {
  if (arithmetic == "double")
    return run_select<double>(x, y, z, min_per_bin, max_per_bin, min_distance);
  if (arithmetic == "float")
    return run_select<float>(x, y, z, min_per_bin, max_per_bin, min_distance);
  if (arithmetic == "fixed32")
    return run_select<gravcal::fixed32>(x, y, z, min_per_bin, max_per_bin,
                                        min_distance);
  if (arithmetic == "fixed16")
    return run_select<gravcal::fixed16>(x, y, z, min_per_bin, max_per_bin,
                                        min_distance);
  Rcpp::stop("unknown arithmetic");
}

namespace {

template <typename T>
Rcpp::List run_gradient(const Rcpp::NumericVector& x,
                        const Rcpp::NumericVector& y,
                        const Rcpp::NumericVector& z,
                        const Rcpp::NumericVector& p0, int max_iter, double h,
                        const Rcpp::NumericVector& rates, bool use_sqrt,
                        bool sum_scale, double tol, bool trace,
                        gravcal::GradientMode mode) {
  const int n = static_cast<int>(x.size());
  std::vector<T> xs(n), ys(n), zs(n);
  for (int i = 0; i < n; ++i) {
    xs[i] = T(x[i]);
    ys[i] = T(y[i]);
    zs[i] = T(z[i]);
  }
  gravcal::GradientConfig<T> cfg;
  cfg.max_iter = max_iter;
  cfg.h = T(h);
  for (int i = 0; i < gravcal::NPARAM; ++i) cfg.rate[i] = T(rates[i]);
  cfg.use_sqrt = use_sqrt;
  cfg.scale = sum_scale ? gravcal::SCALE_SUM : gravcal::SCALE_MEAN;
  cfg.tol = T(tol);
  cfg.gradient = mode;
  T p[gravcal::NPARAM];
  for (int i = 0; i < gravcal::NPARAM; ++i) p[i] = T(p0[i]);
  std::vector<double> tr;
  if (trace) tr.reserve(static_cast<std::size_t>(max_iter) * 10);
  gravcal::GradientResult r = gravcal::fit_gradient(
      p, xs.data(), ys.data(), zs.data(), n, cfg,
      [&](int it, const T* q, const T& f) {
        // Ctrl-C: the core's observer may throw (see gradient.hpp)
        if ((it & 1023) == 0) Rcpp::checkUserInterrupt();
        if (!trace) return;
        for (int i = 0; i < gravcal::NPARAM; ++i)
          tr.push_back(static_cast<double>(q[i]));
        tr.push_back(static_cast<double>(f));
      });
  Rcpp::NumericVector pout(gravcal::NPARAM);
  for (int i = 0; i < gravcal::NPARAM; ++i) pout[i] = static_cast<double>(p[i]);
  const double fend = static_cast<double>(gravcal::gradient_objective(
      p, xs.data(), ys.data(), zs.data(), n, use_sqrt, cfg.scale));
  Rcpp::NumericMatrix tm(10, static_cast<int>(tr.size() / 10));
  std::copy(tr.begin(), tr.end(), tm.begin());
  return Rcpp::List::create(Rcpp::Named("p") = pout,
                            Rcpp::Named("iterations") = r.iterations,
                            Rcpp::Named("converged") = r.converged,
                            Rcpp::Named("finite") = r.finite,
                            Rcpp::Named("objective") = fend,
                            Rcpp::Named("trace") = tm);
}

}  // namespace

// difference: "forward" (the paper's), "central" or "analytic".
// [[Rcpp::export(rng = false)]]
Rcpp::List gc_fit_gradient(const Rcpp::NumericVector& x,
                           const Rcpp::NumericVector& y,
                           const Rcpp::NumericVector& z,
                           const Rcpp::NumericVector& p0, int max_iter,
                           double h, const Rcpp::NumericVector& rates,
                           bool use_sqrt, bool sum_scale, double tol,
                           bool trace, std::string arithmetic,
                           std::string difference = "forward") {
  if (y.size() != x.size() || z.size() != x.size())
    Rcpp::stop("x, y, z lengths differ");
  if (p0.size() != gravcal::NPARAM || rates.size() != gravcal::NPARAM)
    Rcpp::stop("p0 and rates must have 9 values");
  gravcal::GradientMode mode;
  if (difference == "forward") mode = gravcal::GRADIENT_FORWARD;
  else if (difference == "central") mode = gravcal::GRADIENT_CENTRAL;
  else if (difference == "analytic") mode = gravcal::GRADIENT_ANALYTIC;
  else Rcpp::stop("unknown difference");
  if (arithmetic == "double")
    return run_gradient<double>(x, y, z, p0, max_iter, h, rates, use_sqrt,
                                sum_scale, tol, trace, mode);
  if (arithmetic == "float")
    return run_gradient<float>(x, y, z, p0, max_iter, h, rates, use_sqrt,
                               sum_scale, tol, trace, mode);
  if (arithmetic == "fixed32")
    return run_gradient<gravcal::fixed32>(x, y, z, p0, max_iter, h, rates,
                                          use_sqrt, sum_scale, tol, trace, mode);
  if (arithmetic == "fixed16")
    return run_gradient<gravcal::fixed16>(x, y, z, p0, max_iter, h, rates,
                                          use_sqrt, sum_scale, tol, trace, mode);
  Rcpp::stop("unknown arithmetic");
}

// The memory-bandwidth floor for bench/: reads every sample of the given
// columns once (four independent sums per column, so that the loop is bound
// by memory, not by the latency of one chain of additions). Not exported to
// users; the benchmark compares the segmenter with it.
// [[Rcpp::export(rng = false)]]
double gc_read_once(const Rcpp::List& cols) {
  double total = 0.0;
  for (R_xlen_t c = 0; c < cols.size(); ++c) {
    Rcpp::NumericVector v(cols[c]);
    const double* p = v.begin();
    const R_xlen_t n = v.size();
    double a0 = 0.0, a1 = 0.0, a2 = 0.0, a3 = 0.0;
    R_xlen_t i = 0;
    for (; i + 4 <= n; i += 4) {
      a0 += p[i];
      a1 += p[i + 1];
      a2 += p[i + 2];
      a3 += p[i + 3];
    }
    for (; i < n; ++i) a0 += p[i];
    total += (a0 + a1) + (a2 + a3);
  }
  return total;
}

#if defined(__GLIBC__)
#include <malloc.h>
#endif

// For bench/: hand memory that malloc keeps after R freed it back to the
// system (glibc only), so that a peak measured next starts from what is in
// use. Returns whether it could.
// [[Rcpp::export(rng = false)]]
bool gc_release_memory() {
#if defined(__GLIBC__)
  malloc_trim(0);
  return true;
#else
  return false;
#endif
}
