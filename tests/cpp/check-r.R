# R's fit_gradient() against the standalone build of the same core
# (fit_points), bit for bit, in every arithmetic and for every gradient
# (forward, central, analytic; the analytic one also with the square root in
# the objective): the same points go to both, as hexadecimal floating point,
# and the nine parameters must print the same.
#   Rscript check-r.R ./fit_points        (make -C tests/cpp check-r)
#   Rscript check-r.R ./fit_points CASES EXPECTED
#                                         also keeps the cases (the input of
#                                         fit_points) and R's results, one
#                                         line per fit (make check-m4)
suppressPackageStartupMessages(library(gravcal))
args <- commandArgs(TRUE)
prog <- args[1]
set.seed(20241)
cases <- list()
for (arith in c("double", "float", "fixed32", "fixed16")) {
  for (difference in c("forward", "central", "analytic")) {
    for (k in 1:10) {
      cand <- simulate_points(600, noise = c(0.001, 0.005)[k %% 2 + 1])
      pts <- select_points(cand)
      max_iter <- c(50L, 300L)[k %% 2 + 1]
      use_sqrt <- difference == "analytic" && k > 6
      fit <- fit_gradient(pts, arithmetic = arith, difference = difference,
                          max_iter = max_iter, use_sqrt = use_sqrt)
      cases[[length(cases) + 1]] <- list(
        head = sprintf("%s %s %d %s %d %d", arith, difference, max_iter,
                       sprintf("%a", fit$settings$h), nrow(pts), use_sqrt),
        pts = sprintf("%a %a %a", pts$mean_x, pts$mean_y, pts$mean_z),
        r = paste(sprintf("%a", unname(fit$params)), collapse = " "))
    }
  }
}
input <- if (length(args) >= 3) args[2] else tempfile()
writeLines(unlist(lapply(cases, function(k) c(k$head, k$pts))), input)
out <- system2(prog, stdin = input, stdout = TRUE)
r <- vapply(cases, `[[`, "", "r")
if (length(args) >= 3) writeLines(r, args[3])
same <- length(out) == length(r) && all(out == r)
cat(sprintf("R vs standalone core: %d of %d fits identical to the bit\n",
            sum(out == r[seq_along(out)]), length(r)))
if (!same) {
  bad <- which(out != r[seq_along(out)])[1]
  cat("first difference, case", bad, ":", cases[[bad]]$head, "\n R:   ", r[bad],
      "\n core:", out[bad], "\n")
  quit(status = 1)
}
