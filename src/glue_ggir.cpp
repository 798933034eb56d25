// Rcpp glue for the GGIR fit (icp.hpp). Converts and checks shapes only.
#include <RcppEigen.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include <R_ext/Applic.h>

#include "gravcal/icp.hpp"

namespace {

// Weighted least squares by R's own LINPACK routine dqrls, with lm.wfit's
// tolerance and its handling of aliased columns: the numbers GGIR's lm.wfit
// calls get, to the last bit (see icp.hpp, IcpConfig::r_arithmetic).
struct RLeastSquares {
  mutable std::vector<double> qty, qraux, work, b;
  mutable std::vector<int> jpvt;
  void operator()(double* X, const double* y, std::size_t n, int p,
                  double* coef, double* rsd) const {
    int nn = static_cast<int>(n), pp = p, ny = 1, rank = 0;
    double tol = 1e-7;
    qty.assign(n, 0.0);
    qraux.assign(static_cast<std::size_t>(p), 0.0);
    work.assign(2 * static_cast<std::size_t>(p), 0.0);
    b.assign(static_cast<std::size_t>(p), 0.0);
    jpvt.resize(static_cast<std::size_t>(p));
    for (int j = 0; j < p; ++j) jpvt[static_cast<std::size_t>(j)] = j + 1;
    std::vector<double> yy(y, y + n);
    F77_CALL(dqrls)(X, &nn, &pp, yy.data(), &ny, &tol, b.data(), rsd,
                    qty.data(), &rank, jpvt.data(), qraux.data(), work.data());
    for (int j = 0; j < p; ++j) coef[j] = NA_REAL;
    for (int j = 0; j < rank; ++j) coef[jpvt[static_cast<std::size_t>(j)] - 1] = b[static_cast<std::size_t>(j)];
  }
};

}  // namespace

// x, y, z: window means; temp: their temperatures or NULL. stop_rule: 0 =
// GGIR's statistic rule, 1 = parameter convergence.
// [[Rcpp::export(rng = false)]]
Rcpp::List gc_fit_icp(const Rcpp::NumericVector& x, const Rcpp::NumericVector& y,
                      const Rcpp::NumericVector& z,
                      Rcpp::Nullable<Rcpp::NumericVector> temp, bool use_temp,
                      int stop_rule, int max_iter, double tol,
                      double max_weight, bool trace) {
  const R_xlen_t n = x.size();
  if (y.size() != n || z.size() != n) Rcpp::stop("x, y, z lengths differ");
  const double* t = nullptr;
  Rcpp::NumericVector tv;
  if (temp.isNotNull()) {
    tv = Rcpp::NumericVector(temp.get());
    if (tv.size() != n) Rcpp::stop("temperature length differs");
    t = tv.begin();
  }
  gravcal::IcpConfig cfg;
  cfg.max_iter = max_iter;
  cfg.tol = tol;
  cfg.max_weight = max_weight;
  cfg.use_temp = use_temp && t != nullptr;
  cfg.stop = stop_rule == 0 ? gravcal::StopRule::ggir : gravcal::StopRule::parameters;
  // GGIR's rule: GGIR's arithmetic and R's least squares, bit for bit
  cfg.r_arithmetic = stop_rule == 0;
  std::vector<double> tr;
  const gravcal::IcpResult r = gravcal::fit_icp(
      x.begin(), y.begin(), z.begin(), t, static_cast<std::size_t>(n), cfg,
      [&](int it, const gravcal::IcpResult& q) {
        // Ctrl-C: the core's observer may throw (see icp.hpp)
        if ((it & 15) == 0) Rcpp::checkUserInterrupt();
        if (!trace) return;
        for (int k = 0; k < 3; ++k) tr.push_back(q.scale[k]);
        for (int k = 0; k < 3; ++k) tr.push_back(q.offset[k]);
        for (int k = 0; k < 3; ++k) tr.push_back(q.tempoffset[k]);
        tr.push_back(q.statistic);
      }, RLeastSquares());
  Rcpp::NumericMatrix tm(10, static_cast<int>(tr.size() / 10));
  std::copy(tr.begin(), tr.end(), tm.begin());
  return Rcpp::List::create(
      Rcpp::Named("scale") = Rcpp::NumericVector(r.scale, r.scale + 3),
      Rcpp::Named("offset") = Rcpp::NumericVector(r.offset, r.offset + 3),
      Rcpp::Named("tempoffset") = Rcpp::NumericVector(r.tempoffset, r.tempoffset + 3),
      Rcpp::Named("meantemp") = r.meantemp,
      Rcpp::Named("temp_used") = r.temp_used,
      Rcpp::Named("iterations") = r.iterations,
      Rcpp::Named("converged") = r.converged,
      Rcpp::Named("finite") = r.finite,
      Rcpp::Named("statistic") = r.statistic,
      Rcpp::Named("trace") = tm);
}

