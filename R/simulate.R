#' Draw random sensor errors as in Farago et al. (2024)
#'
#' Sensitivities `S` uniform in (0.9, 1.1), non-orthogonalities `T` in
#' (-0.05, 0.05) and offsets `O` in (-0.1, 0.1) g (paper Eq. 17), combined
#' into the nine parameters `k_xx = S_x`, `k_yy = S_y`, `k_zz = S_z`,
#' `k_xy = S_y T_xy`, `k_xz = S_z T_xz`, `k_yz = S_z T_yz`, `o = O` (Eq. 18).
#' Uses R's random number generator, so `set.seed()` reproduces the draw.
#' @param scale,misalignment,offset Half-widths of the uniform ranges.
#' @return A named vector of the nine parameters ([param_names()]).
#' @export
#' @examples
#' set.seed(1)
#' random_params()
random_params <- function(scale = 0.1, misalignment = 0.05, offset = 0.1) {
  # scales 1 +- scale must stay positive
  check_number(scale, "scale", min = 0, max = 1, max_inclusive = FALSE)
  check_number(misalignment, "misalignment", min = 0, max = 1)
  check_number(offset, "offset", min = 0)
  u <- function(n, half) 2 * (stats::runif(n) - 0.5) * half
  S <- 1 + u(3, scale)
  Tm <- u(3, misalignment)
  O <- u(3, offset)
  stats::setNames(c(S, S[2] * Tm[1], S[3] * Tm[2], S[3] * Tm[3], O),
                  param_names())
}

#' Distort true acceleration vectors by the 9-parameter model
#'
#' The inverse of calibration: the measurement `v = K^-1 a - o` that a sensor
#' with parameters `params` gives for the true vector `a`. This is the exact
#' inverse of the model; the paper's Eq. 19 has sign slips in its second and
#' third lines.
#' @param a An n x 3 matrix of true vectors (g).
#' @param params The nine parameters ([param_names()] order).
#' @return An n x 3 matrix of measured vectors.
#' @export
#' @examples
#' p <- c(1.05, 0.97, 1.02, 0.01, -0.02, 0.03, 0.05, -0.03, 0.02)
#' v <- distort(diag(3), p)
#' v
distort <- function(a, params) {
  if (is.data.frame(a)) a <- as.matrix(a)
  if (is.numeric(a) && is.null(dim(a)) && length(a) == 3) a <- matrix(a, 1)
  if (!is.matrix(a) || !is.numeric(a) || ncol(a) != 3) {
    abort("`a` must be a numeric matrix with 3 columns (x, y, z in g), not ",
          if (is.matrix(a)) sprintf("a %s matrix with %d columns",
                                    mode(a), ncol(a)) else describe(a), ".")
  }
  if (!all(is.finite(a))) {
    abort("`a` must hold finite numbers; it has ", sum(!is.finite(a)),
          " NA, NaN or Inf.")
  }
  check_params(params)
  a <- matrix(as.double(a), ncol = 3)
  p <- unname(params)
  ux <- a[, 1] / p[1]
  uy <- (a[, 2] - p[4] * ux) / p[2]
  uz <- (a[, 3] - p[5] * ux - p[6] * uy) / p[3]
  cbind(ux - p[7], uy - p[8], uz - p[9])
}

#' Simulate calibration points as in Farago et al. (2024)
#'
#' The paper's simulation (Sec. III-A, Eq. 17-20): random unit vectors
#' (uniform on the sphere), distorted by the inverse model with parameters
#' drawn by [random_params()] (or given), plus Gaussian noise of standard
#' deviation `noise` on each axis. The result is the candidate stream that
#' [select_points()] picks from.
#'
#' @param n Number of candidate points.
#' @param noise Noise standard deviation in g (paper: 0.001 and 0.005).
#' @param params The true parameters; drawn by [random_params()] when NULL.
#' @return A data frame with columns `mean_x`, `mean_y`, `mean_z` and
#'   attributes `params` (the truth) and `noise`.
#' @export
#' @examples
#' set.seed(2)
#' cand <- simulate_points(300, noise = 0.005)
#' fit <- fit_gradient(select_points(cand))
#' round(fit$params - attr(cand, "params"), 4)
simulate_points <- function(n = 1000, noise = 0.001, params = NULL) {
  check_number(n, "n", min = 1, max = 1e8, integer = TRUE)
  check_number(noise, "noise", min = 0)
  if (is.null(params)) params <- random_params()
  check_params(params)
  a <- random_unit_vectors(n)
  v <- distort(a, params) + matrix(stats::rnorm(3 * n, sd = noise), ncol = 3)
  out <- data.frame(mean_x = v[, 1], mean_y = v[, 2], mean_z = v[, 3])
  attr(out, "params") <- stats::setNames(unname(params), param_names())
  attr(out, "noise") <- noise
  out
}

