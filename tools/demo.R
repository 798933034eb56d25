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

# GGIR part 1's calibrated epoch signals of the same recording, with the fit
ep <- epoch_signals(rec$data, fit)
cat("\n")
print(ep)
out2 <- "gravcal-example-epochs.png"
grDevices::png(out2, width = 1100, height = 500, res = 100)
plot(ep)
invisible(grDevices::dev.off())
cat("\nThe calibrated epoch signals (ENMO and anglez in 5-s epochs, as GGIR part 1 gives them),",
    "written to", out2, "\n")