Rcpp::NumericVector gc_r_mean_sd(const Rcpp::List& v,
                                 const Rcpp::NumericVector& from,
                                 const Rcpp::NumericVector& to, double limit);

// Samples in [from, to) (0-based) whose x, y and z are all exactly zero
// (idle sleep); NA and NaN are not zero.
// [[Rcpp::export(rng = false)]]
double gc_count_zero(const Rcpp::NumericVector& x, const Rcpp::NumericVector& y,
                     const Rcpp::NumericVector& z, double from, double to) {
  const R_xlen_t n = x.size();
  if (y.size() != n || z.size() != n) Rcpp::stop("x, y, z lengths differ");
  if (!(from >= 0 && to <= static_cast<double>(n) && from <= to))
    Rcpp::stop("range out of bounds");
  const double* px = x.begin();
  const double* py = y.begin();
  const double* pz = z.begin();
  std::size_t count = 0;
  // a branch-free scan of stretches of 4096 samples; those holding a zero
  // sample (rare) are counted exactly
  const std::size_t end = static_cast<std::size_t>(to);
  std::size_t i = static_cast<std::size_t>(from);
  while (i < end) {
    const std::size_t stop = std::min(end, i + 4096);
    unsigned any = 0;
    for (std::size_t k = i; k < stop; ++k) {
      any |= static_cast<unsigned>((px[k] == 0.0) & (py[k] == 0.0) & (pz[k] == 0.0));
    }
    if (any) {
      for (std::size_t k = i; k < stop; ++k) {
        count += (px[k] == 0.0) & (py[k] == 0.0) & (pz[k] == 0.0);
      }
    }
    i = stop;
  }
  return static_cast<double>(count);
}

// Is sd(v, na.rm = TRUE) below `threshold`, for the first `limit` values of
// the pieces (see gc_r_mean_sd())? One pass in double (sums about the first
// value); only when the answer is within 1e-6 of the threshold does it take
// R's exact arithmetic (gc_r_mean_sd()), so the answer is R's. NA with fewer
// than 2 values.
// [[Rcpp::export(rng = false)]]
Rcpp::LogicalVector gc_sd_below(const Rcpp::List& v, const Rcpp::NumericVector& from,
                                const Rcpp::NumericVector& to, double limit,
                                double threshold) {
  const R_xlen_t np = v.size();
  if (from.size() != np || to.size() != np) Rcpp::stop("piece bounds differ");
  double left = limit, shift = NA_REAL;
  // four lanes of sums about the first non-NA value (order does not matter:
  // this is the approximate pass)
  double s[4] = {0, 0, 0, 0}, ss[4] = {0, 0, 0, 0}, cnt[4] = {0, 0, 0, 0};
  for (R_xlen_t k = 0; k < np; ++k) {
    Rcpp::NumericVector c(v[k]);
    if (!(from[k] >= 0 && to[k] <= static_cast<double>(c.size()) && from[k] <= to[k]))
      Rcpp::stop("range out of bounds");
    const double len = std::min(to[k] - from[k], std::max(left, 0.0));
    left -= len;
    const double* p = c.begin() + static_cast<R_xlen_t>(from[k]);
    const std::size_t m = static_cast<std::size_t>(len);
    std::size_t i = 0;
    if (std::isnan(shift)) {
      while (i < m && std::isnan(p[i])) ++i;
      if (i < m) shift = p[i];
    }
    for (; i + 4 <= m; i += 4) {
      for (int l = 0; l < 4; ++l) {
        const double a = p[i + l];
        const bool ok = !std::isnan(a);
        const double d = ok ? a - shift : 0.0;
        s[l] += d;
        ss[l] += d * d;
        cnt[l] += ok ? 1.0 : 0.0;
      }
    }
    for (; i < m; ++i) {
      const double a = p[i];
      if (std::isnan(a)) continue;
      const double d = a - shift;
      s[0] += d;
      ss[0] += d * d;
      cnt[0] += 1.0;
    }
  }
  const double sum = (s[0] + s[1]) + (s[2] + s[3]);
  const double sumsq = (ss[0] + ss[1]) + (ss[2] + ss[3]);
  const std::size_t n = static_cast<std::size_t>((cnt[0] + cnt[1]) + (cnt[2] + cnt[3]));
  if (n < 2) return Rcpp::LogicalVector::create(NA_LOGICAL);
  const double nn = static_cast<double>(n);
  const double var = std::max(0.0, (sumsq - sum * sum / nn) / (nn - 1.0));
  const double sd = std::sqrt(var);
  if (std::isfinite(sd) && std::fabs(sd - threshold) > 1e-6 * threshold) {
    return Rcpp::LogicalVector::create(sd < threshold);
  }
  const Rcpp::NumericVector exact = gc_r_mean_sd(v, from, to, limit);
  return Rcpp::LogicalVector::create(exact[1] < threshold);
}

