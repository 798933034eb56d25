// Rcpp glue for the GGIR fit (icp.hpp). Converts and checks shapes only.
#include <RcppEigen.h>

#include <vector>

#include "gravcal/icp.hpp"

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
  std::vector<double> tr;
  const gravcal::IcpResult r = gravcal::fit_icp(
      x.begin(), y.begin(), z.begin(), t, static_cast<std::size_t>(n), cfg,
      [&](int, const gravcal::IcpResult& q) {
        if (!trace) return;
        for (int k = 0; k < 3; ++k) tr.push_back(q.scale[k]);
        for (int k = 0; k < 3; ++k) tr.push_back(q.offset[k]);
        for (int k = 0; k < 3; ++k) tr.push_back(q.tempoffset[k]);
        tr.push_back(q.statistic);
      });
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
