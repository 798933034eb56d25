# The C++ API as a downstream package uses it: a program compiled against the
# installed headers (`LinkingTo: gravcal`, here `// [[Rcpp::depends(gravcal)]]`
# with Rcpp::sourceCpp(), which adds the installed package's include folder),
# running the lightweight pipeline in one streaming pass as a device would:
# the segmenter fed in chunks of an odd size, the range rest rule, the bin
# selector offered each rest window as it closes, and the gradient fit in
# double and in Q3.29 fixed point (the paper's forward differences) and in
# Q1.14 with the analytic gradient. The R functions run the same core, so
# their results must be the same to the bit.
#
# Skipped only when there is no C++ compiler; compiled into tempdir() so
# that nothing is left in the package's folders.

has_compiler <- function() {
  cxx <- tryCatch(system2(file.path(R.home("bin"), "R"),
                          c("CMD", "config", "CXX17"), stdout = TRUE,
                          stderr = TRUE),
                  error = function(e) "")
  cxx <- strsplit(trimws(paste(cxx, collapse = " ")), "[[:space:]]+")[[1]]
  length(cxx) > 0 && nzchar(cxx[1]) && nzchar(Sys.which(cxx[1]))
}

downstream_code <- '
// [[Rcpp::plugins(cpp17)]]
// [[Rcpp::depends(gravcal)]]
#include <Rcpp.h>
#include <algorithm>
#include <vector>
#include <gravcal/gravcal.hpp>

// The window table of a stream pushed in chunks of `chunk` samples, with the
// range rest rule, and the rest windows a bin selector kept, offered in
// time order as each window closes.
// [[Rcpp::export]]
Rcpp::List downstream_windows(Rcpp::NumericVector x, Rcpp::NumericVector y,
                              Rcpp::NumericVector z, double samples_per_window,
                              double max_range, int chunk, double min_distance) {
  gravcal::Segmenter seg(samples_per_window, true);
  gravcal::RangeRestRule rule;
  rule.max_range = max_range;
  gravcal::BinConfig bcfg;
  bcfg.min_distance = min_distance;
  gravcal::BinSelector<double, 90> sel(bcfg);
  std::vector<double> mx, my, mz, sx, sy, sz, rx, ry, rz, nrm;
  std::vector<int> n, rest, kept, bin;
  const std::size_t len = x.size();
  for (std::size_t i = 0; i < len; i += chunk) {
    const std::size_t m = std::min<std::size_t>(chunk, len - i);
    seg.push(x.begin() + i, y.begin() + i, z.begin() + i, nullptr, m,
             [&](const gravcal::WindowStats& w) {
               const bool r = gravcal::is_rest(w, rule);
               n.push_back(w.n);
               mx.push_back(w.mean[0]); my.push_back(w.mean[1]); mz.push_back(w.mean[2]);
               sx.push_back(w.sd[0]); sy.push_back(w.sd[1]); sz.push_back(w.sd[2]);
               rx.push_back(w.max[0] - w.min[0]);
               ry.push_back(w.max[1] - w.min[1]);
               rz.push_back(w.max[2] - w.min[2]);
               nrm.push_back(w.mean_norm);
               rest.push_back(r);
               if (r && !sel.full()) {
                 const int b = sel.offer(gravcal::Vec3<double>{w.mean[0], w.mean[1], w.mean[2]});
                 if (b >= 0) {
                   kept.push_back(static_cast<int>(w.index) + 1);
                   bin.push_back(b + 1);
                 }
               }
             });
  }
  Rcpp::IntegerVector counts(9);
  for (int b = 0; b < 9; ++b) counts[b] = sel.count(b);
  Rcpp::DataFrame w = Rcpp::DataFrame::create(
      Rcpp::Named("n") = Rcpp::wrap(n),
      Rcpp::Named("mean_x") = Rcpp::wrap(mx), Rcpp::Named("mean_y") = Rcpp::wrap(my),
      Rcpp::Named("mean_z") = Rcpp::wrap(mz), Rcpp::Named("sd_x") = Rcpp::wrap(sx),
      Rcpp::Named("sd_y") = Rcpp::wrap(sy), Rcpp::Named("sd_z") = Rcpp::wrap(sz),
      Rcpp::Named("range_x") = Rcpp::wrap(rx), Rcpp::Named("range_y") = Rcpp::wrap(ry),
      Rcpp::Named("range_z") = Rcpp::wrap(rz), Rcpp::Named("mean_norm") = Rcpp::wrap(nrm),
      Rcpp::Named("rest") = Rcpp::LogicalVector(rest.begin(), rest.end()));
  return Rcpp::List::create(
      Rcpp::Named("windows") = w,
      Rcpp::Named("dropped_tail") = static_cast<double>(seg.pending()),
      Rcpp::Named("kept") = Rcpp::wrap(kept), Rcpp::Named("bin") = Rcpp::wrap(bin),
      Rcpp::Named("counts") = counts, Rcpp::Named("complete") = sel.complete());
}

