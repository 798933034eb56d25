// Rcpp glue for the GGIR fit (icp.hpp). Converts and checks shapes only.
#include "gravcal/fp_contract.hpp"  // first: see there

#include <RcppEigen.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <R_ext/Applic.h>

#include "gravcal/ggir_blocks.hpp"
#include "gravcal/icp.hpp"
#include "windows_glue.h"

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

// x, y, z: window means; temp: their temperatures or NULL. rule: "ggir_r"
// (GGIR's stopping statistic in GGIR's arithmetic with R's least squares,
// bit for bit), "ggir" (the same statistic, gravcal's arithmetic: a cheap
// early stop) or "converge" (until no parameter moves by tol).
// [[Rcpp::export(rng = false)]]
Rcpp::List gc_fit_icp(const Rcpp::NumericVector& x, const Rcpp::NumericVector& y,
                      const Rcpp::NumericVector& z,
                      Rcpp::Nullable<Rcpp::NumericVector> temp, bool use_temp,
                      const std::string& rule, int max_iter, double tol,
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
  if (rule != "ggir_r" && rule != "ggir" && rule != "converge")
    Rcpp::stop("rule must be \"ggir_r\", \"ggir\" or \"converge\"");
  cfg.stop = rule == "converge" ? gravcal::StopRule::parameters : gravcal::StopRule::ggir;
  cfg.r_arithmetic = rule == "ggir_r";
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

// GGIR's duplicate filter: the positions i (1-based) in `rows` (1-based row
// numbers of `table`) where rows i and i + 1 are equal in exactly `need` of
// the table's columns 2 to 7 (R's which(same == need), NA never counted).
// [[Rcpp::export(rng = false)]]
Rcpp::IntegerVector gc_ggir_duplicates(const Rcpp::NumericMatrix& table,
                                       const Rcpp::IntegerVector& rows, int need) {
  const std::size_t nr = static_cast<std::size_t>(table.nrow());
  if (table.ncol() < 7) Rcpp::stop("the window table needs at least 7 columns");
  const std::size_t n = static_cast<std::size_t>(rows.size());
  std::vector<std::size_t> r(n);
  for (std::size_t i = 0; i < n; ++i) {
    const int v = rows[static_cast<R_xlen_t>(i)];
    if (v == NA_INTEGER || v < 1 || static_cast<std::size_t>(v) > nr)
      Rcpp::stop("row numbers out of range");
    r[i] = static_cast<std::size_t>(v - 1);
  }
  const std::vector<std::size_t> cut = gravcal::duplicate_cuts(table.begin(), nr, r.data(), n, need);
  Rcpp::IntegerVector out(static_cast<R_xlen_t>(cut.size()));
  for (std::size_t i = 0; i < cut.size(); ++i) {
    out[static_cast<R_xlen_t>(i)] = static_cast<int>(cut[i] + 1);
  }
  return out;
}

// GGIR's block rules in front of segmenter `seg` (see ggir_blocks.hpp);
// temp_min_sd: the threshold of the temperature's sd.
// [[Rcpp::export(rng = false)]]
SEXP gc_blocks_new(SEXP seg, double per_hour, bool compat, bool temperature,
                   double temp_min_sd) {
  if (!(per_hour >= 1)) Rcpp::stop("per_hour must be at least 1");
  return Rcpp::XPtr<gravcal_glue::BlocksBox>(
      new gravcal_glue::BlocksBox(seg, per_hour, compat, temperature, temp_min_sd),
      true);
}

// One block from columns in memory: the pieces [from[k], to[k]) (0-based) of
// x[[k]], y[[k]], z[[k]] and t[[k]] (NULL without temperature), in order.
// [[Rcpp::export(rng = false)]]
Rcpp::List gc_blocks_columns(SEXP blocks, const Rcpp::List& x, const Rcpp::List& y,
                             const Rcpp::List& z, const Rcpp::List& t,
                             const Rcpp::NumericVector& from,
                             const Rcpp::NumericVector& to, int rule,
                             Rcpp::NumericVector par) {
  Rcpp::XPtr<gravcal_glue::BlocksBox> box(blocks);
  gravcal_glue::check_lazy_rule(*box, rule, par);
  const gravcal_glue::RestRule is_rest(rule, par);
  const R_xlen_t np = x.size();
  if (y.size() != np || z.size() != np || t.size() != np || from.size() != np ||
      to.size() != np)
    Rcpp::stop("piece lists differ in length");
  gravcal_glue::WindowTable table;
  auto sink = [&](const gravcal::WindowStats& w) { table.add(w, is_rest(w)); };
  box->blocks.begin_block();
  constexpr std::size_t chunk = 1u << 16;
  for (R_xlen_t k = 0; k < np; ++k) {
    Rcpp::NumericVector xv(x[k]), yv(y[k]), zv(z[k]);
    const R_xlen_t n = xv.size();
    if (yv.size() != n || zv.size() != n) Rcpp::stop("x, y, z lengths differ");
    const double* tp = nullptr;
    Rcpp::NumericVector tv;
    if (box->temperature && !Rf_isNull(t[k])) {
      tv = Rcpp::NumericVector(t[k]);
      if (tv.size() != n) Rcpp::stop("temperature length differs");
      tp = tv.begin();
    }
    if (!(from[k] >= 0 && to[k] <= static_cast<double>(n) && from[k] <= to[k]))
      Rcpp::stop("piece bounds out of range");
    std::size_t i = static_cast<std::size_t>(from[k]);
    const std::size_t end = static_cast<std::size_t>(to[k]);
    while (i < end) {
      const std::size_t m = std::min(chunk, end - i);
      box->blocks.push(xv.begin() + i, yv.begin() + i, zv.begin() + i,
                       tp ? tp + i : nullptr, m, sink);
      i += m;
    }
  }
  return gravcal_glue::block_result(table, box->blocks.end_block(sink));
}
