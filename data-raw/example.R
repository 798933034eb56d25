# Makes inst/extdata/example.rds, the bundled example recording: 12 hours at
# 10 Hz with temperature, from gravcal's own simulator with random (but
# seeded) calibration errors in the paper's ranges. Run from the package root
# with gravcal installed:  Rscript data-raw/example.R
library(gravcal)
rec <- simulate_recording(hours = 12, sf = 10, noise = 0.003,
                          resolution = 1 / 256, temperature = TRUE,
                          seed = 20240101)
attr(rec, "sf") <- 10
# xz at its strongest preset (-9e): the same object, 30 KB less of the
# installed package (R CMD check's 5 MB)
con <- xzfile("inst/extdata/example.rds", "wb", compression = -9)
saveRDS(rec, con)
close(con)