template <typename T>
Rcpp::List fit_in(const Rcpp::NumericVector& x, const Rcpp::NumericVector& y,
                  const Rcpp::NumericVector& z, int max_iter, double h,
                  bool analytic) {
  const int n = x.size();
  std::vector<T> xs(n), ys(n), zs(n);
  for (int i = 0; i < n; ++i) { xs[i] = T(x[i]); ys[i] = T(y[i]); zs[i] = T(z[i]); }
  gravcal::GradientConfig<T> cfg;   // the paper\'s rates, mean objective
  cfg.max_iter = max_iter;
  cfg.h = T(h);
  if (analytic) cfg.gradient = gravcal::GRADIENT_ANALYTIC;
  T p[gravcal::NPARAM];
  gravcal::identity_params(p);
  const gravcal::GradientResult r =
      gravcal::fit_gradient(p, xs.data(), ys.data(), zs.data(), n, cfg);
  Rcpp::NumericVector out(gravcal::NPARAM);
  for (int i = 0; i < gravcal::NPARAM; ++i) out[i] = static_cast<double>(p[i]);
  return Rcpp::List::create(Rcpp::Named("p") = out,
                            Rcpp::Named("iterations") = r.iterations,
                            Rcpp::Named("finite") = r.finite);
}

// [[Rcpp::export]]
Rcpp::List downstream_fit(Rcpp::NumericVector x, Rcpp::NumericVector y,
                          Rcpp::NumericVector z, std::string arithmetic,
                          int max_iter, double h, bool analytic = false) {
  if (arithmetic == "fixed32")
    return fit_in<gravcal::fixed32>(x, y, z, max_iter, h, analytic);
  if (arithmetic == "fixed16")
    return fit_in<gravcal::fixed16>(x, y, z, max_iter, h, analytic);
  return fit_in<double>(x, y, z, max_iter, h, analytic);
}
'

test_that("a program built against the installed headers gives the R functions' results to the bit", {
  skip_if_quick()
  skip_if_not(has_compiler(), "no C++ compiler (R CMD config CXX17)")
  # the headers as installed, where LinkingTo and Rcpp::depends look
  inc <- system.file("include", "gravcal", "gravcal.hpp", package = "gravcal")
  expect_true(nzchar(inc) && file.exists(inc))

  cache <- file.path(tempdir(), "gravcal-downstream")
  dir.create(cache, showWarnings = FALSE)
  env <- new.env()
  Rcpp::sourceCpp(code = downstream_code, env = env, cacheDir = cache,
                  rebuild = TRUE, showOutput = FALSE, verbose = FALSE)
  on.exit(unlink(cache, recursive = TRUE), add = TRUE)

  # 30 hours of a sensor with scale, misalignment and offset errors; the
  # last window is incomplete (dropped by both)
  rec <- simulate_recording(hours = 30, sf = 10, seed = 19,
                            params = c(1.03, 0.97, 1.02, 0.01, -0.02, 0.015,
                                       0.04, -0.03, 0.02))
  rec <- rec[seq_len(nrow(rec) - 23), ]

  # the segmenter and the rest rule: pushed in chunks of 4099 samples (not
  # a multiple of the 50-sample window), against R's chunks of 1e6
  w_r <- rest_windows(rec, sf = 10)
  d <- env$downstream_windows(rec$x, rec$y, rec$z, 5 * 10, 0.12, 4099L, 0.3)
  w_c <- d$windows
  expect_gt(nrow(w_r), 20000)
  expect_gt(sum(w_r$rest), 100)
  expect_identical(nrow(w_c), nrow(w_r))
  cols <- names(w_c)
  expect_identical(w_c, w_r[, cols])
  expect_identical(d$dropped_tail, attr(w_r, "dropped_tail"))

  # the bin selector, offered rest windows as they close
  pts <- select_points(w_r, min_distance = 0.3)
  expect_true(attr(pts, "complete"))
  expect_true(d$complete)
  expect_identical(d$kept, pts$row)
  expect_identical(bin_names()[d$bin], as.character(pts$bin))
  expect_identical(d$counts, unname(attr(pts, "counts")))

  # the gradient fit: double and Q3.29 fixed point
  f_r <- fit_gradient(pts)
  f_c <- env$downstream_fit(pts$mean_x, pts$mean_y, pts$mean_z, "double", 50L, 1e-5)
  expect_identical(f_r$status, "ok")
  expect_true(f_c$finite)
  expect_identical(f_c$iterations, f_r$iterations)
  expect_identical(f_c$p, unname(f_r$params))
  # the fit moved: a comparison of two identity fits would prove nothing
  expect_gt(max(abs(f_c$p - c(1, 1, 1, 0, 0, 0, 0, 0, 0))), 0.01)

  f_r32 <- fit_gradient(pts, arithmetic = "fixed32", max_iter = 40)
  f_c32 <- env$downstream_fit(pts$mean_x, pts$mean_y, pts$mean_z, "fixed32", 40L, 1e-5)
  expect_identical(f_r32$status, "ok")
  expect_identical(f_c32$p, unname(f_r32$params))
  expect_false(identical(f_c32$p, f_c$p))

  # Q1.14 with the analytic gradient
  f_r16 <- fit_gradient(pts, arithmetic = "fixed16", difference = "analytic")
  f_c16 <- env$downstream_fit(pts$mean_x, pts$mean_y, pts$mean_z, "fixed16",
                              50L, 0.01, TRUE)
  expect_identical(f_r16$status, "ok")
  expect_identical(f_c16$p, unname(f_r16$params))
  expect_lt(max(abs(f_c16$p - f_c$p)), 0.002)
})