random_unit_vectors <- function(n) {
  g <- matrix(stats::rnorm(3 * n), ncol = 3)
  g / sqrt(rowSums(g^2))
}

check_params <- function(params) {
  if (is.numeric(params) && length(params) == 9 && all(is.finite(params)) &&
      any(params[1:3] <= 0)) {
    abort("`params` must have positive scales (k_xx, k_yy, k_zz), not ",
          paste(unname(params[1:3]), collapse = ", "), ".")
  }
  if (!is.numeric(params) || length(params) != 9 || !all(is.finite(params))) {
    abort("`params` must be 9 finite numbers (", paste(param_names(),
          collapse = ", "), "), not ", describe(params), ".")
  }
}

#' Simulate a raw accelerometer recording with known calibration errors
#'
#' A wrist-worn-like recording: bouts of rest in varied postures (long ones at
#' night, short ones by day) alternate with bouts of movement, in which the
#' device turns between postures while shaking at 1-3 Hz. The true signal is
#' distorted by the 9-parameter model ([distort()]), by a temperature offset
#' when `tempoffset` is non-zero, and by Gaussian noise, then rounded to the
#' sensor's resolution.
#'
#' @param hours Duration in hours.
#' @param sf Sampling frequency in Hz.
#' @param params True parameters of the 9-parameter model; drawn by
#'   [random_params()] when NULL.
#' @param noise Sample noise standard deviation in g.
#' @param resolution Quantisation step in g (0 for none).
#' @param temperature Add a `temperature` column (a daily cycle of +-3
#'   degrees C around 28 plus a slow drift).
#' @param tempoffset Temperature offset per axis in g per degree C, so that
#'   the true acceleration is `K (v + o) + (T - meantemp) * tempoffset`.
#' @param rest_fraction Fraction of daytime spent in rest bouts.
#' @param start Start time (POSIXct).
#' @param seed Optional seed; the caller's RNG state is restored afterwards.
#' @param idle_sleep,stuck Hours of the recording (default 0) replaced by
#'   stretches of samples that are not a sensor at rest, in 30-minute
#'   stretches at random, non-overlapping places (the last stretch may be
#'   shorter): `idle_sleep` repeats the sample before the stretch, as
#'   ActiGraph devices in idle sleep mode do; `stuck` holds a constant vector
#'   that is not gravity: the sample before the stretch moved by a random
#'   0.05-0.2 g on each axis (either sign), as a stuck sensor gives. With
#'   both 0 the recording (and the random numbers drawn) are those without
#'   the arguments.
#' @param vehicle Hours (default 0) of near-rest that is not rest, as in a
#'   vehicle, in one stretch from a random whole half hour that overlaps no
#'   `idle_sleep` or `stuck` stretch: the wearer's arm keeps a posture
#'   (a new one, from the same postures as the recording's rest, every 10
#'   minutes) while the vehicle's accelerations scale the true vector's
#'   norm by 1 + d, d drawn for each 10 s from +-(0.03 to 0.08) (either
#'   sign, uniform in size), and the road's vibration adds Gaussian noise
#'   of sd 5 mg on each axis: every 10 s window passes the rest rules of
#'   both methods (low sd, small range, norm well within 0.3 g of 1 g) but
#'   its norm is 30-80 mg off 1 g. The stretch goes through the same sensor
#'   (distortion, temperature offset, noise, resolution) as the rest of the
#'   recording, and its random numbers are drawn after all others, so
#'   outside the stretch the recording is the one without `vehicle`.
#' @return A data frame with columns `time`, `x`, `y`, `z` and (optionally)
#'   `temperature`, and an attribute `truth`: a list with `params`, `K`,
#'   `offset`, `tempoffset`, `meantemp` and `sf`, and, with `idle_sleep`,
#'   `stuck` or `vehicle`, `contaminated`: a data frame of the stretches
#'   (`kind`, `from`, `to`: sample numbers).
#' @export
#' @examples
#' rec <- simulate_recording(hours = 1, sf = 10, seed = 1)
#' str(rec)
#' attr(rec, "truth")$params
simulate_recording <- function(hours = 72, sf = 30, params = NULL,
                               noise = 0.003, resolution = 1 / 256,
                               temperature = TRUE,
                               tempoffset = c(0, 0, 0), rest_fraction = 0.4,
                               start = as.POSIXct("2024-01-01 00:00:00",
                                                  tz = "UTC"),
                               seed = NULL, idle_sleep = 0, stuck = 0,
                               vehicle = 0) {
  check_number(hours, "hours", min = 0, min_inclusive = FALSE)
  check_number(idle_sleep, "idle_sleep", min = 0)
  check_number(stuck, "stuck", min = 0)
  check_number(vehicle, "vehicle", min = 0)
  if (idle_sleep + stuck + vehicle > hours) {
    abort("`idle_sleep` + `stuck` + `vehicle` must be at most `hours` (",
          format(hours), "), not ", format(idle_sleep + stuck + vehicle), ".")
  }
  check_sf(sf)
  check_number(noise, "noise", min = 0)
  check_number(resolution, "resolution", min = 0)
  check_flag(temperature, "temperature")
  check_number(rest_fraction, "rest_fraction", min = 0, max = 1)
  if (!is.numeric(tempoffset) || length(tempoffset) != 3 ||
      !all(is.finite(tempoffset))) {
    abort("`tempoffset` must be 3 finite numbers (g per degree C), not ",
          describe(tempoffset), ".")
  }
  if (any(tempoffset != 0) && !temperature) {
    abort("`tempoffset` needs `temperature = TRUE`.")
  }
  if (!(inherits(start, "POSIXct") && length(start) == 1 && !is.na(start))) {
    abort("`start` must be one date-time (POSIXct), not ", describe(start),
          ".")
  }
  if (hours * 3600 * sf > 2^31 - 1) {
    abort("`hours` * 3600 * `sf` must be at most 2^31 - 1 samples, not ",
          format(hours * 3600 * sf), " (hours = ", format(hours), ", sf = ",
          format(sf), " Hz).")
  }
  if (!is.null(seed)) {
    check_number(seed, "seed", integer = TRUE)
    old <- if (exists(".Random.seed", envir = globalenv())) {
      get(".Random.seed", envir = globalenv())
    }
    on.exit({
      if (is.null(old)) rm(".Random.seed", envir = globalenv())
      else assign(".Random.seed", old, envir = globalenv())
    }, add = TRUE)
    set.seed(seed)
  }
  if (is.null(params)) params <- random_params()
  check_params(params)
  n <- as.integer(round(hours * 3600 * sf))
  tsec <- (seq_len(n) - 1) / sf

  # Bouts: rest (a posture) and movement (turning to the next posture).
  postures <- simulated_postures(200)
  bouts <- simulate_bouts(hours * 3600, rest_fraction)
  nb <- nrow(bouts)
  pidx <- sample.int(nrow(postures), nb + 1, replace = TRUE,
                     prob = attr(postures, "prob"))
  # each rest bout holds the posture of its index; movement goes from the
  # previous rest posture to the next one
  edges <- c(0, cumsum(bouts$duration))
  bout_of <- findInterval(tsec, edges, rightmost.closed = TRUE)
  bout_of[bout_of > nb] <- nb
  from <- postures[pidx[bout_of], , drop = FALSE]
  to <- postures[pidx[bout_of + 1], , drop = FALSE]
  frac <- (tsec - edges[bout_of]) / bouts$duration[bout_of]
  moving <- !bouts$rest[bout_of]
  g <- from
  if (any(moving)) {
    w <- frac[moving]
    g[moving, ] <- from[moving, ] * (1 - w) + to[moving, ] * w
    g[moving, ] <- g[moving, ] / sqrt(rowSums(g[moving, , drop = FALSE]^2))
  }
  a <- g
  if (any(moving)) {
    f <- bouts$freq[bout_of[moving]]
    amp <- bouts$amp[bout_of[moving]]
    tm <- tsec[moving]
    a[moving, 1] <- a[moving, 1] + amp * sin(2 * pi * f * tm)
    a[moving, 2] <- a[moving, 2] + 0.7 * amp * sin(2 * pi * f * tm + 1)
    a[moving, 3] <- a[moving, 3] + 0.5 * amp * sin(2 * pi * 1.3 * f * tm + 2)
  }
  temp <- NULL
  meantemp <- NA_real_
  if (temperature) {
    temp <- 28 + 3 * sin(2 * pi * (tsec / 86400 - 0.3)) +
      0.5 * tsec / max(tsec[n], 1)
    meantemp <- mean(temp)
    if (any(tempoffset != 0)) {
      a <- a - outer(temp - meantemp, tempoffset)
    }
  }
  v <- distort(a, params) + matrix(stats::rnorm(3 * n, sd = noise), ncol = 3)
  if (resolution > 0) v <- round(v / resolution) * resolution
  bad <- NULL
  if (idle_sleep + stuck > 0) {
    cont <- contaminate(v, sf, idle_sleep, stuck)
    v <- cont$v
    bad <- cont$stretches
  }
  out <- data.frame(time = start + tsec, x = v[, 1], y = v[, 2], z = v[, 3])
  if (temperature) out$temperature <- round(temp, 2)
  attr(out, "truth") <- list(
    params = stats::setNames(unname(params), param_names()),
    K = params_to_K(params), offset = unname(params[7:9]),
    tempoffset = tempoffset, meantemp = meantemp, sf = sf)
  if (vehicle > 0) {
    veh <- vehicle_stretch(n, sf, vehicle, bad, postures, params, temp,
                           meantemp, tempoffset, noise, resolution)
    out[veh$rows, c("x", "y", "z")] <- veh$v
    bad <- rbind(bad, data.frame(kind = "vehicle", from = veh$rows[1],
                                 to = veh$rows[length(veh$rows)],
                                 stringsAsFactors = FALSE))
  }
  if (!is.null(bad)) attr(out, "truth")$contaminated <- bad
  out
}

