// Rcpp glue for the GGIR fit (icp.hpp). Converts and checks shapes only.
#include "gravcal/mcu/fp_contract.hpp"  // first: see there

#include <RcppEigen.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "gravcal/ggir/ggir_blocks.hpp"
#include "gravcal/ggir/icp.hpp"
#include "r_services.h"
#include "windows_glue.h"


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
  cfg.r_long_double = gravcal_glue::r_long_double();
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
      }, gravcal_glue::RLeastSquares());
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
