# The README's first command: calibrate the bundled example recording.
library(gravcal)
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
out <- "gravcal-example.png"
grDevices::png(out, width = 1100, height = 500, res = 100)
plot(fit)
invisible(grDevices::dev.off())
cat("\nWhere the recording rested, and each rest window's error before and after",
    "calibration, written to", out, "\n")