# Vehicle-like near-rest (simulate_recording()'s `vehicle`): the rows of one
# stretch of `hours` from a whole half hour clear of the stretches `bad`,
# and its measured samples v (through the sensor: params, temperature
# offset, noise, resolution). Per 10 minutes a posture of `postures`, per
# 10 s a norm of 1 + d (|d| in 0.03-0.08, either sign), 5 mg of vibration.
vehicle_stretch <- function(n, sf, hours, bad, postures, params, temp,
                            meantemp, tempoffset, noise, resolution) {
  len <- as.integer(round(hours * 3600 * sf))
  slot <- max(1L, as.integer(round(1800 * sf)))
  starts <- seq(0L, n - len, by = slot)
  if (!is.null(bad) && nrow(bad)) {
    clear <- vapply(starts, function(s) {
      all(bad$to < s + 1L | bad$from > s + len)
    }, TRUE)
    starts <- starts[clear]
  }
  if (!length(starts) || len < 1) {
    abort("`vehicle` (", format(hours), " h) finds no whole half hour to ",
          "start from that leaves it clear of the other stretches.")
  }
  at <- starts[sample.int(length(starts), 1)]
  rows <- at + seq_len(len)
  ts <- (seq_len(len) - 1) / sf
  piece <- floor(ts / 600) + 1
  pidx <- sample.int(nrow(postures), max(piece), replace = TRUE,
                     prob = attr(postures, "prob"))
  tick <- floor(ts / 10) + 1
  d <- sample(c(-1, 1), max(tick), replace = TRUE) *
    stats::runif(max(tick), 0.03, 0.08)
  a <- postures[pidx[piece], , drop = FALSE] * (1 + d[tick]) +
    matrix(stats::rnorm(3 * len, sd = 0.005), ncol = 3)
  if (!is.null(temp) && any(tempoffset != 0)) {
    a <- a - outer(temp[rows] - meantemp, tempoffset)
  }
  v <- distort(a, params) + matrix(stats::rnorm(3 * len, sd = noise), ncol = 3)
  if (resolution > 0) v <- round(v / resolution) * resolution
  list(rows = rows, v = v)
}

