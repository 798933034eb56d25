// Rcpp glue for GGIR part 1's epoch signals of one block (ggir_epochs.hpp).
// Converts and checks shapes only.
#include "gravcal/fp_contract.hpp"  // first: see there

#include <Rcpp.h>

#include <string>
#include <vector>

#include "gravcal/ggir_epochs.hpp"
#include "r_services.h"

namespace {

const double* column_or_null(const Rcpp::Nullable<Rcpp::NumericVector>& v, R_xlen_t n,
                             Rcpp::NumericVector& keep, const char* what) {
  if (v.isNull()) return nullptr;
  keep = Rcpp::NumericVector(v.get());
  if (keep.size() < n) Rcpp::stop("%s is shorter than the samples used", what);
  return keep.begin();
}

Rcpp::NumericVector as_r(const std::vector<double>& v) {
  return Rcpp::NumericVector(v.begin(), v.end());
}

}  // namespace

// One block of g.getmeta(): x, y, z (raw, g), temperature and light (or
// NULL), the calibration (list: offset, inv_scale, and when the
// temperature term applies meantemp, inv_tempoffset), sf, windowsizes
// (ws3, ws2, ws), the short-epoch metric names (ggir_epochs.hpp
// short_metrics()), non-wear settings (list: clipthres, sdcriter,
// racriter, approach "2013"/"2023"), the filters (ggir_filter_coefs() or
// NULL) and whether R's stats::filter() fuses, and n_use: how many of the
// columns' first samples form the block. Returns list(short = named list of
// epoch means, nonwear, clipping, epochs, en, temperature, lightmean,
// lightpeak), unrounded.
// [[Rcpp::export(rng = false)]]
Rcpp::List gc_ggir_block_epochs(const Rcpp::NumericVector& x, const Rcpp::NumericVector& y,
                                const Rcpp::NumericVector& z,
                                Rcpp::Nullable<Rcpp::NumericVector> temperature,
                                Rcpp::Nullable<Rcpp::NumericVector> light,
                                const Rcpp::List& cal, double sf,
                                const Rcpp::NumericVector& windowsizes,
                                const Rcpp::CharacterVector& metrics,
                                const Rcpp::List& nonwear,
                                Rcpp::Nullable<Rcpp::List> filters, bool conv_fused,
                                bool rec_fused, double n_use) {
  namespace p1 = gravcal::ggir_part1;
  const R_xlen_t len = x.size();
  if (y.size() != len || z.size() != len) Rcpp::stop("x, y, z lengths differ");
  // the block's first n_use samples (GGIR's data[1:use, ]), without a copy in R
  if (!(n_use >= 0) || n_use > static_cast<double>(len)) Rcpp::stop("n_use out of range");
  const R_xlen_t n = static_cast<R_xlen_t>(n_use);
  if (windowsizes.size() != 3) Rcpp::stop("windowsizes must have 3 values");
  if (!(sf > 0)) Rcpp::stop("sf must be positive");
  Rcpp::NumericVector tk, lk;
  const double* t = column_or_null(temperature, n, tk, "temperature");
  const double* li = column_or_null(light, n, lk, "light");
  p1::Calibration c;
  const Rcpp::NumericVector off = cal["offset"], isc = cal["inv_scale"];
  if (off.size() != 3 || isc.size() != 3) Rcpp::stop("offset and inv_scale need 3 values");
  for (int a = 0; a < 3; ++a) {
    c.offset[a] = off[a];
    c.inv_scale[a] = isc[a];
  }
  if (cal.containsElementNamed("meantemp") && t != nullptr) {
    const Rcpp::NumericVector ito = cal["inv_tempoffset"];
    if (ito.size() != 3) Rcpp::stop("inv_tempoffset needs 3 values");
    c.temp = true;
    c.meantemp = Rcpp::as<double>(cal["meantemp"]);
    for (int a = 0; a < 3; ++a) c.inv_tempoffset[a] = ito[a];
  }
  const std::size_t un = static_cast<std::size_t>(n);
  std::vector<double> cx(x.begin(), x.begin() + n), cy(y.begin(), y.begin() + n),
      cz(z.begin(), z.begin() + n);
  p1::apply_calibration(c, cx.data(), cy.data(), cz.data(), t, un);
  std::vector<std::string> names(metrics.size());
  for (R_xlen_t k = 0; k < metrics.size(); ++k) names[static_cast<std::size_t>(k)] = Rcpp::as<std::string>(metrics[k]);
  p1::NonwearConfig nw;
  nw.sf = sf;
  nw.ws2 = windowsizes[1];
  nw.ws = windowsizes[2];
  nw.clipthres = Rcpp::as<double>(nonwear["clipthres"]);
  nw.sdcriter = Rcpp::as<double>(nonwear["sdcriter"]);
  nw.racriter = Rcpp::as<double>(nonwear["racriter"]);
  const std::string appr = Rcpp::as<std::string>(nonwear["approach"]);
  if (appr != "2013" && appr != "2023") Rcpp::stop("nonwear approach must be \"2013\" or \"2023\"");
  nw.approach_2023 = appr == "2023";
  const bool ld = gravcal_glue::r_long_double();
  gravcal::GgirFilterCoefs fc;
  std::vector<Rcpp::NumericVector> keep_coefs;
  const bool have_f = filters.isNotNull();
  if (have_f) {
    const Rcpp::List fl(filters.get());
    auto arma = [&](const char* nm) {
      const Rcpp::List co = fl[nm];
      keep_coefs.push_back(Rcpp::NumericVector(co["b"]));
      keep_coefs.push_back(Rcpp::NumericVector(co["a"]));
      const Rcpp::NumericVector& b = keep_coefs[keep_coefs.size() - 2];
      const Rcpp::NumericVector& a = keep_coefs.back();
      return gravcal::ArmaCoefs{b.begin(), static_cast<std::size_t>(b.size()), a.begin(),
                                static_cast<std::size_t>(a.size())};
    };
    keep_coefs.reserve(8);
    fc.band = arma("band");
    fc.low = arma("low");
    fc.high = arma("high");
    fc.zc = arma("zc");
    fc.zc_sb = Rcpp::as<double>(fl["zc_sb"]);
  }
  gravcal::RFilterArith arith;
  arith.conv_fused = conv_fused;
  arith.rec_fused = rec_fused;
  Rcpp::List shorts(metrics.size());
  Rcpp::List out;
  try {
    gravcal::with_r_acc(ld, [&](auto acc) {
      using Acc = decltype(acc);
      const std::vector<std::vector<double>> s =
          p1::short_metrics<Acc>(cx.data(), cy.data(), cz.data(), un, sf, windowsizes[0], names,
                                have_f ? &fc : nullptr, arith);
      for (std::size_t k = 0; k < s.size(); ++k) shorts[static_cast<R_xlen_t>(k)] = as_r(s[k]);
      shorts.names() = metrics;
      const double* xyz[3] = {cx.data(), cy.data(), cz.data()};
      const p1::NonwearResult r = p1::nonwear_clipping<Acc>(xyz, un, nw);
      const double M = windowsizes[1] * sf;
      std::vector<double> en(un);
      for (std::size_t i = 0; i < un; ++i) en[i] = p1::r_norm(cx[i], cy[i], cz[i]);
      out = Rcpp::List::create(
          Rcpp::Named("short") = shorts, Rcpp::Named("nonwear") = as_r(r.nonwear),
          Rcpp::Named("clipping") = as_r(r.clipping),
          Rcpp::Named("epochs") = static_cast<double>(r.epochs),
          Rcpp::Named("en") = as_r(p1::per_epoch<Acc>(en.data(), un, M, true)),
          Rcpp::Named("temperature") =
              t ? Rcpp::RObject(as_r(p1::per_epoch<Acc>(t, un, M, true))) : Rcpp::RObject(),
          Rcpp::Named("lightmean") =
              li ? Rcpp::RObject(as_r(p1::per_epoch<Acc>(li, un, M, true))) : Rcpp::RObject(),
          Rcpp::Named("lightpeak") =
              li ? Rcpp::RObject(as_r(p1::light_peaks(li, un, M))) : Rcpp::RObject());
      return 0;
    });
  } catch (const std::exception& e) {
    Rcpp::stop(e.what());
  }
  return out;
}

