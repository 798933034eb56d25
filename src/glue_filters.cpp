// Rcpp glue for GGIR's filtered signals (gravcal/ggir/ggir_filters.hpp), internal
// (for tests and for R/ggir-filters.R): converts, calls, and turns the
// core's statuses into R's own errors. Converts and calls, nothing more.
#include "gravcal/mcu/fp_contract.hpp"  // first: see there

#include <Rcpp.h>

#include <string>
#include <vector>

#include "gravcal/ggir/ggir_filters.hpp"

namespace {

gravcal::ArmaCoefs arma(const Rcpp::List& coef, const char* what) {
  if (!coef.containsElementNamed("b") || !coef.containsElementNamed("a"))
    Rcpp::stop("`%s` must hold numeric vectors `b` and `a`", what);
  SEXP b = coef["b"];
  SEXP a = coef["a"];
  if (TYPEOF(b) != REALSXP || TYPEOF(a) != REALSXP || Rf_xlength(a) < 1)
    Rcpp::stop("`%s$b` and `%s$a` must be numeric vectors, `a` not empty", what, what);
  gravcal::ArmaCoefs c;
  c.b = REAL(b);
  c.nb = static_cast<std::size_t>(Rf_xlength(b));
  c.a = REAL(a);
  c.na = static_cast<std::size_t>(Rf_xlength(a));
  return c;
}

gravcal::RFilterArith arith_of(bool conv_fused, bool rec_fused) {
  gravcal::RFilterArith ar;
  ar.conv_fused = conv_fused;
  ar.rec_fused = rec_fused;
  return ar;
}

}  // namespace

// signal::filter(list(b, a), x) as signal's filter.default computes it
// with its zero initial state; the result shorter than x where R's na.omit
// drops NAs at the ends. conv_fused, rec_fused: whether R's stats::filter
// fuses its multiply-adds (stats_filter_fused()).
// [[Rcpp::export(rng = false)]]
Rcpp::NumericVector gc_ggir_filter(const Rcpp::NumericVector& b, const Rcpp::NumericVector& a,
                                   const Rcpp::NumericVector& x, bool conv_fused,
                                   bool rec_fused) {
  if (a.size() < 1) Rcpp::stop("`a` must not be empty");
  const std::size_t n = static_cast<std::size_t>(x.size());
  std::vector<double> y(n);
  const gravcal::FilterResult r =
      gravcal::filter_arma(b.begin(), static_cast<std::size_t>(b.size()), a.begin(),
                           static_cast<std::size_t>(a.size()), x.begin(), n, y.data(),
                           arith_of(conv_fused, rec_fused));
  if (r.status == gravcal::FilterStatus::internal_na)
    Rcpp::stop("time series contains internal NAs");
  return Rcpp::NumericVector(y.begin(), y.begin() + static_cast<std::ptrdiff_t>(r.length));
}

// g.applymetrics()'s filtered per-sample signals (metrics: GGIR's names,
// "BFEN", ..., "ZCZ") of a block's calibrated axes, each filter run once for
// all of them (ggir_filtered_signals()): a list, one signal per metric.
// coefs: list(band, low, high, zc = list(b, a) each, zc_sb), as
// ggir_filter_coefs() gives. R's error for the first metric, in the order
// given, that R could not compute. chunk: the parts the block is filtered in
// (gravcal::kFilterChunk in g.getmeta()).
// [[Rcpp::export(rng = false)]]
Rcpp::List gc_ggir_filtered_signal(const Rcpp::NumericVector& x, const Rcpp::NumericVector& y,
                                   const Rcpp::NumericVector& z,
                                   const Rcpp::CharacterVector& metrics, const Rcpp::List& coefs,
                                   bool conv_fused, bool rec_fused, double chunk) {
  const R_xlen_t n = x.size();
  if (y.size() != n || z.size() != n) Rcpp::stop("x, y, z lengths differ");
  std::vector<gravcal::FilteredMetric> ms(static_cast<std::size_t>(metrics.size()));
  for (R_xlen_t k = 0; k < metrics.size(); ++k) {
    const std::string nm = Rcpp::as<std::string>(metrics[k]);
    if (!gravcal::filtered_metric_from_name(nm.c_str(), &ms[static_cast<std::size_t>(k)]))
      Rcpp::stop("`metric` must be one of GGIR's filtered metrics, not \"%s\"", nm);
  }
  gravcal::GgirFilterCoefs c;
  c.band = arma(coefs["band"], "coefs$band");
  c.low = arma(coefs["low"], "coefs$low");
  c.high = arma(coefs["high"], "coefs$high");
  c.zc = arma(coefs["zc"], "coefs$zc");
  c.zc_sb = Rcpp::as<double>(coefs["zc_sb"]);
  std::vector<std::vector<double>> sig(ms.size());
  std::vector<gravcal::SignalStatus> status(ms.size(), gravcal::SignalStatus::ok);
  struct Sink {
    std::vector<std::vector<double>>& sig;
    std::vector<gravcal::SignalStatus>& status;
    void begin(std::size_t i, gravcal::SignalStatus st) {
      status[i] = st;
      sig[i].clear();
    }
    void values(std::size_t i, const double* v, std::size_t len) { sig[i].insert(sig[i].end(), v, v + len); }
    void end_part() {}
  } sink{sig, status};
  if (chunk < 1) Rcpp::stop("`chunk` must be a positive number of samples");
  gravcal::ggir_filtered_signals(ms.data(), ms.size(), x.begin(), y.begin(), z.begin(),
                                 static_cast<std::size_t>(n), c, arith_of(conv_fused, rec_fused),
                                 sink, static_cast<std::size_t>(chunk));
  Rcpp::List out(metrics.size());
  for (std::size_t i = 0; i < ms.size(); ++i) {
    if (status[i] == gravcal::SignalStatus::ok) {
      if (sig[i].size() != static_cast<std::size_t>(n)) Rcpp::stop("internal: a signal of the wrong length");
      out[static_cast<R_xlen_t>(i)] = Rcpp::NumericVector(sig[i].begin(), sig[i].end());
    }
  }
  for (gravcal::SignalStatus s : status) {
    switch (s) {
      case gravcal::SignalStatus::ok: break;
      case gravcal::SignalStatus::internal_na: Rcpp::stop("time series contains internal NAs");
      case gravcal::SignalStatus::replacement_length:
        Rcpp::stop("number of items to replace is not a multiple of replacement length");
      case gravcal::SignalStatus::too_short:
        Rcpp::stop("GGIR's zero crossings need at least 2 samples");
    }
  }
  out.names() = metrics;
  return out;
}