# Samples v (n x 3) with `idle_sleep` and `stuck` hours replaced by
# 30-minute stretches (see simulate_recording()) at random 30-minute slots;
# list(v, stretches).
contaminate <- function(v, sf, idle_sleep, stuck) {
  n <- nrow(v)
  slot <- max(1L, as.integer(round(1800 * sf)))
  slots <- n %/% slot
  len <- function(h) {
    k <- as.integer(round(h * 3600 * sf))
    if (k == 0) return(integer(0))
    c(rep(slot, k %/% slot), if (k %% slot) k %% slot)
  }
  lens <- c(len(idle_sleep), len(stuck))
  kind <- rep(c("idle_sleep", "stuck"), c(length(len(idle_sleep)),
                                          length(len(stuck))))
  if (length(lens) > slots) {
    abort("`idle_sleep` + `stuck` need ", length(lens), " 30-minute ",
          "stretches, more than the recording's ", slots, ".")
  }
  at <- sample.int(slots, length(lens)) - 1L
  from <- at * slot + 2L  # keep a sample before each stretch
  to <- pmin(from + lens - 1L, n)
  for (i in seq_along(lens)) {
    val <- v[from[i] - 1L, ]
    if (kind[i] == "stuck") {
      val <- val + sample(c(-1, 1), 3, replace = TRUE) *
        stats::runif(3, 0.05, 0.2)
    }
    v[from[i]:to[i], ] <- rep(val, each = to[i] - from[i] + 1L)
  }
  list(v = v, stretches = data.frame(kind = kind, from = from, to = to,
                                     stringsAsFactors = FALSE))
}

