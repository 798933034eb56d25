# The Wald test that two independent fits have the same coefficients: the
# difference d of the coefficients compared, weighed by the sum of their
# covariances, W = d' (V_a + V_b)^-1 d, against chi-squared with as many
# degrees of freedom as coefficients compared (Wald 1943; e.g. Greene,
# Econometric Analysis, Sec. 5.4). Used to merge neighbouring segments of
# one recording (fit_segments()) and to check that a device's recordings
# agree before they are pooled (pool_devices()).
#
# `nm`: the coefficients compared, by default those both fits fitted.
# Returns the p-value: 0 when V_a + V_b cannot be inverted (a difference
# that cannot be weighed is not taken as agreement), NA when there is
# nothing to compare (no common coefficient, or a fit without covariance).
wald_test <- function(a, b, nm = intersect(a$model, b$model)) {
  if (!length(nm) || is.null(a$vcov) || is.null(b$vcov)) return(NA_real_)
  d <- stats::coef(a)[nm] - stats::coef(b)[nm]
  V <- a$vcov[nm, nm, drop = FALSE] + b$vcov[nm, nm, drop = FALSE]
  W <- tryCatch(drop(t(d) %*% solve(V, d)), error = function(e) Inf)
  stats::pchisq(W, df = length(nm), lower.tail = FALSE)
}
