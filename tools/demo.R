# The README's first command: calibrate the bundled example recording.
library(gravcal)
# a picture of `x` (its plot() method) written to `out`, then what it shows
picture <- function(x, out, what) {
  grDevices::png(out, width = 1100, height = 500, res = 100)
  plot(x)
  invisible(grDevices::dev.off())
  cat("\n", what, ", written to ", out, "\n", sep = "")
}
rec <- read_recording(gravcal_example())
cat(sprintf("Example recording: %d samples at %g Hz (%.1f h)\n\n",
            nrow(rec$data), rec$sf, nrow(rec$data) / rec$sf / 3600))
fit <- calibrate(rec$data, sf = rec$sf)
print(fit)
cat("\n")
print(summary(fit))
truth <- attr(rec$data, "truth")$params
cat("\nTrue parameters of the simulated sensor, and the fit's:\n")
print(round(rbind(truth = truth, fit = fit$params), 5))
picture(fit, "gravcal-example.png",
        "Where the recording rested, and each rest window's error before and after calibration")

# GGIR part 1's calibrated epoch signals of the same recording, with the fit
ep <- epoch_signals(rec$data, fit)
cat("\n")
print(ep)
picture(ep, "gravcal-example-epochs.png",
        "The calibrated epoch signals (ENMO and anglez in 5-s epochs, as GGIR part 1 gives them)")