# Unit vectors of typical postures (lying, sitting, arm hanging, ...) with
# uneven weights, plus random ones so that every side of the sphere is seen.
simulated_postures <- function(n_random) {
  base <- rbind(c(0, 0, 1), c(0, 0, -1), c(1, 0, 0), c(-1, 0, 0),
                c(0, 1, 0), c(0, -1, 0), c(0.7, 0, 0.7), c(0, -0.7, 0.7),
                c(-0.6, 0.6, 0.5))
  tilt <- base + matrix(stats::rnorm(length(base), sd = 0.08), ncol = 3)
  rnd <- random_unit_vectors(n_random)
  p <- rbind(tilt, rnd)
  p <- p / sqrt(rowSums(p^2))
  attr(p, "prob") <- c(rep(3, nrow(tilt)), rep(1, n_random))
  p
}

# Alternating rest / movement bouts covering `total` seconds.
simulate_bouts <- function(total, rest_fraction) {
  est <- ceiling(total / 60) + 10
  rest <- rep(c(TRUE, FALSE), length.out = est)
  dur <- ifelse(rest, stats::rexp(est, 1 / (120 * rest_fraction + 1)) + 20,
                stats::rexp(est, 1 / (120 * (1 - rest_fraction) + 1)) + 10)
  keep <- cumsum(dur) - dur < total
  dur <- dur[keep]
  rest <- rest[keep]
  dur[length(dur)] <- total - sum(dur[-length(dur)])
  data.frame(rest = rest, duration = dur,
             freq = stats::runif(length(dur), 1, 3),
             amp = stats::runif(length(dur), 0.1, 0.6))
}