// The gradient of each short epoch's ENMO with respect to a linear
// calibration's coefficients (ggir_epochs.hpp enmo_gradient()), for one
// block: x, y, z raw (g), temperature (or NULL: no temperature term), n_use
// as above, sf, the short epoch ws3 (s), and the calibration as a list: K
// (3 x 3), offset, and, for the temperature term, tempoffset and meantemp.
// Returns a matrix, one row per short epoch, 12 columns named as coef().
// [[Rcpp::export(rng = false)]]
Rcpp::NumericMatrix gc_enmo_gradient(const Rcpp::NumericVector& x, const Rcpp::NumericVector& y,
                                     const Rcpp::NumericVector& z,
                                     Rcpp::Nullable<Rcpp::NumericVector> temperature,
                                     double n_use, double sf, double ws3, const Rcpp::List& cal) {
  namespace p1 = gravcal::ggir_part1;
  const R_xlen_t len = x.size();
  if (y.size() != len || z.size() != len) Rcpp::stop("x, y, z lengths differ");
  if (!(n_use >= 0) || n_use > static_cast<double>(len)) Rcpp::stop("n_use out of range");
  if (!(sf > 0) || !(ws3 > 0)) Rcpp::stop("sf and ws3 must be positive");
  const R_xlen_t n = static_cast<R_xlen_t>(n_use);
  Rcpp::NumericVector tk;
  const double* t = column_or_null(temperature, n, tk, "temperature");
  p1::LinearCalibration m;
  const Rcpp::NumericMatrix K = cal["K"];
  const Rcpp::NumericVector off = cal["offset"];
  if (K.nrow() != 3 || K.ncol() != 3 || off.size() != 3) Rcpp::stop("K must be 3 x 3, offset 3 values");
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) m.K[r][c] = K(r, c);
    m.offset[r] = off[r];
  }
  if (t != nullptr) {
    const Rcpp::NumericVector to = cal["tempoffset"];
    if (to.size() != 3) Rcpp::stop("tempoffset needs 3 values");
    m.temp = true;
    m.meantemp = Rcpp::as<double>(cal["meantemp"]);
    for (int a = 0; a < 3; ++a) m.tempoffset[a] = to[a];
  }
  std::vector<double> g;
  try {
    g = p1::enmo_gradient(x.begin(), y.begin(), z.begin(), t, static_cast<std::size_t>(n), sf * ws3, m);
  } catch (const std::exception& e) {
    Rcpp::stop(e.what());
  }
  const std::size_t C = p1::kGradientColumns;
  const std::size_t ne = g.size() / C;
  Rcpp::NumericMatrix out(static_cast<int>(ne), static_cast<int>(C));
  for (std::size_t e = 0; e < ne; ++e) {
    for (std::size_t c = 0; c < C; ++c) out(static_cast<int>(e), static_cast<int>(c)) = g[e * C + c];
  }
  Rcpp::colnames(out) = Rcpp::CharacterVector::create("k_xx", "k_yy", "k_zz", "k_xy", "k_xz", "k_yz",
                                                      "o_x", "o_y", "o_z", "t_x", "t_y", "t_z");
  return out;
}
