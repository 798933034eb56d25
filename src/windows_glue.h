// The window table and the segmenter box the glue files share: the windows
// the core completes, collected into vectors for R, and a segmenter with the
// buffer it borrows in R-compatible arithmetic.
#ifndef GRAVCAL_GLUE_WINDOWS_H
#define GRAVCAL_GLUE_WINDOWS_H

#include <Rcpp.h>

#include <cmath>
#include <vector>

#include "gravcal/gravcal.hpp"
#include "gravcal/host/segmenter.hpp"
#include "gravcal/ggir/ggir_blocks.hpp"
#include "r_services.h"

namespace gravcal_glue {

struct WindowTable {
  std::vector<double> start, mean[3], sd[3], min[3], max[3], norm, temp;
  std::vector<int> n, n_invalid;
  std::vector<double> n_repeat;
  std::vector<double> index;
  std::vector<int> rest;

  // room for about `windows` windows, so that the vectors are allocated
  // once rather than grown
  void reserve(std::size_t windows) {
    start.reserve(windows);
    for (int a = 0; a < 3; ++a) {
      mean[a].reserve(windows);
      sd[a].reserve(windows);
      min[a].reserve(windows);
      max[a].reserve(windows);
    }
    norm.reserve(windows);
    temp.reserve(windows);
    n.reserve(windows);
    n_invalid.reserve(windows);
    n_repeat.reserve(windows);
    index.reserve(windows);
    rest.reserve(windows);
  }

  void add(const gravcal::WindowStats& s, bool is_rest) {
    index.push_back(static_cast<double>(s.index));
    start.push_back(static_cast<double>(s.first));
    n.push_back(s.n);
    n_invalid.push_back(s.n_invalid);
    n_repeat.push_back(static_cast<double>(s.n_repeat));
    for (int a = 0; a < 3; ++a) {
      mean[a].push_back(s.mean[a]);
      sd[a].push_back(s.sd[a]);
      min[a].push_back(s.min[a]);
      max[a].push_back(s.max[a]);
    }
    norm.push_back(s.mean_norm);
    temp.push_back(s.temperature);
    rest.push_back(is_rest ? 1 : 0);
  }

  Rcpp::List to_list() const {
    Rcpp::LogicalVector r(rest.begin(), rest.end());
    return Rcpp::List::create(
        Rcpp::Named("window") = Rcpp::wrap(index),
        Rcpp::Named("first") = Rcpp::wrap(start),
        Rcpp::Named("n") = Rcpp::wrap(n),
        Rcpp::Named("n_invalid") = Rcpp::wrap(n_invalid),
        Rcpp::Named("mean_x") = Rcpp::wrap(mean[0]),
        Rcpp::Named("mean_y") = Rcpp::wrap(mean[1]),
        Rcpp::Named("mean_z") = Rcpp::wrap(mean[2]),
        Rcpp::Named("sd_x") = Rcpp::wrap(sd[0]),
        Rcpp::Named("sd_y") = Rcpp::wrap(sd[1]),
        Rcpp::Named("sd_z") = Rcpp::wrap(sd[2]),
        Rcpp::Named("min_x") = Rcpp::wrap(min[0]),
        Rcpp::Named("min_y") = Rcpp::wrap(min[1]),
        Rcpp::Named("min_z") = Rcpp::wrap(min[2]),
        Rcpp::Named("max_x") = Rcpp::wrap(max[0]),
        Rcpp::Named("max_y") = Rcpp::wrap(max[1]),
        Rcpp::Named("max_z") = Rcpp::wrap(max[2]),
        Rcpp::Named("mean_norm") = Rcpp::wrap(norm),
        Rcpp::Named("temperature") = Rcpp::wrap(temp),
        Rcpp::Named("n_repeat") = Rcpp::wrap(n_repeat),
        Rcpp::Named("rest") = r);
  }
};

// A segmenter together with the window buffer it borrows in R-compatible
// arithmetic (the core allocates nothing itself).
struct SegmenterBox {
  SegmenterBox(double samples_per_window, bool skip_zero, bool r_arithmetic)
      : seg(samples_per_window, skip_zero) {
    if (r_arithmetic) {
      buffer.assign(3 * (static_cast<std::size_t>(std::ceil(samples_per_window)) + 1), 0.0);
      if (!seg.use_r_arithmetic(buffer.data(), buffer.size(), r_long_double()))
        Rcpp::stop("could not set up the window buffer");
    }
  }
  std::vector<double> buffer;
  gravcal::Segmenter seg;
};


// The rest rule chosen from R: 0 = range rule (lightweight; par = max_range,
// axes mask), 1 = sd rule (GGIR; par = max_sd, max_abs_mean).
struct RestRule {
  RestRule(int rule, const Rcpp::NumericVector& par) : which(rule) {
    if (par.size() < 2) Rcpp::stop("par must have 2 values");
    range.max_range = par[0];
    range.axes = static_cast<unsigned>(par[1]);
    sd.max_sd = par[0];
    sd.max_abs_mean = par[1];
  }
  bool operator()(const gravcal::WindowStats& w) const {
    return which == 0 ? gravcal::is_rest(w, range) : gravcal::is_rest(w, sd);
  }
  int which;
  gravcal::RangeRestRule range;
  gravcal::SdRestRule sd;
};

// A block's result for R: the windows and what the block rules saw.
inline Rcpp::List block_result(const WindowTable& table, const gravcal::GgirBlockInfo& b) {
  return Rcpp::List::create(
      Rcpp::Named("windows") = table.to_list(),
      Rcpp::Named("rows") = static_cast<double>(b.rows),
      Rcpp::Named("zeros") = static_cast<double>(b.zeros),
      Rcpp::Named("ld") = static_cast<double>(b.ld),
      Rcpp::Named("used") = static_cast<double>(b.used),
      Rcpp::Named("carried") = static_cast<double>(b.carried),
      Rcpp::Named("first_mean") = b.first_mean,
      Rcpp::Named("temp_sd") = b.temp_sd,
      Rcpp::Named("temp_sd_exact") = b.temp_sd_exact);
}

}  // namespace gravcal_glue

#endif