// mean(v, na.rm = TRUE) and sd(v, na.rm = TRUE) as R computes them (long
// double sums, R's correction pass for the mean), of the first `limit`
// values of the pieces: v[[k]][from[k] + 1 .. to[k]] in order, without
// copying them. Returns c(mean, sd, n) with n the number of non-NA values.
// [[Rcpp::export(rng = false)]]
Rcpp::NumericVector gc_r_mean_sd(const Rcpp::List& v,
                                 const Rcpp::NumericVector& from,
                                 const Rcpp::NumericVector& to, double limit) {
  const R_xlen_t np = v.size();
  if (from.size() != np || to.size() != np) Rcpp::stop("piece bounds differ");
  std::vector<const double*> base(static_cast<std::size_t>(np));
  std::vector<R_xlen_t> lo(static_cast<std::size_t>(np)), hi(static_cast<std::size_t>(np));
  double left = limit;
  for (R_xlen_t k = 0; k < np; ++k) {
    Rcpp::NumericVector c(v[k]);
    if (!(from[k] >= 0 && to[k] <= static_cast<double>(c.size()) && from[k] <= to[k]))
      Rcpp::stop("range out of bounds");
    base[k] = c.begin();
    lo[k] = static_cast<R_xlen_t>(from[k]);
    const double len = std::min(to[k] - from[k], std::max(left, 0.0));
    hi[k] = lo[k] + static_cast<R_xlen_t>(len);
    left -= len;
  }
  auto each = [&](auto&& f) {
    for (R_xlen_t k = 0; k < np; ++k) {
      const double* p = base[k];
      for (R_xlen_t i = lo[k]; i < hi[k]; ++i) {
        if (!std::isnan(p[i])) f(p[i]);
      }
    }
  };
  std::size_t n = 0;
  long double s = 0.0L;
  each([&](double a) { s += a; ++n; });
  if (n == 0) return Rcpp::NumericVector::create(R_NaN, NA_REAL, 0.0);
  const long double ln = static_cast<long double>(n);
  long double m = s / ln;
  if (std::isfinite(static_cast<double>(m))) {
    long double c = 0.0L;
    each([&](double a) { c += (a - m); });
    m += c / ln;
  }
  const double mean = static_cast<double>(m);
  double sd = NA_REAL;
  if (n > 1) {
    long double ss = 0.0L;
    const long double xm = mean;
    each([&](double a) { ss += (a - xm) * (a - xm); });
    sd = std::sqrt(static_cast<double>(ss / static_cast<long double>(n - 1)));
  }
  return Rcpp::NumericVector::create(mean, sd, static_cast<double>(n));
}
